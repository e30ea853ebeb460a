//! Light transport: the wavefront path tracer, its reference twin, and the render loop that
//! splits an image into tiles and passes.
//!
//! The integrator is generic over the effects that change its state and loops (SPECTRAL,
//! MEDIA, MOTION): eight monomorphised variants, chosen once per render, so an absent effect
//! costs no branch per ray. LENS is a flag read once per render.

pub mod bsdf;
pub mod packet;
pub mod path;
pub mod reference;
pub mod transport;
pub mod wavefront;

use crate::systems::{Effect, RenderScene};
use glam::Vec3;
use rayon::prelude::*;
use std::marker::PhantomData;
use std::time::Instant;

pub use path::Ctx;

/// Square tiles of this many pixels a side: the unit of parallel work. Tiles never share
/// pixels (no splatting), so workers need no locks and the image does not depend on which
/// thread rendered which tile.
pub const TILE: u32 = 16;

#[derive(Clone, Copy, Debug)]
pub struct Tile {
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
}

impl Tile {
    #[inline]
    pub fn pixels(&self) -> usize {
        (self.w * self.h) as usize
    }

    /// Image coordinates of the tile's `p`-th pixel (row-major).
    #[inline]
    pub fn pixel(&self, p: usize) -> (u32, u32) {
        let p = p as u32;
        (self.x0 + p % self.w, self.y0 + p / self.w)
    }
}

pub fn tiles(width: u32, height: u32) -> Vec<Tile> {
    let mut t = Vec::new();
    for y0 in (0..height).step_by(TILE as usize) {
        for x0 in (0..width).step_by(TILE as usize) {
            t.push(Tile {
                x0,
                y0,
                w: TILE.min(width - x0),
                h: TILE.min(height - y0),
            });
        }
    }
    t
}

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Newton iterations and brackets of surfaces of revolution.
    pub revolution: crate::geometry::RevolutionStats,
    /// Camera samples whose radiance reached the film.
    pub samples: u64,
    /// Samples whose radiance was not finite: dropped and counted, never written.
    pub dropped: u64,
    pub rays: u64,
    pub shadow_rays: u64,
    /// Lanes offered to paths by the packet kernel, one per lane per step (live or not):
    /// `rays / lane_slots` is its mean lane occupancy. Zero for the per-path integrators.
    pub lane_slots: u64,
}

impl RenderStats {
    fn add(&mut self, o: &RenderStats) {
        self.samples += o.samples;
        self.dropped += o.dropped;
        self.rays += o.rays;
        self.shadow_rays += o.shadow_rays;
        self.lane_slots += o.lane_slots;
        self.revolution += o.revolution;
    }
}

/// Adds one finished path to its pixel of the tile film, or drops it if it is not finite.
#[inline]
pub(crate) fn accumulate(
    film: &mut [[f64; 3]],
    tile: &Tile,
    width: u32,
    pixel: u32,
    l: Vec3,
    stats: &mut RenderStats,
) {
    if !l.is_finite() {
        stats.dropped += 1;
        return;
    }
    stats.samples += 1;
    let (x, y) = (pixel % width, pixel / width);
    let i = ((y - tile.y0) * tile.w + (x - tile.x0)) as usize;
    let px = &mut film[i];
    px[0] += l.x as f64;
    px[1] += l.y as f64;
    px[2] += l.z as f64;
}

thread_local! {
    // Each worker thread allocates its queues once and reuses them for every tile, pass and
    // render (rayon's `map_init` would build them again for every split of the work).
    static QUEUES_RGB: std::cell::RefCell<wavefront::Queues<transport::Rgb>> =
        std::cell::RefCell::new(wavefront::Queues::default());
    static QUEUES_SPECTRAL: std::cell::RefCell<wavefront::Queues<transport::Spectral>> =
        std::cell::RefCell::new(wavefront::Queues::default());
}

/// This thread's reusable queues for a transport, and its packet kernel.
trait WithQueues: transport::Transport {
    fn with_queues<R>(f: impl FnOnce(&mut wavefront::Queues<Self>) -> R) -> R;
    /// [`packet::render_tile`] with this transport's channel count.
    fn packet_tile<F: crate::simd::Float, const MOTION: bool, const MEDIA: bool>(
        t: PacketTile<'_, '_, MOTION>,
    );
}

