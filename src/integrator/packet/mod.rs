//! The packet kernel: one worker traces `F::WIDTH` paths at once, one per lane, their state in
//! lane-SoA registers, and refills a lane with the tile's next sample as soon as its path ends.
//!
//! ```text
//! refill → intersect (packet kd walk) → surfaces (per lane) → emission → light samples +
//!    ↑      shadow packet → BSDF per material class → roulette → film
//!    |____________________________________________________________|
//! ```
//!
//! Camera rays, the sampler, the kd walk and the analytic shapes' tests, rectangle light
//! samples, the BSDFs, MIS, Russian roulette and the throughput arithmetic run over lanes,
//! written once over [`Float`] with the scalar integrator's operations in the same order, so a
//! lane's path is the reference path up to rounding (and bit for bit where both use the same
//! lane functions). Still one lane at a time inside the packet: mesh and revolution tests,
//! surface reconstruction with its texture lookups, other lights' samples.
//!
//! Every effect variant runs here. Spectral paths carry four channels (`Chan<F, 4>`, one per
//! hero wavelength) and keep their wavelengths per lane, where the per-lane stages evaluate
//! the scene's spectra with the scalar transport's functions. With MEDIA, lanes inside a
//! medium sample their free flight and scatter there over lanes ([`medium`]); lanes that
//! meet a medium's boundary cross it over lanes.

mod medium;

use super::bsdf::{Chan, Dielectric, Diffuse, Frame, LaneChannels, Mirror, Mode};
use super::path::{self, Ctx, DIM_BOUNCE, DIMS_PER_BOUNCE, camera_rays, surface_material};
use super::transport::{ChannelArray, Transport};
use super::{RenderStats, Tile};
use crate::components::Material;
use crate::geometry::{Ray, offset_ray_origin_lanes};
use crate::simd::{Float, Mask, UInt, V3};
use crate::spectrum::Channels;
use crate::systems::light_lanes::LaneLightSample;
use crate::systems::packet::PacketHit;
use crate::systems::primitives::{NO_MEDIUM, emitted};
use glam::Vec3;

type U<F> = <F as Float>::U32;
type M<F> = <F as Float>::Mask;

/// The widest packet: scratch arrays for per-lane work are this long.
const MAX_W: usize = 16;

/// Channels of lanes: N = 3 for RGB, 4 for spectral.
type C<F, const N: usize> = Chan<F, N>;

/// Per-lane material classes after the surface stage.
const CLASS_NONE: u32 = 0;
const CLASS_DIFFUSE: u32 = 1;
const CLASS_MIRROR: u32 = 2;
const CLASS_DIELECTRIC: u32 = 3;
/// MEDIA: a medium's boundary, crossed without scattering.
const CLASS_BOUNDARY: u32 = 4;

/// The state of `F::WIDTH` paths, one per lane. Dead lanes hold stale values until refilled.
struct Paths<F: Float, T: Transport, const N: usize> {
    o: V3<F>,
    d: V3<F>,
    beta: C<F, N>,
    l: C<F, N>,
    /// Each lane's wavelengths (nothing in RGB).
    lam: [T::Lambda; MAX_W],
    eta_scale: F,
    depth: U<F>,
    specular: M<F>,
    prev_pdf: F,
    prev_p: V3<F>,
    time: F,
    pixel: U<F>,
    sample: U<F>,
    alive: M<F>,
    /// MEDIA: each lane's medium and the medium segments its path has sampled so far.
    medium: [u32; MAX_W],
    segments: [u32; MAX_W],
}

/// What the surface stage found at each lane's hit point.
struct Surface<F: Float, const N: usize> {
    hit: M<F>,
    p: V3<F>,
    /// Geometric and shading normals on the side the ray arrived from.
    nf: V3<F>,
    nsf: V3<F>,
    front: M<F>,
    class: U<F>,
    /// Albedo (Diffuse) or tint (Mirror), texture-modulated.
    color: C<F, N>,
    /// Each lane's material index (for a dielectric's IOR model) and primitive (for the
    /// medium behind a dielectric).
    mat: [u32; MAX_W],
    prim: [u32; MAX_W],
    /// Lanes that hit an emitter with non-zero radiance, the radiance and its MIS weight.
    emits: M<F>,
    le: C<F, N>,
    le_w: F,
}

