//! Light transport: a path tracer with next-event estimation, MIS and Russian roulette, run as
//! packets of paths in SIMD lanes, and the pass loop that splits an image into tiles.
//!
//! One kernel ([`kernel::render_tile`]) serves every width: at width 1 it traces one path at a
//! time and is the reference; at 8 or 16 lanes it traces that many paths per instruction.
//! The stages, in pipeline order, one file each:
//!
//! | stage | file | what it does |
//! |---|---|---|
//! | generate | `generate.rs` | camera rays for the tile's next samples, in the lanes whose paths ended |
//! | intersect | `crate::scene::packet` | closest hits: the kd-tree walked once per packet |
//! | media | `media.rs` | MEDIA: free flight, scattering in a medium, equiangular sampling |
//! | surface | `surface.rs` | the winning hit's surface, textures, material class |
//! | emission | `emission.rs` | the environment on escape, emitters hit by chance |
//! | material | `material.rs` | a BSDF sample per material class present |
//! | light | `light.rs` | next-event estimation at diffuse lanes |
//! | shadow | `shadow.rs` | shadow rays as one packet any-hit query (with MEDIA, transmittance) |
//! | roulette | `roulette.rs` | Russian roulette |
//! | film | `crate::film::tile` | finished paths into the tile's film |
//!
//! `state::Paths` declares the state of a path once; [`ctx::Ctx`] holds what no stage
//! changes; [`bsdf`] the BSDFs over lanes; [`transport`] what a path carries (RGB or four hero
//! wavelengths) and how the scene's colours enter it.
//!
//! The kernel is generic over the effects that change its state and loops (SPECTRAL, MEDIA,
//! MOTION): eight monomorphised variants, chosen once per render, so an absent effect costs no
//! branch per ray. LENS, TEXTURES and NORMAL_MAPS are flags read once per render.

pub mod bdpt;
pub mod bsdf;
pub mod coat;
pub mod ctx;
pub mod dielectric_energy;
mod emission;
pub mod generate;
mod ggx_tables;
pub mod kernel;
mod light;
pub mod light_tracer;
mod material;
mod media;
pub mod microfacet;
mod roulette;
mod shadow;
mod state;
mod surface;
pub mod transport;

pub use ctx::Ctx;

use crate::film::{Film, Tile, TileFilm, TileWork, tiles};
use crate::scene::{Effect, RenderScene};
use crate::scene_file::schema::Estimator;
use crate::simd::Lanes;
use rayon::prelude::*;
use std::marker::PhantomData;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Newton iterations and brackets of surfaces of revolution.
    pub revolution: crate::geometry::RevolutionStats,
    /// Camera samples whose radiance reached the film.
    pub samples: u64,
    /// Samples whose radiance was not finite: dropped and counted, never written.
    pub dropped: u64,
    /// Closest-hit rays traced: camera rays and every bounce.
    pub rays: u64,
    /// Shadow rays traced for next-event estimation.
    pub shadow_rays: u64,
    /// Lanes offered to paths, one per lane per step (live or not): `rays / lane_slots` is
    /// the mean lane occupancy.
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

/// How much of the image to render, and how.
pub struct RenderOptions {
    /// First sample index of every pixel: sample ranges rendered apart never repeat samples.
    pub sample_offset: u32,
    /// Samples per pixel to render.
    pub spp: u32,
    /// Stop between whole passes once this many seconds are spent.
    pub time_limit: Option<f64>,
    /// The lane width and instruction set the kernel runs at.
    pub lanes: Lanes,
    /// Every path carries this one wavelength (nm) and the film receives its radiance as that
    /// wavelength's colour: a monochromatic render, for studies of dispersion. Spectral
    /// transport only (RGB transport ignores it); `None` renders normally.
    pub monochromatic: Option<f32>,
    /// Once this is set, tiles not yet started are skipped and the pass in flight is dropped:
    /// the output holds the whole passes before it ([`RenderOutput::interrupted`]).
    pub stop: Option<&'static AtomicBool>,
    /// Render in passes until the image's estimated relMSE is at most this, spending samples
    /// where the estimated error is ([`crate::film::estimate`]); `spp` becomes the most any
    /// pixel may receive. `None` renders `spp` samples in every pixel.
    pub target_error: Option<f64>,
    /// BDPT only: which strategies to add (a debugging view: one strategy alone, unweighted,
    /// converges to the image of the paths of its length; weighted, it shows its share of
    /// the estimator's image). `None` adds them all, weighted.
    pub strategy: Option<bdpt::Strategies>,
}

