//! Bidirectional path tracing (Veach 1997, ch. 10): per camera sample, a camera subpath and a
//! light subpath, and every way of joining them. Strategy (s, t) takes the first `s` vertices
//! of the light subpath and the first `t` of the camera subpath:
//!
//! - `s = 0`: the camera subpath hits an emitter;
//! - `s = 1`: a camera vertex samples a light point of its own, as next-event estimation does;
//! - `t = 1`: a light vertex connects to the camera and splats, as light tracing does;
//! - otherwise a camera vertex and a light vertex connect through a shadow ray.
//!
//! Each contribution is weighted by the power heuristic over every strategy that could have
//! made the same path, computed from ratios of neighbouring densities (the recurrence of
//! pbrt's BDPT): no product of densities that could underflow or overflow.
//!
//! Both subpaths run through the kernel's own stages at width 1: the surface stage, and the
//! material stage with a vertex hook that keeps the BSDF for later connections. The light
//! subpath carries importance (BSDFs sampled in importance mode, Veach's shading-normal
//! correction), as in [`super::light_tracer`]. Both carry the camera sample's four hero
//! wavelengths; a connection keeps the hero alone when either side's vertices dispersed.
//! Like light tracing, the estimator splats: each work item adds its values in fixed point,
//! so the image is the same on any thread count.
//!
//! MEDIA: both subpaths sample their free flight inside a medium; a scattering event there
//! is a vertex whose phase function connects as a BSDF does (no cosine, its own adjoint), and
//! every connection carries the transmittance along it, across media's boundaries. The MIS
//! densities include free flight as a grey medium would sample it (each medium's mean σt):
//! a strategy that would have to cross a thick stretch of fog by chance weighs less than one
//! that connects across it. The σt of a vertex in a medium is the same whichever side
//! generates it and cancels in the ratios; each segment's transmittance stays. Weights are
//! unbiased with any densities so long as every strategy of a path computes the same ones.

use super::bsdf::{Frame, LaneChannels, Mode};
use super::ctx::{Ctx, DIM_BOUNCE, DIM_MEDIA, DIMS_PER_BOUNCE};
use super::light::Glossy;
use super::light_tracer::{Camera, Splats, path_state};
use super::material::{self, Vertex};
use super::media::Flight;
use super::microfacet::RoughDielectric;
use super::state::{C, M, MAX_W, Paths, U};
use super::surface::{CLASS_BOUNDARY, CLASS_NONE, Surface};
use super::transport::{ChannelArray, Transport};
use super::{Observer, RenderOptions, RenderOutput, RenderStats};
use crate::components::Material;
use crate::film::{Tile, TileWork};
use crate::geometry::{Ray, offset_ray_origin};
use crate::scene::RenderScene;
use crate::scene::lights::LightKind;
use crate::scene::primitives::NO_MEDIUM;
use crate::scene_file::schema::Estimator;
use crate::simd::V3;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// First sample dimension of the light subpath: its emission takes the block there, event k
/// the block `k + 1` after it. Far from the camera subpath's events and the media's range.
pub const DIM_LIGHT_PATH: u32 = 1 << 21;

/// MEDIA: first sample dimension of the light subpath's medium segments, as [`DIM_MEDIA`]
/// is the camera subpath's.
const DIM_LIGHT_MEDIA: u32 = DIM_LIGHT_PATH + DIM_MEDIA;

/// Which strategies a render adds (a debugging view, as pbrt's `visualize_strategies`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategies {
    /// Every strategy, MIS-weighted: the estimator.
    All,
    /// Strategy (s, t) alone and unweighted (paths of `s + t - 1` edges).
    Only {
        /// Vertices from the light subpath.
        s: u32,
        /// Vertices from the camera subpath.
        t: u32,
    },
    /// Strategy (s, t) alone with its MIS weight: its share of the estimator's image.
    Weighted {
        /// Vertices from the light subpath.
        s: u32,
        /// Vertices from the camera subpath.
        t: u32,
    },
}

/// The BSDF parts the material stage builds at a vertex with a density, kept for its later
/// connections.
#[derive(Clone, Copy)]
struct GlossyParts {
    plastic: bool,
    conductor: bool,
    dielectric: bool,
    rough_dielectric: RoughDielectric<f32>,
}

/// What scatters at a connectible vertex: a surface's BSDF, or a medium's phase function
/// (Henyey–Greenstein, asymmetry `g`).
// Unboxed: vertices live in buffers reused from sample to sample, and a box would allocate
// per vertex.
#[allow(clippy::large_enum_variant)]
enum Scatter<const N: usize> {
    Surface(Surface<f32, N>, GlossyParts),
    Phase(f32),
}

/// A vertex of either subpath.
struct Vtx<T: Transport, const N: usize> {
    /// The point; at infinity, the unit direction towards it from the scene.
    p: Vec3,
    /// On the environment: the light subpath's start there, or where the camera subpath
    /// escaped.
    inf: bool,
    /// The geometric normal, on the side the subpath arrived from (an area emitter's own
    /// normal at the light subpath's start; zero at the camera, at a point light and at
    /// infinity).
    ng: Vec3,
    /// Unit direction towards the previous vertex.
    wo: Vec3,
    /// The subpath's throughput on arrival, and its wavelengths.
    beta: C<f32, N>,
    lam: T::Lanes<f32>,
    /// Area densities of generating this vertex from the previous one (forward) and from the
    /// next (reverse), as the subpath's own sampling would.
    fwd: f32,
    rev: f32,
    /// MEDIA: the probability, in the MIS densities, that a free flight crosses the segment
    /// from the previous vertex to this one ([`passes`]); 1 at a subpath's start.
    pass: f32,
    /// The BSDF sampled a delta lobe here.
    delta: bool,
    /// The BSDF or phase function at a vertex with a density (one that connects).
    bsdf: Option<Scatter<N>>,
    /// MEDIA: the medium the subpath arrived in (at its start: the one it leaves into).
    medium: u32,
    /// The camera subpath's emitter hit: radiance towards the previous vertex, primitive.
    emits: Option<(C<f32, N>, u32)>,
    /// The first sample dimension of the event at this vertex.
    dim: u32,
}

impl<T: Transport, const N: usize> Vtx<T, N> {
    /// A vertex at `p` (a direction when `inf`) with normal `ng`, reached with throughput
    /// `beta` at wavelengths `lam` and generated with area density `fwd`; nothing is known
    /// of its neighbours or sampled from it yet.
    #[inline(always)]
    fn start(
        p: Vec3,
        inf: bool,
        ng: Vec3,
        beta: C<f32, N>,
        lam: T::Lanes<f32>,
        fwd: f32,
        dim: u32,
    ) -> Self {
        Vtx {
            p,
            inf,
            ng,
            wo: Vec3::ZERO,
            beta,
            lam,
            fwd,
            rev: 0.0,
            pass: 1.0,
            delta: false,
            bsdf: None,
            medium: NO_MEDIUM,
            emits: None,
            dim,
        }
    }
}

/// The material stage's hook on BDPT subpaths: nothing is connected during the walk; the
/// BSDF parts of a vertex with a density are kept. `LIGHT` subpaths carry importance.
struct Keep<const LIGHT: bool> {
    parts: Option<GlossyParts>,
}

impl<T: Transport<S: ChannelArray<N>>, const N: usize, const LIGHT: bool> Vertex<f32, T, N>
    for Keep<LIGHT>
{
    const MODE: Mode = if LIGHT {
        Mode::Importance
    } else {
        Mode::Radiance
    };

    #[inline(always)]
    fn connect<const MOTION: bool, const MEDIA: bool>(
        &mut self,
        _: &Ctx,
        _: &mut Paths<f32, T, N>,
        _: &Surface<f32, N>,
        m: M<f32>,
        glossy: &Glossy<'_, f32>,
        _: &Frame<f32>,
        _: U<f32>,
        _: &mut RenderStats,
    ) {
        if m {
            self.parts = Some(GlossyParts {
                plastic: glossy.plastic,
                conductor: glossy.conductor,
                dielectric: glossy.dielectric,
                rough_dielectric: glossy.rough_dielectric,
            });
        }
    }
}