#[inline(always)]
fn mask_from_bits<F: Float>(bits: u32) -> M<F> {
    M::<F>::from_fn(|i| bits >> i & 1 != 0)
}

#[inline(always)]
fn select_c<F: Float, const N: usize>(m: M<F>, a: C<F, N>, b: C<F, N>) -> C<F, N> {
    Chan(std::array::from_fn(|c| F::select(m, a.0[c], b.0[c])))
}

/// Lane `i` of channels `c` as the scalar transport's channels.
#[inline(always)]
fn chan_lane<F: Float, S: ChannelArray<N>, const N: usize>(c: &C<F, N>, i: usize) -> S {
    S::from_array(std::array::from_fn(|k| c.0[k].lane(i)))
}

/// Channels gathered one lane at a time, loaded into lanes afterwards.
struct ScratchC<const N: usize>([[f32; MAX_W]; N]);

impl<const N: usize> ScratchC<N> {
    #[inline(always)]
    fn new() -> Self {
        ScratchC([[0.0; MAX_W]; N])
    }
    #[inline(always)]
    fn set<S: ChannelArray<N>>(&mut self, i: usize, v: S) {
        for (k, c) in v.to_array().into_iter().enumerate() {
            self.0[k][i] = c;
        }
    }
    #[inline(always)]
    fn load<F: Float>(&self) -> C<F, N> {
        Chan(std::array::from_fn(|k| F::load(&self.0[k])))
    }
}

/// Per-lane results gathered one lane at a time, loaded into lanes afterwards.
struct Scratch3 {
    x: [f32; MAX_W],
    y: [f32; MAX_W],
    z: [f32; MAX_W],
}

impl Scratch3 {
    #[inline(always)]
    fn new() -> Self {
        Scratch3 {
            x: [0.0; MAX_W],
            y: [0.0; MAX_W],
            z: [0.0; MAX_W],
        }
    }
    #[inline(always)]
    fn set(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }
    #[inline(always)]
    fn v3<F: Float>(&self) -> V3<F> {
        V3::new(F::load(&self.x), F::load(&self.y), F::load(&self.z))
    }
}

