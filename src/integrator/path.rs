//! One path vertex at a time: camera rays and the shading step shared by the wavefront
//! stages and the reference integrator, so both simulate exactly the same physics.

use super::bsdf::{Dielectric, Diffuse, Frame, Mirror, Mode};
use super::transport::{MediumOps, SpectralData, Transport};
use crate::components::Material;
use crate::components::camera::CameraFrame;
use crate::geometry::{Ray, offset_ray_origin, spawn_ray_to};
use crate::medium::{DistanceSample, Equiangular};
use crate::sampling::warp::lanes as warp;
use crate::sampling::{self, Sampler};
use crate::scene_file::schema::{Fresnel, LightSampling};
use crate::simd::{Float, UInt, V3, math};
use crate::spectrum::Channels;
use crate::systems::lights::{EquiangularTarget, LightSource};
use crate::systems::primitives::NO_MEDIUM;
use crate::systems::{Hit, RenderScene, primitives::emitted};
use glam::{Vec2, Vec3};

// Sample dimensions. The layout is fixed whatever the effect set, so an absent effect never
// shifts the dimensions of the others: a scene renders the same image with or without code
// for effects it does not use.
pub const DIM_FILM: u32 = 0;
pub const DIM_LENS: u32 = 2;
pub const DIM_TIME: u32 = 4;
pub const DIM_WAVELENGTH: u32 = 5;
pub const DIM_BOUNCE: u32 = 8;
/// Dimensions each scattering event may use: light choice (1), light point (2), lobe (1),
/// direction (2), Russian roulette (1), and one reserved.
pub const DIMS_PER_BOUNCE: u32 = 8;
/// Medium segments take their dimensions from a separate range, 12 per segment: channel,
/// distance, light choice, light point (2), phase direction (2), Russian roulette, and the
/// equiangular technique's light choice, distance and light point (2). A path may cross
/// boundaries without scattering, so segments are counted apart from bounces.
pub const DIM_MEDIA: u32 = 1 << 20;
pub const DIMS_PER_SEGMENT: u32 = 12;

/// Per-render constants of the shading step, hoisted out of the per-ray loop.
#[derive(Clone, Copy)]
pub struct Ctx<'a> {
    pub scene: &'a RenderScene,
    pub sampler: Sampler,
    pub width: u32,
    pub max_depth: u32,
    pub rr_depth: u32,
    pub nee: bool,
    pub schlick: bool,
    pub lens: bool,
    /// TEXTURES and NORMAL_MAPS: read once per render, never per ray from the world.
    pub textures: bool,
    pub normal_maps: bool,
    pub equiangular: bool,
    /// A box pixel filter instead of the tent.
    pub box_filter: bool,
    /// Spectral forms of the scene's colours (empty in RGB transport).
    pub spectral: &'a SpectralData,
    /// One wavelength per path instead of four (`render.integrator.wavelengths: 1`).
    pub single_wavelength: bool,
}

static NO_SPECTRAL_DATA: SpectralData = SpectralData::EMPTY;

impl<'a> Ctx<'a> {
    pub fn new(scene: &'a RenderScene, lens: bool) -> Self {
        let s = &scene.settings;
        Ctx {
            scene,
            sampler: Sampler::new(
                match s.sampler {
                    crate::scene_file::schema::SamplerChoice::Sobol => sampling::SamplerKind::Sobol,
                    crate::scene_file::schema::SamplerChoice::Independent => {
                        sampling::SamplerKind::Independent
                    }
                },
                s.seed,
            ),
            width: s.width,
            max_depth: s.max_depth,
            rr_depth: s.rr_depth,
            nee: s.light_sampling == LightSampling::Nee && !scene.lights.is_empty(),
            schlick: s.fresnel == Fresnel::Schlick,
            lens,
            textures: scene.effects.has(crate::systems::Effect::Textures),
            normal_maps: scene.effects.has(crate::systems::Effect::NormalMaps),
            equiangular: s.equiangular,
            box_filter: s.filter == crate::scene_file::schema::Filter::Box,
            spectral: &NO_SPECTRAL_DATA,
            single_wavelength: s.wavelengths == 1,
        }
    }

    /// The same constants with the spectral data spectral transport reads.
    pub fn with_spectral(self, spectral: &'a SpectralData) -> Self {
        Ctx { spectral, ..self }
    }
}

