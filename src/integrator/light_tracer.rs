//! Light tracing (particle tracing): paths start on the emitters, and every vertex whose BSDF
//! has a density connects to the camera, splatting its contribution through the pixel filter.
//!
//! One light path per camera sample, keyed by (seed, pixel, sample index) like every other
//! sample, so batches hold disjoint light paths and the image is a sample-weighted mean as
//! the path tracer's is. Pixel `j` of an image of `spp` samples per pixel is
//! `(1/spp) Σ β f_s |cos| f_j(p) / (r² A cos³θ)` over every connection: `A` is the film's
//! area at distance 1, θ the angle of the connection to the camera's axis, `f_j` the pixel
//! filter at the raster point `p` (pbrt's `We` of the pinhole and of the thin lens, whose
//! lens density cancels). The paths carry importance: the BSDFs are sampled in importance
//! mode (no 1/η² at refraction) and shading normals get Veach's adjoint correction (thesis
//! §5.3).
//!
//! Splats land anywhere on the film, so each work item adds them in 64-bit fixed point:
//! integer sums do not depend on their order, and the image is the same on any thread count.
//! The paths run one at a time through the width-1 instantiation of the kernel's stages.
//! MEDIA: a path inside a medium samples its free flight as the path tracer's does; where it
//! scatters, it connects to the camera through the phase function. Connections carry the
//! transmittance of the media and boundaries they cross.

use super::bsdf::{Frame, LaneChannels, Mode};
use super::ctx::{Ctx, DIM_BOUNCE, DIM_MEDIA, DIM_TIME, DIMS_PER_BOUNCE};
use super::light::Glossy;
use super::material::{self, Vertex};
use super::media::Flight;
use super::state::{C, M, MAX_W, Paths, U, gdot};
use super::surface::{CLASS_BOUNDARY, CLASS_NONE, Surface};
use super::transport::{ChannelArray, MediumOps, Transport};
use super::{Observer, RenderOptions, RenderOutput, RenderStats, uniform_passes};
use crate::components::camera::CameraFrame;
use crate::film::{Tile, TileWork};
use crate::geometry::{Ray, offset_ray_origin};
use crate::scene::RenderScene;
use crate::scene::lights::{LightKind, LightSource};
use crate::scene::primitives::{NO_MEDIUM, PrimKind, emitted};
use crate::simd::V3;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::f32::consts::PI;
use std::marker::PhantomData;
use std::sync::atomic::Ordering;
use std::time::Instant;

/// One in fixed point: splats are summed as integers in units of 2⁻³² (a pixel's sum may
/// reach 2³¹ before it saturates).
const ONE: f64 = 4_294_967_296.0;

/// A film of splats in fixed point, three channels per pixel.
pub(super) struct Splats {
    width: u32,
    height: u32,
    sums: Vec<[i64; 3]>,
    /// With a target error, the sums of the samples of half B alone (see
    /// [`crate::film::estimate`]); empty otherwise.
    half: Vec<[i64; 3]>,
    /// The sample being traced belongs to half B: what it adds goes to `half` too.
    pub(super) half_b: bool,
}

impl Splats {
    pub(super) fn new(width: u32, height: u32) -> Self {
        Splats {
            width,
            height,
            sums: vec![[0; 3]; width as usize * height as usize],
            half: Vec::new(),
            half_b: false,
        }
    }

    /// An empty film that also keeps the sums of half B.
    fn with_halves(width: u32, height: u32) -> Self {
        let mut s = Self::new(width, height);
        s.half = s.sums.clone();
        s
    }

    /// Adds `v` (fixed point) to pixel `i`, and to its half B when the sample is of that half.
    #[inline(always)]
    fn deposit(&mut self, i: usize, v: [i64; 3]) {
        let add = |s: &mut [i64; 3]| {
            for (s, v) in s.iter_mut().zip(v) {
                *s = s.saturating_add(v);
            }
        };
        add(&mut self.sums[i]);
        if self.half_b
            && let Some(h) = self.half.get_mut(i)
        {
            add(h);
        }
    }

    /// Adds `rgb` to pixel (`x`, `y`) alone: a camera sample's own value (its filter is
    /// importance-sampled).
    #[inline(always)]
    pub(super) fn add_pixel(&mut self, x: u32, y: u32, rgb: Vec3) {
        let v = rgb.to_array().map(|c| (f64::from(c) * ONE).round() as i64);
        self.deposit((y * self.width + x) as usize, v);
    }

    /// Adds `rgb` at raster point (`fx`, `fy`) to the pixels whose filter covers it.
    #[inline(always)]
    pub(super) fn add(&mut self, fx: f32, fy: f32, rgb: Vec3, box_filter: bool) {
        let mut put = |x: i64, y: i64, w: f32| {
            if x < 0 || y < 0 || x >= i64::from(self.width) || y >= i64::from(self.height) {
                return;
            }
            // `as` saturates: no splat wraps a sum around.
            let v = rgb
                .to_array()
                .map(|c| (f64::from(c * w) * ONE).round() as i64);
            self.deposit((y * i64::from(self.width) + x) as usize, v);
        };
        if box_filter {
            put(fx.floor() as i64, fy.floor() as i64, 1.0);
            return;
        }
        // A tent of radius one: the two pixel centres on each axis within one pixel.
        let (x0, y0) = ((fx - 0.5).floor(), (fy - 0.5).floor());
        for dy in 0..2 {
            let wy = 1.0 - (fy - (y0 + dy as f32 + 0.5)).abs();
            for dx in 0..2 {
                let wx = 1.0 - (fx - (x0 + dx as f32 + 0.5)).abs();
                if wx > 0.0 && wy > 0.0 {
                    put(x0 as i64 + dx, y0 as i64 + dy, wx * wy);
                }
            }
        }
    }