impl WithQueues for transport::Rgb {
    fn with_queues<R>(f: impl FnOnce(&mut wavefront::Queues<Self>) -> R) -> R {
        QUEUES_RGB.with_borrow_mut(f)
    }
    #[inline(always)]
    fn packet_tile<F: crate::simd::Float, const MOTION: bool, const MEDIA: bool>(
        t: PacketTile<'_, '_, MOTION>,
    ) {
        packet::render_tile::<F, Self, 3, MOTION, MEDIA>(t.ctx, t.tile, t.s0, t.s1, t.film, t.stats)
    }
}

impl WithQueues for transport::Spectral {
    fn with_queues<R>(f: impl FnOnce(&mut wavefront::Queues<Self>) -> R) -> R {
        QUEUES_SPECTRAL.with_borrow_mut(f)
    }
    #[inline(always)]
    fn packet_tile<F: crate::simd::Float, const MOTION: bool, const MEDIA: bool>(
        t: PacketTile<'_, '_, MOTION>,
    ) {
        packet::render_tile::<F, Self, 4, MOTION, MEDIA>(t.ctx, t.tile, t.s0, t.s1, t.film, t.stats)
    }
}

/// Which integrator runs the passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Integrator {
    #[default]
    Wavefront,
    Reference,
}

pub struct RenderOptions {
    /// First sample index of every pixel: sample ranges rendered apart never repeat samples.
    pub sample_offset: u32,
    pub spp: u32,
    /// Stop between whole passes once this many seconds are spent.
    pub time_limit: Option<f64>,
    pub integrator: Integrator,
    /// The lane width asked for: the packet kernel runs at it where it covers the scene's
    /// effects, the per-path integrator at width 1 elsewhere.
    pub lanes: crate::simd::Lanes,
}

/// Linear per-pixel sums of a render and what it cost.
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    /// Sum of the radiance of every sample, per pixel (row-major, top row first).
    pub sums: Vec<[f64; 3]>,
    /// Samples per pixel actually rendered (fewer than asked under a time limit).
    pub spp: u32,
    pub stats: RenderStats,
    pub seconds: f64,
    /// The lane width that ran.
    pub lanes: crate::simd::Lanes,
}

impl RenderOutput {
    /// The image: sums divided by the sample count.
    pub fn image(&self) -> crate::film::Image {
        let k = 1.0 / self.spp.max(1) as f64;
        crate::film::Image {
            width: self.width,
            height: self.height,
            pixels: self
                .sums
                .iter()
                .map(|s| [(s[0] * k) as f32, (s[1] * k) as f32, (s[2] * k) as f32])
                .collect(),
        }
    }
}