/// The BSDF of a connectible vertex, as the material stage evaluates it.
struct Bsdf<'a, const N: usize> {
    sf: &'a Surface<f32, N>,
    glossy: Glossy<'a, f32>,
    frame: Frame<f32>,
}

impl<'a, const N: usize> Bsdf<'a, N> {
    #[inline(always)]
    fn new(ctx: &'a Ctx, sf: &'a Surface<f32, N>, g: &GlossyParts) -> Self {
        Bsdf {
            sf,
            glossy: Glossy {
                plastic: g.plastic,
                coat: &ctx.scene.prims.coat,
                conductor: g.conductor,
                dielectric: g.dielectric,
                rough_dielectric: g.rough_dielectric,
            },
            frame: sf.frame(),
        }
    }

    #[inline(always)]
    fn local(&self, w: Vec3) -> V3<f32> {
        self.frame.to_local(V3::splat(w))
    }

    /// The solid-angle density of sampling `wi` given `wo` (world directions). From the far
    /// side of a rough dielectric (a reverse density across the interface) it is the
    /// interface seen from there: the normal flipped and the relative IOR inverted.
    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = (self.local(wo), self.local(wi));
        if self.glossy.dielectric && wo.z < 0.0 {
            let mut far = self.glossy.rough_dielectric;
            far.eta = far.eta.recip();
            let flip = |v: V3<f32>| V3::new(v.x, v.y, -v.z);
            return far.pdf(flip(wo), flip(wi));
        }
        self.glossy.eval(self.sf, wo, wi, Mode::Radiance).1
    }

    /// At a camera vertex: f |cos| towards `wi` seen from `wo`, with next-event estimation's
    /// rules (above both normals, or through a rough dielectric), and the density of
    /// sampling `wi`.
    #[inline(always)]
    fn camera_side(&self, wo: Vec3, wi: Vec3) -> Option<(C<f32, N>, f32)> {
        let (wo_l, wi_l) = (self.local(wo), self.local(wi));
        let side = wi.dot(self.sf.nf.lane(0));
        let through = self.glossy.dielectric && wi_l.z < 0.0 && side < 0.0;
        if !((wi_l.z > 0.0 && side > 0.0) || through) {
            return None;
        }
        let (f, pdf) = self.glossy.eval(self.sf, wo_l, wi_l, Mode::Radiance);
        Some((f * wi_l.z.abs(), pdf))
    }

    /// At a light vertex reached from `wl`: the adjoint BSDF towards `wc` with Veach's
    /// shading-normal factor, f |wl·n_s| |wc·n_g| / |wl·n_g| (light tracing's rules), and
    /// the density of sampling `wc`.
    #[inline(always)]
    fn light_side(&self, wl: Vec3, wc: Vec3) -> Option<(C<f32, N>, f32)> {
        let (wl_l, wc_l) = (self.local(wl), self.local(wc));
        let ng = self.sf.nf.lane(0);
        let side = wc.dot(ng);
        let through = self.glossy.dielectric && wc_l.z < 0.0 && side < 0.0;
        if !(wl_l.z > 0.0 && (side > 0.0 || through)) {
            return None;
        }
        let (f_imp, pdf) = self.glossy.eval(self.sf, wl_l, wc_l, Mode::Importance);
        let f = if through {
            f_imp
        } else {
            self.glossy.eval(self.sf, wc_l, wl_l, Mode::Radiance).0
        };
        let g = wl_l.z * side.abs() / wl.dot(ng).abs();
        Some((f * g, pdf))
    }
}

/// A connectible vertex's scattering as the strategies evaluate it: a surface's BSDF, or a
/// medium's phase function, which is its own adjoint and needs no shading-normal factor
/// (the vertex's throughput already holds σs).
enum Scatterer<'a, const N: usize> {
    Bsdf(Bsdf<'a, N>),
    Phase(f32),
}

/// The scattering at vertex `v`, if it connects.
#[inline(always)]
fn scatterer<'a, T: Transport, const N: usize>(
    ctx: &'a Ctx,
    v: &'a Vtx<T, N>,
) -> Option<Scatterer<'a, N>> {
    Some(match v.bsdf.as_ref()? {
        Scatter::Surface(sf, parts) => Scatterer::Bsdf(Bsdf::new(ctx, sf, parts)),
        Scatter::Phase(g) => Scatterer::Phase(*g),
    })
}

impl<const N: usize> Scatterer<'_, N> {
    /// See [`Bsdf::pdf`]; a phase function's density is its value.
    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Scatterer::Bsdf(b) => b.pdf(wo, wi),
            Scatterer::Phase(g) => crate::medium::hg_phase_dirs(wo, wi, *g),
        }
    }

    /// See [`Bsdf::camera_side`].
    #[inline(always)]
    fn camera_side(&self, wo: Vec3, wi: Vec3) -> Option<(C<f32, N>, f32)> {
        match self {
            Scatterer::Bsdf(b) => b.camera_side(wo, wi),
            Scatterer::Phase(g) => phase_value(wo, wi, *g),
        }
    }

    /// See [`Bsdf::light_side`].
    #[inline(always)]
    fn light_side(&self, wl: Vec3, wc: Vec3) -> Option<(C<f32, N>, f32)> {
        match self {
            Scatterer::Bsdf(b) => b.light_side(wl, wc),
            Scatterer::Phase(g) => phase_value(wl, wc, *g),
        }
    }
}

/// The phase function between `wo` and `wi` (both away from the point), as value and density.
#[inline(always)]
fn phase_value<const N: usize>(wo: Vec3, wi: Vec3, g: f32) -> Option<(C<f32, N>, f32)> {
    let p = crate::medium::hg_phase_dirs(wo, wi, g);
    (p > 0.0).then(|| (C::<f32, N>::splat(p), p))
}

/// MEDIA: the medium a connection leaving vertex `v` along `w` starts in: the one the subpath
/// arrived in, unless `w` leaves a surface on its far side, where it is the medium beyond.
#[inline(always)]
fn medium_toward<T: Transport, const N: usize>(ctx: &Ctx, v: &Vtx<T, N>, w: Vec3) -> u32 {
    match &v.bsdf {
        Some(Scatter::Surface(sf, _)) if w.dot(v.ng) < 0.0 => ctx
            .scene
            .prims
            .medium_after_crossing(sf.prim[0], sf.front, v.medium),
        _ => v.medium,
    }
}

/// Converts a solid-angle density at `from` towards `to` into an area density at `to`. A
/// direction at infinity keeps its solid-angle density; from infinity, `pdf` is the planar
/// density of the parallel rays' origins, and only `to`'s cosine converts it.
#[inline(always)]
fn density<T: Transport, const N: usize>(pdf: f32, from: &Vtx<T, N>, to: &Vtx<T, N>) -> f32 {
    if to.inf {
        return pdf;
    }
    let cos_to = |w: Vec3| {
        if to.ng == Vec3::ZERO {
            1.0
        } else {
            to.ng.dot(w).abs()
        }
    };
    if from.inf {
        return pdf * cos_to(from.p);
    }
    let d = to.p - from.p;
    let r2 = d.length_squared();
    if r2 == 0.0 {
        return 0.0;
    }
    pdf * cos_to(d / r2.sqrt()) / r2
}

/// MEDIA: the extinction with which the MIS densities follow medium `m`'s free flight: the
/// mean of its σt over the RGB channels. The sampler's own channel mixture depends on each
/// path's throughput, which a reverse density does not know; a grey stand-in is exact for
/// grey media and the same for every strategy.
#[inline(always)]
fn mis_extinction(ctx: &Ctx, m: u32) -> f32 {
    ctx.scene.prims.media[m as usize].sigma_t().element_sum() * (1.0 / 3.0)
}

/// The probability, in the MIS densities, of a free flight crossing a segment of grey
/// optical depth `depth`; 1 without MEDIA.
#[inline(always)]
fn passes<const MEDIA: bool>(depth: f32) -> f32 {
    if MEDIA { (-depth).exp() } else { 1.0 }
}

/// MEDIA: the grey optical depth of the stretches a transmittance query crosses
/// ([`super::light_tracer::transmittance`]'s `piece`), for the MIS densities.
struct Depth<'a, 'c> {
    ctx: &'a Ctx<'c>,
    sum: std::cell::Cell<f32>,
}

