//! Media: each lane inside a medium samples its free flight; lanes that scatter there take a
//! light sample through the phase function, an equiangular sample and a phase-sampled
//! continuation, and lanes that pass go on to their surface.
//!
//! Lane math throughout, except the equiangular set-ups, which stay per lane in f64 (their
//! accuracy as the light nears the ray line is the point of [`Equiangular`]'s formulation).

use super::bsdf::Chan;
use super::ctx::{Ctx, DIM_MEDIA, DIMS_PER_SEGMENT};
use super::light::lane_radiance;
use super::state::{
    M, MAX_W, Paths, Scratch3, ScratchC, U, chan_lane, finite, gdot, mask_from_bits,
    power_heuristic, select_c,
};
use super::surface::Surface;
use super::transport::{ChannelArray, MediumOps, Transport};
use super::{RenderStats, roulette, shadow};
use crate::geometry::{Ray, offset_ray_origin, offset_ray_origin_lanes};
use crate::medium::{Equiangular, lanes};
use crate::scene::lights::{EquiangularTarget, LightSource};
use crate::scene::packet::PacketHit;
use crate::scene::primitives::NO_MEDIUM;
use crate::simd::{Float, Mask, UInt, V3};
use crate::spectrum::Channels;
use glam::Vec3;

/// The lanes in `m` cross the surface they hit, a medium's boundary or a dielectric's
/// interface: each takes the medium beyond it.
#[inline(always)]
pub(super) fn cross<F: Float, T: Transport, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
    m: M<F>,
) {
    let prims = &ctx.scene.prims;
    let bits = m.bits();
    let mut inside = 0u32;
    for i in 0..F::WIDTH {
        if bits >> i & 1 != 0 {
            st.medium[i] = prims.medium_after_crossing(sf.prim[i], sf.front.lane(i), st.medium[i]);
            inside |= u32::from(st.medium[i] != NO_MEDIUM) << i;
        }
    }
    st.in_medium = st.in_medium.and_not(m) | mask_from_bits::<F>(inside);
}

/// Dimension `k` of a segment's block.
#[inline(always)]
fn plus<F: Float>(dim: U<F>, k: u32) -> U<F> {
    dim.wrapping_add(U::<F>::splat(k))
}