/// glam's `Vec3::dot` over lanes: unfused, in the same order, so the decisions the scalar
/// integrator takes on glam's dot products come out the same.
#[inline(always)]
fn gdot<F: Float>(a: V3<F>, b: V3<F>) -> F {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// glam's `Vec3::normalize` over lanes.
#[inline(always)]
fn gnormalize<F: Float>(v: V3<F>) -> V3<F> {
    v * gdot(v, v).sqrt().recip()
}

/// `path::reflect_above` over lanes.
#[inline(always)]
fn reflect_above<F: Float>(r: V3<F>, n: V3<F>) -> V3<F> {
    let c = gdot(r, n);
    let flipped = gnormalize(r - n * (F::splat(2.0) * c));
    V3::select(c.ge(F::zero()), r, flipped)
}

/// `path::below` over lanes.
#[inline(always)]
fn below<F: Float>(wt: V3<F>, n: V3<F>) -> V3<F> {
    let c = gdot(wt, n);
    let flipped = gnormalize(wt - n * (F::splat(2.0) * c));
    V3::select(c.le(F::zero()), wt, flipped)
}

#[inline(always)]
fn power_heuristic<F: Float>(a: F, b: F) -> F {
    let (a2, b2) = (a * a, b * b);
    let s = a2 + b2;
    F::select(s.eq(F::zero()), F::zero(), a2 / s)
}

/// Starts new paths in the dead lanes, from the tile's next samples (pixel-major, as the
/// per-path integrator orders them).
#[inline(always)]
fn refill<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize, const MOTION: bool>(
    ctx: &Ctx,
    tile: &Tile,
    s0: u32,
    spp: usize,
    total: usize,
    next: &mut usize,
    st: &mut Paths<F, T, N>,
) {
    let mut x = [0u32; MAX_W];
    let mut y = [0u32; MAX_W];
    let mut idx = [0u32; MAX_W];
    let mut fresh = 0u32;
    let mut beta0 = ScratchC::<N>::new();
    let alive = st.alive.bits();
    for i in 0..F::WIDTH {
        if alive >> i & 1 == 0 && *next < total {
            let (p, k) = (*next / spp, *next % spp);
            (x[i], y[i]) = tile.pixel(p);
            idx[i] = s0 + k as u32;
            fresh |= 1 << i;
            *next += 1;
            st.medium[i] = ctx.scene.camera_medium;
            st.segments[i] = 0;
            if T::SPECTRAL {
                let lam = T::wavelengths(ctx, y[i] * ctx.width + x[i], idx[i]);
                beta0.set(i, T::initial_beta(&lam));
                st.lam[i] = lam;
            }
        }
    }
    if fresh == 0 {
        return;
    }
    let fm = mask_from_bits::<F>(fresh);
    let (xl, yl, il) = (
        U::<F>::from_fn(|i| x[i]),
        U::<F>::from_fn(|i| y[i]),
        U::<F>::from_fn(|i| idx[i]),
    );
    let cam = camera_rays::<F, MOTION>(ctx, xl, yl, il);
    st.o = V3::select(fm, cam.o, st.o);
    st.d = V3::select(fm, cam.d, st.d);
    st.time = F::select(fm, cam.time, st.time);
    let beta0 = if T::SPECTRAL {
        beta0.load()
    } else {
        C::<F, N>::splat(F::one())
    };
    st.beta = select_c(fm, beta0, st.beta);
    st.l = select_c(fm, C::<F, N>::splat(F::zero()), st.l);
    st.eta_scale = F::select(fm, F::one(), st.eta_scale);
    st.depth = U::<F>::select(fm, U::<F>::splat(0), st.depth);
    st.specular = st.specular.and_not(fm);
    st.prev_pdf = F::select(fm, F::zero(), st.prev_pdf);
    st.prev_p = V3::select(fm, cam.o, st.prev_p);
    let pixel = yl.wrapping_mul(U::<F>::splat(ctx.width)).wrapping_add(xl);
    st.pixel = U::<F>::select(fm, pixel, st.pixel);
    st.sample = U::<F>::select(fm, il, st.sample);
    st.alive |= fm;
}

impl<F: Float, const N: usize> C<F, N> {
    #[inline(always)]
    fn is_zero(&self) -> M<F> {
        let mut z = self.0[0].eq(F::zero());
        for c in &self.0[1..] {
            z &= c.eq(F::zero());
        }
        z
    }
    /// The largest channel (the scalar `max_element`).
    #[inline(always)]
    fn max_element(&self) -> F {
        let mut m = self.0[0];
        for &c in &self.0[1..] {
            m = m.max(c);
        }
        m
    }
}

/// What lies at each lane's closest hit, one lane at a time: the surface, its textures and
/// material, and for emitters their radiance with its MIS weight.
#[inline(always)]
fn surfaces<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    st: &Paths<F, T, N>,
    hits: &PacketHit<F>,
    at: M<F>,
) -> Surface<F, N> {
    let scene = ctx.scene;
    let prims = &scene.prims;
    let (mut p, mut n, mut ns) = (Scratch3::new(), Scratch3::new(), Scratch3::new());
    let (mut color, mut le) = (ScratchC::<N>::new(), ScratchC::<N>::new());
    let mut class = [CLASS_NONE; MAX_W];
    let mut mats = [0u32; MAX_W];
    let mut prim = [0u32; MAX_W];
    let mut le_w = [0.0f32; MAX_W];
    let (mut hit_bits, mut front_bits, mut emit_bits) = (0u32, 0u32, 0u32);
    let found = (hits.hit & at).bits();
    for i in 0..F::WIDTH {
        if found >> i & 1 == 0 {
            continue;
        }
        let ray = Ray::new(st.o.lane(i), st.d.lane(i));
        let time = st.time.lane(i);
        let Some(hit) = hits.lane(i) else {
            continue;
        };
        let mat = prims.material[hit.prim as usize];
        hit_bits |= 1 << i;
        mats[i] = mat;
        prim[i] = hit.prim;
        let (sp, material, tex_albedo) = surface_material::<MOTION>(ctx, &ray, &hit, time);
        let lam = &st.lam[i];
        p.set(i, sp.p);
        n.set(i, sp.facing());
        ns.set(i, sp.shading_facing());
        front_bits |= (sp.front as u32) << i;
        match material {
            Material::Diffuse { albedo } => {
                class[i] = CLASS_DIFFUSE;
                color.set(
                    i,
                    T::reflectance(ctx, mat, albedo, tex_albedo.is_some(), lam),
                );
            }
            Material::Mirror { tint } => {
                class[i] = CLASS_MIRROR;
                color.set(i, T::reflectance(ctx, mat, tint, tex_albedo.is_some(), lam));
            }
            Material::Dielectric { .. } => class[i] = CLASS_DIELECTRIC,
            Material::Light { .. } => {
                let radiance = emitted(&material, sp.n, -ray.d);
                if radiance != Vec3::ZERO {
                    emit_bits |= 1 << i;
                    le.set(i, T::emission(ctx, mat, radiance, tex_albedo, lam));
                    let (depth, specular) = (st.depth.lane(i), st.specular.lane(i));
                    le_w[i] = if depth == 0 || specular || !ctx.nee {
                        1.0
                    } else {
                        let pdf = scene.lights.pdf_area::<MOTION>(
                            prims,
                            hit.prim,
                            st.prev_p.lane(i),
                            sp.p,
                            sp.n,
                            time,
                        );
                        path::power_heuristic(st.prev_pdf.lane(i), pdf)
                    };
                }
            }
            // Only MEDIA scenes have boundaries.
            Material::Boundary => class[i] = if MEDIA { CLASS_BOUNDARY } else { CLASS_NONE },
        }
    }
    Surface {
        hit: mask_from_bits::<F>(hit_bits),
        p: p.v3(),
        nf: n.v3(),
        nsf: ns.v3(),
        front: mask_from_bits::<F>(front_bits),
        class: U::<F>::from_fn(|i| class[i]),
        color: color.load(),
        mat: mats,
        prim,
        emits: mask_from_bits::<F>(emit_bits),
        le: le.load(),
        le_w: F::load(&le_w),
    }
}

