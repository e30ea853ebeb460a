//! The command line's grammar: clap's commands and options, and the parsers of their values.

use super::{farm, frames};
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// The whole command line as parsed.
#[derive(Parser, Debug)]
#[command(
    name = "prism",
    version,
    about = "A physically based spectral path tracer for RON scenes",
    arg_required_else_help = true
)]
pub struct Cli {
    /// The command to run.
    #[command(subcommand)]
    pub(super) command: Command,
    /// Mesh and image paths must resolve inside DIR (default: the parent of the scene's
    /// folder); absolute paths are refused.
    #[arg(long, global = true, value_name = "DIR")]
    pub(super) asset_root: Option<PathBuf>,
    /// Let scenes name mesh and image files anywhere, absolute paths included.
    #[arg(long, global = true, conflicts_with = "asset_root")]
    pub(super) allow_any_path: bool,
}

/// A command with its options.
#[derive(Subcommand, Debug)]
pub(super) enum Command {
    /// Render a scene to a PNG or EXR image.
    Render(RenderArgs),
    /// Print a scene's entities, effects manifest, primitive counts and kd-tree statistics.
    Info(InfoArgs),
    /// Print RMSE, relMSE and the maximum error between an image and a reference (B).
    Compare { a: PathBuf, b: PathBuf },
    /// Measure error against a converged reference per second of render, for one or more
    /// configurations; writes converge.csv, converge.png/.svg and summary.md into DIR.
    Converge(ConvergeArgs),
    /// Time per sample of each scene, and with each effect it does not need forced on.
    Costs {
        #[arg(required = true)]
        scenes: Vec<PathBuf>,
        /// Samples per pixel of each timed render.
        #[arg(long, default_value_t = 4)]
        spp: u32,
        /// Timed renders per configuration; the median is reported.
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Image size WxH (default: each scene's own).
        #[arg(long, value_parser = parse_size)]
        size: Option<(u32, u32)>,
    },
    /// Combine EXR sample batches of one image, weighted by their sample counts.
    Merge {
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// The merged EXR.
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// The options of `prism render`.
#[derive(Args, Debug)]
pub(super) struct RenderArgs {
    pub(super) scene: PathBuf,
    /// Output image, .png (sRGB 8-bit) or .exr (32-bit float); default: the scene's name .png.
    #[arg(short, long)]
    pub(super) output: Option<PathBuf>,
    /// Samples per pixel (overrides render.spp).
    #[arg(long)]
    pub(super) spp: Option<u32>,
    /// Random seed (overrides render.seed).
    #[arg(long)]
    pub(super) seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(short = 't', long)]
    pub(super) threads: Option<usize>,
    /// Image size WxH (overrides render.width and render.height).
    #[arg(long, value_parser = parse_size)]
    pub(super) size: Option<(u32, u32)>,
    /// Stop between whole passes after this many seconds; every pixel keeps the same count.
    #[arg(long, allow_negative_numbers = true)]
    pub(super) time_limit: Option<f64>,
    /// Override a scene value by path, e.g. render.integrator.fresnel=Schlick or
    /// 'entities["floor"].material.albedo=Rgb(0.2, 0.2, 0.2)'.
    #[arg(long = "set", value_parser = parse_key_value)]
    pub(super) set: Vec<(String, String)>,
    /// Simulate an effect the scene does not need (lens, motion, spectral, media, ...).
    #[arg(long)]
    pub(super) force: Vec<String>,
    /// First sample index per pixel, so separately rendered sample ranges never overlap.
    #[arg(long, default_value_t = 0)]
    pub(super) sample_offset: u32,
    /// Sample batch B: sample indices from B·2²⁴ (--sample-offset B·16777216), a range no
    /// adaptive render of another batch reaches; `prism merge` combines batches.
    #[arg(long, conflicts_with = "sample_offset")]
    pub(super) batch: Option<u32>,
    /// Render until the image's estimated relative MSE is at most T (in (0, 1], e.g. 0.01),
    /// spending samples where the noise is (Bdpt and LightTracing: the same count for every
    /// pixel); --spp (the most any pixel gets) and --time-limit cap it. Overrides
    /// render.target_error.
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub(super) target_error: Option<f64>,
    /// PNG exposure in stops.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_exposure)]
    pub(super) exposure: f32,
    /// Render one frame (7) or a range in Rust syntax: 0..24 is frames 0 to 23 (the end is
    /// excluded), 0..=23 the same; `-o` names frames with a run of '#', e.g.
    /// out/frame_####.png.
    #[arg(long, value_parser = frames::parse_range)]
    pub(super) frames: Option<std::ops::Range<u32>>,
    /// With --frames: skip frames whose image already exists.
    #[arg(long, requires = "frames")]
    pub(super) resume: bool,
    /// With --frames: also write the range as an animated GIF.
    #[arg(long, requires = "frames")]
    pub(super) gif: Option<PathBuf>,
    /// With --frames: render only shard I of N (frames f with f mod N = I).
    #[arg(long, requires = "frames", value_parser = farm::parse_shard, conflicts_with = "shard_from_env")]
    pub(super) shard: Option<(u32, u32)>,
    /// With --frames: take the shard index I from this environment variable (e.g.
    /// SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX); N comes from --shard-count.
    #[arg(long, requires = "frames")]
    pub(super) shard_from_env: Option<String>,
    /// The number of shards N for --shard-from-env.
    #[arg(long, requires = "shard_from_env")]
    pub(super) shard_count: Option<u32>,
    /// Lane width: auto (the widest this CPU runs natively), 16 (AVX-512), 8 (AVX2) or 1.
    /// Overrides render.simd. Pin it on a farm: widths round differently.
    #[arg(long)]
    pub(super) simd: Option<crate::simd::SimdChoice>,
    /// Render at width 1, the reference the wider packets are tested against (as `--simd 1`).
    #[arg(long, hide = true)]
    pub(super) reference: bool,
    /// Print render statistics.
    #[arg(long)]
    pub(super) stats: bool,
    /// No progress output.
    #[arg(short, long)]
    pub(super) quiet: bool,
}

/// The options of `prism converge`.
#[derive(Args, Debug)]
pub(super) struct ConvergeArgs {
    pub(super) scene: PathBuf,
    /// Output folder.
    #[arg(short, long)]
    pub(super) output: PathBuf,
    /// A converged reference image; default: render one (cached in the output folder).
    #[arg(long)]
    pub(super) reference: Option<PathBuf>,
    /// Samples per pixel of a reference prism renders.
    #[arg(long, default_value_t = 1024)]
    pub(super) reference_spp: u32,
    /// Seconds each configuration may spend on its ladder of sample counts.
    #[arg(long, default_value_t = 10.0)]
    pub(super) budget: f64,
    /// KEY=V1,V2,...: one curve per value (several --vary: every combination). Keys: spp,
    /// target_error (one adaptive curve over the targets; `none` adds uniform sampling),
    /// max_depth, rr_depth, light_sampling, fresnel, wavelengths, sampler, force,
    /// kd.intersect_cost, kd.traversal_cost, kd.empty_bonus, kd.max_leaf_prims, or any --set key.
    #[arg(long, value_parser = parse_vary)]
    pub(super) vary: Vec<(String, Vec<String>)>,
    /// Override a scene value by path for every configuration, as render's --set.
    #[arg(long = "set", value_parser = parse_key_value)]
    pub(super) set: Vec<(String, String)>,
    /// Image size WxH for the study and its reference.
    #[arg(long, value_parser = parse_size)]
    pub(super) size: Option<(u32, u32)>,
    /// No progress output.
    #[arg(short, long)]
    pub(super) quiet: bool,
}

/// `KEY=V1,V2,...` of `--vary`: the key and its non-empty values.
fn parse_vary(s: &str) -> Result<(String, Vec<String>), String> {
    let (k, v) = parse_key_value(s)?;
    let vals: Vec<String> = v
        .split(',')
        .map(|x| x.trim().to_string())
        .filter(|x| !x.is_empty())
        .collect();
    if vals.is_empty() {
        return Err(format!("expected KEY=V1,V2,..., got '{s}'"));
    }
    Ok((k, vals))
}

/// The options of `prism info`.
#[derive(Args, Debug)]
pub(super) struct InfoArgs {
    pub(super) scene: PathBuf,
    /// Override a scene value by path, as render's --set.
    #[arg(long = "set", value_parser = parse_key_value)]
    pub(super) set: Vec<(String, String)>,
    /// Show the manifest with an effect forced on, as render's --force.
    #[arg(long)]
    pub(super) force: Vec<String>,
}

/// `WxH` in pixels, each side in 1..=65536.
fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, e.g. 640x480, got '{s}'"))?;
    let p = |v: &str| -> Result<u32, String> {
        let n: u32 = v
            .trim()
            .parse()
            .map_err(|_| format!("expected WxH with whole numbers, got '{s}'"))?;
        if (1..=65536).contains(&n) {
            Ok(n)
        } else {
            Err(format!(
                "width and height must be in 1..=65536 pixels, got '{s}'"
            ))
        }
    };
    let (w, h) = (p(w)?, p(h)?);
    crate::scene_file::schema::check_film_size(w, h)?;
    Ok((w, h))
}

/// `--exposure`: a finite number of stops in -100..=100 (2¹⁰⁰ already saturates any film).
fn parse_exposure(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(x) if x.is_finite() && (-100.0..=100.0).contains(&x) => Ok(x),
        _ => Err(format!(
            "expected stops in -100..=100, e.g. -1.5, got '{s}'"
        )),
    }
}

/// `KEY=VALUE` of `--set`, both trimmed.
fn parse_key_value(s: &str) -> Result<(String, String), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected KEY=VALUE, got '{s}'"))?;
    Ok((k.trim().to_string(), v.trim().to_string()))
}