impl RenderOptions {
    /// All `spp` samples from sample 0, at `lanes`, without a time limit.
    pub fn new(spp: u32, lanes: Lanes) -> Self {
        RenderOptions {
            sample_offset: 0,
            spp,
            time_limit: None,
            lanes,
            monochromatic: None,
            stop: None,
            target_error: None,
            strategy: None,
        }
    }
}

/// The most samples a pixel of an adaptive render may receive when nothing lower caps it:
/// 2²⁴ in each of its halves, the index range of one sample batch.
pub const MAX_ADAPTIVE_SPP: u32 = 1 << 25;

/// What the render reports after each whole pass (besides the samples of each tile).
#[derive(Clone, Copy, Debug)]
pub struct PassReport {
    /// Samples rendered so far, over the whole image.
    pub samples: u64,
    /// Seconds since the render began.
    pub seconds: f64,
    /// The image's estimated relMSE after the pass (with a target error).
    pub estimate: Option<f64>,
}

/// Receives a render's progress: samples as tiles finish, and each pass's report.
pub trait Observer: Sync {
    /// `n` more samples are done.
    fn samples(&self, n: u64);
    /// A pass is done.
    fn pass(&self, _report: &PassReport) {}
}

struct SampleCount<'a>(&'a (dyn Fn(u64) + Sync));

impl Observer for SampleCount<'_> {
    fn samples(&self, n: u64) {
        (self.0)(n)
    }
}

/// The sizes of a render's passes without a time limit. Below [`MIN_PASS`] samples per pixel,
/// one pass. From there, a first pass of [`FIRST_PASS`] samples (so a stop after the first
/// moments still has an image to write), then passes that end at [`MIN_PASS`], twice that, and
/// so on, growing to a [`MAX_PASSES`]th of `spp`: a stop loses at most that share (or the part
/// after [`MIN_PASS`] of a shorter render). The schedule depends on `spp` alone, so images do
/// not depend on when anything happened.
fn pass_sizes(spp: u32) -> impl Iterator<Item = u32> {
    let cap = spp.div_ceil(MAX_PASSES).max(MIN_PASS);
    let mut done = 0u32;
    std::iter::from_fn(move || {
        if done >= spp {
            return None;
        }
        let end = if spp < MIN_PASS {
            spp
        } else if done == 0 {
            FIRST_PASS
        } else if done < MIN_PASS {
            MIN_PASS
        } else {
            let end = done.saturating_add(done.min(cap)).min(spp);
            // A short remainder joins this pass rather than end a pass of its own.
            if spp - end < MIN_PASS { spp } else { end }
        };
        let n = end - done;
        done = end;
        Some(n)
    })
}

/// The first pass of a render of at least [`MIN_PASS`] samples per pixel.
const FIRST_PASS: u32 = 16;
/// Passes of a long render: a stop loses at most 1/`MAX_PASSES` of its samples.
const MAX_PASSES: u32 = 16;
/// The smallest pass after the first. Each extra pass cost about half a sample per pixel of
/// time on the Cornell box at one thread, with the same instruction count (packets drain at
/// the end of each tile's pass); with passes of at least 128, a 256-spp render measured 0.8 %
/// slower than one pass.
const MIN_PASS: u32 = 128;

/// Linear per-pixel sums of a render and what it cost.
pub struct RenderOutput {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Sum of the radiance of every sample, per pixel (row-major, top row first).
    pub sums: Vec<[f64; 3]>,
    /// Samples per pixel actually rendered (fewer than asked under a time limit); with a
    /// target error, the most any pixel received.
    pub spp: u32,
    /// With a target error, each pixel's sample count (row-major); empty otherwise.
    pub counts: Vec<u32>,
    /// With a target error, each pixel's sums over its half-B samples; empty otherwise.
    pub half: Vec<[f64; 3]>,
    /// With a target error, the image's estimated relMSE at the end.
    pub estimate: Option<f64>,
    /// Counters of the render.
    pub stats: RenderStats,
    /// Wall-clock seconds the render took.
    pub seconds: f64,
    /// The lane width that ran.
    pub lanes: Lanes,
    /// [`RenderOptions::stop`] ended the render before its samples were done.
    pub interrupted: bool,
}