/// Next-event estimation at the diffuse lanes `dm`: a light sample per lane, its BSDF value
/// and MIS weight over lanes, then a shadow ray per lane whose contribution is not zero.
#[inline(always)]
fn light_samples<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
    dm: M<F>,
    frame: &Frame<F>,
    dim: U<F>,
    stats: &mut RenderStats,
) {
    let wo_l = frame.to_local(-st.d);
    let scene = ctx.scene;
    let prims = &scene.prims;
    let u_sel = ctx.sampler.get_1d_lanes::<F>(st.pixel, st.sample, dim);
    let (ux, uy) =
        ctx.sampler
            .get_2d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(1)));
    let ls = scene.lights.sample_lanes::<F, MOTION>(
        prims,
        sf.p,
        dm,
        u_sel,
        ux,
        uy,
        st.time,
        ctx.textures,
        T::SPECTRAL,
    );
    let wi = ls.wi;
    let wi_l = frame.to_local(wi);
    let cos = wi_l.z;
    let ok = ls.has & cos.gt(F::zero()) & gdot(wi, sf.nf).gt(F::zero());
    if ok.none() {
        return;
    }
    let bsdf = Diffuse { albedo: sf.color };
    let bsdf_pdf = bsdf.pdf(wo_l, wi_l);
    let f = bsdf.eval(wo_l, wi_l) * cos;
    let pdf = ls.pdf;
    let w = F::select(ls.delta, F::one(), power_heuristic(pdf, bsdf_pdf));
    let rad = lane_radiance(ctx, st, &ls, ok);
    let contrib = st.beta * f * rad * (w / pdf);
    let shoot = ok & !contrib.is_zero();
    let (so, sd, t_max) = shadow_rays(sf.p, sf.nf, &ls);
    if MEDIA {
        medium::shadows::<F, T, N, MOTION>(ctx, st, so, sd, t_max, contrib, shoot, stats);
        return;
    }
    stats.shadow_rays += u64::from(shoot.count());
    let blocked = scene.occluded_packet::<F, MOTION>(so, sd, shoot, t_max, st.time);
    let lit = shoot.and_not(blocked);
    st.l = select_c(lit, st.l + contrib, st.l);
}