impl<'a, 'c> Depth<'a, 'c> {
    #[inline(always)]
    fn new(ctx: &'a Ctx<'c>) -> Self {
        Depth {
            ctx,
            sum: std::cell::Cell::new(0.0),
        }
    }

    /// A stretch of length `d` in medium `m`. An unbounded one transmits nothing: its
    /// connection is dropped, and its depth is not needed.
    #[inline(always)]
    fn piece(&self, m: u32, d: f32) {
        if d.is_finite() {
            self.sum
                .set(self.sum.get() + mis_extinction(self.ctx, m) * d);
        }
    }
}

/// The ray from `a` to `b` (at parameter 1), each end offset off its surface (`na`, `nb`;
/// zero at the lens, at a point light and in a medium), and the parameter it stops at.
#[inline(always)]
fn segment_ray(a: Vec3, na: Vec3, b: Vec3, nb: Vec3) -> (Ray, f32) {
    let d = b - a;
    let off = |p: Vec3, n: Vec3, towards: Vec3| {
        if n == Vec3::ZERO {
            p
        } else {
            offset_ray_origin(p, if n.dot(towards) >= 0.0 { n } else { -n })
        }
    };
    let o = off(a, na, d);
    let e = off(b, nb, -d);
    // An end on no surface cannot occlude itself; stop just short of it.
    let t_max = if na == Vec3::ZERO || nb == Vec3::ZERO {
        1.0 - 1e-4
    } else {
        1.0
    };
    (Ray::new(o, e - o), t_max)
}

/// A strategy's value in the transport's channels, and the wavelengths that carry it.
type Value<T, const N: usize> = (C<f32, N>, <T as Transport>::Lanes<f32>);

/// Updated reverse densities of the four vertices next to a connection, for its MIS weight.
struct Rev {
    pt: f32,
    pt_minus: f32,
    qs: f32,
    qs_minus: f32,
}

/// The power heuristic's weight of strategy (s, t) over every strategy that makes the same
/// path, by the ratio recurrence: walking away from the connection, each step multiplies the
/// ratio of the densities with which the neighbouring strategy and this one sample a vertex.
/// Strategies that would connect at a delta vertex (or start on a delta light's point by
/// hitting it) are not counted.
#[inline(always)]
fn mis_weight<T: Transport, const N: usize>(
    cam: &[Vtx<T, N>],
    light: &[Vtx<T, N>],
    s: usize,
    t: usize,
    rev: &Rev,
    delta_light: bool,
) -> f32 {
    if s + t == 2 {
        return 1.0;
    }
    let remap = |x: f32| if x != 0.0 { x } else { 1.0 };
    let mut sum = 0.0f32;
    let mut ri = 1.0f32;
    for i in (1..t).rev() {
        let r = if i == t - 1 {
            rev.pt
        } else if i + 2 == t {
            rev.pt_minus
        } else {
            cam[i].rev
        };
        ri *= remap(r) / remap(cam[i].fwd);
        let delta = i != t - 1 && cam[i].delta;
        if !delta && !cam[i - 1].delta {
            sum += ri * ri;
        }
    }
    ri = 1.0;
    for i in (0..s).rev() {
        let r = if i == s - 1 {
            rev.qs
        } else if i + 2 == s {
            rev.qs_minus
        } else {
            light[i].rev
        };
        ri *= remap(r) / remap(light[i].fwd);
        let delta = i != s - 1 && light[i].delta;
        let before = if i > 0 {
            light[i - 1].delta
        } else {
            delta_light
        };
        if !delta && !before {
            sum += ri * ri;
        }
    }
    1.0 / (1.0 + sum)
}

/// A subpath's walk: from the state `st` (its first ray), intersects and scatters through the
/// kernel's stages, pushing a vertex per hit until the path ends or `path` holds `max`
/// vertices; `pdf_dir` is the solid-angle density of the first ray. `LIGHT` subpaths carry
/// importance. MEDIA: a subpath inside a medium first samples its free flight, as the path
/// tracer's does; one that scatters there pushes a vertex with the medium's phase function.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn walk<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
    const LIGHT: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<f32, T, N>,
    path: &mut Vec<Vtx<T, N>>,
    max: usize,
    mut pdf_dir: f32,
    first_dim: u32,
    stats: &mut RenderStats,
) {
    let scene = ctx.scene;
    // MEDIA: the grey optical depth of the segment since the last vertex, across boundaries;
    // its transmittance enters both densities of the segment.
    let mut depth = 0.0f32;
    while st.alive && path.len() < max {
        stats.rays += 1;
        stats.lane_slots += 1;
        let hits = scene.intersect_packet::<f32, MOTION>(st.o, st.d, true, st.time);
        let prev = path.len() - 1;
        if MEDIA && st.in_medium {
            let base = if LIGHT { DIM_LIGHT_MEDIA } else { DIM_MEDIA };
            let sigma = mis_extinction(ctx, st.medium[0]);
            match super::media::flight(ctx, st, &hits, base) {
                Flight::Passes => {
                    if hits.hit {
                        depth += sigma * hits.t;
                    }
                }
                Flight::Ends => break,
                Flight::Scatters { p, t, g, dim } => {
                    // A vertex in the medium.
                    depth += sigma * t;
                    let pass = passes::<MEDIA>(depth);
                    let wo = -st.d.lane(0);
                    let mut v = Vtx {
                        wo,
                        medium: st.medium[0],
                        pass,
                        ..Vtx::<T, N>::start(p, false, Vec3::ZERO, st.beta, st.lam, 0.0, dim + 2)
                    };
                    v.fwd = density(pdf_dir, &path[prev], &v) * pass;
                    if LIGHT || path.len() + 1 < max {
                        v.bsdf = Some(Scatter::Phase(g));
                    }
                    path.push(v);
                    if path.len() >= max {
                        break;
                    }
                    // The phase function is symmetric: the reverse density is the forward one.
                    pdf_dir = super::media::scatter_phase(ctx, st, p, g, dim);
                    path[prev].rev = density(pdf_dir, &path[prev + 1], &path[prev]) * pass;
                    depth = 0.0;
                    continue;
                }
            }
        }
        let sf = super::surface::surfaces::<f32, T, N, MOTION, MEDIA>(ctx, st, &hits, true);
        let dim = first_dim + st.depth * DIMS_PER_BOUNCE;
        if !sf.hit {
            // The camera subpath that escapes meets the environment (s = 0).
            if !LIGHT && scene.lights.has_infinite() {
                let p = st.d.lane(0).normalize();
                let mut v = Vtx::<T, N>::start(p, true, Vec3::ZERO, st.beta, st.lam, 0.0, dim);
                v.fwd = density(pdf_dir, &path[prev], &v);
                if MEDIA {
                    v.pass = passes::<MEDIA>(depth);
                    v.fwd *= v.pass;
                }
                path.push(v);
            }
            break;
        }
        if MEDIA && sf.class == CLASS_BOUNDARY {
            // A medium's boundary: on in the same direction, in the medium beyond.
            st.o = V3::splat(offset_ray_origin(sf.p.lane(0), -sf.nf.lane(0)));
            super::media::cross(ctx, st, &sf, true);
            continue;
        }
        let (p, ng) = (sf.p.lane(0), sf.nf.lane(0));
        let mut v = Vtx {
            wo: -st.d.lane(0),
            medium: st.medium[0],
            ..Vtx::<T, N>::start(p, false, ng, st.beta, st.lam, 0.0, dim)
        };
        v.fwd = density(pdf_dir, &path[prev], &v);
        if MEDIA {
            v.pass = passes::<MEDIA>(depth);
            v.fwd *= v.pass;
        }
        if sf.class == CLASS_NONE {
            // Emitters absorb. The camera subpath keeps the hit for strategy s = 0.
            if !LIGHT && sf.emits {
                v.emits = Some((sf.le, sf.prim[0]));
                path.push(v);
            }
            break;
        }
        if !LIGHT && path.len() + 1 >= max {
            // The camera subpath's last vertex only ever meets an emitter (s = 0): no BSDF.
            path.push(v);
            break;
        }
        let wo = -st.d;
        let eta_scale = st.eta_scale;
        let mut keep = Keep::<LIGHT> { parts: None };
        material::scatter::<f32, T, N, MOTION, MEDIA, _>(
            ctx, st, &sf, true, stats, first_dim, &mut keep,
        );
        if LIGHT {
            // Importance is not compressed at refraction: keep the roulette's scale.
            st.eta_scale = eta_scale;
        }
        // A dispersive interface ended the secondary wavelengths before its BSDF was built:
        // connections here see the hero alone too.
        lift_termination::<T, N>(st, &mut v);
        v.delta = st.specular;
        // The densities of this event: forward to the next vertex, reverse to the previous.
        let (wi, wo_w) = (st.d.lane(0), wo.lane(0));
        let rev = match keep.parts {
            _ if v.delta => {
                // A delta lobe has unit density in projected solid angle, both ways (a
                // reflection keeps projected solid angle; refraction's η² cancels over the
                // two interfaces a path crosses). As solid-angle densities, |cos| on each
                // side: the specular chain's geometry then enters every strategy's density,
                // and the ratios across it are those of the paths' true densities.
                let ns = sf.nsf.lane(0);
                pdf_dir = wi.dot(ns).abs();
                wo_w.dot(ns).abs()
            }
            Some(parts) if st.alive => {
                pdf_dir = st.prev_pdf;
                Bsdf::new(ctx, &sf, &parts).pdf(wi, wo_w)
            }
            _ => {
                pdf_dir = 0.0;
                0.0
            }
        };
        if LIGHT && st.alive {
            super::light_tracer::adjoint_correction(st, wo, &sf);
        }
        if let Some(parts) = keep.parts {
            v.bsdf = Some(Scatter::Surface(sf, parts));
        }
        path.push(v);
        // The light subpath's last vertex still needed its BSDF, for t = 1.
        if !st.alive || path.len() >= max {
            break;
        }
        path[prev].rev = density(rev, &path[prev + 1], &path[prev]);
        if MEDIA {
            path[prev].rev *= path[prev + 1].pass;
            depth = 0.0;
        }
    }
}