/// The state a path carries between vertices.
#[derive(Clone, Copy, Debug)]
pub struct PathState<T: Transport> {
    pub ray: Ray,
    pub beta: T::S,
    /// Radiance gathered so far.
    pub l: T::S,
    /// The path's wavelengths (spectral transport).
    pub lambda: T::Lambda,
    /// Product of squared relative IORs crossed; Russian roulette divides it out of the
    /// throughput so entering dense glass does not kill paths.
    pub eta_scale: f32,
    pub depth: u32,
    pub specular: bool,
    /// Solid-angle pdf of the direction that reached this vertex (for MIS on emitters).
    pub prev_pdf: f32,
    pub prev_p: Vec3,
    pub time: f32,
    pub pixel: u32,
    pub sample: u32,
    pub alive: bool,
    /// The medium the ray travels in (`NO_MEDIUM` for none).
    pub medium: u32,
    /// Medium segments sampled so far (their sample dimensions).
    pub segments: u32,
}

/// A shadow ray whose contribution lands on the path if nothing blocks it (with MEDIA, scaled
/// by the transmittance along it, starting in `medium`).
#[derive(Clone, Copy, Debug)]
pub struct ShadowRequest<S> {
    pub ray: Ray,
    pub t_max: f32,
    pub contrib: S,
    pub medium: u32,
}

#[inline]
pub(crate) fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 == 0.0 { 0.0 } else { a2 / (a2 + b2) }
}

/// Camera rays of one lane of samples: where each starts, where it goes, and when.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays<F: Float> {
    pub o: V3<F>,
    pub d: V3<F>,
    pub time: F,
}

/// The camera frame's vectors in lanes: the same in every lane, or each lane's own for a
/// camera moving within the shutter.
struct FrameLanes<F: Float> {
    origin: V3<F>,
    forward: V3<F>,
    right: V3<F>,
    up: V3<F>,
    half_x: F,
    half_y: F,
}

impl<F: Float> FrameLanes<F> {
    #[inline(always)]
    fn splat(c: &CameraFrame) -> Self {
        FrameLanes {
            origin: V3::splat(c.origin),
            forward: V3::splat(c.forward),
            right: V3::splat(c.right),
            up: V3::splat(c.up),
            half_x: F::splat(c.half.x),
            half_y: F::splat(c.half.y),
        }
    }
}

/// Samples `index` of pixels (x, y), one per lane: film position importance-sampled from the
/// pixel filter (a tent of radius one pixel, or a box of one pixel), a lens position when the LENS effect is on, a time when
/// MOTION is on. Lane `i` is exactly [`camera_ray`]'s ray for lane `i`'s sample.
#[inline(always)]
pub fn camera_rays<F: Float, const MOTION: bool>(
    ctx: &Ctx,
    x: F::U32,
    y: F::U32,
    index: F::U32,
) -> CameraRays<F> {
    type U<F> = <F as Float>::U32;
    let scene = ctx.scene;
    let s = &scene.settings;
    let pixel = y.wrapping_mul(U::<F>::splat(ctx.width)).wrapping_add(x);
    let sampler = &ctx.sampler;
    let time = if MOTION {
        let (open, close) = scene.shutter;
        let u = sampler.get_1d_lanes::<F>(pixel, index, U::<F>::splat(DIM_TIME));
        F::splat(open) + F::splat(close - open) * u
    } else {
        F::splat(scene.shutter.0)
    };
    // A camera moving within the shutter is evaluated at each ray's own time, one lane at a
    // time (a spline through keyframes).
    let cam = if MOTION && scene.camera_moves {
        let path = scene
            .camera_path
            .as_ref()
            .expect("camera_moves implies a path");
        let at = |i: usize| {
            path.at(time.lane(i), &scene.base_camera)
                .frame(s.width, s.height)
        };
        if F::WIDTH == 1 {
            FrameLanes::splat(&at(0))
        } else {
            let mut frames = [scene.camera; 16];
            for (i, f) in frames.iter_mut().enumerate().take(F::WIDTH) {
                *f = at(i);
            }
            FrameLanes {
                origin: V3::from_fn(|i| frames[i].origin),
                forward: V3::from_fn(|i| frames[i].forward),
                right: V3::from_fn(|i| frames[i].right),
                up: V3::from_fn(|i| frames[i].up),
                half_x: F::from_fn(|i| frames[i].half.x),
                half_y: F::from_fn(|i| frames[i].half.y),
            }
        }
    } else {
        FrameLanes::splat(&scene.camera)
    };
    let (ux, uy) = sampler.get_2d_lanes::<F>(pixel, index, U::<F>::splat(DIM_FILM));
    let half = F::splat(0.5);
    // Offsets from the pixel centre, distributed as the filter (one branch per packet).
    let (ox, oy) = if ctx.box_filter {
        (ux - half, uy - half)
    } else {
        (warp::sample_tent(ux), warp::sample_tent(uy))
    };
    let fx = x.i32_to_f32() + half + ox;
    let fy = y.i32_to_f32() + half + oy;
    let two = F::splat(2.0);
    let sx = two * fx / F::splat(s.width as f32) - F::one();
    let sy = F::one() - two * fy / F::splat(s.height as f32);
    let dir = cam.forward + cam.right * (sx * cam.half_x) + cam.up * (sy * cam.half_y);
    let dir = dir.normalize();
    if ctx.lens {
        let c = &scene.camera;
        let (lx, ly) = sampler.get_2d_lanes::<F>(pixel, index, U::<F>::splat(DIM_LENS));
        let (px, py) = lens_point_lanes(lx, ly, c.blades);
        let a = F::splat(c.aperture_radius);
        let o = cam.origin + cam.right * (px * a) + cam.up * (py * a);
        // `dir` has unit length along `forward`, so this is the point on the focal plane.
        let focus = cam.origin + dir * F::splat(c.focus_distance);
        CameraRays {
            o,
            d: (focus - o).normalize(),
            time,
        }
    } else {
        CameraRays {
            o: cam.origin,
            d: dir,
            time,
        }
    }
}