    fn merge(mut self, o: Splats) -> Splats {
        for (a, b) in self.sums.iter_mut().zip(&o.sums) {
            for c in 0..3 {
                a[c] = a[c].saturating_add(b[c]);
            }
        }
        for (a, b) in self.half.iter_mut().zip(&o.half) {
            for c in 0..3 {
                a[c] = a[c].saturating_add(b[c]);
            }
        }
        self
    }

    /// Adds the fixed-point sums of `from` to `to` (f64).
    fn accumulate(to: &mut [[f64; 3]], from: &[[i64; 3]]) {
        for (s, p) in to.iter_mut().zip(from) {
            for c in 0..3 {
                s[c] += p[c] as f64 / ONE;
            }
        }
    }
}

/// The camera as a light path sees it: where a point lands on the film, and its importance.
pub(super) struct Camera<'a> {
    pub(super) scene: &'a RenderScene,
    pub(super) width: f32,
    pub(super) height: f32,
    pub(super) lens: bool,
    pub(super) box_filter: bool,
}

/// A connection from a scene point to the camera.
pub(super) struct Connection {
    /// The point on the lens (the pinhole without one).
    pub(super) lens: Vec3,
    /// Unit direction from the scene point to `lens`.
    pub(super) wc: Vec3,
    /// Raster position, in pixels.
    pub(super) fx: f32,
    pub(super) fy: f32,
    /// 1 / (r² A cos³θ).
    pub(super) importance: f32,
}

impl<'a> Camera<'a> {
    /// The camera of a render of `ctx`'s scene.
    pub(super) fn new(ctx: &Ctx<'a>) -> Self {
        let s = &ctx.scene.settings;
        Camera {
            scene: ctx.scene,
            width: s.width as f32,
            height: s.height as f32,
            lens: ctx.lens,
            box_filter: ctx.box_filter,
        }
    }

    /// The solid-angle density of a camera ray along unit `d` at `time`: 1 / (A cos³θ), the
    /// film's area `A` at distance 1 (a thin lens's rays through one lens point too).
    #[inline(always)]
    pub(super) fn pdf_dir<const MOTION: bool>(&self, time: f32, d: Vec3) -> f32 {
        let cam = self.frame::<MOTION>(time);
        let cos = d.dot(cam.forward);
        if cos <= 0.0 {
            return 0.0;
        }
        1.0 / (4.0 * cam.half.x * cam.half.y * cos * cos * cos)
    }

    /// The camera's frame at `time`.
    #[inline(always)]
    fn frame<const MOTION: bool>(&self, time: f32) -> CameraFrame {
        let s = self.scene;
        match &s.camera_path {
            Some(path) if MOTION && s.camera_moves => path
                .at(time, &s.base_camera)
                .frame(s.settings.width, s.settings.height),
            _ => s.camera,
        }
    }

    /// Connects `p` to the camera through the lens point drawn from `u`; `None` when `p` is
    /// behind the camera or off the film (beyond the filter's reach of every pixel).
    #[inline(always)]
    pub(super) fn connect<const MOTION: bool>(
        &self,
        p: Vec3,
        time: f32,
        u: (f32, f32),
    ) -> Option<Connection> {
        let cam = self.frame::<MOTION>(time);
        let lens = if self.lens {
            let c = &self.scene.camera;
            let (px, py) = super::generate::lens_point_lanes::<f32>(u.0, u.1, c.blades);
            let a = c.aperture_radius;
            cam.origin + cam.right * (px * a) + cam.up * (py * a)
        } else {
            cam.origin
        };
        let d = p - lens;
        let r2 = d.length_squared();
        let v = d / r2.sqrt();
        let cos = v.dot(cam.forward);
        if !(cos > 0.0 && r2 > 0.0) {
            return None;
        }
        // Where the ray from the lens point through `p` crosses the plane in focus, seen from
        // the pinhole at distance 1 (the inverse of `generate::camera_rays`).
        let film = if self.lens {
            let f = self.scene.camera.focus_distance;
            ((lens - cam.origin) + v * (f / cos)) / f
        } else {
            v / cos
        };
        let sx = film.dot(cam.right) / cam.half.x;
        let sy = film.dot(cam.up) / cam.half.y;
        let fx = (sx + 1.0) * 0.5 * self.width;
        let fy = (1.0 - sy) * 0.5 * self.height;
        let reach = if self.box_filter { 0.0 } else { 1.0 };
        let inside =
            fx > -reach && fx < self.width + reach && fy > -reach && fy < self.height + reach;
        if !inside {
            return None;
        }
        let area = 4.0 * cam.half.x * cam.half.y;
        let importance = 1.0 / (r2 * area * cos * cos * cos);
        importance.is_finite().then_some(Connection {
            lens,
            wc: -v,
            fx,
            fy,
            importance,
        })
    }

    /// The transmittance between `p` (leaving on the side of `n`; zero on no surface, in
    /// `medium`) and the lens point of `c`, as [`transmittance`] gives it.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn seen_from<
        T: Transport<S: ChannelArray<N>>,
        const N: usize,
        const MOTION: bool,
        const MEDIA: bool,
    >(
        &self,
        ctx: &Ctx,
        p: Vec3,
        n: Vec3,
        c: &Connection,
        medium: u32,
        time: f32,
        lam: &T::Lanes<f32>,
    ) -> Option<C<f32, N>> {
        // The lens lies on no surface: stop just short of it.
        let ray = self.ray_from(p, n, c);
        let tr = transmittance::<T, N, MOTION, MEDIA>;
        tr(
            ctx,
            &ray,
            1.0 - 1e-4,
            medium,
            time,
            lam,
            |_: u32, _: f32| {},
        )
    }

