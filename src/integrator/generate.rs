//! Generate: camera rays for the tile's next samples, started in the lanes whose paths ended.

use super::bsdf::LaneChannels;
use super::ctx::{Ctx, DIM_FILM, DIM_LENS, DIM_TIME};
use super::state::{C, M, MAX_W, Paths, U, mask_from_bits, select_c};
use super::transport::{ChannelArray, Transport};
use crate::components::camera::CameraFrame;
use crate::film::{Tile, TileWork};
use crate::sampling::warp::lanes as warp;
use crate::scene::primitives::NO_MEDIUM;
use crate::simd::{Float, Mask, UInt, V3, math};
use glam::Vec2;

/// Camera rays of one lane of samples: where each starts, where it goes, and when.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays<F: Float> {
    /// Ray origins, world space (points on the lens when it has an aperture).
    pub o: V3<F>,
    /// Unit ray directions.
    pub d: V3<F>,
    /// Scene time of each ray, in frames.
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
/// pixel filter (a tent of radius one pixel, or a box of one pixel), a lens position when the
/// LENS effect is on, a time when MOTION is on. Lane `i` holds the width-1 ray of its sample,
/// bit for bit.
#[inline(always)]
pub fn camera_rays<F: Float, const MOTION: bool>(
    ctx: &Ctx,
    x: F::U32,
    y: F::U32,
    index: F::U32,
) -> CameraRays<F> {
    let pixel = y
        .wrapping_mul(<F::U32 as UInt>::splat(ctx.width))
        .wrapping_add(x);
    camera_rays_keyed::<F, MOTION>(ctx, x, y, pixel, index)
}

/// [`camera_rays`] with the sampler keyed by `pixel` (the pixel's number, with
/// [`crate::film::HALF_B`] set for the second of two independent halves).
#[inline(always)]
pub fn camera_rays_keyed<F: Float, const MOTION: bool>(
    ctx: &Ctx,
    x: F::U32,
    y: F::U32,
    pixel: F::U32,
    index: F::U32,
) -> CameraRays<F> {
    type U<F> = <F as Float>::U32;
    let scene = ctx.scene;
    let s = &scene.settings;
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
    // Unit length along `forward` (the film plane at distance 1), so `focus_distance` times
    // it lands on the focal plane.
    let film = cam.forward + cam.right * (sx * cam.half_x) + cam.up * (sy * cam.half_y);
    let dir = film.normalize();
    if ctx.lens {
        let c = &scene.camera;
        let (lx, ly) = sampler.get_2d_lanes::<F>(pixel, index, U::<F>::splat(DIM_LENS));
        let (px, py) = lens_point_lanes(lx, ly, c.blades);
        let a = F::splat(c.aperture_radius);
        let o = cam.origin + cam.right * (px * a) + cam.up * (py * a);
        // The thin lens focuses a plane, not a sphere: every lens point's ray through this
        // pixel meets the pinhole ray where it crosses the plane at `focus_distance`.
        let focus = cam.origin + film * F::splat(c.focus_distance);
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

/// Where a tile's pass stands: the tile pixel being sampled and its next sample of the pass.
#[derive(Clone, Copy, Default)]
pub(super) struct Cursor {
    p: usize,
    k: u32,
}

/// Starts new paths in the dead lanes, from the tile's next samples in pixel-major order
/// (every width takes them in the same order).
#[inline(always)]
pub(super) fn refill<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
>(
    ctx: &Ctx,
    tile: &Tile,
    work: &TileWork,
    cur: &mut Cursor,
    st: &mut Paths<F, T, N>,
) {
    let mut x = [0u32; MAX_W];
    let mut y = [0u32; MAX_W];
    let mut idx = [0u32; MAX_W];
    let mut half = [0u32; MAX_W];
    let mut fresh = 0u32;
    let alive = st.alive.bits();
    let pixels = tile.pixels();
    for i in 0..F::WIDTH {
        if alive >> i & 1 != 0 {
            continue;
        }
        while cur.p < pixels && cur.k >= work.range(cur.p).1 {
            cur.p += 1;
            cur.k = 0;
        }
        if cur.p >= pixels {
            break;
        }
        (x[i], y[i]) = tile.pixel(cur.p);
        (idx[i], half[i]) = work.index(work.range(cur.p).0 + cur.k);
        cur.k += 1;
        fresh |= 1 << i;
        st.medium[i] = ctx.scene.camera_medium;
        st.segments[i] = 0;
    }
    if fresh == 0 {
        return;
    }
    let fm = mask_from_bits::<F>(fresh);
    let cam_in = M::<F>::splat(ctx.scene.camera_medium != NO_MEDIUM);
    st.in_medium = st.in_medium.and_not(fm) | (fm & cam_in);
    let (xl, yl, il) = (
        U::<F>::from_fn(|i| x[i]),
        U::<F>::from_fn(|i| y[i]),
        U::<F>::from_fn(|i| idx[i]),
    );
    // The half bit keys the sampler apart (every dimension, the camera's too); the film
    // clears it again.
    let pixel =
        yl.wrapping_mul(U::<F>::splat(ctx.width)).wrapping_add(xl) | U::<F>::from_fn(|i| half[i]);
    let cam = camera_rays_keyed::<F, MOTION>(ctx, xl, yl, pixel, il);
    st.o = V3::select(fm, cam.o, st.o);
    st.d = V3::select(fm, cam.d, st.d);
    st.time = F::select(fm, cam.time, st.time);
    let lam = T::wavelengths::<F>(ctx, pixel, il);
    st.beta = select_c(fm, T::initial_beta(&lam), st.beta);
    st.lam = T::select_lanes(fm, lam, st.lam);
    st.l = select_c(fm, C::<F, N>::splat(F::zero()), st.l);
    st.eta_scale = F::select(fm, F::one(), st.eta_scale);
    st.depth = U::<F>::select(fm, U::<F>::splat(0), st.depth);
    st.specular = st.specular.and_not(fm);
    st.prev_pdf = F::select(fm, F::zero(), st.prev_pdf);
    st.prev_p = V3::select(fm, cam.o, st.prev_p);
    st.pixel = U::<F>::select(fm, pixel, st.pixel);
    st.sample = U::<F>::select(fm, il, st.sample);
    st.alive |= fm;
}