impl RenderOutput {
    /// The image: sums divided by the sample count (each pixel's own, with a target error).
    pub fn image(&self) -> crate::film::Image {
        if self.counts.is_empty() {
            return crate::film::mean_image(self.width, self.height, &self.sums, self.spp);
        }
        crate::film::Image {
            width: self.width,
            height: self.height,
            pixels: self
                .sums
                .iter()
                .zip(&self.counts)
                .map(|(s, &n)| {
                    let k = 1.0 / f64::from(n.max(1));
                    [(s[0] * k) as f32, (s[1] * k) as f32, (s[2] * k) as f32]
                })
                .collect(),
        }
    }

    /// With a target error, each pixel's estimated relMSE; empty otherwise.
    pub fn errors(&self) -> Vec<f64> {
        if self.half.is_empty() {
            return Vec::new();
        }
        crate::film::estimate::pixel_errors(
            &self.sums,
            &self.half,
            &self.counts,
            self.width,
            self.height,
        )
    }

    /// Mean samples per pixel.
    pub fn mean_spp(&self) -> f64 {
        if self.counts.is_empty() {
            return f64::from(self.spp);
        }
        self.counts.iter().map(|&n| f64::from(n)).sum::<f64>() / self.counts.len().max(1) as f64
    }
}

/// Renders the scene on the current rayon pool. `progress` is told the number of samples
/// finished, once per tile.
pub fn render(
    scene: &RenderScene,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> RenderOutput {
    render_observed(scene, opts, &SampleCount(progress))
}

/// [`render`], reporting to an [`Observer`] (which also hears of each pass).
pub fn render_observed(
    scene: &RenderScene,
    opts: &RenderOptions,
    progress: &dyn Observer,
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
        (false, false, false) => render_with::<Rgb, 3, false, false>(scene, opts, progress),
        (false, false, true) => render_with::<Rgb, 3, false, true>(scene, opts, progress),
        (false, true, false) => render_with::<Rgb, 3, true, false>(scene, opts, progress),
        (false, true, true) => render_with::<Rgb, 3, true, true>(scene, opts, progress),
        (true, false, false) => render_with::<Spectral, 4, false, false>(scene, opts, progress),
        (true, false, true) => render_with::<Spectral, 4, false, true>(scene, opts, progress),
        (true, true, false) => render_with::<Spectral, 4, true, false>(scene, opts, progress),
        (true, true, true) => render_with::<Spectral, 4, true, true>(scene, opts, progress),
    }
}

/// The width a render runs at and the one `auto` picks, for `prism info`.
pub fn describe_lanes(asked: Lanes) -> String {
    format!("{} (auto: {})", asked.describe(), Lanes::auto().describe())
}

/// One tile's samples through the kernel, in transport `T` with `N` channels, at the lane
/// type `dispatch` picks.
struct TileKernel<'a, 'c, T, const N: usize, const MOTION: bool, const MEDIA: bool> {
    ctx: &'a Ctx<'c>,
    work: TileWork<'a>,
    film: &'a mut TileFilm,
    stats: &'a mut RenderStats,
    transport: PhantomData<T>,
}

impl<
    T: transport::Transport<S: transport::ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
> crate::simd::LaneKernel for TileKernel<'_, '_, T, N, MOTION, MEDIA>
{
    type Output = ();
    const SHARD: usize = home::<T>(MEDIA, MOTION, false);
    #[inline(always)]
    fn run<F: crate::simd::Float>(self) {
        let tile = self.film.tile;
        kernel::render_tile::<F, T, N, MOTION, MEDIA>(
            self.ctx, &tile, &self.work, self.film, self.stats,
        )
    }
}