/// The free flight of every lane in `started` that is inside a medium, and the scattering
/// events it samples. Returns the lanes that scattered in a medium (their vertex is done);
/// the others that were in a medium have their throughput weighted for reaching their hit.
#[inline(always)]
pub(super) fn free_flight<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    hits: &PacketHit<F>,
    started: M<F>,
    stats: &mut RenderStats,
) -> M<F> {
    let inm = started & st.in_medium;
    if inm.none() {
        return inm;
    }
    let bits = inm.bits();
    let (mut sigma_s, mut sigma_t) = (ScratchC::<N>::new(), ScratchC::<N>::new());
    let mut g = [0.0f32; MAX_W];
    let mut dims = [0u32; MAX_W];
    let mut meds: [Option<T::Med>; MAX_W] = [None; MAX_W];
    for i in 0..F::WIDTH {
        if bits >> i & 1 != 0 {
            let med = T::medium(ctx, st.medium[i], &T::lane(&st.lam, i));
            sigma_s.set(i, med.sigma_s());
            sigma_t.set(i, med.sigma_t());
            g[i] = med.g();
            meds[i] = Some(med);
            dims[i] = DIM_MEDIA.wrapping_add(st.segments[i].wrapping_mul(DIMS_PER_SEGMENT));
            st.segments[i] = st.segments[i].wrapping_add(1);
        }
    }
    let (sigma_s, sigma_t) = (sigma_s.load::<F>().0, sigma_t.load::<F>().0);
    let g = F::load(&g);
    let dim = U::<F>::from_fn(|i| dims[i]);
    let t_hit = F::select(hits.hit, hits.t, F::splat(f32::INFINITY));
    let sampler = &ctx.sampler;
    let u_c = sampler.get_1d_lanes::<F>(st.pixel, st.sample, dim);
    let u_t = sampler.get_1d_lanes::<F>(st.pixel, st.sample, plus::<F>(dim, 1));
    let probs = st.beta;
    let below_max = st.depth.lt(U::<F>::splat(ctx.max_depth));
    if ctx.equiangular && ctx.nee {
        equiangular_lanes::<F, T, N, MOTION>(ctx, st, inm & below_max, &meds, t_hit, &dims, stats);
    }
    let ff = lanes::sample_free_flight(&sigma_s, &sigma_t, t_hit, u_c, u_t, &probs.0);
    st.beta = select_c(inm, st.beta * Chan(ff.weight), st.beta);
    let scat = inm & ff.scatter;
    // Passing lanes go on to their hit, unless the flight left them nothing.
    st.alive = st
        .alive
        .and_not(inm.and_not(ff.scatter) & st.beta.is_zero());
    let live = scat & below_max;
    st.alive = st.alive.and_not(scat.and_not(live));
    if live.none() {
        return scat;
    }
    st.depth = U::<F>::select(live, st.depth.wrapping_add(U::<F>::splat(1)), st.depth);
    let t = ff.t;
    let p = st.o + st.d * t;
    let wo = -st.d;
    if ctx.nee {
        let u_sel = sampler.get_1d_lanes::<F>(st.pixel, st.sample, plus::<F>(dim, 2));
        let (ux, uy) = sampler.get_2d_lanes::<F>(st.pixel, st.sample, plus::<F>(dim, 3));
        let scene = ctx.scene;
        let mut sources = [LightSource::Environment; MAX_W];
        let ls = scene.lights.sample_lanes::<F, MOTION>(
            &scene.prims,
            p,
            live,
            u_sel,
            ux,
            uy,
            st.time,
            ctx.textures,
            (T::SPECTRAL || ctx.equiangular).then_some(&mut sources),
        );
        if ls.has.any() {
            let ph = lanes::hg_phase_dirs(wo, ls.wi, g);
            let w = if ctx.equiangular {
                let p_ff = lanes::free_flight_pdf(&sigma_t, t, &probs.0);
                let mut w = [0.0f32; MAX_W];
                let has = ls.has.bits();
                for (i, w) in w.iter_mut().enumerate().take(F::WIDTH) {
                    if has >> i & 1 != 0 {
                        let seg = Segment {
                            ray: Ray::new(st.o.lane(i), st.d.lane(i)),
                            t: t.lane(i),
                            t_hit: t_hit.lane(i),
                            p_ff: p_ff.lane(i),
                        };
                        let point = ls.at_point.lane(i).then(|| (ls.q.lane(i), ls.nq.lane(i)));
                        *w = medium_light_weight::<MOTION>(
                            ctx,
                            point,
                            ls.delta.lane(i),
                            sources[i],
                            ls.pdf.lane(i),
                            ph.lane(i),
                            p.lane(i),
                            &seg,
                            st.time.lane(i),
                        );
                    }
                }
                F::load(&w)
            } else {
                F::select(ls.delta, F::one(), power_heuristic(ls.pdf, ph))
            };
            let rad = lane_radiance(ctx, st, &ls, &sources, ls.has);
            let contrib = st.beta * rad * (ph * w / ls.pdf);
            let shoot = ls.has & !contrib.is_zero() & finite(&contrib);
            // A point in a medium lies on no surface: no offset at this end.
            let to_q = ls.q - p;
            let nt = V3::select(gdot(ls.nq, to_q).le(F::zero()), ls.nq, -ls.nq);
            let area = ls.at_point.and_not(ls.delta);
            let dir = V3::select(
                area,
                offset_ray_origin_lanes(ls.q, nt) - p,
                V3::select(ls.at_point, to_q, ls.wi),
            );
            let t_max = F::select(
                area,
                F::one(),
                F::select(ls.at_point, F::splat(1.0 - 1e-4), F::splat(f32::INFINITY)),
            );
            shadow::trace::<F, T, N, MOTION, true>(ctx, st, p, dir, t_max, contrib, shoot, stats);
        }
    }
    let (ux, uy) = sampler.get_2d_lanes::<F>(st.pixel, st.sample, plus::<F>(dim, 5));
    let (wi, pdf) = lanes::sample_hg(wo, g, ux, uy);
    st.prev_pdf = F::select(live, pdf, st.prev_pdf);
    st.specular = st.specular.and_not(live);
    st.prev_p = V3::select(live, p, st.prev_p);
    st.o = V3::select(live, p, st.o);
    st.d = V3::select(live, wi, st.d);
    roulette::russian_roulette(ctx, st, live, plus::<F>(dim, 7));
    scat
}

