//! The wavefront integrator: per tile, structure-of-arrays queues pushed through named stages.
//!
//! ```text
//! generate → intersect → shade (emission, scattering, light samples) → shadow → compact
//!     ↑__________________________ refill when fewer than half are live ______|
//! ```
//! Queues are allocated once per worker and reused for every tile: no allocation per ray.

use super::path::{Ctx, PathState, ShadowRequest, camera_ray, shade};
use super::transport::{MediumOps, Transport};
use super::{RenderStats, Tile};
use crate::geometry::Ray;
use crate::spectrum::Channels;
use crate::systems::Hit;
use glam::Vec3;

/// Live path records, one field per array.
pub struct RayQueue<T: Transport> {
    len: usize,
    o: Vec<Vec3>,
    d: Vec<Vec3>,
    beta: Vec<T::S>,
    l: Vec<T::S>,
    lambda: Vec<T::Lambda>,
    eta_scale: Vec<f32>,
    depth: Vec<u32>,
    specular: Vec<bool>,
    prev_pdf: Vec<f32>,
    prev_p: Vec<Vec3>,
    time: Vec<f32>,
    pixel: Vec<u32>,
    sample: Vec<u32>,
    alive: Vec<bool>,
    medium: Vec<u32>,
    segments: Vec<u32>,
}

impl<T: Transport> RayQueue<T> {
    fn new(cap: usize) -> Self {
        Self {
            len: 0,
            o: vec![Vec3::ZERO; cap],
            d: vec![Vec3::ZERO; cap],
            beta: vec![T::S::ZERO; cap],
            l: vec![T::S::ZERO; cap],
            lambda: vec![T::Lambda::default(); cap],
            eta_scale: vec![0.0; cap],
            depth: vec![0; cap],
            specular: vec![false; cap],
            prev_pdf: vec![0.0; cap],
            prev_p: vec![Vec3::ZERO; cap],
            time: vec![0.0; cap],
            pixel: vec![0; cap],
            sample: vec![0; cap],
            alive: vec![false; cap],
            medium: vec![0; cap],
            segments: vec![0; cap],
        }
    }

    fn cap(&self) -> usize {
        self.o.len()
    }

    #[inline]
    fn load(&self, i: usize) -> PathState<T> {
        PathState {
            ray: Ray::new(self.o[i], self.d[i]),
            beta: self.beta[i],
            l: self.l[i],
            lambda: self.lambda[i],
            eta_scale: self.eta_scale[i],
            depth: self.depth[i],
            specular: self.specular[i],
            prev_pdf: self.prev_pdf[i],
            prev_p: self.prev_p[i],
            time: self.time[i],
            pixel: self.pixel[i],
            sample: self.sample[i],
            alive: self.alive[i],
            medium: self.medium[i],
            segments: self.segments[i],
        }
    }

    #[inline]
    fn store(&mut self, i: usize, s: &PathState<T>) {
        self.o[i] = s.ray.o;
        self.d[i] = s.ray.d;
        self.beta[i] = s.beta;
        self.l[i] = s.l;
        self.lambda[i] = s.lambda;
        self.eta_scale[i] = s.eta_scale;
        self.depth[i] = s.depth;
        self.specular[i] = s.specular;
        self.prev_pdf[i] = s.prev_pdf;
        self.prev_p[i] = s.prev_p;
        self.time[i] = s.time;
        self.pixel[i] = s.pixel;
        self.sample[i] = s.sample;
        self.alive[i] = s.alive;
        self.medium[i] = s.medium;
        self.segments[i] = s.segments;
    }
}

/// Shadow rays of the current step and the path slot each one serves.
struct ShadowQueue<S> {
    len: usize,
    o: Vec<Vec3>,
    d: Vec<Vec3>,
    t_max: Vec<f32>,
    time: Vec<f32>,
    contrib: Vec<S>,
    medium: Vec<u32>,
    slot: Vec<u32>,
}

impl<S: Channels> ShadowQueue<S> {
    fn new(cap: usize) -> Self {
        Self {
            len: 0,
            o: vec![Vec3::ZERO; cap],
            d: vec![Vec3::ZERO; cap],
            t_max: vec![0.0; cap],
            time: vec![0.0; cap],
            contrib: vec![S::ZERO; cap],
            medium: vec![0; cap],
            slot: vec![0; cap],
        }
    }

    #[inline]
    fn push(&mut self, r: &ShadowRequest<S>, slot: usize, time: f32) {
        let i = self.len;
        self.time[i] = time;
        self.o[i] = r.ray.o;
        self.d[i] = r.ray.d;
        self.t_max[i] = r.t_max;
        self.contrib[i] = r.contrib;
        self.medium[i] = r.medium;
        self.slot[i] = slot as u32;
        self.len += 1;
    }
}