/// Each lane's light-sample radiance in the transport's channels, for the lanes in `m`.
#[inline(always)]
fn lane_radiance<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    st: &Paths<F, T, N>,
    ls: &LaneLightSample<F>,
    m: M<F>,
) -> C<F, N> {
    if T::SPECTRAL {
        let mut rad = ScratchC::<N>::new();
        let bits = m.bits();
        for i in 0..F::WIDTH {
            if bits >> i & 1 != 0 {
                let rgb = ls.radiance.lane(i);
                rad.set(i, T::source_radiance(ctx, &ls.sources[i], rgb, &st.lam[i]));
            }
        }
        rad.load()
    } else {
        // RGB: N = 3.
        let r = [ls.radiance.x, ls.radiance.y, ls.radiance.z];
        Chan(std::array::from_fn(|k| r[k]))
    }
}

/// `path::shadow_ray_from_surface` over lanes: towards the sampled point of an area light
/// (offset at both ends), a point light's position, or along `wi` to infinity.
#[inline(always)]
fn shadow_rays<F: Float>(p: V3<F>, nf: V3<F>, ls: &LaneLightSample<F>) -> (V3<F>, V3<F>, F) {
    // Area lights: `spawn_ray_to`.
    let d = ls.q - p;
    let n = V3::select(gdot(nf, d).ge(F::zero()), nf, -nf);
    let o_area = offset_ray_origin_lanes(p, n);
    let nt = V3::select(gdot(ls.nq, d).le(F::zero()), ls.nq, -ls.nq);
    let end = offset_ray_origin_lanes(ls.q, nt);
    // Point lights and the environment leave from the surface's own side.
    let o_up = offset_ray_origin_lanes(p, nf);
    let area = ls.at_point.and_not(ls.delta);
    let o = V3::select(area, o_area, o_up);
    let dir = V3::select(
        area,
        end - o_area,
        V3::select(ls.at_point, ls.q - o_up, ls.wi),
    );
    let t_max = F::select(
        area,
        F::one(),
        F::select(ls.at_point, F::splat(1.0 - 1e-4), F::splat(f32::INFINITY)),
    );
    (o, dir, t_max)
}