/// Starts the path of sample `index` of pixel (x, y): [`camera_rays`] at width 1, with the
/// path's wavelengths.
#[inline(always)]
pub fn camera_ray<T: Transport, const MOTION: bool>(
    ctx: &Ctx,
    x: u32,
    y: u32,
    index: u32,
) -> PathState<T> {
    let pixel = y * ctx.width + x;
    let r = camera_rays::<f32, MOTION>(ctx, x, y, index);
    let ray = Ray::new(r.o.into(), r.d.into());
    let lambda = T::wavelengths(ctx, pixel, index);
    PathState {
        ray,
        beta: T::initial_beta(&lambda),
        l: T::S::ZERO,
        lambda,
        eta_scale: 1.0,
        depth: 0,
        specular: false,
        prev_pdf: 0.0,
        prev_p: ray.o,
        time: r.time,
        pixel,
        sample: index,
        alive: true,
        medium: ctx.scene.camera_medium,
        segments: 0,
    }
}

/// A point on the unit aperture: a disc, or a regular polygon with `blades` sides.
#[inline]
pub fn lens_point(u: Vec2, blades: u32) -> Vec2 {
    let (x, y) = lens_point_lanes(u.x, u.y, blades);
    Vec2::new(x, y)
}

/// [`lens_point`] over lanes.
#[inline(always)]
pub fn lens_point_lanes<F: Float>(ux: F, uy: F, blades: u32) -> (F, F) {
    if blades < 3 {
        return warp::square_to_uniform_disk_concentric(ux, uy);
    }
    // Pick one of the polygon's equal triangles, reuse the rest of u.x inside it.
    let n = F::splat(blades as f32);
    let k = (ux * n).floor().min(n - F::one());
    let ux = ux * n - k;
    let tau = F::splat(std::f32::consts::TAU);
    let (s0, c0) = math::sin_cos(tau * k / n);
    let (s1, c1) = math::sin_cos(tau * (k + F::one()) / n);
    let (b0, b1) = warp::square_to_uniform_triangle(ux, uy);
    (c0 * b0 + c1 * b1, s0 * b0 + s1 * b1)
}