/// Renders the scene on the current rayon pool. `progress` is told the number of samples
/// finished, once per tile.
pub fn render(
    scene: &RenderScene,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> RenderOutput {
    let fx = &scene.effects;
    let (s, m, mo) = (
        fx.has(Effect::Spectral),
        fx.has(Effect::Media),
        fx.has(Effect::Motion),
    );
    // One dispatch per render into the variant for this effect set.
    use transport::{Rgb, Spectral};
    match (s, m, mo) {
        (false, false, false) => render_with::<Rgb, false, false>(scene, opts, progress),
        (false, false, true) => render_with::<Rgb, false, true>(scene, opts, progress),
        (false, true, false) => render_with::<Rgb, true, false>(scene, opts, progress),
        (false, true, true) => render_with::<Rgb, true, true>(scene, opts, progress),
        (true, false, false) => render_with::<Spectral, false, false>(scene, opts, progress),
        (true, false, true) => render_with::<Spectral, false, true>(scene, opts, progress),
        (true, true, false) => render_with::<Spectral, true, false>(scene, opts, progress),
        (true, true, true) => render_with::<Spectral, true, true>(scene, opts, progress),
    }
}

/// The lane width a render runs at: `asked` with the wavefront integrator (the packet
/// kernel covers every effect variant), width 1 with the reference integrator.
pub fn lanes_for(integrator: Integrator, asked: crate::simd::Lanes) -> crate::simd::Lanes {
    if integrator == Integrator::Wavefront {
        asked
    } else {
        crate::simd::Lanes::scalar()
    }
}

/// The width a render runs at and the one `auto` picks, for `prism info`.
pub fn describe_lanes(asked: crate::simd::Lanes) -> String {
    format!(
        "{} (auto: {})",
        asked.describe(),
        crate::simd::Lanes::auto().describe()
    )
}

/// One tile's samples through the packet kernel.
struct PacketTile<'a, 'c, const MOTION: bool> {
    ctx: &'a Ctx<'c>,
    tile: &'a Tile,
    s0: u32,
    s1: u32,
    film: &'a mut [[f64; 3]],
    stats: &'a mut RenderStats,
}

/// A [`PacketTile`] in transport `T`, at the lane type `dispatch` picks.
struct PacketKernel<'a, 'c, T, const MOTION: bool, const MEDIA: bool>(
    PacketTile<'a, 'c, MOTION>,
    PhantomData<T>,
);

impl<T: WithQueues, const MOTION: bool, const MEDIA: bool> crate::simd::LaneKernel
    for PacketKernel<'_, '_, T, MOTION, MEDIA>
{
    type Output = ();
    #[inline(always)]
    fn run<F: crate::simd::Float>(self) {
        T::packet_tile::<F, MOTION, MEDIA>(self.0)
    }
}

fn render_with<T: WithQueues, const MEDIA: bool, const MOTION: bool>(
    scene: &RenderScene,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> RenderOutput {
    let lanes = lanes_for(opts.integrator, opts.lanes);
    let spectral = if scene.effects.has(Effect::Spectral) {
        transport::SpectralData::new(scene)
    } else {
        transport::SpectralData::EMPTY
    };
    let ctx = Ctx::new(scene, scene.effects.has(Effect::Lens)).with_spectral(&spectral);
    let (w, h) = (scene.settings.width, scene.settings.height);
    let tiles = tiles(w, h);
    let mut sums = vec![[0.0f64; 3]; (w * h) as usize];
    let mut stats = RenderStats::default();
    let start = Instant::now();
    let mut done = 0u32;
    // Without a time limit one pass renders everything; with one, passes double in size
    // so the limit is checked often early on and rarely later.
    let mut pass = if opts.time_limit.is_some() {
        1
    } else {
        opts.spp.max(1)
    };
    while done < opts.spp {
        let n = pass.min(opts.spp - done);
        let s0 = opts.sample_offset + done;
        let t_pass = Instant::now();
        let results: Vec<(Vec<[f64; 3]>, RenderStats)> = tiles
            .par_iter()
            .map(|tile| {
                let mut film = vec![[0.0f64; 3]; tile.pixels()];
                let mut st = RenderStats::default();
                // Width 1 runs inside its entry point so the lane code it inlines (warps,
                // BSDFs, camera rays, lane math) uses the CPU's FMA.
                match opts.integrator {
                    Integrator::Wavefront => {
                        let wide = crate::simd::dispatch_wide(
                            lanes,
                            PacketKernel::<T, MOTION, MEDIA>(
                                PacketTile {
                                    ctx: &ctx,
                                    tile,
                                    s0,
                                    s1: s0 + n,
                                    film: &mut film,
                                    stats: &mut st,
                                },
                                PhantomData,
                            ),
                        );
                        if wide.is_none() {
                            T::with_queues(|q| {
                                crate::simd::scalar_entry(
                                    #[inline(always)]
                                    || {
                                        wavefront::render_tile::<T, MOTION, MEDIA>(
                                            &ctx,
                                            q,
                                            tile,
                                            s0,
                                            s0 + n,
                                            &mut film,
                                            &mut st,
                                        )
                                    },
                                )
                            })
                        }
                    }
                    Integrator::Reference => crate::simd::scalar_entry(
                        #[inline(always)]
                        || {
                            reference::render_tile::<T, MOTION, MEDIA>(
                                &ctx,
                                tile,
                                s0,
                                s0 + n,
                                &mut film,
                                &mut st,
                            )
                        },
                    ),
                }
                st.revolution += crate::systems::primitives::take_revolution_stats();
                progress(tile.pixels() as u64 * n as u64);
                (film, st)
            })
            .collect();
        for (tile, (film, st)) in tiles.iter().zip(&results) {
            for (p, src) in film.iter().enumerate() {
                let (x, y) = tile.pixel(p);
                let dst = &mut sums[(y * w + x) as usize];
                for c in 0..3 {
                    dst[c] += src[c];
                }
            }
            stats.add(st);
        }
        done += n;
        if let Some(limit) = opts.time_limit {
            let elapsed = start.elapsed().as_secs_f64();
            let per_sample = t_pass.elapsed().as_secs_f64() / n as f64;
            let next = (pass * 2).min(opts.spp - done);
            if elapsed + per_sample * next as f64 > limit {
                break;
            }
            pass *= 2;
        }
    }
    RenderOutput {
        width: w,
        height: h,
        sums,
        spp: done,
        stats,
        seconds: start.elapsed().as_secs_f64(),
        lanes,
    }
}