/// The equiangular technique's light sample for each lane in `m`, set up per lane (see
/// [`equiangular_nee`]), its shadow rays as a packet.
#[inline(always)]
fn equiangular_lanes<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    m: M<F>,
    meds: &[Option<T::Med>; MAX_W],
    t_hit: F,
    dims: &[u32; MAX_W],
    stats: &mut RenderStats,
) {
    let (mut o, mut d) = (Scratch3::new(), Scratch3::new());
    let mut t_max = [0.0f32; MAX_W];
    let mut contrib = ScratchC::<N>::new();
    let mut shoot = 0u32;
    let bits = m.bits();
    for i in 0..F::WIDTH {
        if bits >> i & 1 == 0 {
            continue;
        }
        let Some(med) = &meds[i] else {
            continue;
        };
        if let Some((ray, t, c)) =
            equiangular_nee::<F, T, N, MOTION>(ctx, st, i, med, t_hit.lane(i), dims[i])
        {
            o.set(i, ray.o);
            d.set(i, ray.d);
            t_max[i] = t;
            contrib.set(i, c);
            shoot |= 1 << i;
        }
    }
    if shoot != 0 {
        let shoot = mask_from_bits::<F>(shoot);
        shadow::trace::<F, T, N, MOTION, true>(
            ctx,
            st,
            o.v3(),
            d.v3(),
            F::load(&t_max),
            contrib.load(),
            shoot,
            stats,
        );
    }
}

/// Where free-flight sampling put a scattering event: the segment's ray, the distance, the
/// segment's end and the density of that distance (for MIS with equiangular sampling).
struct Segment {
    pub ray: Ray,
    pub t: f32,
    pub t_hit: f32,
    pub p_ff: f32,
}