/// The surface at `hit` with its material after textures: the albedo texture modulates the
/// material (and is returned for spectral upsampling), a normal map tilts the shading normal.
#[inline(always)]
pub(crate) fn surface_material<const MOTION: bool>(
    ctx: &Ctx,
    ray: &Ray,
    hit: &Hit,
    time: f32,
) -> (crate::geometry::SurfacePoint, Material, Option<Vec3>) {
    let prims = &ctx.scene.prims;
    let mut sp = prims.surface_at::<MOTION>(ray, hit, time);
    let mut material = prims.materials[prims.material[hit.prim as usize] as usize];
    let mut tex_albedo = None;
    if (ctx.textures || ctx.normal_maps)
        && let Some(tex) = prims.texture_of(hit.prim)
    {
        let (uv, dpdu, dpdv) = prims.uv_frame::<MOTION>(ray, hit, &sp, time);
        if ctx.textures
            && let Some(a) = tex.albedo(uv)
        {
            material = material.modulated(a);
            tex_albedo = Some(a);
        }
        if ctx.normal_maps && tex.normal_map.is_some() {
            // As pbrt does: the perturbed normal is turned to the geometric normal's side;
            // directions it would send below the geometric surface are absorbed in scattering.
            let ns = tex.shading_normal(uv, sp.ns, dpdu, dpdv);
            sp.ns = if ns.dot(sp.n) < 0.0 { -ns } else { ns };
        }
    }
    (sp, material, tex_albedo)
}

/// The shadow ray of a light sample taken at surface point `p` (normal `nf` on the side the
/// path is on): to a point light, stopping just short of it (it sits on no surface); to a
/// point on an emitter, offset at both ends; or along `wi` to the environment.
#[inline(always)]
pub(crate) fn shadow_ray_from_surface(
    p: Vec3,
    nf: Vec3,
    point: Option<(Vec3, Vec3)>,
    delta: bool,
    wi: Vec3,
) -> (Ray, f32) {
    match point {
        Some((q, _)) if delta => {
            let o = offset_ray_origin(p, nf);
            (Ray::new(o, q - o), 1.0 - 1e-4)
        }
        Some((q, nq)) => spawn_ray_to(p, nf, q, nq),
        None => (Ray::new(offset_ray_origin(p, nf), wi), f32::INFINITY),
    }
}

/// A reflected direction kept on the side of `n`: at grazing angles (or about a tilted shading
/// normal) it can point a hair below the surface, and it must leave on the side it is spawned.
#[inline]
fn reflect_above(r: Vec3, n: Vec3) -> Vec3 {
    let c = r.dot(n);
    if c >= 0.0 {
        r
    } else {
        (r - 2.0 * c * n).normalize()
    }
}

/// A transmitted direction kept strictly below the surface `n` faces.
#[inline]
fn below(wt: Vec3, n: Vec3) -> Vec3 {
    let c = wt.dot(n);
    if c <= 0.0 {
        wt
    } else {
        (wt - 2.0 * c * n).normalize()
    }
}