    /// The ray from `p` (leaving on the side of `n`; zero on no surface) to the lens point
    /// of `c`, which it reaches at parameter 1.
    #[inline(always)]
    pub(super) fn ray_from(&self, p: Vec3, n: Vec3, c: &Connection) -> Ray {
        let n = if n.dot(c.wc) >= 0.0 { n } else { -n };
        let o = offset_ray_origin(p, n);
        Ray::new(o, c.lens - o)
    }
}

/// Light-path vertices: the connection to the camera, and the adjoint BSDF sample.
struct CameraVertex<'a, 'b> {
    camera: &'a Camera<'b>,
    splats: &'a mut Splats,
    dropped: u64,
}

impl CameraVertex<'_, '_> {
    /// Splats the contribution `c` (the transport's channels) of connection `conn`.
    #[inline(always)]
    pub(super) fn splat<T: Transport<S: ChannelArray<N>>, const N: usize>(
        &mut self,
        c: &C<f32, N>,
        lam: &T::Lanes<f32>,
        conn: &Connection,
    ) {
        let mut rgb = [Vec3::ZERO; MAX_W];
        T::ended_rgb(c, lam, 1, &mut rgb);
        if rgb[0].is_finite() {
            self.splats
                .add(conn.fx, conn.fy, rgb[0], self.camera.box_filter);
        } else {
            self.dropped += 1;
        }
    }
}

impl<T: Transport<S: ChannelArray<N>>, const N: usize> Vertex<f32, T, N> for CameraVertex<'_, '_> {
    const MODE: Mode = Mode::Importance;

    #[inline(always)]
    fn connect<const MOTION: bool, const MEDIA: bool>(
        &mut self,
        ctx: &Ctx,
        st: &mut Paths<f32, T, N>,
        sf: &Surface<f32, N>,
        m: M<f32>,
        glossy: &Glossy<'_, f32>,
        frame: &Frame<f32>,
        dim: U<f32>,
        stats: &mut RenderStats,
    ) {
        if !m {
            return;
        }
        let u = ctx
            .sampler
            .get_2d_lanes::<f32>(st.pixel, st.sample, dim + 1);
        let p = sf.p.lane(0);
        let Some(conn) = self.camera.connect::<MOTION>(p, st.time, u) else {
            return;
        };
        let wc = V3::<f32>::splat(conn.wc);
        let (wl_l, wc_l) = (frame.to_local(-st.d), frame.to_local(wc));
        let side = gdot(wc, sf.nf);
        // The path tracer's BSDF as its light samples evaluate it, with the camera as the
        // viewer: the light's direction above both normals, the viewer above the geometric
        // one (a rough dielectric also transmits: the viewer below both).
        let through = glossy.dielectric && wc_l.z < 0.0 && side < 0.0;
        if !(wl_l.z > 0.0 && (side > 0.0 || through)) {
            return;
        }
        let (f, _) = if through {
            // The far side's frame is not this one: the adjoint at (w_l, w_c) is the same
            // value.
            glossy.eval(sf, wl_l, wc_l, Mode::Importance)
        } else {
            glossy.eval(sf, wc_l, wl_l, Mode::Radiance)
        };
        // f_s |w_l · n_s| |w_c · n_g| / |w_l · n_g|: Veach's shading-normal form of the
        // measurement, whose camera side is `conn.importance`.
        let g = wl_l.z * side.abs() / gdot(-st.d, sf.nf).abs();
        let c = st.beta * f * (g * conn.importance);
        if c.is_zero() {
            return;
        }
        stats.shadow_rays += 1;
        // MEDIA: through a rough dielectric the connection starts in the medium beyond it.
        let m = if through {
            let prims = &ctx.scene.prims;
            prims.medium_after_crossing(sf.prim[0], sf.front, st.medium[0])
        } else {
            st.medium[0]
        };
        let n = sf.nf.lane(0);
        let seen = Camera::seen_from::<T, N, MOTION, MEDIA>;
        if let Some(tr) = seen(self.camera, ctx, p, n, &conn, m, st.time, &st.lam) {
            self.splat::<T, N>(&(c * tr), &st.lam, &conn);
        }
    }
}

impl CameraVertex<'_, '_> {
    /// MEDIA: connects the light path `st`, scattered at `p` in its medium (asymmetry `g`;
    /// the event's dimensions from `dim`, see [`super::media::Flight`]), to the camera.
    #[inline(always)]
    fn medium_vertex<T: Transport<S: ChannelArray<N>>, const N: usize, const MOTION: bool>(
        &mut self,
        ctx: &Ctx,
        st: &Paths<f32, T, N>,
        (p, g, dim): (Vec3, f32, u32),
        stats: &mut RenderStats,
    ) {
        let u = ctx
            .sampler
            .get_2d_lanes::<f32>(st.pixel, st.sample, dim + 3);
        let Some(conn) = self.camera.connect::<MOTION>(p, st.time, u) else {
            return;
        };
        let ph = crate::medium::hg_phase_dirs(-st.d.lane(0), conn.wc, g);
        let c = st.beta * (ph * conn.importance);
        if c.is_zero() {
            return;
        }
        stats.shadow_rays += 1;
        let (m, n) = (st.medium[0], Vec3::ZERO);
        let seen = Camera::seen_from::<T, N, MOTION, true>;
        if let Some(tr) = seen(self.camera, ctx, p, n, &conn, m, st.time, &st.lam) {
            self.splat::<T, N>(&(c * tr), &st.lam, &conn);
        }
    }
}