/// Equiangular sampling (Kulla & Fajardo 2012): a scattering distance on the segment drawn
/// towards a chosen light, whose single-scattering contribution is combined with the other
/// techniques that produce the same path.
///
/// Point and spot lights: only free-flight distance + light sample also produces the path
/// (t, light); the two are weighted by the balance heuristic over the two distance densities
/// (the light choice probability is common to both).
///
/// Area lights: the path is the pair (t, y), y on the light, in the measure dt·dA(y).
/// Three techniques produce it:
/// - (a) free flight, then a light sample from x_t: `p_a = p_ff(t) · p_light(ω) · G`,
/// - (b) free flight, then a phase sample that hits y: `p_b = p_ff(t) · p_phase(ω) · G`,
/// - (c) here: y first (by area, see `Lights::pick_equiangular`), then t equiangular towards
///   y: `p_c = p_A(y) · p_eq(t|y)`,
///
/// with `G = |cos θ_y| / |y − x_t|²`. (a) and (b) keep the power-heuristic weights they have
/// without equiangular sampling, `w_b = p_b² / (p_a² + p_b²)`, and (a) hands part of its
/// share to (c) by the balance heuristic: `w_a = (1 − w_b) p_a / (p_a + p_c)`,
/// `w_c = (1 − w_b) p_c / (p_a + p_c)`. The three sum to 1 wherever any density is
/// non-zero (where (b) is the only one, `w_b = 1`), so the sum is unbiased. Every factor is
/// known at each technique's sample, and (b)'s weight does not involve (c), so emitters hit
/// by chance need nothing about the segment they were reached from.
// Always inlined: out of the lane kernels' `target_feature` entry points, the lane math it
// runs at width 1 would call `fmaf` for every fused multiply-add.
#[inline(always)]
fn equiangular_nee<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
>(
    ctx: &Ctx,
    st: &Paths<F, T, N>,
    i: usize,
    med: &T::Med,
    t_hit: f32,
    dim: u32,
) -> Option<(Ray, f32, T::S)> {
    let (pixel, index) = (st.pixel.lane(i), st.sample.lane(i));
    let ray = Ray::new(st.o.lane(i), st.d.lane(i));
    let (time, lambda) = (st.time.lane(i), &T::lane(&st.lam, i));
    let beta: T::S = chan_lane(&st.beta, i);
    let lights = &ctx.scene.lights;
    let prims = &ctx.scene.prims;
    let target = lights.pick_equiangular::<MOTION>(
        prims,
        &ray,
        t_hit,
        (
            ctx.sampler.get_1d(pixel, index, dim + 8),
            ctx.sampler.get_2d(pixel, index, dim + 10),
        ),
        time,
    )?;
    let u_t = ctx.sampler.get_1d(pixel, index, dim + 9);
    let wo = -ray.d;
    match target {
        EquiangularTarget::Point {
            index: li,
            light: pl,
            pmf,
        } => {
            let eq = Equiangular::new(ray.o, ray.d, 0.0, t_hit, pl.position)?;
            let (t, p_eq) = eq.sample(u_t);
            let x = ray.at(t);
            let d = pl.position - x;
            let d2 = d.length_squared();
            let wi = d / d2.sqrt();
            let radiance = T::point_radiance(ctx, li, pl.intensity, pl.falloff(-wi) / d2, lambda);
            let p_ff = med.distance_pdf(t, beta);
            let contrib = beta
                * med.sigma_s()
                * med.transmittance(t)
                * radiance
                * (med.phase(wo, wi) / (pmf * (p_eq + p_ff)));
            (contrib != T::S::ZERO && contrib.is_finite()).then_some((
                Ray::new(x, d),
                1.0 - 1e-4,
                contrib,
            ))
        }
        EquiangularTarget::Area {
            prim,
            p: y,
            n,
            density,
        } => {
            let eq = Equiangular::new(ray.o, ray.d, 0.0, t_hit, y)?;
            let (t, p_eq) = eq.sample(u_t);
            let x = ray.at(t);
            let ls = lights.area_seen_from::<MOTION>(prims, prim, (y, n), x, time, ctx.textures)?;
            let d = y - x;
            let d2 = d.length_squared();
            let g = n.dot(ls.wi).abs() / d2;
            let ph = med.phase(wo, ls.wi);
            let p_a = med.distance_pdf(t, beta) * ls.pdf * g;
            let p_c = density * p_eq;
            // f · w_c / p_c with f = β σs Tr(t) ph Le G (see above).
            let w = power_heuristic::<f32>(ls.pdf, ph) * g / (p_a + p_c);
            let contrib = beta
                * med.sigma_s()
                * med.transmittance(t)
                * T::light_radiance(ctx, &ls, lambda)
                * (ph * w);
            (contrib != T::S::ZERO && contrib.is_finite()).then_some((
                shadow_ray_to_area(x, y, n),
                1.0,
                contrib,
            ))
        }
    }
}

/// The MIS weight of a light sample (`point`, `delta`, `source`, solid-angle `pdf`) taken
/// from the scattering point `p` of `seg`, whose phase function gives `ph` towards it.
#[inline]
#[allow(clippy::too_many_arguments)]
fn medium_light_weight<const MOTION: bool>(
    ctx: &Ctx,
    point: Option<(Vec3, Vec3)>,
    delta: bool,
    source: LightSource,
    pdf: f32,
    ph: f32,
    p: Vec3,
    seg: &Segment,
    time: f32,
) -> f32 {
    match (point, source) {
        // The equiangular technique also produces this point light's scattering: weight by
        // the two distance densities.
        (Some((q, _)), _) if delta && ctx.equiangular => {
            Equiangular::new(seg.ray.o, seg.ray.d, 0.0, seg.t_hit, q)
                .map_or(1.0, |eq| seg.p_ff / (seg.p_ff + eq.pdf(seg.t)))
        }
        _ if delta => 1.0,
        // An area light: (a) of `equiangular_nee`'s three techniques.
        (Some((q, nq)), LightSource::Area { prim, .. }) if ctx.equiangular => {
            let d = q - p;
            let d2 = d.length_squared();
            let g = nq.dot(d).abs() / (d2 * d2.sqrt());
            let p_a = seg.p_ff * pdf * g;
            let p_c = Equiangular::new(seg.ray.o, seg.ray.d, 0.0, seg.t_hit, q)
                .map_or(0.0, |eq| eq.pdf(seg.t))
                * ctx.scene.lights.equiangular_area_density::<MOTION>(
                    &ctx.scene.prims,
                    prim,
                    nq,
                    &seg.ray,
                    seg.t_hit,
                    time,
                );
            let share = p_a / (p_a + p_c);
            power_heuristic::<f32>(pdf, ph) * if share.is_finite() { share } else { 1.0 }
        }
        _ => power_heuristic::<f32>(pdf, ph),
    }
}