/// Processes the vertex where `s.ray` ends: adds emission found there (MIS-weighted), then
/// either ends the path or scatters it, returning a shadow ray for next-event estimation.
///
/// In a medium, a second shadow ray may come back in `extra`: the equiangular technique's.
#[inline(always)]
pub fn shade<T: Transport, const MOTION: bool, const MEDIA: bool>(
    ctx: &Ctx,
    s: &mut PathState<T>,
    hit: Option<Hit>,
    extra: &mut Option<ShadowRequest<T::S>>,
) -> Option<ShadowRequest<T::S>> {
    let scene = ctx.scene;
    let lights = &scene.lights;
    let wo = -s.ray.d;
    if MEDIA && s.medium != NO_MEDIUM {
        let med = T::medium(ctx, s.medium, &s.lambda);
        let dim = DIM_MEDIA + s.segments * DIMS_PER_SEGMENT;
        s.segments += 1;
        let (pixel, index) = (s.pixel, s.sample);
        let t_hit = hit.map_or(f32::INFINITY, |h| h.t);
        let u_c = ctx.sampler.get_1d(pixel, index, dim);
        let u_t = ctx.sampler.get_1d(pixel, index, dim + 1);
        let probs = s.beta;
        if ctx.equiangular && ctx.nee && s.depth < ctx.max_depth {
            *extra = equiangular_nee::<T, MOTION>(ctx, s, &med, t_hit, dim);
        }
        match med.sample_distance(t_hit, u_c, u_t, probs) {
            DistanceSample::Pass { weight } => s.beta *= weight,
            DistanceSample::Scatter { t, weight } => {
                s.beta *= weight;
                let seg = Segment {
                    ray: s.ray,
                    t,
                    t_hit,
                    p_ff: med.distance_pdf(t, probs),
                };
                return scatter_in_medium::<T, MOTION>(ctx, s, &med, seg, dim);
            }
        }
        if s.beta == T::S::ZERO {
            s.alive = false;
            return None;
        }
    }
    let mis_emitter = |s: &PathState<T>, pdf_light: f32| -> f32 {
        if s.depth == 0 || s.specular || !ctx.nee {
            1.0
        } else {
            power_heuristic(s.prev_pdf, pdf_light)
        }
    };
    let Some(hit) = hit else {
        if scene.environment != Vec3::ZERO {
            let w = mis_emitter(s, lights.pdf_environment());
            s.l += s.beta * T::environment(ctx, &s.lambda) * w;
        }
        s.alive = false;
        return None;
    };
    let prims = &scene.prims;
    let mat = prims.material[hit.prim as usize];
    let (sp, material, tex_albedo) = surface_material::<MOTION>(ctx, &s.ray, &hit, s.time);
    if MEDIA && let Material::Boundary = material {
        // A medium's boundary: carry on in the same direction, in the medium beyond.
        s.medium = prims.medium_after_crossing(hit.prim, sp.front, s.medium);
        s.ray = Ray::new(offset_ray_origin(sp.p, -sp.facing()), s.ray.d);
        return None;
    }
    if let Material::Light { .. } = material {
        let le = emitted(&material, sp.n, wo);
        if le != Vec3::ZERO {
            let w = if s.depth == 0 || s.specular || !ctx.nee {
                1.0
            } else {
                mis_emitter(
                    s,
                    lights.pdf_area::<MOTION>(prims, hit.prim, s.prev_p, sp.p, sp.n, s.time),
                )
            };
            s.l += s.beta * T::emission(ctx, mat, le, tex_albedo, &s.lambda) * w;
        }
        // Emitters absorb what they do not emit.
        s.alive = false;
        return None;
    }
    if s.depth >= ctx.max_depth {
        s.alive = false;
        return None;
    }
    let dim = DIM_BOUNCE + s.depth * DIMS_PER_BOUNCE;
    let (pixel, index) = (s.pixel, s.sample);
    s.depth += 1;
    // Surfaces scatter on both sides: work in the frame facing the incoming ray. `nf` (the
    // geometric normal) decides which side a direction is on, so light never leaks through a
    // surface; `nsf` (the shading normal) shapes the scattering.
    let nf = sp.facing();
    let nsf = sp.shading_facing();
    let frame = Frame::<f32>::from_normal(nsf.into());
    let wo_l = frame.to_local(wo.into());
    let mut shadow = None;
    match material {
        Material::Diffuse { albedo } => {
            // Evaluated once for the light sample and the bounce (spectrally it is a sigmoid
            // at four wavelengths, not free).
            let bsdf = Diffuse {
                albedo: T::reflectance(ctx, mat, albedo, tex_albedo.is_some(), &s.lambda),
            };
            if ctx.nee {
                let u_sel = ctx.sampler.get_1d(pixel, index, dim);
                let u_l = ctx.sampler.get_2d(pixel, index, dim + 1);
                if let Some(ls) =
                    lights.sample::<MOTION>(prims, sp.p, u_sel, u_l, s.time, ctx.textures)
                {
                    let wi_l = frame.to_local(ls.wi.into());
                    let cos = wi_l.z;
                    if cos > 0.0 && ls.wi.dot(nf) > 0.0 {
                        let bsdf_pdf = bsdf.pdf(wo_l, wi_l);
                        let f = bsdf.eval(wo_l, wi_l) * cos;
                        let w = if ls.delta {
                            1.0
                        } else {
                            power_heuristic(ls.pdf, bsdf_pdf)
                        };
                        let contrib =
                            s.beta * f * T::light_radiance(ctx, &ls, &s.lambda) * (w / ls.pdf);
                        if contrib != T::S::ZERO {
                            let (ray, t_max) =
                                shadow_ray_from_surface(sp.p, nf, ls.point, ls.delta, ls.wi);
                            shadow = Some(ShadowRequest {
                                ray,
                                t_max,
                                contrib,
                                medium: s.medium,
                            });
                        }
                    }
                }
            }
            let u = ctx.sampler.get_2d(pixel, index, dim + 4);
            let bs = bsdf.sample(wo_l, u.x, u.y);
            let wi: Vec3 = frame.to_world(bs.wi).normalize().into();
            if wi.dot(nf) <= 0.0 {
                // Sampled around a tilted shading normal into the geometric back side: the
                // surface absorbs it rather than letting light through.
                s.alive = false;
                return shadow;
            }
            s.beta *= bs.weight;
            s.prev_pdf = bs.pdf;
            s.specular = false;
            s.ray = Ray::new(offset_ray_origin(sp.p, nf), wi);
        }
        Material::Mirror { tint } => {
            let bsdf = Mirror {
                tint: T::reflectance(ctx, mat, tint, tex_albedo.is_some(), &s.lambda),
            };
            let bs = bsdf.sample(wo_l);
            s.beta *= bs.weight;
            s.specular = true;
            let wi: Vec3 = frame.to_world(bs.wi).into();
            s.ray = Ray::new(offset_ray_origin(sp.p, nf), reflect_above(wi, nf));
        }
        Material::Dielectric { ior } => {
            // The geometric normal points out of a closed shape: entering on its front.
            let n = T::eta(&ior, &mut s.lambda, &mut s.beta);
            let bsdf = Dielectric {
                eta: if sp.front { n } else { 1.0 / n },
                schlick: ctx.schlick,
            };
            let u = ctx.sampler.get_1d(pixel, index, dim + 3);
            let bs = bsdf.sample::<T::S>(wo_l, u, Mode::Radiance);
            s.specular = true;
            s.beta *= bs.weight;
            let wi: Vec3 = frame.to_world(bs.wi).into();
            if bs.is_transmission() {
                s.eta_scale *= bs.eta * bs.eta;
                if MEDIA {
                    s.medium = prims.medium_after_crossing(hit.prim, sp.front, s.medium);
                }
                s.ray = Ray::new(offset_ray_origin(sp.p, -nf), below(wi, nf));
            } else {
                s.ray = Ray::new(offset_ray_origin(sp.p, nf), reflect_above(wi, nf));
            }
        }
        Material::Light { .. } | Material::Boundary => {
            // Lights returned above; a boundary exists only with MEDIA, which handled it.
            s.alive = false;
            return None;
        }
    }
    s.prev_p = sp.p;
    russian_roulette(ctx, s, dim + 6);
    shadow
}