/// The transmittance along `ray` up to `t_max` at the wavelengths `lam`: with MEDIA, starting
/// in `medium` and crossing media's boundaries, calling `piece(m, d)` for each stretch of
/// length `d` in medium `m`; without, 1 where nothing lies on the ray. `None` where a surface
/// (other than a boundary) blocks it.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn transmittance<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    ray: &Ray,
    t_max: f32,
    medium: u32,
    time: f32,
    lam: &T::Lanes<f32>,
    piece: impl Fn(u32, f32),
) -> Option<C<f32, N>> {
    if !MEDIA {
        let clear = !ctx.scene.occluded::<MOTION>(ray, t_max, time);
        return clear.then(|| C::<f32, N>::splat(1.0));
    }
    let lam = T::lane(lam, 0);
    let tr: T::S = ctx.scene.transmittance_with::<MOTION, T::S>(
        ray,
        t_max,
        time,
        medium,
        #[inline(always)]
        |m, d| {
            piece(m, d);
            T::medium(ctx, m, &lam).transmittance(d)
        },
    );
    let c = super::bsdf::Chan(tr.to_array());
    (!c.is_zero()).then_some(c)
}

/// A point and direction drawn on an emitter, with the throughput of the path they start.
pub(super) struct Emission<S> {
    pub(super) p: Vec3,
    /// The emitter's normal (zero at a point light).
    pub(super) n: Vec3,
    pub(super) d: Vec3,
    /// Radiance (area) or intensity (point) along `d`, over the densities of choosing the
    /// emitter, the point and the direction, times |cos| at an area emitter.
    pub(super) beta: S,
    /// Area emitters: radiance in the transport's channels, over the densities of choosing
    /// the emitter and the point (the emitter seen by the camera); zero at point lights.
    pub(super) le: S,
    pub(super) two_sided: bool,
    /// The environment or the sun: a direction at infinity, the path's origin drawn on a
    /// disc of the scene's bounding radius facing it.
    pub(super) at_infinity: bool,
    /// The densities of choosing the emitter and the point (area measure; the choice alone
    /// at a point light), and of the direction `d` (solid angle). At infinity the roles
    /// swap, as the path's vertices see them: `pdf_pos` is the density of the direction
    /// (solid angle, with the choice of the light) and `pdf_dir` that of the origin on the
    /// disc (planar).
    pub(super) pdf_pos: f32,
    pub(super) pdf_dir: f32,
}

impl<S: Copy> Emission<S> {
    /// The light path leaving the drawn point along `d` with throughput `beta`: its origin
    /// off the emitter's surface, Russian roulette weighing the throughput against this
    /// first one.
    #[inline(always)]
    pub(super) fn path<T: Transport<S = S>, const N: usize>(
        &self,
        beta: C<f32, N>,
        lam: T::Lanes<f32>,
        time: f32,
        pixel: u32,
        sample: u32,
    ) -> Paths<f32, T, N>
    where
        S: ChannelArray<N>,
    {
        let n = self.n;
        let o = if n == Vec3::ZERO {
            self.p
        } else {
            offset_ray_origin(self.p, if n.dot(self.d) >= 0.0 { n } else { -n })
        };
        let first_max = beta.max_element();
        let scale = if first_max > 0.0 {
            1.0 / first_max
        } else {
            1.0
        };
        let mut st = path_state::<T, N>(o, self.d, beta, lam, scale, time, pixel, sample);
        st.prev_p = V3::splat(self.p);
        st
    }
}

/// A fresh width-1 path state: the ray `o`, `d` at `time`, throughput `beta`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn path_state<T: Transport<S: ChannelArray<N>>, const N: usize>(
    o: Vec3,
    d: Vec3,
    beta: C<f32, N>,
    lam: T::Lanes<f32>,
    eta_scale: f32,
    time: f32,
    pixel: u32,
    sample: u32,
) -> Paths<f32, T, N> {
    Paths {
        o: V3::splat(o),
        d: V3::splat(d),
        beta,
        l: C::<f32, N>::splat(0.0),
        lam,
        eta_scale,
        depth: 0,
        specular: false,
        prev_pdf: 0.0,
        prev_p: V3::splat(o),
        time,
        pixel,
        sample,
        alive: true,
        medium: [NO_MEDIUM; MAX_W],
        in_medium: false,
        segments: [0; MAX_W],
    }
}

/// Veach's correction of the adjoint BSDF for shading normals (thesis §5.3), after a light
/// path scattered at `sf` from `wo` into `st.d`. The path tracer's BSDF reflects only light
/// arriving above the shading normal: reflected light from below it ends the path.
#[inline(always)]
pub(super) fn adjoint_correction<T: Transport, const N: usize>(
    st: &mut Paths<f32, T, N>,
    wo: V3<f32>,
    sf: &Surface<f32, N>,
) {
    let (wi, ns, ng) = (st.d, sf.nsf, sf.nf);
    let reflected = gdot(wi, ng) > 0.0;
    let num = gdot(wo, ns).abs() * gdot(wi, ng).abs();
    let den = gdot(wo, ng).abs() * gdot(wi, ns).abs();
    if den > 0.0 && !(reflected && gdot(wo, ns) <= 0.0) {
        st.beta = st.beta * (num / den);
    } else {
        st.alive = false;
    }
}

/// The density with which a point or spot light's emission sends its ray along unit `w`:
/// uniform over the sphere, or over a spot's cone.
#[inline(always)]
pub(super) fn point_emission_pdf(pl: &crate::components::PointLight, w: Vec3) -> f32 {
    if pl.cos_cone <= -1.0 {
        crate::sampling::uniform_sphere_pdf()
    } else if w.dot(pl.direction) >= pl.cos_cone {
        1.0 / (2.0 * PI * (1.0 - pl.cos_cone))
    } else {
        0.0
    }
}