/// A shadow ray from a point in a medium (on no surface: no offset at this end) to the point
/// `q` (normal `nq`) on an emitter, stopping just off its surface on the side facing `p`.
#[inline]
fn shadow_ray_to_area(p: Vec3, q: Vec3, nq: Vec3) -> Ray {
    let d = q - p;
    let nt = if nq.dot(d) <= 0.0 { nq } else { -nq };
    Ray::new(p, offset_ray_origin(q, nt) - p)
}

/// Width 1 (the splatting estimators' subpaths): what a path inside a medium does on its way
/// to its hit.
pub(super) enum Flight {
    /// It reaches the hit, its throughput weighted for passing.
    Passes,
    /// No throughput is left: the path ends.
    Ends,
    /// It scatters at `p`, at distance `t` along the ray, in a medium of asymmetry `g`; the
    /// event's dimensions are the segment's block from `dim` (the light choice and the lens
    /// point at 2 to 4, as [`free_flight`]'s light samples take them).
    Scatters { p: Vec3, t: f32, g: f32, dim: u32 },
}

/// Width 1: samples the free flight of the path `st`, inside a medium, towards `hits`, its
/// segments' dimensions in blocks from `base` (as [`free_flight`], without its light samples).
#[inline(always)]
pub(super) fn flight<T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<f32, T, N>,
    hits: &PacketHit<f32>,
    base: u32,
) -> Flight {
    let med = T::medium(ctx, st.medium[0], &T::lane(&st.lam, 0));
    let dim = base.wrapping_add(st.segments[0].wrapping_mul(DIMS_PER_SEGMENT));
    st.segments[0] = st.segments[0].wrapping_add(1);
    let u_c = ctx.sampler.get_1d(st.pixel, st.sample, dim);
    let u_t = ctx.sampler.get_1d(st.pixel, st.sample, dim + 1);
    let t_hit = if hits.hit { hits.t } else { f32::INFINITY };
    let ff = lanes::sample_free_flight::<f32, N>(
        &med.sigma_s().to_array(),
        &med.sigma_t().to_array(),
        t_hit,
        u_c,
        u_t,
        &st.beta.0,
    );
    st.beta = st.beta * Chan(ff.weight);
    if st.beta.is_zero() {
        Flight::Ends
    } else if ff.scatter {
        let p = st.o.lane(0) + st.d.lane(0) * ff.t;
        Flight::Scatters {
            p,
            t: ff.t,
            g: med.g(),
            dim,
        }
    } else {
        Flight::Passes
    }
}

/// Width 1: the path `st` scattered at `p` ([`Flight::Scatters`]) takes its next direction
/// from the phase function, then Russian roulette. Returns the direction's density.
#[inline(always)]
pub(super) fn scatter_phase<T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<f32, T, N>,
    p: Vec3,
    g: f32,
    dim: u32,
) -> f32 {
    let u = ctx.sampler.get_2d(st.pixel, st.sample, dim + 5);
    let (wi, pdf) = crate::medium::sample_hg(-st.d.lane(0), g, u);
    st.depth += 1;
    st.o = V3::splat(p);
    st.d = V3::splat(wi);
    st.prev_pdf = pdf;
    st.prev_p = V3::splat(p);
    st.specular = false;
    roulette::russian_roulette(ctx, st, true, dim + 7);
    pdf
}