/// Russian roulette on the throughput with the IOR compression removed.
#[inline]
fn russian_roulette<T: Transport>(ctx: &Ctx, s: &mut PathState<T>, dim: u32) {
    if s.depth >= ctx.rr_depth {
        let rr = (s.beta * s.eta_scale).max_element();
        if rr < 1.0 {
            let q = (1.0 - rr).max(0.0);
            if ctx.sampler.get_1d(s.pixel, s.sample, dim) < q {
                s.alive = false;
                return;
            }
            s.beta /= 1.0 - q;
        }
    }
    if s.beta == T::S::ZERO {
        s.alive = false;
    }
}

/// Where free-flight sampling put a scattering event: the segment's ray, the distance, the
/// segment's end and the density of that distance (for MIS with equiangular sampling).
pub(crate) struct Segment {
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
pub(crate) fn equiangular_nee<T: Transport, const MOTION: bool>(
    ctx: &Ctx,
    s: &PathState<T>,
    med: &T::Med,
    t_hit: f32,
    dim: u32,
) -> Option<ShadowRequest<T::S>> {
    let (pixel, index) = (s.pixel, s.sample);
    let lights = &ctx.scene.lights;
    let prims = &ctx.scene.prims;
    let target = lights.pick_equiangular::<MOTION>(
        prims,
        &s.ray,
        t_hit,
        (
            ctx.sampler.get_1d(pixel, index, dim + 8),
            ctx.sampler.get_2d(pixel, index, dim + 10),
        ),
        s.time,
    )?;
    let u_t = ctx.sampler.get_1d(pixel, index, dim + 9);
    let wo = -s.ray.d;
    match target {
        EquiangularTarget::Point {
            index: li,
            light: pl,
            pmf,
        } => {
            let eq = Equiangular::new(s.ray.o, s.ray.d, 0.0, t_hit, pl.position)?;
            let (t, p_eq) = eq.sample(u_t);
            let x = s.ray.at(t);
            let d = pl.position - x;
            let d2 = d.length_squared();
            let wi = d / d2.sqrt();
            let radiance =
                T::point_radiance(ctx, li, pl.intensity, pl.falloff(-wi) / d2, &s.lambda);
            let p_ff = med.distance_pdf(t, s.beta);
            let contrib = s.beta
                * med.sigma_s()
                * med.transmittance(t)
                * radiance
                * (med.phase(wo, wi) / (pmf * (p_eq + p_ff)));
            (contrib != T::S::ZERO && contrib.is_finite()).then_some(ShadowRequest {
                ray: Ray::new(x, d),
                t_max: 1.0 - 1e-4,
                contrib,
                medium: s.medium,
            })
        }
        EquiangularTarget::Area {
            prim,
            p: y,
            n,
            density,
        } => {
            let eq = Equiangular::new(s.ray.o, s.ray.d, 0.0, t_hit, y)?;
            let (t, p_eq) = eq.sample(u_t);
            let x = s.ray.at(t);
            let ls =
                lights.area_seen_from::<MOTION>(prims, prim, (y, n), x, s.time, ctx.textures)?;
            let d = y - x;
            let d2 = d.length_squared();
            let g = n.dot(ls.wi).abs() / d2;
            let ph = med.phase(wo, ls.wi);
            let p_a = med.distance_pdf(t, s.beta) * ls.pdf * g;
            let p_c = density * p_eq;
            // f · w_c / p_c with f = β σs Tr(t) ph Le G (see above).
            let w = power_heuristic(ls.pdf, ph) * g / (p_a + p_c);
            let contrib = s.beta
                * med.sigma_s()
                * med.transmittance(t)
                * T::light_radiance(ctx, &ls, &s.lambda)
                * (ph * w);
            (contrib != T::S::ZERO && contrib.is_finite()).then_some(ShadowRequest {
                ray: shadow_ray_to_area(x, y, n),
                t_max: 1.0,
                contrib,
                medium: s.medium,
            })
        }
    }
}

/// The MIS weight of a light sample (`point`, `delta`, `source`, solid-angle `pdf`) taken
/// from the scattering point `p` of `seg`, whose phase function gives `ph` towards it.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn medium_light_weight<const MOTION: bool>(
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
            power_heuristic(pdf, ph) * if share.is_finite() { share } else { 1.0 }
        }
        _ => power_heuristic(pdf, ph),
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