/// Infinite light `light` (the environment or the sun) seen along unit `wi` (towards it):
/// its radiance in the transport's channels, and the density with which light sampling (and
/// a light path's start) draws `wi` from it, with the probability of choosing it. `None`
/// where it sends nothing.
#[inline(always)]
pub(super) fn infinite_light<T: Transport>(
    ctx: &Ctx,
    light: u32,
    lam: &T::Lambda,
    wi: Vec3,
) -> Option<(T::S, f32)> {
    let lights = &ctx.scene.lights;
    let pmf = lights.table.pmf(light as usize);
    let (rgb, source, pdf) = match lights.lights[light as usize] {
        LightKind::Environment(l) => (
            l,
            LightSource::Environment,
            crate::sampling::uniform_sphere_pdf(),
        ),
        LightKind::EnvMap => {
            let map = lights.map.as_deref()?;
            // A sky's radiance is the model's, not its tabulation's.
            let rgb = lights
                .sky
                .as_deref()
                .map_or_else(|| map.eval(wi), |s| s.rgb(wi));
            (rgb, LightSource::EnvMap { wi }, map.pdf(wi))
        }
        LightKind::Sun => {
            let sky = lights.sky.as_deref()?;
            if !sky.on_sun(wi) {
                return None;
            }
            (sky.sun_rgb(), LightSource::Sun, 1.0 / sky.sun_solid_angle())
        }
        LightKind::Area(_) | LightKind::Point(_) => return None,
    };
    if rgb == Vec3::ZERO || pdf.is_nan() || pdf <= 0.0 {
        return None;
    }
    Some((T::source_radiance(ctx, &source, rgb, lam), pmf * pdf))
}

/// Calls `f` with each infinite light's index: the environment's, then the sun's.
#[inline(always)]
pub(super) fn each_infinite(ctx: &Ctx, mut f: impl FnMut(u32)) {
    let lights = &ctx.scene.lights;
    for i in [lights.environment, lights.sun].into_iter().flatten() {
        f(i);
    }
}

/// Draws a point on an emitter chosen by power, and a direction from it: cosine-weighted
/// about an area emitter's normal (either side of a two-sided one), uniform in a spot's cone
/// or over the sphere of a point light.
#[inline(always)]
pub(super) fn emit<T: Transport<S: ChannelArray<N>>, const N: usize, const MOTION: bool>(
    ctx: &Ctx,
    lam: &T::Lambda,
    time: f32,
    u_sel: f32,
    u_pos: Vec2,
    u_dir: Vec2,
) -> Option<Emission<T::S>> {
    let scene = ctx.scene;
    let lights = &scene.lights;
    if lights.is_empty() {
        return None;
    }
    let prims = &scene.prims;
    let (i, pmf) = lights.table.sample(u_sel);
    match lights.lights[i] {
        LightKind::Point(pl) => {
            let (d, pdf) = if pl.cos_cone <= -1.0 {
                (
                    crate::sampling::square_to_uniform_sphere(u_dir),
                    crate::sampling::uniform_sphere_pdf(),
                )
            } else {
                // Uniform in the cone: nothing shines outside it.
                let cos = 1.0 - u_dir.x * (1.0 - pl.cos_cone);
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                let phi = 2.0 * PI * u_dir.y;
                let (a, b) = pl.direction.any_orthonormal_pair();
                let d = a * (sin * phi.cos()) + b * (sin * phi.sin()) + pl.direction * cos;
                (d.normalize(), 1.0 / (2.0 * PI * (1.0 - pl.cos_cone)))
            };
            let scale = pl.falloff(d);
            let source = LightSource::Point {
                light: i as u32,
                scale,
            };
            let i_rgb = pl.intensity * scale;
            let beta = T::source_radiance(ctx, &source, i_rgb, lam);
            Some(Emission {
                p: pl.position,
                n: Vec3::ZERO,
                d,
                beta: beta * (1.0 / (pmf * pdf)),
                le: T::S::from_array([0.0; N]),
                two_sided: false,
                at_infinity: false,
                pdf_pos: pmf,
                pdf_dir: pdf,
            })
        }
        LightKind::Area(prim) => {
            let l = prims.local[prim as usize] as usize;
            let motion = if MOTION { prims.motion_of(prim) } else { None };
            // Uniform by area, in the rest pose (a rigid motion keeps areas).
            let (p, n, area) = match prims.kind[prim as usize] {
                PrimKind::Sphere => {
                    let s = &prims.spheres[l];
                    let n = crate::sampling::square_to_uniform_sphere(u_pos);
                    (s.center + n * s.radius, n, s.area())
                }
                kind @ (PrimKind::Rect | PrimKind::Disk) => {
                    let q = &prims.planars[l];
                    let (a, b) = if kind == PrimKind::Disk {
                        let d = crate::sampling::square_to_uniform_disk_concentric(u_pos);
                        (d.x, d.y)
                    } else {
                        (2.0 * u_pos.x - 1.0, 2.0 * u_pos.y - 1.0)
                    };
                    (q.center + a * q.u + b * q.v, q.n, q.area())
                }
                PrimKind::Box | PrimKind::Revolution | PrimKind::Mesh => return None,
            };
            let material = prims.material[prim as usize];
            let mut m = prims.materials[material as usize];
            let mut tex = None;
            if ctx.textures
                && let Some(t) = prims.texture_of(prim)
                && let Some(a) = t.albedo(prims.uv_at(prim, p))
            {
                m = m.modulated(a);
                tex = Some(a);
            }
            let (p, n) = match motion {
                Some(mo) => (mo.point_to_world(p, time), mo.vector_to_world(n, time)),
                None => (p, n),
            };
            let crate::components::Material::Light { two_sided, .. } = m else {
                return None;
            };
            // Cosine-weighted about the emitting side (a two-sided emitter picks its side
            // with the first half of u).
            let (side, ux, sides) = if !two_sided {
                (n, u_dir.x, 1.0)
            } else if u_dir.x < 0.5 {
                (n, 2.0 * u_dir.x, 2.0)
            } else {
                (-n, 2.0 * u_dir.x - 1.0, 2.0)
            };
            let local = crate::sampling::square_to_cosine_hemisphere(Vec2::new(ux, u_dir.y));
            let (a, b) = side.any_orthonormal_pair();
            let d = (a * local.x + b * local.y + side * local.z).normalize();
            let rgb = emitted(&m, side, d);
            if rgb == Vec3::ZERO || local.z <= 0.0 {
                return None;
            }
            let source = LightSource::Area {
                material,
                tex,
                prim,
            };
            let le = T::source_radiance(ctx, &source, rgb, lam) * (area / pmf);
            // L cos / (pmf · (1/area) · cos/(π · sides)).
            Some(Emission {
                p,
                n,
                d,
                beta: le * (PI * sides),
                le,
                two_sided,
                at_infinity: false,
                pdf_pos: pmf / area,
                pdf_dir: local.z / (PI * sides),
            })
        }
        LightKind::Environment(_) | LightKind::EnvMap | LightKind::Sun => {
            // A direction drawn as light sampling draws it, then an origin uniform on the disc
            // of the scene's bounding radius facing it, one radius beyond the centre.
            let wi = match lights.lights[i] {
                LightKind::Environment(_) => crate::sampling::square_to_uniform_sphere(u_dir),
                LightKind::EnvMap => lights.map.as_deref()?.sample(u_dir)?.0,
                _ => lights.sky.as_deref()?.sample_sun(u_dir),
            };
            let (le, pdf) = infinite_light::<T>(ctx, i as u32, lam, wi)?;
            let (centre, r) = lights.sphere;
            let disc = crate::sampling::square_to_uniform_disk_concentric(u_pos);
            let (a, b) = wi.any_orthonormal_pair();
            let p = centre + (wi + a * disc.x + b * disc.y) * r;
            let planar = lights.disc_density();
            if !(p.is_finite() && planar > 0.0) {
                return None;
            }
            Some(Emission {
                p,
                n: Vec3::ZERO,
                d: -wi,
                beta: le * (1.0 / (pdf * planar)),
                le: T::S::from_array([0.0; N]),
                two_sided: false,
                at_infinity: true,
                pdf_pos: pdf,
                pdf_dir: planar,
            })
        }
    }
}