/// Carries a termination of the secondary wavelengths at vertex `v`'s event into `v`.
#[inline(always)]
fn lift_termination<T: Transport<S: ChannelArray<N>>, const N: usize>(
    st: &Paths<f32, T, N>,
    v: &mut Vtx<T, N>,
) {
    if T::terminated::<f32>(&st.lam) {
        T::terminate_secondary::<f32, N>(&mut v.lam, &mut v.beta, true);
    }
}

/// The wavelengths of a connection: the hero alone if either side's have ended.
#[inline(always)]
fn joined<T: Transport<S: ChannelArray<N>>, const N: usize>(
    a: &T::Lanes<f32>,
    b: &T::Lanes<f32>,
    c: &mut C<f32, N>,
) -> T::Lanes<f32> {
    let mut lam = *a;
    if T::terminated::<f32>(b) {
        T::terminate_secondary::<f32, N>(&mut lam, c, true);
    }
    lam
}

/// The per-tile buffers of one worker: both subpaths, reused from sample to sample.
struct Subpaths<T: Transport, const N: usize> {
    cam: Vec<Vtx<T, N>>,
    light: Vec<Vtx<T, N>>,
}

/// Renders the samples `work` names of every pixel of `tile`: per sample, both subpaths and
/// the strategies `which` asks for, into `splats`.
#[allow(clippy::too_many_arguments)]
fn trace_tile<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    camera: &Camera,
    which: Strategies,
    holders: &[u32],
    tile: &Tile,
    work: &TileWork,
    splats: &mut Splats,
    stats: &mut RenderStats,
) {
    let max_depth = ctx.max_depth as usize;
    let mut paths = Subpaths::<T, N> {
        cam: Vec::with_capacity(max_depth + 2),
        light: Vec::with_capacity(max_depth + 1),
    };
    for p in 0..tile.pixels() {
        let (x, y) = tile.pixel(p);
        let (first, count) = work.range(p);
        for k in 0..count {
            let (index, half) = work.index(first + k);
            let pixel = (y * ctx.width + x) | half;
            stats.samples += 1;
            splats.half_b = half != 0;
            let rgb = sample::<T, N, MOTION, MEDIA>(
                ctx, camera, which, holders, &mut paths, x, y, pixel, index, splats, stats,
            );
            if rgb.is_finite() {
                splats.add_pixel(x, y, rgb);
            } else {
                stats.dropped += 1;
            }
        }
    }
}

/// One camera sample: both subpaths, then every strategy. Returns the value of the sample's
/// own pixel; light-tracing strategies (t = 1) splat where they land.
#[allow(clippy::too_many_arguments)]
fn sample<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    camera: &Camera,
    which: Strategies,
    holders: &[u32],
    paths: &mut Subpaths<T, N>,
    x: u32,
    y: u32,
    pixel: u32,
    index: u32,
    splats: &mut Splats,
    stats: &mut RenderStats,
) -> Vec3 {
    let max_depth = ctx.max_depth as usize;
    let sampler = &ctx.sampler;
    // The camera subpath.
    let ray = super::generate::camera_rays_keyed::<f32, MOTION>(ctx, x, y, pixel, index);
    let time = ray.time;
    let (o, d) = (ray.o.lane(0), ray.d.lane(0));
    let lam = T::wavelengths::<f32>(ctx, pixel, index);
    let init = T::initial_beta::<f32, N>(&lam);
    let cam = &mut paths.cam;
    cam.clear();
    let camera_medium = ctx.scene.camera_medium;
    cam.push(Vtx {
        medium: camera_medium,
        ..Vtx::start(o, false, Vec3::ZERO, init, lam, 1.0, 0)
    });
    let mut st = path_state::<T, N>(o, d, init, lam, 1.0, time, pixel, index);
    if MEDIA {
        st.medium[0] = camera_medium;
        st.in_medium = camera_medium != NO_MEDIUM;
    }
    let pdf_cam = camera.pdf_dir::<MOTION>(time, d);
    <f32 as crate::simd::Float>::enter_typed(Walk::<T, N, MOTION, MEDIA, false> {
        ctx,
        st: &mut st,
        path: cam,
        max: max_depth + 2,
        pdf_dir: pdf_cam,
        first_dim: DIM_BOUNCE,
        stats,
    });
    // The light subpath.
    let light = &mut paths.light;
    light.clear();
    let dim = DIM_LIGHT_PATH;
    let u_sel = sampler.get_1d_lanes::<f32>(pixel, index, dim);
    let u_pos = sampler.get_2d_lanes::<f32>(pixel, index, dim + 1);
    let u_dir = sampler.get_2d_lanes::<f32>(pixel, index, dim + 4);
    let emission = super::light_tracer::emit::<T, N, MOTION>(
        ctx,
        &T::lane(&lam, 0),
        time,
        u_sel,
        Vec2::new(u_pos.0, u_pos.1),
        Vec2::new(u_dir.0, u_dir.1),
    );
    let chan = |s: T::S| super::bsdf::Chan(s.to_array());
    if let Some(e) = &emission {
        // At infinity the vertex is the direction towards the light; its ray's origin on the
        // disc is not a vertex.
        let inf = e.at_infinity;
        let p = if inf { -e.d } else { e.p };
        let mut st = e.path::<T, N>(init * chan(e.beta), lam, time, pixel, index);
        let mut v = Vtx::start(p, inf, e.n, init, lam, e.pdf_pos, dim);
        if MEDIA {
            v.medium = ctx.scene.prims.medium_among(st.o.lane(0), holders);
            st.medium[0] = v.medium;
            st.in_medium = v.medium != NO_MEDIUM;
        }
        light.push(v);
        if max_depth >= 1 {
            <f32 as crate::simd::Float>::enter_typed(Walk::<T, N, MOTION, MEDIA, true> {
                ctx,
                st: &mut st,
                path: light,
                max: max_depth + 1,
                pdf_dir: e.pdf_dir,
                first_dim: DIM_LIGHT_PATH + DIMS_PER_BOUNCE,
                stats,
            });
        }
    }
    <f32 as crate::simd::Float>::enter_typed(Joins::<T, N, MOTION, MEDIA> {
        ctx,
        camera,
        which,
        paths,
        key: (pixel, index),
        time,
        splats,
        stats,
    })
}