/// One worker's reusable queues.
pub struct Queues<T: Transport> {
    rays: RayQueue<T>,
    hits: Vec<Option<Hit>>,
    shadow: ShadowQueue<T::S>,
}

/// Rays per queue: small enough that a queue's hot fields stay in L2.
pub const QUEUE_CAPACITY: usize = 2048;

impl<T: Transport> Queues<T> {
    pub fn new(cap: usize) -> Self {
        Self {
            rays: RayQueue::new(cap),
            hits: vec![None; cap],
            // Up to two shadow rays per path step (light sampling, and in media the
            // equiangular technique).
            shadow: ShadowQueue::new(2 * cap),
        }
    }
}

impl<T: Transport> Default for Queues<T> {
    fn default() -> Self {
        Self::new(QUEUE_CAPACITY)
    }
}

/// Renders samples `s0..s1` of every pixel of `tile`, adding each finished path's radiance to
/// `film` (the tile's pixels, row-major).
#[inline(always)]
pub fn render_tile<T: Transport, const MOTION: bool, const MEDIA: bool>(
    ctx: &Ctx,
    q: &mut Queues<T>,
    tile: &Tile,
    s0: u32,
    s1: u32,
    film: &mut [[f64; 3]],
    stats: &mut RenderStats,
) {
    let spp = (s1 - s0) as usize;
    let total = tile.pixels() * spp;
    let mut next = 0usize;
    let cap = q.rays.cap();
    loop {
        // Stage 1, generate: refill once fewer than half the slots are live.
        if q.rays.len < cap / 2 {
            while q.rays.len < cap && next < total {
                let (p, k) = (next / spp, next % spp);
                let (x, y) = tile.pixel(p);
                let s = camera_ray::<T, MOTION>(ctx, x, y, s0 + k as u32);
                let i = q.rays.len;
                q.rays.store(i, &s);
                q.rays.len += 1;
                next += 1;
            }
        }
        let n = q.rays.len;
        if n == 0 {
            break;
        }
        // Stage 2, intersect: closest hits into a small-record queue.
        for i in 0..n {
            let ray = Ray::new(q.rays.o[i], q.rays.d[i]);
            q.hits[i] = ctx
                .scene
                .intersect::<MOTION>(&ray, f32::INFINITY, q.rays.time[i]);
        }
        stats.rays += n as u64;
        // Stages 3–4, emission and shading: one vertex per path, light samples queued.
        q.shadow.len = 0;
        for i in 0..n {
            let mut s = q.rays.load(i);
            let mut extra = None;
            if let Some(r) = shade::<T, MOTION, MEDIA>(ctx, &mut s, q.hits[i], &mut extra) {
                q.shadow.push(&r, i, s.time);
            }
            if let Some(r) = extra {
                q.shadow.push(&r, i, s.time);
            }
            q.rays.store(i, &s);
        }
        // Stage 5, shadow: any-hit tests (with MEDIA, transmittance through medium
        // boundaries); unblocked light samples land on their path.
        let sh = &q.shadow;
        for j in 0..sh.len {
            let ray = Ray::new(sh.o[j], sh.d[j]);
            if MEDIA {
                let slot = sh.slot[j] as usize;
                let lambda = &q.rays.lambda[slot];
                let tr = ctx.scene.transmittance_with::<MOTION, T::S>(
                    &ray,
                    sh.t_max[j],
                    sh.time[j],
                    sh.medium[j],
                    |m, d| T::medium(ctx, m, lambda).transmittance(d),
                );
                q.rays.l[slot] += sh.contrib[j] * tr;
            } else if !ctx.scene.occluded::<MOTION>(&ray, sh.t_max[j], sh.time[j]) {
                q.rays.l[sh.slot[j] as usize] += sh.contrib[j];
            }
        }
        stats.shadow_rays += sh.len as u64;
        // Stage 6, compact: finished paths go to the film; each hole is filled from the live
        // paths at the end of the queue, so only as many records move as paths finished.
        for i in 0..n {
            if !q.rays.alive[i] {
                let l = T::to_rgb(q.rays.l[i], &q.rays.lambda[i]);
                super::accumulate(film, tile, ctx.width, q.rays.pixel[i], l, stats);
            }
        }
        let (mut lo, mut hi) = (0, n);
        loop {
            while lo < hi && q.rays.alive[lo] {
                lo += 1;
            }
            while hi > lo && !q.rays.alive[hi - 1] {
                hi -= 1;
            }
            if lo >= hi {
                break;
            }
            let s = q.rays.load(hi - 1);
            q.rays.store(lo, &s);
            q.rays.alive[hi - 1] = false;
            lo += 1;
            hi -= 1;
        }
        q.rays.len = lo;
    }
}