/// The light paths of the samples `work` names of every pixel of `tile`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn trace_tile<
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    camera: &Camera,
    holders: &[u32],
    tile: &Tile,
    work: &TileWork,
    splats: &mut Splats,
    stats: &mut RenderStats,
) {
    let scene = ctx.scene;
    let mut vertex = CameraVertex {
        camera,
        splats,
        dropped: 0,
    };
    let max_depth = ctx.max_depth;
    let infinite = scene.lights.has_infinite();
    for p in 0..tile.pixels() {
        let (x, y) = tile.pixel(p);
        let (first, count) = work.range(p);
        for k in 0..count {
            let (index, half) = work.index(first + k);
            let pixel = (y * ctx.width + x) | half;
            stats.samples += 1;
            vertex.splats.half_b = half != 0;
            let time = if MOTION {
                let (open, close) = scene.shutter;
                open + (close - open) * ctx.sampler.get_1d_lanes::<f32>(pixel, index, DIM_TIME)
            } else {
                scene.shutter.0
            };
            let lam = T::wavelengths::<f32>(ctx, pixel, index);
            let init = T::initial_beta::<f32, N>(&lam);
            let chan = |s: T::S| super::bsdf::Chan(s.to_array());
            if infinite {
                // No light path reaches the pinhole from infinity: the camera ray looks up
                // the environment it sees directly.
                let ray =
                    super::generate::camera_rays_keyed::<f32, MOTION>(ctx, x, y, pixel, index);
                let (o, d) = (ray.o.lane(0), ray.d.lane(0).normalize());
                stats.rays += 1;
                // MEDIA: seen through the media and boundaries along the ray.
                let (ray, m) = (Ray::new(o, d), scene.camera_medium);
                let tr = transmittance::<T, N, MOTION, MEDIA>;
                if let Some(tr) = tr(ctx, &ray, f32::INFINITY, m, time, &lam, |_: u32, _: f32| {}) {
                    let mut c = C::<f32, N>::splat(0.0);
                    each_infinite(ctx, |i| {
                        if let Some((le, _)) = infinite_light::<T>(ctx, i, &T::lane(&lam, 0), d) {
                            c = c + init * chan(le) * tr;
                        }
                    });
                    let mut rgb = [Vec3::ZERO; MAX_W];
                    T::ended_rgb(&c, &lam, 1, &mut rgb);
                    if rgb[0].is_finite() {
                        vertex.splats.add_pixel(x, y, rgb[0]);
                    } else {
                        vertex.dropped += 1;
                    }
                }
            }
            // The emission takes the dimensions of event 0; the path's events follow.
            let dim = DIM_BOUNCE;
            let sampler = &ctx.sampler;
            let u_sel = sampler.get_1d_lanes::<f32>(pixel, index, dim);
            let u_pos = sampler.get_2d_lanes::<f32>(pixel, index, dim + 1);
            let u_dir = sampler.get_2d_lanes::<f32>(pixel, index, dim + 4);
            let Some(e) = emit::<T, N, MOTION>(
                ctx,
                &T::lane(&lam, 0),
                time,
                u_sel,
                Vec2::new(u_pos.0, u_pos.1),
                Vec2::new(u_dir.0, u_dir.1),
            ) else {
                continue;
            };
            // The emitter seen by the camera: a point light is not, as in the path tracer.
            if e.n != Vec3::ZERO {
                let u = sampler.get_2d_lanes::<f32>(pixel, index, dim + 6);
                if let Some(conn) = camera.connect::<MOTION>(e.p, time, u) {
                    let cos = e.n.dot(conn.wc);
                    if e.two_sided || cos > 0.0 {
                        let c = init * chan(e.le) * (cos.abs() * conn.importance);
                        stats.shadow_rays += 1;
                        // MEDIA: the medium on the camera's side of the emitter.
                        let m = if MEDIA {
                            let side = if e.n.dot(conn.wc) >= 0.0 { e.n } else { -e.n };
                            scene
                                .prims
                                .medium_among(offset_ray_origin(e.p, side), holders)
                        } else {
                            NO_MEDIUM
                        };
                        let seen = Camera::seen_from::<T, N, MOTION, MEDIA>;
                        if !c.is_zero()
                            && let Some(tr) = seen(camera, ctx, e.p, e.n, &conn, m, time, &lam)
                        {
                            vertex.splat::<T, N>(&(c * tr), &lam, &conn);
                        }
                    }
                }
            }
            let mut st = e.path::<T, N>(init * chan(e.beta), lam, time, pixel, index);
            if MEDIA {
                st.medium[0] = scene.prims.medium_among(st.o.lane(0), holders);
                st.in_medium = st.medium[0] != NO_MEDIUM;
            }
            while st.alive && st.depth < max_depth {
                stats.rays += 1;
                stats.lane_slots += 1;
                let hits = scene.intersect_packet::<f32, MOTION>(st.o, st.d, true, time);
                if MEDIA && st.in_medium {
                    // A light path has no camera subpath: it takes the media's range.
                    match super::media::flight(ctx, &mut st, &hits, DIM_MEDIA) {
                        Flight::Passes => {}
                        Flight::Ends => break,
                        Flight::Scatters { p, g, dim, .. } => {
                            vertex.medium_vertex::<T, N, MOTION>(ctx, &st, (p, g, dim), stats);
                            super::media::scatter_phase(ctx, &mut st, p, g, dim);
                            continue;
                        }
                    }
                }
                let sf =
                    super::surface::surfaces::<f32, T, N, MOTION, MEDIA>(ctx, &st, &hits, true);
                // Emitters absorb, as in the path tracer.
                if !sf.hit || sf.class == CLASS_NONE {
                    break;
                }
                if MEDIA && sf.class == CLASS_BOUNDARY {
                    // A medium's boundary: on in the same direction, in the medium beyond.
                    st.o = V3::splat(offset_ray_origin(sf.p.lane(0), -sf.nf.lane(0)));
                    super::media::cross(ctx, &mut st, &sf, true);
                    continue;
                }
                let wo = -st.d;
                let eta_scale = st.eta_scale;
                material::scatter::<f32, T, N, MOTION, MEDIA, _>(
                    ctx,
                    &mut st,
                    &sf,
                    true,
                    stats,
                    DIM_BOUNCE + DIMS_PER_BOUNCE,
                    &mut vertex,
                );
                // Importance is not compressed at refraction: keep the roulette's scale.
                st.eta_scale = eta_scale;
                if st.alive {
                    adjoint_correction(&mut st, wo, &sf);
                }
            }
        }
    }
    stats.dropped += vertex.dropped;
}