/// A subpath's walk, run inside the width-1 FMA entry point (see [`Joins`]).
struct Walk<
    'a,
    'c,
    T: Transport,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
    const LIGHT: bool,
> {
    ctx: &'a Ctx<'c>,
    st: &'a mut Paths<f32, T, N>,
    path: &'a mut Vec<Vtx<T, N>>,
    max: usize,
    pdf_dir: f32,
    first_dim: u32,
    stats: &'a mut RenderStats,
}

impl<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
    const LIGHT: bool,
> crate::simd::TypedKernel<f32> for Walk<'_, '_, T, N, MOTION, MEDIA, LIGHT>
{
    type Output = ();
    const SHARD: usize = super::home::<T>(MEDIA, MOTION, true);
    #[inline(always)]
    fn run(self) {
        walk::<T, N, MOTION, MEDIA, LIGHT>(
            self.ctx,
            self.st,
            self.path,
            self.max,
            self.pdf_dir,
            self.first_dim,
            self.stats,
        );
    }
}

/// Every strategy of one sample's subpaths, run inside the width-1 FMA entry point: width-1
/// code outside the lanes' entry points calls libm for each `f32::mul_add`. The walks and
/// the joins are three entries per sample rather than one, which keeps each function the
/// compiler optimises of a size it handles quickly. They are typed kernels of `f32`, not lane
/// kernels: a lane kernel is compiled in every lane form `dispatch` knows, six copies where
/// width 1 runs two.
struct Joins<'a, 'c, T: Transport, const N: usize, const MOTION: bool, const MEDIA: bool> {
    ctx: &'a Ctx<'c>,
    camera: &'a Camera<'c>,
    which: Strategies,
    paths: &'a Subpaths<T, N>,
    key: (u32, u32),
    time: f32,
    splats: &'a mut Splats,
    stats: &'a mut RenderStats,
}

impl<T: Transport<S: ChannelArray<N>>, const N: usize, const MOTION: bool, const MEDIA: bool>
    crate::simd::TypedKernel<f32> for Joins<'_, '_, T, N, MOTION, MEDIA>
{
    type Output = Vec3;
    const SHARD: usize = super::home::<T>(MEDIA, MOTION, true);
    #[inline(always)]
    fn run(self) -> Vec3 {
        joins::<T, N, MOTION, MEDIA>(
            self.ctx,
            self.camera,
            self.which,
            self.paths,
            self.key,
            self.time,
            self.splats,
            self.stats,
        )
    }
}

/// Every strategy (s, t) that `which` asks for over `paths`: the value of the sample's own
/// pixel, the t = 1 strategies splatted where they land.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn joins<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    camera: &Camera,
    which: Strategies,
    paths: &Subpaths<T, N>,
    (pixel, index): (u32, u32),
    time: f32,
    splats: &mut Splats,
    stats: &mut RenderStats,
) -> Vec3 {
    let max_depth = ctx.max_depth as usize;
    let mut own = Vec3::ZERO;
    let (cam, light) = (&paths.cam, &paths.light);
    for t in 1..=cam.len() {
        // s = 1 samples its own light point, with or without a light subpath.
        for s in 0..=light.len().max(1) {
            let depth = s as i64 + t as i64 - 2;
            if (s == 1 && t == 1) || depth < 0 || depth > max_depth as i64 {
                continue;
            }
            let all = match which {
                Strategies::All => true,
                Strategies::Only { s: os, t: ot } | Strategies::Weighted { s: os, t: ot } => {
                    if os as usize != s || ot as usize != t {
                        continue;
                    }
                    matches!(which, Strategies::Weighted { .. })
                }
            };
            if t == 1 {
                let key = (pixel, index);
                if let Some(((c, lam), conn)) = light_to_camera::<T, N, MOTION, MEDIA>(
                    ctx, camera, cam, light, s, all, key, time, stats,
                ) {
                    let mut rgb = [Vec3::ZERO; MAX_W];
                    T::ended_rgb(&c, &lam, 1, &mut rgb);
                    if rgb[0].is_finite() {
                        splats.add(conn.0, conn.1, rgb[0], camera.box_filter);
                    } else {
                        stats.dropped += 1;
                    }
                }
                continue;
            }
            let got = match s {
                0 => emitter_hit::<T, N>(ctx, cam, t, all),
                1 => light_sample::<T, N, MOTION, MEDIA>(
                    ctx,
                    cam,
                    t,
                    all,
                    (pixel, index),
                    time,
                    stats,
                ),
                _ => connect::<T, N, MOTION, MEDIA>(ctx, cam, light, s, t, all, time, stats),
            };
            if let Some((c, lam)) = got {
                let mut rgb = [Vec3::ZERO; MAX_W];
                T::ended_rgb(&c, &lam, 1, &mut rgb);
                own += rgb[0];
            }
        }
    }
    own
}

/// Strategy (0, t): the camera subpath's vertex `t - 1` is an emitter.
#[inline(always)]
fn emitter_hit<T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    cam: &[Vtx<T, N>],
    t: usize,
    weighted: bool,
) -> Option<Value<T, N>> {
    let pt = &cam[t - 1];
    if pt.inf {
        return environment_hit::<T, N>(ctx, cam, t, weighted);
    }
    let (le, prim) = pt.emits?;
    let c = pt.beta * le;
    if c.is_zero() {
        return None;
    }
    if !weighted || t == 2 {
        return Some((c, pt.lam));
    }
    let scene = ctx.scene;
    let prims = &scene.prims;
    let area = crate::scene::lights::emitter_area(prims, prim);
    if !area.is_finite() {
        // Emissive shapes no light path starts on: only this strategy finds them.
        return Some((c, pt.lam));
    }
    let pmf = scene.lights.table.pmf(prims.light[prim as usize] as usize);
    let prev = &cam[t - 2];
    let pdf_dir = area_emission_pdf(prims, prims.material[prim as usize], pt.ng, pt.wo);
    let rev = Rev {
        pt: pmf / area,
        pt_minus: density(pdf_dir, pt, prev) * pt.pass,
        qs: 0.0,
        qs_minus: 0.0,
    };
    let w = mis_weight(cam, &[], 0, t, &rev, false);
    Some((c * w, pt.lam))
}

/// The density with which an area emitter of `material` sends a light path's first ray
/// along `w` from a point of normal `n`: cosine-weighted over its one side, or over both.
#[inline(always)]
fn area_emission_pdf(
    prims: &crate::scene::primitives::Primitives,
    material: u32,
    n: Vec3,
    w: Vec3,
) -> f32 {
    let sides = match prims.materials[material as usize] {
        Material::Light {
            two_sided: true, ..
        } => 2.0,
        _ => 1.0,
    };
    n.dot(w).abs() / (PI * sides)
}

/// Strategy (0, t) at infinity: the camera subpath's vertex `t - 1` is a direction towards
/// the environment. Each infinite light (the environment, the sun) is its own emitter, with
/// its own weight.
#[inline(always)]
fn environment_hit<T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    cam: &[Vtx<T, N>],
    t: usize,
    weighted: bool,
) -> Option<Value<T, N>> {
    use super::bsdf::LaneChannels;
    let pt = &cam[t - 1];
    let mut sum = C::<f32, N>::splat(0.0);
    super::light_tracer::each_infinite(ctx, |light| {
        let lam = T::lane(&pt.lam, 0);
        let Some((le, pdf)) = super::light_tracer::infinite_light::<T>(ctx, light, &lam, pt.p)
        else {
            return;
        };
        let c = pt.beta * super::bsdf::Chan(le.to_array());
        let w = if !weighted || t == 2 {
            1.0
        } else {
            let disc = ctx.scene.lights.disc_density();
            let rev = Rev {
                pt: pdf,
                pt_minus: density(disc, pt, &cam[t - 2]) * pt.pass,
                qs: 0.0,
                qs_minus: 0.0,
            };
            mis_weight(cam, &[], 0, t, &rev, false)
        };
        sum = sum + c * w;
    });
    (!sum.is_zero()).then_some((sum, pt.lam))
}