/// Renders samples `s0..s1` of every pixel of `tile` with packets of `F::WIDTH` paths, adding
/// each finished path's radiance to `film` (the tile's pixels, row-major).
#[inline(always)]
pub fn render_tile<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    tile: &Tile,
    s0: u32,
    s1: u32,
    film: &mut [[f64; 3]],
    stats: &mut RenderStats,
) {
    let spp = (s1 - s0) as usize;
    let total = tile.pixels() * spp;
    let mut next = 0usize;
    let zero3 = V3::<F>::zero();
    let mut st = Paths::<F, T, N> {
        o: zero3,
        d: zero3,
        beta: C::<F, N>::splat(F::zero()),
        l: C::<F, N>::splat(F::zero()),
        lam: [T::Lambda::default(); MAX_W],
        eta_scale: F::one(),
        depth: U::<F>::splat(0),
        specular: M::<F>::splat(false),
        prev_pdf: F::zero(),
        prev_p: zero3,
        time: F::zero(),
        pixel: U::<F>::splat(0),
        sample: U::<F>::splat(0),
        alive: M::<F>::splat(false),
        medium: [NO_MEDIUM; MAX_W],
        segments: [0; MAX_W],
    };
    let scene = ctx.scene;
    let env = scene.environment;
    let max_depth = U::<F>::splat(ctx.max_depth);
    loop {
        refill::<F, T, N, MOTION>(ctx, tile, s0, spp, total, &mut next, &mut st);
        let started = st.alive;
        if started.none() {
            break;
        }
        stats.rays += started.count() as u64;
        stats.lane_slots += F::WIDTH as u64;
        let hits = scene.intersect_packet::<F, MOTION>(st.o, st.d, st.alive, st.time);
        // MEDIA: lanes in a medium first sample their flight; those that scatter there are
        // done with this vertex, the rest reach their hit.
        let in_medium = if MEDIA {
            medium::medium_stage::<F, T, N, MOTION>(ctx, &mut st, &hits, started, stats)
        } else {
            M::<F>::splat(false)
        };
        let at = st.alive.and_not(in_medium);
        let sf = surfaces::<F, T, N, MOTION, MEDIA>(ctx, &st, &hits, at);
        // Misses see the environment.
        let miss = at.and_not(sf.hit);
        if env != Vec3::ZERO && miss.any() {
            let first = st.depth.eq(U::<F>::splat(0)) | st.specular | M::<F>::splat(!ctx.nee);
            let w = F::select(
                first,
                F::one(),
                power_heuristic(st.prev_pdf, F::splat(scene.lights.pdf_environment())),
            );
            let e = if T::SPECTRAL {
                let mut e = ScratchC::<N>::new();
                let bits = miss.bits();
                for i in 0..F::WIDTH {
                    if bits >> i & 1 != 0 {
                        e.set(i, T::environment(ctx, &st.lam[i]));
                    }
                }
                e.load()
            } else {
                // RGB: N = 3.
                let e = [env.x, env.y, env.z];
                Chan(std::array::from_fn(|k| F::splat(e[k])))
            };
            st.l = select_c(miss, st.l + st.beta * e * w, st.l);
        }
        // Emitters add their radiance and absorb the rest.
        st.l = select_c(sf.emits, st.l + st.beta * sf.le * sf.le_w, st.l);
        let boundary = sf.hit & sf.class.eq(U::<F>::splat(CLASS_BOUNDARY));
        let scatters = !sf.class.eq(U::<F>::splat(CLASS_NONE)) & !boundary;
        let surface = sf.hit & scatters & st.depth.lt(max_depth);
        st.alive = (st.alive & in_medium) | surface | boundary;
        if surface.any() {
            scatter::<F, T, N, MOTION, MEDIA>(ctx, &mut st, &sf, surface, stats);
        }
        if MEDIA && boundary.any() {
            // Carry on in the same direction, in the medium beyond.
            st.o = V3::select(boundary, offset_ray_origin_lanes(sf.p, -sf.nf), st.o);
            let bits = boundary.bits();
            let prims = &scene.prims;
            for i in 0..F::WIDTH {
                if bits >> i & 1 != 0 {
                    st.medium[i] =
                        prims.medium_after_crossing(sf.prim[i], sf.front.lane(i), st.medium[i]);
                }
            }
        }
        // Finished paths go to the film.
        let ended = started.and_not(st.alive).bits();
        for i in 0..F::WIDTH {
            if ended >> i & 1 != 0 {
                let l = T::to_rgb(chan_lane(&st.l, i), &st.lam[i]);
                super::accumulate(film, tile, ctx.width, st.pixel.lane(i), l, stats);
            }
        }
    }
}