/// Renders `opts.spp` light paths per pixel (fewer if stopped or out of time), in passes.
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
) -> RenderOutput {
    let camera = Camera::new(ctx);
    // MEDIA: the shapes that hold a medium, where a light path's start is looked up.
    let holders = if MEDIA {
        ctx.scene.prims.medium_holders()
    } else {
        Vec::new()
    };
    splat_passes(opts, ctx, tiles, progress, |tile, work, splats, stats| {
        let job = TileJob::<T, N, MOTION, MEDIA> {
            ctx,
            camera: &camera,
            holders: &holders,
            tile,
            work,
            splats,
            stats,
            transport: PhantomData,
        };
        <f32 as crate::simd::Float>::enter_typed(job)
    })
}

/// One tile of light tracing, run at width 1 inside the lanes' FMA entry point: the paths'
/// stages inline there, where `f32::mul_add` is one instruction (outside it, a call into
/// libm).
struct TileJob<'a, 'c, 'w, T, const N: usize, const MOTION: bool, const MEDIA: bool> {
    ctx: &'a Ctx<'c>,
    camera: &'a Camera<'c>,
    holders: &'a [u32],
    tile: &'a Tile,
    work: &'a TileWork<'w>,
    splats: &'a mut Splats,
    stats: &'a mut RenderStats,
    transport: PhantomData<T>,
}

impl<T: Transport<S: ChannelArray<N>>, const N: usize, const MOTION: bool, const MEDIA: bool>
    crate::simd::TypedKernel<f32> for TileJob<'_, '_, '_, T, N, MOTION, MEDIA>
{
    type Output = ();
    const SHARD: usize = super::home::<T>(MEDIA, MOTION, true);
    #[inline(always)]
    fn run(self) {
        trace_tile::<T, N, MOTION, MEDIA>(
            self.ctx,
            self.camera,
            self.holders,
            self.tile,
            self.work,
            self.splats,
            self.stats,
        )
    }
}