/// Strategy (s, 1): light vertex `s - 1` connects to the camera (a point on the lens drawn
/// from the event's dimensions). Returns the value, its wavelengths and the raster point.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn light_to_camera<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    camera: &Camera,
    cam: &[Vtx<T, N>],
    light: &[Vtx<T, N>],
    s: usize,
    weighted: bool,
    key: (u32, u32),
    time: f32,
    stats: &mut RenderStats,
) -> Option<(Value<T, N>, (f32, f32))> {
    let qs = &light[s - 1];
    let bsdf = scatterer(ctx, qs)?;
    let u = ctx.sampler.get_2d_lanes::<f32>(key.0, key.1, qs.dim + 1);
    let conn = camera.connect::<MOTION>(qs.p, time, u)?;
    let (f, _) = bsdf.light_side(qs.wo, conn.wc)?;
    let mut c = qs.beta * f * conn.importance;
    if c.is_zero() {
        return None;
    }
    stats.shadow_rays += 1;
    let m = medium_toward(ctx, qs, conn.wc);
    // The lens lies on no surface: stop just short of it (as `Camera::seen_from`).
    let ray = camera.ray_from(qs.p, qs.ng, &conn);
    let depth = Depth::new(ctx);
    let tr = super::light_tracer::transmittance::<T, N, MOTION, MEDIA>;
    c = c * tr(ctx, &ray, 1.0 - 1e-4, m, time, &qs.lam, |m, d| {
        depth.piece(m, d)
    })?;
    let lam = joined::<T, N>(&qs.lam, &cam[0].lam, &mut c);
    if weighted {
        let prev = &light[s - 2];
        // The camera's density towards qs is its importance (1 / (r² A cos³θ)) with qs's
        // cosine: the pinhole's and the lens's alike.
        let rev = Rev {
            pt: 0.0,
            pt_minus: 0.0,
            qs: conn.importance * cosine(qs.ng, conn.wc) * passes::<MEDIA>(depth.sum.get()),
            qs_minus: density(bsdf.pdf(conn.wc, qs.wo), qs, prev) * qs.pass,
        };
        c = c * mis_weight(cam, light, s, 1, &rev, delta_light_of(light));
    }
    Some(((c, lam), (conn.fx, conn.fy)))
}

/// |cos| between direction `w` and normal `n`; 1 on no surface (a point in a medium).
#[inline(always)]
fn cosine(n: Vec3, w: Vec3) -> f32 {
    if n == Vec3::ZERO { 1.0 } else { n.dot(w).abs() }
}

/// Whether the light subpath starts on a point or spot light (its start has no normal and
/// is not at infinity).
#[inline(always)]
fn delta_light_of<T: Transport, const N: usize>(light: &[Vtx<T, N>]) -> bool {
    light.first().is_some_and(|v| v.ng == Vec3::ZERO && !v.inf)
}

/// Strategies (s ≥ 1, t ≥ 2): camera vertex `t - 1` connects to light vertex `s - 1` (the
/// point on the emitter when s = 1) through a shadow ray.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn connect<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    cam: &[Vtx<T, N>],
    light: &[Vtx<T, N>],
    s: usize,
    t: usize,
    weighted: bool,
    time: f32,
    stats: &mut RenderStats,
) -> Option<Value<T, N>> {
    let (pt, qs) = (&cam[t - 1], &light[s - 1]);
    let bc = scatterer(ctx, pt)?;
    let d = qs.p - pt.p;
    let r2 = d.length_squared();
    if r2 == 0.0 {
        return None;
    }
    let w = d / r2.sqrt();
    let (fc, pdf_c) = bc.camera_side(pt.wo, w)?;
    // The light side: the adjoint BSDF.
    let bl = scatterer(ctx, qs)?;
    let (fl, pdf_l) = bl.light_side(qs.wo, -w)?;
    let mut c = pt.beta * fc * qs.beta * fl * (1.0 / r2);
    if c.is_zero() {
        return None;
    }
    stats.shadow_rays += 1;
    let m = medium_toward(ctx, pt, w);
    let (ray, t_max) = segment_ray(pt.p, pt.ng, qs.p, qs.ng);
    let depth = Depth::new(ctx);
    let tr = super::light_tracer::transmittance::<T, N, MOTION, MEDIA>;
    c = c * tr(ctx, &ray, t_max, m, time, &pt.lam, |m, d| depth.piece(m, d))?;
    let lam = joined::<T, N>(&pt.lam, &qs.lam, &mut c);
    if !weighted {
        return Some((c, lam));
    }
    let cp = &cam[t - 2];
    let across = passes::<MEDIA>(depth.sum.get());
    let rev = Rev {
        pt: density(pdf_l, qs, pt) * across,
        pt_minus: density(bc.pdf(w, pt.wo), pt, cp) * pt.pass,
        qs: density(pdf_c, pt, qs) * across,
        qs_minus: density(bl.pdf(-w, qs.wo), qs, &light[s - 2]) * qs.pass,
    };
    let weight = mis_weight(cam, light, s, t, &rev, delta_light_of(light));
    Some((c * weight, lam))
}

/// Strategy (1, t): camera vertex `t - 1` samples a light as next-event estimation does (its
/// own point, by solid angle where the light allows). Its weight treats that point as the
/// light subpath's start, with that start's densities: MIS stays unbiased with any densities
/// so long as every strategy of a path is weighted by the same ones (pbrt does the same).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn light_sample<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    cam: &[Vtx<T, N>],
    t: usize,
    weighted: bool,
    key: (u32, u32),
    time: f32,
    stats: &mut RenderStats,
) -> Option<Value<T, N>> {
    let pt = &cam[t - 1];
    let bc = scatterer(ctx, pt)?;
    let scene = ctx.scene;
    // The camera subpath's walk leaves each event's light dimensions unused.
    let u_sel = ctx.sampler.get_1d_lanes::<f32>(key.0, key.1, pt.dim);
    let u = ctx.sampler.get_2d_lanes::<f32>(key.0, key.1, pt.dim + 1);
    let ls = scene.lights.sample::<MOTION>(
        &scene.prims,
        pt.p,
        u_sel,
        Vec2::new(u.0, u.1),
        time,
        ctx.textures,
    )?;
    let w = ls.wi;
    let (fc, pdf_c) = bc.camera_side(pt.wo, w)?;
    let le = T::source_radiance(ctx, &ls.source, ls.radiance, &T::lane(&pt.lam, 0));
    let mut c = pt.beta * fc * super::bsdf::Chan(le.to_array()) * (1.0 / ls.pdf);
    if c.is_zero() {
        return None;
    }
    stats.shadow_rays += 1;
    let (ray, t_max) = match ls.point {
        Some((q, n)) => segment_ray(pt.p, pt.ng, q, n),
        None => {
            let n = if pt.ng.dot(w) >= 0.0 { pt.ng } else { -pt.ng };
            (Ray::new(offset_ray_origin(pt.p, n), w), f32::INFINITY)
        }
    };
    let m = medium_toward(ctx, pt, w);
    let depth = Depth::new(ctx);
    let tr = super::light_tracer::transmittance::<T, N, MOTION, MEDIA>;
    c = c * tr(ctx, &ray, t_max, m, time, &pt.lam, |m, d| depth.piece(m, d))?;
    if !weighted {
        return Some((c, pt.lam));
    }
    let (qs, pdf_l) = light_start::<T, N>(ctx, &ls, pt)?;
    let across = passes::<MEDIA>(depth.sum.get());
    let rev = Rev {
        pt: density(pdf_l, &qs, pt) * across,
        pt_minus: density(bc.pdf(w, pt.wo), pt, &cam[t - 2]) * pt.pass,
        qs: density(pdf_c, pt, &qs) * across,
        qs_minus: 0.0,
    };
    let weight = mis_weight(cam, std::slice::from_ref(&qs), 1, t, &rev, ls.delta);
    Some((c * weight, pt.lam))
}