/// The uniform passes of a render of `opts.spp` samples per pixel, started at `start`: `pass`
/// renders the samples its work item names in every tile, or returns `None` when a stop came
/// (the pass is dropped). Returns the samples per pixel done and whether a stop came.
fn uniform_passes(
    opts: &RenderOptions,
    w: u32,
    h: u32,
    progress: &dyn Observer,
    start: Instant,
    mut pass: impl FnMut(TileWork<'static>) -> Option<()>,
) -> (u32, bool) {
    let mut done = 0u32;
    // With a time limit, passes double in size so the limit is checked often early on and
    // rarely later; without one, they follow `pass_sizes`.
    let mut size = 1;
    let mut sizes = pass_sizes(opts.spp);
    while done < opts.spp {
        let n = if opts.time_limit.is_some() {
            size.min(opts.spp - done)
        } else {
            sizes.next().unwrap_or(opts.spp - done)
        };
        let t_pass = Instant::now();
        let work = TileWork {
            offset: opts.sample_offset,
            uniform: (done, n),
            per_pixel: None,
            split: false,
        };
        if pass(work).is_none() {
            return (done, true);
        }
        done += n;
        progress.pass(&PassReport {
            samples: u64::from(done) * u64::from(w) * u64::from(h),
            seconds: start.elapsed().as_secs_f64(),
            estimate: None,
        });
        if let Some(limit) = opts.time_limit {
            let elapsed = start.elapsed().as_secs_f64();
            let per_sample = t_pass.elapsed().as_secs_f64() / f64::from(n);
            let next = (size * 2).min(opts.spp - done);
            if elapsed + per_sample * f64::from(next) > limit {
                break;
            }
            size *= 2;
        }
    }
    (done, false)
}

/// The codegen home of a kernel variant (see [`crate::simd::LaneKernel::SHARD`]): one per
/// effect set, the path tracer's in the first half of the homes and the splatting
/// estimators' in the second, so that variants of similar size compile in parallel.
pub(super) const fn home<T: transport::Transport>(
    media: bool,
    motion: bool,
    splats: bool,
) -> usize {
    8 * splats as usize + 4 * T::SPECTRAL as usize + 2 * media as usize + motion as usize
}

/// Runs a tile kernel at `lanes`.
#[cfg(not(test))]
fn run_at<K: crate::simd::LaneKernel>(lanes: Lanes, k: K) -> K::Output {
    crate::simd::dispatch(lanes, k)
}

/// The lib's unit tests never render (the integration tests do, against the real build), so
/// their build instantiates the kernel at width 1 alone: all 48 variants, compiled a second
/// time, would double the time of `cargo test --release`.
#[cfg(test)]
fn run_at<K: crate::simd::LaneKernel>(_lanes: Lanes, k: K) -> K::Output {
    k.run::<f32>()
}

fn render_with<
    T: transport::Transport<S: transport::ChannelArray<N>>,
    const N: usize,
    const MEDIA: bool,
    const MOTION: bool,
>(
    scene: &RenderScene,
    opts: &RenderOptions,
    progress: &dyn Observer,
) -> RenderOutput {
    let spectral = if scene.effects.has(Effect::Spectral) {
        transport::SpectralData::new(scene)
    } else {
        transport::SpectralData::EMPTY
    };
    let mut ctx = Ctx::new(scene, scene.effects.has(Effect::Lens)).with_spectral(&spectral);
    ctx.monochromatic = opts.monochromatic;
    // The splatting estimators render to a target error with uniform counts (see
    // `light_tracer::target_passes`); only the path tracer's are adaptive.
    let (kind, _) = bdpt::choose(scene);
    if kind != Estimator::Path {
        let tiles = tiles(scene.settings.width, scene.settings.height);
        if kind == Estimator::LightTracing {
            return light_tracer::render::<T, N, MOTION, MEDIA>(&ctx, opts, &tiles, progress);
        }
        let which = opts.strategy.unwrap_or(bdpt::Strategies::All);
        return bdpt::render::<T, N, MOTION, MEDIA>(&ctx, opts, &tiles, progress, which);
    }
    let pass = Passes::<T, N, MEDIA, MOTION> {
        ctx: &ctx,
        opts,
        tiles: tiles(scene.settings.width, scene.settings.height),
        progress,
        transport: PhantomData,
    };
    match opts.target_error {
        Some(t) => pass.adaptive(t),
        None => pass.uniform(),
    }
}

/// The pass loop of one render: its tiles, rendered in parallel, one pass at a time.
struct Passes<'a, 'c, T, const N: usize, const MEDIA: bool, const MOTION: bool> {
    ctx: &'a Ctx<'c>,
    opts: &'a RenderOptions,
    tiles: Vec<Tile>,
    progress: &'a dyn Observer,
    transport: PhantomData<T>,
}

/// Uniform passes come first, doubling from [`WARMUP_FIRST`] to at most [`WARMUP_LAST`]
/// samples per pixel while the estimate is above twice the target: a pixel's neighbourhood needs
/// a few samples in each half before it can steer anything, and near the target a doubling
/// would overshoot it. The first is one sample per half: an easy target (the Cornell box at
/// 128² reaches relMSE 0.05 at about 3 spp) would otherwise be overshot from the start, and
/// the estimate holds at that count (see [`crate::film::estimate`]).
const WARMUP_FIRST: u32 = 2;
/// See [`WARMUP_FIRST`].
const WARMUP_LAST: u32 = 32;

impl<
    T: transport::Transport<S: transport::ChannelArray<N>>,
    const N: usize,
    const MEDIA: bool,
    const MOTION: bool,
> Passes<'_, '_, T, N, MEDIA, MOTION>
{
    fn stopped(&self) -> bool {
        self.opts.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// One pass over every tile; `work(i)` names tile `i`'s samples. `None` if a stop came
    /// during the pass (which is then dropped).
    fn run<'w>(
        &self,
        image: &mut Film,
        stats: &mut RenderStats,
        work: &(dyn Fn(usize) -> TileWork<'w> + Sync),
    ) -> Option<()> {
        let (w, split) = (self.ctx.width, !image.half.is_empty());
        let results: Vec<(TileFilm, RenderStats)> = self
            .tiles
            .par_iter()
            .enumerate()
            .map(|(i, tile)| {
                let mut film = if split {
                    TileFilm::with_halves(*tile, w)
                } else {
                    TileFilm::new(*tile, w)
                };
                let mut st = RenderStats::default();
                if self.stopped() {
                    // The pass is dropped: skip what is left of it.
                    return (film, st);
                }
                let work = work(i);
                let samples = work.total(tile.pixels());
                if samples == 0 {
                    return (film, st);
                }
                // Each width runs inside its entry point, so the lane code it inlines uses
                // that width's instructions (width 1: the CPU's FMA).
                run_at(
                    self.opts.lanes,
                    TileKernel::<T, N, MOTION, MEDIA> {
                        ctx: self.ctx,
                        work,
                        film: &mut film,
                        stats: &mut st,
                        transport: PhantomData,
                    },
                );
                st.samples += film.samples;
                st.dropped += film.dropped;
                st.revolution += crate::scene::primitives::take_revolution_stats();
                self.progress.samples(samples);
                (film, st)
            })
            .collect();
        if self.stopped() {
            return None;
        }
        for (film, st) in &results {
            image.add_tile(film);
            stats.add(st);
        }
        Some(())
    }

    fn output(&self, image: Film, stats: RenderStats, spp: u32, start: Instant) -> RenderOutput {
        RenderOutput {
            width: image.width,
            height: image.height,
            sums: image.sums,
            spp,
            counts: Vec::new(),
            half: image.half,
            estimate: None,
            stats,
            seconds: start.elapsed().as_secs_f64(),
            lanes: self.opts.lanes,
            interrupted: false,
        }
    }

    /// `spp` samples in every pixel.
    fn uniform(&self) -> RenderOutput {
        let opts = self.opts;
        let (w, h) = (self.ctx.width, self.ctx.scene.settings.height);
        let mut image = Film::new(w, h);
        let mut stats = RenderStats::default();
        let start = Instant::now();
        let (done, interrupted) = uniform_passes(opts, w, h, self.progress, start, |work| {
            self.run(&mut image, &mut stats, &|_| work)
        });
        let mut out = self.output(image, stats, done, start);
        out.interrupted = interrupted;
        out
    }

    /// Passes until the estimated relMSE is at most `target`: uniform ones first
    /// ([`WARMUP_FIRST`]), then adaptive ones ([`crate::film::estimate::allocate`]).
    fn adaptive(&self, target: f64) -> RenderOutput {
        use crate::film::estimate;
        let opts = self.opts;
        let (w, h) = (self.ctx.width, self.ctx.scene.settings.height);
        let mut image = Film::with_halves(w, h);
        let mut counts = vec![0u32; image.sums.len()];
        let mut stats = RenderStats::default();
        let start = Instant::now();
        // Even, so both halves always hold as many samples.
        let cap = opts.spp.max(2) & !1;
        let mut interrupted = false;
        let mut estimate = f64::INFINITY;
        let mut total = 0u64;
        let mut warm = Some(WARMUP_FIRST.min(cap));
        loop {
            let t_pass = Instant::now();
            let before = total;
            // Per tile, per pixel: (first sample, samples this pass).
            let ranges: Vec<Vec<(u32, u32)>> = if let Some(end) = warm {
                let done = counts.first().copied().unwrap_or(0);
                self.tiles
                    .iter()
                    .map(|t| vec![(done, end.saturating_sub(done)); t.pixels()])
                    .collect()
            } else {
                let errors = estimate::pixel_errors(&image.sums, &image.half, &counts, w, h);
                let near = estimate < 2.0 * target;
                let add = estimate::allocate(
                    &errors,
                    &counts,
                    w,
                    h,
                    &estimate::Allocation {
                        target,
                        aim: 0.9,
                        cap,
                        growth: if near { 1.25 } else { 2.0 },
                    },
                );
                self.tiles
                    .iter()
                    .map(|t| {
                        (0..t.pixels())
                            .map(|p| {
                                let (x, y) = t.pixel(p);
                                let i = (y * w + x) as usize;
                                (counts[i], add[i])
                            })
                            .collect()
                    })
                    .collect()
            };
            let pass_samples: u64 = ranges.iter().flatten().map(|r| u64::from(r.1)).sum();
            if pass_samples == 0 {
                break;
            }
            let offset = opts.sample_offset;
            let ok = self.run(&mut image, &mut stats, &|i| TileWork {
                offset,
                uniform: (0, 0),
                per_pixel: Some(&ranges[i]),
                split: true,
            });
            if ok.is_none() {
                interrupted = true;
                break;
            }
            for (t, r) in self.tiles.iter().zip(&ranges) {
                for (p, &(_, n)) in r.iter().enumerate() {
                    let (x, y) = t.pixel(p);
                    counts[(y * w + x) as usize] += n;
                }
            }
            total += pass_samples;
            estimate = estimate::image_error(&estimate::pixel_errors(
                &image.sums,
                &image.half,
                &counts,
                w,
                h,
            ));
            self.progress.pass(&PassReport {
                samples: total,
                seconds: start.elapsed().as_secs_f64(),
                estimate: Some(estimate),
            });
            if estimate <= target {
                break;
            }
            warm = warm
                .map(|n| (n * 2).min(cap))
                .filter(|&n| n <= WARMUP_LAST && estimate > 2.0 * target && n > counts[0]);
            if let Some(limit) = opts.time_limit {
                // The next pass is at most twice this one's samples.
                let per_sample = t_pass.elapsed().as_secs_f64() / (total - before) as f64;
                let elapsed = start.elapsed().as_secs_f64();
                if elapsed + per_sample * 2.0 * pass_samples as f64 > limit {
                    break;
                }
            }
        }
        let spp = counts.iter().copied().max().unwrap_or(0);
        let mut out = self.output(image, stats, spp, start);
        out.counts = counts;
        out.estimate = Some(estimate);
        out.interrupted = interrupted;
        out
    }
}

#[cfg(test)]
mod pass_tests {
    use super::pass_sizes;

    #[test]
    fn passes_add_up_and_grow_to_a_sixteenth() {
        for spp in [
            0,
            1,
            7,
            127,
            128,
            129,
            255,
            256,
            1000,
            4096,
            65_536,
            u32::MAX,
        ] {
            let p: Vec<u64> = pass_sizes(spp).take(100).map(u64::from).collect();
            assert_eq!(p.iter().sum::<u64>(), u64::from(spp), "{spp}");
            assert!(p.iter().all(|&n| n > 0));
            if spp >= 128 {
                assert_eq!(p[..2], [16, 112]);
                let cap = u64::from(spp.div_ceil(16).max(128));
                let most = 2 + (cap / 128).ilog2() as usize + 16;
                assert!(p.len() <= most, "{spp}: {} passes", p.len());
                // The last pass may take a remainder shorter than a pass with it.
                assert!(p.iter().all(|&n| n < cap + 128), "{spp}: {p:?}");
            } else if spp > 0 {
                assert_eq!(p, [u64::from(spp)]);
            }
        }
        assert_eq!(pass_sizes(128).collect::<Vec<_>>(), [16, 112]);
        assert_eq!(pass_sizes(300).collect::<Vec<_>>(), [16, 112, 172]);
        assert_eq!(
            pass_sizes(1024).collect::<Vec<_>>()[..4],
            [16, 112, 128, 128]
        );
    }
}