/// A scattering event inside a medium: next-event estimation through the phase function
/// (MIS with phase sampling and with the equiangular technique, see [`equiangular_nee`]),
/// then a phase-sampled continuation.
#[inline]
fn scatter_in_medium<T: Transport, const MOTION: bool>(
    ctx: &Ctx,
    s: &mut PathState<T>,
    med: &T::Med,
    seg: Segment,
    dim: u32,
) -> Option<ShadowRequest<T::S>> {
    let p = seg.ray.at(seg.t);
    if s.depth >= ctx.max_depth {
        s.alive = false;
        return None;
    }
    s.depth += 1;
    let (pixel, index) = (s.pixel, s.sample);
    let wo = -s.ray.d;
    let mut shadow = None;
    if ctx.nee {
        let u_sel = ctx.sampler.get_1d(pixel, index, dim + 2);
        let u_l = ctx.sampler.get_2d(pixel, index, dim + 3);
        let prims = &ctx.scene.prims;
        if let Some(ls) =
            ctx.scene
                .lights
                .sample::<MOTION>(prims, p, u_sel, u_l, s.time, ctx.textures)
        {
            let ph = med.phase(wo, ls.wi);
            let w = medium_light_weight::<MOTION>(
                ctx, ls.point, ls.delta, ls.source, ls.pdf, ph, p, &seg, s.time,
            );
            let contrib = s.beta * T::light_radiance(ctx, &ls, &s.lambda) * (ph * w / ls.pdf);
            if contrib != T::S::ZERO && contrib.is_finite() {
                // A point in a medium lies on no surface: no offset at this end.
                let (ray, t_max) = match ls.point {
                    Some((q, _)) if ls.delta => (Ray::new(p, q - p), 1.0 - 1e-4),
                    Some((q, nq)) => (shadow_ray_to_area(p, q, nq), 1.0),
                    None => (Ray::new(p, ls.wi), f32::INFINITY),
                };
                shadow = Some(ShadowRequest {
                    ray,
                    t_max,
                    contrib,
                    medium: s.medium,
                });
            }
        }
    }
    let (wi, pdf) = med.sample_phase(wo, ctx.sampler.get_2d(pixel, index, dim + 5));
    s.prev_pdf = pdf;
    s.specular = false;
    s.prev_p = p;
    s.ray = Ray::new(p, wi);
    russian_roulette(ctx, s, dim + 7);
    shadow
}