/// The light sample `ls` taken from `pt` as a light subpath's start: its vertex (with the
/// density of choosing the light and the point, or at infinity the direction), and the
/// density with which the emission would have sent its ray towards `pt`.
#[inline(always)]
fn light_start<T: Transport, const N: usize>(
    ctx: &Ctx,
    ls: &crate::scene::lights::LightSample,
    pt: &Vtx<T, N>,
) -> Option<(Vtx<T, N>, f32)> {
    use crate::scene::lights::LightSource;
    let lights = &ctx.scene.lights;
    let prims = &ctx.scene.prims;
    let vertex = |p: Vec3, ng: Vec3, inf: bool, fwd: f32| {
        Vtx::<T, N>::start(p, inf, ng, pt.beta, pt.lam, fwd, 0)
    };
    match (ls.source, ls.point) {
        (LightSource::Area { prim, material, .. }, Some((q, n))) => {
            let pmf = lights.table.pmf(prims.light[prim as usize] as usize);
            let area = crate::scene::lights::emitter_area(prims, prim);
            let pdf_dir = area_emission_pdf(prims, material, n, ls.wi);
            Some((vertex(q, n, false, pmf / area), pdf_dir))
        }
        (LightSource::Point { light, .. }, Some((q, _))) => {
            let LightKind::Point(pl) = lights.lights[light as usize] else {
                return None;
            };
            let pmf = lights.table.pmf(light as usize);
            let pdf_dir = super::light_tracer::point_emission_pdf(&pl, -ls.wi);
            Some((vertex(q, Vec3::ZERO, false, pmf), pdf_dir))
        }
        // The environment and the sun: `ls.pdf` is the direction's density with the choice.
        (_, None) => Some((
            vertex(ls.wi, Vec3::ZERO, true, ls.pdf),
            lights.disc_density(),
        )),
        _ => None,
    }
}

/// Renders `opts.spp` samples per pixel by BDPT (fewer if stopped or out of time), in
/// passes, adding the strategies `which` names.
pub(super) fn render<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    opts: &RenderOptions,
    tiles: &[Tile],
    progress: &dyn Observer,
    which: Strategies,
) -> RenderOutput {
    let camera = Camera::new(ctx);
    // MEDIA: the shapes that hold a medium, where a light subpath's start is looked up.
    let holders = if MEDIA {
        ctx.scene.prims.medium_holders()
    } else {
        Vec::new()
    };
    super::light_tracer::splat_passes(opts, ctx, tiles, progress, |tile, work, splats, stats| {
        trace_tile::<T, N, MOTION, MEDIA>(ctx, &camera, which, &holders, tile, work, splats, stats)
    })
}

/// Emission rays [`choose`] traces to find the surfaces the lights reach.
const PROBE_RAYS: u32 = 16384;

/// The estimator `render.integrator.kind` resolves to, and why: `Auto` takes BDPT where a
/// light reaches a specular or dispersive surface (a smooth dielectric, a dispersive one of
/// any roughness, a mirror or a smooth conductor: the first vertex of caustic paths), the
/// caustics carry at least 3 % of the light the camera sees on other surfaces, where the
/// sun shines on such a surface, or where a light sits inside a scattering medium;
/// otherwise, and for a target error, the path tracer. Reach
/// and share are found by 16,384 emission rays, drawn as light paths start (lights by power)
/// and followed through specular chains and media's boundaries (media's attenuation is not
/// weighed). Other kinds resolve to themselves.
pub fn choose(scene: &RenderScene) -> (Estimator, String) {
    let kind = scene.settings.kind;
    if kind != Estimator::Auto {
        return (kind, "render.integrator.kind".into());
    }
    if scene.lights.lights.is_empty() {
        return (Estimator::Path, "Auto: the scene has no light".into());
    }
    let prims = &scene.prims;
    if let Some((lamp, holder)) = light_in_fog(scene) {
        return (
            Estimator::Bdpt,
            format!(
                "Auto: {lamp} shines inside the scattering medium of entity {}",
                crate::components::quoted(&prims.names[holder as usize])
            ),
        );
    }
    let caustic = |prim: u32| -> Option<&'static str> {
        let smooth = |a: crate::components::Alpha| a.x.max(a.y) < super::microfacet::SMOOTH_ALPHA;
        match prims.materials[prims.material[prim as usize] as usize] {
            Material::Dielectric { ior, .. } if ior.is_dispersive() => {
                Some("dispersive Dielectric")
            }
            Material::Dielectric { alpha, .. } if smooth(alpha) => Some("smooth Dielectric"),
            Material::Mirror { .. } => Some("Mirror"),
            Material::Conductor { alpha, .. } if smooth(alpha) => Some("smooth Conductor"),
            _ => None,
        }
    };
    // Hits per (specular primitive, light). Each probe then follows its specular chain to
    // the first other surface, and what the camera sees there (the light tracer's splat with
    // the surface's albedo, at the lens's centre) adds to the light seen directly or to the
    // light seen through a specular chain: the caustics' share of the image.
    let mut hits: Vec<(u32, usize, u32)> = Vec::new();
    let mut seen = [0.0f64; 2];
    let ctx = Ctx::new(scene, false);
    let camera = Camera::new(&ctx);
    let sampler = crate::sampling::Sampler::new(crate::sampling::SamplerKind::Independent, 1);
    let time = scene.shutter.0;
    for i in 0..PROBE_RAYS {
        let u = |d: u32| sampler.get_1d(i, 0, d);
        let u_sel = u(0);
        let (light, _) = scene.lights.table.sample(u_sel);
        let Some(e) = super::light_tracer::emit::<super::transport::Rgb, 3, false>(
            &ctx,
            &(),
            time,
            u_sel,
            Vec2::new(u(1), u(2)),
            Vec2::new(u(3), u(4)),
        ) else {
            continue;
        };
        let power = f64::from(crate::scene::lights::luminance(e.beta));
        if !power.is_finite() {
            continue;
        }
        let o = if e.n == Vec3::ZERO {
            e.p
        } else {
            offset_ray_origin(e.p, if e.n.dot(e.d) >= 0.0 { e.n } else { -e.n })
        };
        let mut ray = Ray::new(o, e.d);
        let mut bounce = 0;
        // Media's boundaries are crossed without a bounce, a bounded number of times.
        for _ in 0..=PROBE_CHAIN + 16 {
            let Some(hit) = scene.intersect::<false>(&ray, f32::INFINITY, time) else {
                break;
            };
            let sp = prims.surface(&ray, &hit);
            let m = prims.materials[prims.material[hit.prim as usize] as usize];
            if matches!(m, Material::Boundary) {
                ray = Ray::new(offset_ray_origin(sp.p, -sp.facing()), ray.d);
                continue;
            }
            if caustic(hit.prim).is_some() {
                if bounce == PROBE_CHAIN {
                    break;
                }
                if bounce == 0 {
                    match hits.iter_mut().find(|h| h.0 == hit.prim && h.1 == light) {
                        Some(h) => h.2 += 1,
                        None => hits.push((hit.prim, light, 1)),
                    }
                }
                // The chain's likelier branch: refraction where the glass allows it (at the
                // spectrum's middle), else reflection.
                let (wo, n) = (-ray.d, sp.facing());
                let d = match m {
                    Material::Dielectric { ior, .. } => {
                        let eta = ior.eta(550.0);
                        let eta = if sp.front { eta } else { 1.0 / eta };
                        super::bsdf::refract(wo, n, eta)
                            .unwrap_or_else(|| super::bsdf::reflect(wo, n))
                    }
                    _ => super::bsdf::reflect(wo, n),
                };
                let side = if d.dot(n) >= 0.0 { n } else { -n };
                ray = Ray::new(offset_ray_origin(sp.p, side), d);
                bounce += 1;
                continue;
            }
            let albedo = match m {
                Material::Diffuse { albedo } | Material::Plastic { albedo, .. } => {
                    f64::from(crate::scene::lights::luminance(albedo))
                }
                Material::Light { .. } | Material::Boundary => 0.0,
                _ => 1.0,
            };
            // Seen through media's boundaries: the probes weigh no medium's attenuation.
            if albedo > 0.0
                && let Some(c) = camera.connect::<false>(sp.p, time, (0.5, 0.5))
                && scene.transmittance_with::<false, Vec3>(
                    &camera.ray_from(sp.p, sp.n, &c),
                    1.0 - 1e-4,
                    time,
                    NO_MEDIUM,
                    |_, _| Vec3::ONE,
                ) != Vec3::ZERO
            {
                let cos = f64::from(sp.n.dot(c.wc).abs());
                seen[usize::from(bounce > 0)] += power * albedo * cos * f64::from(c.importance);
            }
            break;
        }
    }
    // The sun is half a degree wide and very bright: its caustics are paths a camera subpath
    // completes only by chance, each worth thousands of times a pixel's value, and BDPT's MIS
    // weighs them down (docs/accuracy.md, the sky scenes). The probes above start on a disc
    // as wide as the scene, which a small specular object under a sky may never meet, so
    // each specular primitive is asked directly whether the sun shines on it.
    if let Some(sky) = scene.lights.sky.as_deref()
        && scene
            .lights
            .lights
            .iter()
            .any(|l| matches!(l, LightKind::Sun))
        && let Some(p) = (0..prims.material.len() as u32)
            .find(|&p| caustic(p).is_some() && sun_reaches(scene, p, sky.sun_direction(), time))
    {
        return (
            Estimator::Bdpt,
            format!(
                "Auto: entity {}: {}; the sun shines on it",
                crate::components::quoted(&prims.names[p as usize]),
                caustic(p).unwrap_or_default()
            ),
        );
    }
    // The specular surface the lights reach most, and the light that reaches it most.
    let Some(&(prim, light, _)) = hits.iter().max_by_key(|h| (h.2, std::cmp::Reverse(h.0))) else {
        return (
            Estimator::Path,
            "Auto: no light reaches a specular or dispersive surface".into(),
        );
    };
    let lamp = match scene.lights.lights[light] {
        LightKind::Area(p) => format!(
            "light {}",
            crate::components::quoted(&prims.names[p as usize])
        ),
        LightKind::Point(_) => "a point light".into(),
        LightKind::Sun => "the sun".into(),
        LightKind::Environment(_) | LightKind::EnvMap => "the environment".into(),
    };
    let what = format!(
        "entity {}: {}",
        crate::components::quoted(&prims.names[prim as usize]),
        caustic(prim).unwrap_or_default()
    );
    let total = seen[0] + seen[1];
    let share = if total > 0.0 { seen[1] / total } else { 0.0 };
    let percent = (100.0 * share).round();
    if share < MIN_CAUSTIC_SHARE {
        return (
            Estimator::Path,
            format!(
                "Auto: {what}; {lamp} reaches it, but caustics carry {percent} % of the light \
                 seen on other surfaces, under the {} % where Bdpt pays",
                100.0 * MIN_CAUSTIC_SHARE
            ),
        );
    }
    (
        Estimator::Bdpt,
        format!(
            "Auto: {what}; {lamp} reaches it (caustics carry {percent} % of the light seen \
             on other surfaces)"
        ),
    )
}