/// The pass loop of the estimators that splat: `trace` renders the samples a pass names of
/// one tile into a work item's splats; the items' fixed-point sums are added per pass. With a
/// target error, the passes are those of [`target_passes`].
pub(super) fn splat_passes(
    opts: &RenderOptions,
    ctx: &Ctx,
    tiles: &[Tile],
    progress: &dyn Observer,
    trace: impl Fn(&Tile, &TileWork, &mut Splats, &mut RenderStats) + Sync,
) -> RenderOutput {
    let scene = ctx.scene;
    let (w, h) = (scene.settings.width, scene.settings.height);
    let stopped = || opts.stop.is_some_and(|s| s.load(Ordering::Relaxed));
    // One pass: every tile's samples that `work` names, each work item's splats merged in
    // fixed point. `None` if a stop came during it.
    let pass = |work: &TileWork| -> Option<(Splats, RenderStats)> {
        let result = tiles
            .par_iter()
            .fold(
                || {
                    let splats = if work.split {
                        Splats::with_halves(w, h)
                    } else {
                        Splats::new(w, h)
                    };
                    (splats, RenderStats::default())
                },
                |(mut splats, mut st), tile| {
                    if !stopped() {
                        trace(tile, work, &mut splats, &mut st);
                        progress.samples(work.total(tile.pixels()));
                    }
                    (splats, st)
                },
            )
            .reduce_with(|(a, mut sa), (b, sb)| {
                sa.add(&sb);
                (a.merge(b), sa)
            });
        if stopped() {
            return None;
        }
        Some(result.unwrap_or_else(|| (Splats::new(w, h), RenderStats::default())))
    };
    let start = Instant::now();
    if let Some(target) = opts.target_error {
        return target_passes(opts, w, h, progress, start, target, pass);
    }
    let mut sums = vec![[0.0f64; 3]; w as usize * h as usize];
    let mut stats = RenderStats::default();
    let (done, interrupted) = uniform_passes(opts, w, h, progress, start, |work| {
        let (splats, st) = pass(&work)?;
        Splats::accumulate(&mut sums, &splats.sums);
        stats.add(&st);
        Some(())
    });
    RenderOutput {
        width: w,
        height: h,
        sums,
        spp: done,
        counts: Vec::new(),
        half: Vec::new(),
        estimate: None,
        stats,
        seconds: start.elapsed().as_secs_f64(),
        lanes: crate::simd::Lanes::scalar(),
        interrupted,
    }
}

/// The passes of a splatting render to a target error: every pixel takes the same number of
/// samples, alternating between the two independent halves the estimate needs (a splat lands
/// in the half of the sample whose light path made it). A light path's splats spread over the
/// image in proportion to one light path per camera sample, which holds only if every pixel
/// has the same count: so the counts are uniform, not adaptive. The image's relMSE falls as
/// 1/spp, so each pass aims at 0.9 of the target from the estimate so far, growing the count
/// at most 2× a pass (1.25× within twice the target, so the stop does not overshoot).
fn target_passes(
    opts: &RenderOptions,
    w: u32,
    h: u32,
    progress: &dyn Observer,
    start: Instant,
    target: f64,
    pass: impl Fn(&TileWork) -> Option<(Splats, RenderStats)>,
) -> RenderOutput {
    use crate::film::estimate;
    let pixels = w as usize * h as usize;
    let (mut sums, mut half) = (vec![[0.0f64; 3]; pixels], vec![[0.0f64; 3]; pixels]);
    let mut stats = RenderStats::default();
    // Even, so both halves always hold as many samples.
    let cap = opts.spp.max(2) & !1;
    let (mut done, mut next) = (0u32, super::WARMUP_FIRST.min(cap));
    let mut estimate = f64::INFINITY;
    let mut interrupted = false;
    while next > done {
        let t_pass = Instant::now();
        let n = next - done;
        let work = TileWork {
            offset: opts.sample_offset,
            uniform: (done, n),
            per_pixel: None,
            split: true,
        };
        let Some((splats, st)) = pass(&work) else {
            interrupted = true;
            break;
        };
        Splats::accumulate(&mut sums, &splats.sums);
        Splats::accumulate(&mut half, &splats.half);
        stats.add(&st);
        done = next;
        let counts = vec![done; pixels];
        estimate = estimate::image_error(&estimate::pixel_errors(&sums, &half, &counts, w, h));
        progress.pass(&super::PassReport {
            samples: u64::from(done) * pixels as u64,
            seconds: start.elapsed().as_secs_f64(),
            estimate: Some(estimate),
        });
        if estimate <= target {
            break;
        }
        let growth = if estimate < 2.0 * target { 1.25 } else { 2.0 };
        let want = f64::from(done) * estimate / (0.9 * target);
        let want = want.min(f64::from(done) * growth).min(f64::from(cap));
        // In even steps, rounded down (at a few samples per pixel one step is a large
        // fraction), and at least one more sample per half.
        next = ((want as u32) & !1).max(done + 2).min(cap);
        if let Some(limit) = opts.time_limit {
            let per_sample = t_pass.elapsed().as_secs_f64() / f64::from(n);
            let elapsed = start.elapsed().as_secs_f64();
            if elapsed + per_sample * f64::from(next - done) > limit {
                break;
            }
        }
    }
    RenderOutput {
        width: w,
        height: h,
        sums,
        spp: done,
        counts: vec![done; pixels],
        half,
        estimate: Some(estimate),
        stats,
        seconds: start.elapsed().as_secs_f64(),
        lanes: crate::simd::Lanes::scalar(),
        interrupted,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A splat a pixel or more inside the film adds its whole value, over up to four pixels
    /// (the tent's weights sum to one); the box puts it in the pixel it lands in.
    #[test]
    fn splat_weights_sum_to_one() {
        for (i, box_filter) in [false, true].into_iter().enumerate() {
            let mut s = Splats::new(8, 6);
            let points = [
                (1.0, 1.0),
                (3.3, 2.7),
                (6.99, 4.01),
                (4.5, 3.5),
                (2.25, 1.75),
            ];
            for &(x, y) in &points {
                s.add(x, y, Vec3::new(1.0, 2.0, 0.5), box_filter);
            }
            let total: i64 = s.sums.iter().map(|p| p[1]).sum();
            let want = 2.0 * points.len() as f64 * ONE;
            // The weights are f32: a few ulp of the value.
            let err = (total as f64 - want).abs();
            assert!(err <= want * 1e-6, "case {i}: {total} against {want}");
        }
        let mut s = Splats::new(4, 4);
        s.add(2.5, 1.5, Vec3::ONE, false);
        assert_eq!(
            s.sums[4 + 2][0] as f64,
            ONE,
            "a pixel centre takes the whole splat"
        );
    }
}