/// One scattering event in every lane of `live`: light samples at diffuse lanes, then a BSDF
/// sample per material class present, then Russian roulette.
#[inline(always)]
fn scatter<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
    live: M<F>,
    stats: &mut RenderStats,
) {
    let dim = U::<F>::splat(DIM_BOUNCE)
        .wrapping_add(st.depth.wrapping_mul(U::<F>::splat(DIMS_PER_BOUNCE)));
    st.depth = U::<F>::select(live, st.depth.wrapping_add(U::<F>::splat(1)), st.depth);
    let wo = -st.d;
    let frame = Frame::from_normal(sf.nsf);
    let wo_l = frame.to_local(wo);
    let class = |c: u32| live & sf.class.eq(U::<F>::splat(c));
    let (dm, mm, em) = (
        class(CLASS_DIFFUSE),
        class(CLASS_MIRROR),
        class(CLASS_DIELECTRIC),
    );
    let up = offset_ray_origin_lanes(sf.p, sf.nf);
    let mut scattered = M::<F>::splat(false);
    if dm.any() {
        if ctx.nee {
            light_samples::<F, T, N, MOTION, MEDIA>(ctx, st, sf, dm, &frame, dim, stats);
        }
        let (ux, uy) =
            ctx.sampler
                .get_2d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(4)));
        let bs = Diffuse { albedo: sf.color }.sample(wo_l, ux, uy);
        let wi = frame.to_world(bs.wi).normalize();
        // Sampled around a tilted shading normal into the geometric back side: absorbed.
        let ok = dm & gdot(wi, sf.nf).gt(F::zero());
        st.alive = st.alive.and_not(dm.and_not(ok));
        st.beta = select_c(ok, st.beta * bs.weight, st.beta);
        st.prev_pdf = F::select(ok, bs.pdf, st.prev_pdf);
        st.specular = st.specular.and_not(ok);
        st.o = V3::select(ok, up, st.o);
        st.d = V3::select(ok, wi, st.d);
        scattered |= ok;
    }
    if mm.any() {
        let bs = Mirror { tint: sf.color }.sample(wo_l);
        st.beta = select_c(mm, st.beta * bs.weight, st.beta);
        st.specular |= mm;
        let wi = frame.to_world(bs.wi);
        st.o = V3::select(mm, up, st.o);
        st.d = V3::select(mm, reflect_above(wi, sf.nf), st.d);
        scattered |= mm;
    }
    if em.any() {
        // The IOR per lane; a dispersive one ends the lane's secondary wavelengths.
        let prims = &ctx.scene.prims;
        let mut ior = [1.0f32; MAX_W];
        let mut beta = ScratchC::<N>::new();
        let bits = em.bits();
        for (i, n) in ior.iter_mut().enumerate().take(F::WIDTH) {
            if bits >> i & 1 != 0 {
                let Material::Dielectric { ior: model } = prims.materials[sf.mat[i] as usize]
                else {
                    continue;
                };
                // RGB transport's `eta` leaves the throughput alone.
                let mut b: T::S = if T::SPECTRAL {
                    chan_lane(&st.beta, i)
                } else {
                    T::S::ONE
                };
                *n = T::eta(&model, &mut st.lam[i], &mut b);
                if T::SPECTRAL {
                    beta.set(i, b);
                }
            }
        }
        if T::SPECTRAL {
            st.beta = select_c(em, beta.load(), st.beta);
        }
        let ior = F::load(&ior);
        let eta = F::select(sf.front, ior, ior.recip());
        let u =
            ctx.sampler
                .get_1d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(3)));
        let bsdf = Dielectric {
            eta,
            schlick: ctx.schlick,
        };
        let bs = bsdf.sample::<C<F, N>>(wo_l, u, Mode::Radiance);
        st.specular |= em;
        st.beta = select_c(em, st.beta * bs.weight, st.beta);
        let wi = frame.to_world(bs.wi);
        let t = em & bs.is_transmission();
        st.eta_scale = F::select(t, st.eta_scale * (bs.eta * bs.eta), st.eta_scale);
        let down = offset_ray_origin_lanes(sf.p, -sf.nf);
        let o = V3::select(t, down, up);
        let d = V3::select(t, below(wi, sf.nf), reflect_above(wi, sf.nf));
        if MEDIA {
            let bits = t.bits();
            let prims = &ctx.scene.prims;
            for i in 0..F::WIDTH {
                if bits >> i & 1 != 0 {
                    st.medium[i] =
                        prims.medium_after_crossing(sf.prim[i], sf.front.lane(i), st.medium[i]);
                }
            }
        }
        st.o = V3::select(em, o, st.o);
        st.d = V3::select(em, d, st.d);
        scattered |= em;
    }
    st.prev_p = V3::select(scattered, sf.p, st.prev_p);
    russian_roulette(ctx, st, scattered, dim.wrapping_add(U::<F>::splat(6)));
}

/// `path::russian_roulette` over lanes, for the lanes in `m`.
#[inline(always)]
fn russian_roulette<F: Float, T: Transport, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    m: M<F>,
    dim: U<F>,
) {
    let deep = m & !st.depth.lt(U::<F>::splat(ctx.rr_depth));
    if deep.any() {
        let rr = (st.beta * st.eta_scale).max_element();
        let low = deep & rr.lt(F::one());
        if low.any() {
            let q = (F::one() - rr).max(F::zero());
            let u = ctx.sampler.get_1d_lanes::<F>(st.pixel, st.sample, dim);
            let kill = low & u.lt(q);
            st.alive = st.alive.and_not(kill);
            let keep = low.and_not(kill);
            let k = F::one() - q;
            st.beta = select_c(keep, Chan(st.beta.0.map(|c| c / k)), st.beta);
        }
    }
    st.alive = st.alive.and_not(m & st.beta.is_zero());
}