/// The first light (named as `choose` names it) that sits inside a scattering medium, and
/// the primitive holding that medium. Light subpaths scatter around such a lamp at once and
/// reach the camera from its glow; the path tracer finds that glow one scattering at a
/// time (BDPT renders the lamps in fog to equal relMSE 5 times sooner, docs/accuracy.md).
/// An area light is placed by its bounding box's centre.
fn light_in_fog(scene: &RenderScene) -> Option<(String, u32)> {
    let prims = &scene.prims;
    let holders = prims.medium_holders();
    scene.lights.lights.iter().find_map(|l| {
        let (p, lamp) = match *l {
            LightKind::Area(prim) => {
                let b = prims.bounds_of(prim);
                let name = crate::components::quoted(&prims.names[prim as usize]);
                ((b.min + b.max) * 0.5, format!("light {name}"))
            }
            LightKind::Point(pl) => (pl.position, "a point light".into()),
            _ => return None,
        };
        let m = prims.medium_among(p, &holders);
        if m == NO_MEDIUM || prims.media[m as usize].sigma_s.max_element() <= 0.0 {
            return None;
        }
        let holder = holders
            .iter()
            .copied()
            .find(|&h| prims.medium_inside[h as usize] == m && prims.contains(h, p).is_some())?;
        Some((lamp, holder))
    })
}

/// Whether the sun, towards `dir`, shines on primitive `prim`: any of five rays towards it
/// from the side of the primitive's bounding sphere that faces it (its centre and four
/// points halfway out) is clear.
fn sun_reaches(scene: &RenderScene, prim: u32, dir: Vec3, time: f32) -> bool {
    let b = scene.prims.bounds_of(prim);
    let (c, r) = ((b.min + b.max) * 0.5, (b.max - b.min).length() * 0.5);
    if !(c.is_finite() && r.is_finite()) {
        return false;
    }
    let (a, t) = dir.any_orthonormal_pair();
    [Vec3::ZERO, a, -a, t, -t].iter().any(|&o| {
        let from = c + dir * (r * 1.001) + o * (0.5 * r);
        !scene.occluded::<false>(&Ray::new(from, dir), f32::INFINITY, time)
    })
}

/// The caustics' share of the light the camera sees on non-specular surfaces above which
/// `Auto` takes BDPT: between the shipped scenes where BDPT loses at equal time (2 % and
/// less) and those where it wins (5 % and more), measured in docs/accuracy.md.
const MIN_CAUSTIC_SHARE: f64 = 0.03;

/// The longest specular chain `Auto`'s probes follow.
const PROBE_CHAIN: u32 = 8;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::bsdf::LaneChannels;
    use crate::integrator::transport::Rgb;
    use crate::sampling::{Sampler, SamplerKind};

    /// A vertex with densities `fwd`, `rev` (nothing else matters to the weights).
    fn vtx(fwd: f32, rev: f32, delta: bool) -> Vtx<Rgb, 3> {
        Vtx {
            rev,
            delta,
            ..Vtx::start(Vec3::ZERO, false, Vec3::ZERO, C::splat(1.0), (), fwd, 0)
        }
    }

    /// On random paths of 1 to 8 edges, with random densities on both sides, delta vertices
    /// and delta lights, the weights of every strategy that can make the path sum to 1.
    #[test]
    fn mis_weights_of_a_path_sum_to_one() {
        let u = Sampler::new(SamplerKind::Independent, 7);
        let mut dim = 0;
        let mut next = || {
            dim += 1;
            u.get_1d(0, 0, dim)
        };
        for path in 0..4000 {
            let k = 1 + (next() * 8.0) as usize;
            // x_0 is the camera, x_k on the light. Densities of x_i sampled from the camera's
            // side (pc) and from the light's (pl), over many orders of magnitude.
            let delta: Vec<bool> = (0..=k).map(|i| i > 0 && i < k && next() < 0.3).collect();
            let delta_light = next() < 0.3;
            let mut pc: Vec<f32> = (0..=k).map(|_| (20.0 * next() - 10.0).exp()).collect();
            let mut pl: Vec<f32> = (0..=k).map(|_| (20.0 * next() - 10.0).exp()).collect();
            // Next to a delta vertex a subpath stores no density.
            for i in 1..k {
                if delta[i] {
                    pc[i + 1] = 0.0;
                    pl[i - 1] = 0.0;
                }
            }
            let mut sum = 0.0f64;
            let mut counted = 0;
            for s in 0..=k {
                let t = k + 1 - s;
                if s == 1 && t == 1 || t == 0 {
                    continue;
                }
                // The connection's ends must not be delta; a delta light is never hit.
                if (s == 0 && delta_light) || (t >= 2 && delta[t - 1]) || (s >= 2 && delta[t]) {
                    continue;
                }
                let cam: Vec<_> = (0..t).map(|i| vtx(pc[i], pl[i], delta[i])).collect();
                let light: Vec<_> = (0..s)
                    .map(|j| {
                        let i = k - j;
                        vtx(pl[i], pc[i], delta[i])
                    })
                    .collect();
                let at = |v: &[f32], i: usize| v.get(i).copied().unwrap_or(0.0);
                let rev = Rev {
                    pt: if t >= 1 { pl[t - 1] } else { 0.0 },
                    pt_minus: if t >= 2 { pl[t - 2] } else { 0.0 },
                    qs: if s >= 1 { at(&pc, t) } else { 0.0 },
                    qs_minus: if s >= 2 { at(&pc, t + 1) } else { 0.0 },
                };
                sum += f64::from(mis_weight(&cam, &light, s, t, &rev, delta_light));
                counted += 1;
            }
            if counted > 0 {
                assert!(
                    (sum - 1.0).abs() < 1e-4,
                    "path {path} of {k} edges: weights sum to {sum} over {counted} strategies"
                );
            }
        }
    }
}
