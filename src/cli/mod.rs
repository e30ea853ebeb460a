//! The `prism` command line: render, info, compare.

pub mod farm;
pub mod frames;
mod progress;

use crate::film::{self, ImageMeta, PngOptions};
use crate::integrator::{self, RenderOptions};
use crate::kdtree::KdParams;
use crate::scene::{Effect, RenderScene};
use crate::scene_file::{self, LoadedScene};
use crate::systems;
use clap::{Args, Parser, Subcommand};
use std::fmt;
use std::path::{Path, PathBuf};

#[derive(Parser, Debug)]
#[command(
    name = "prism",
    version,
    about = "A physically based spectral path tracer for RON scenes",
    arg_required_else_help = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
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

#[derive(Args, Debug)]
pub struct RenderArgs {
    pub scene: PathBuf,
    /// Output image, .png (sRGB 8-bit) or .exr (32-bit float); default: the scene's name .png.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Samples per pixel (overrides render.spp).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Random seed (overrides render.seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(short = 't', long)]
    pub threads: Option<usize>,
    /// Image size WxH (overrides render.width and render.height).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Stop between whole passes after this many seconds; every pixel keeps the same count.
    #[arg(long, allow_negative_numbers = true)]
    pub time_limit: Option<f64>,
    /// Override a scene value by path, e.g. render.integrator.fresnel=Schlick or
    /// 'entities["floor"].material.albedo=Rgb(0.2, 0.2, 0.2)'.
    #[arg(long = "set", value_parser = parse_key_value)]
    pub set: Vec<(String, String)>,
    /// Simulate an effect the scene does not need (lens, motion, spectral, media, ...).
    #[arg(long)]
    pub force: Vec<String>,
    /// First sample index per pixel, so separately rendered sample ranges never overlap.
    #[arg(long, default_value_t = 0)]
    pub sample_offset: u32,
    /// PNG exposure in stops.
    #[arg(long, default_value_t = 0.0)]
    pub exposure: f32,
    /// Render one frame (7) or a range in Rust syntax: 0..24 is frames 0 to 23 (the end is
    /// excluded), 0..=23 the same; `-o` names frames with a run of '#', e.g.
    /// out/frame_####.png.
    #[arg(long, value_parser = frames::parse_range)]
    pub frames: Option<std::ops::Range<u32>>,
    /// With --frames: skip frames whose image already exists.
    #[arg(long, requires = "frames")]
    pub resume: bool,
    /// With --frames: also write the range as an animated GIF.
    #[arg(long, requires = "frames")]
    pub gif: Option<PathBuf>,
    /// With --frames: render only shard I of N (frames f with f mod N = I).
    #[arg(long, requires = "frames", value_parser = farm::parse_shard, conflicts_with = "shard_from_env")]
    pub shard: Option<(u32, u32)>,
    /// With --frames: take the shard index I from this environment variable (e.g.
    /// SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX); N comes from --shard-count.
    #[arg(long, requires = "frames")]
    pub shard_from_env: Option<String>,
    /// The number of shards N for --shard-from-env.
    #[arg(long, requires = "shard_from_env")]
    pub shard_count: Option<u32>,
    /// Lane width: auto (the widest this CPU runs natively), 16 (AVX-512), 8 (AVX2) or 1.
    /// Overrides render.simd. Pin it on a farm: widths round differently.
    #[arg(long)]
    pub simd: Option<crate::simd::SimdChoice>,
    /// Render at width 1, the reference the wider packets are tested against (as `--simd 1`).
    #[arg(long, hide = true)]
    pub reference: bool,
    /// Print render statistics.
    #[arg(long)]
    pub stats: bool,
    /// No progress output.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    pub scene: PathBuf,
    /// Output folder.
    #[arg(short, long)]
    pub output: PathBuf,
    /// A converged reference image; default: render one (cached in the output folder).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Samples per pixel of a reference prism renders.
    #[arg(long, default_value_t = 1024)]
    pub reference_spp: u32,
    /// Seconds each configuration may spend on its ladder of sample counts.
    #[arg(long, default_value_t = 10.0)]
    pub budget: f64,
    /// KEY=V1,V2,...: one curve per value (several --vary: every combination). Keys: spp,
    /// max_depth, rr_depth, light_sampling, fresnel, wavelengths, sampler, force,
    /// kd.intersect_cost, kd.traversal_cost, kd.empty_bonus, kd.max_leaf_prims, or any --set key.
    #[arg(long, value_parser = parse_vary)]
    pub vary: Vec<(String, Vec<String>)>,
    /// Override a scene value by path for every configuration, as render's --set.
    #[arg(long = "set", value_parser = parse_key_value)]
    pub set: Vec<(String, String)>,
    /// Image size WxH for the study and its reference.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// No progress output.
    #[arg(short, long)]
    pub quiet: bool,
}

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

#[derive(Args, Debug)]
pub struct InfoArgs {
    pub scene: PathBuf,
    /// Override a scene value by path, as render's --set.
    #[arg(long = "set", value_parser = parse_key_value)]
    pub set: Vec<(String, String)>,
    /// Show the manifest with an effect forced on, as render's --force.
    #[arg(long)]
    pub force: Vec<String>,
}

/// A command-line failure: one readable line.
#[derive(Debug)]
pub struct CliError(pub String);

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for CliError {}

macro_rules! from_error {
    ($($t:ty),*) => {$(
        impl From<$t> for CliError {
            fn from(e: $t) -> Self {
                CliError(e.to_string())
            }
        }
    )*};
}
from_error!(scene_file::SceneError, film::FilmError);

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
    Ok((p(w)?, p(h)?))
}

fn parse_key_value(s: &str) -> Result<(String, String), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected KEY=VALUE, got '{s}'"))?;
    Ok((k.trim().to_string(), v.trim().to_string()))
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Render(a) => render(a),
        Command::Info(a) => info(a),
        Command::Converge(a) => {
            if !(a.budget.is_finite() && a.budget > 0.0) {
                return Err(CliError(format!(
                    "--budget must be a positive number of seconds, got {}",
                    a.budget
                )));
            }
            let mut set = a.set.clone();
            if let Some((w, h)) = a.size {
                set.push(("render.width".into(), w.to_string()));
                set.push(("render.height".into(), h.to_string()));
            }
            // Check the scene and the overrides once, with located errors, before the study.
            load_scene(&a.scene, &set, &[])?;
            let r = crate::report::converge(&crate::report::ConvergeOptions {
                scene: a.scene.clone(),
                set,
                reference: a.reference.clone(),
                reference_spp: a.reference_spp.max(2),
                budget: a.budget,
                vary: a.vary.clone(),
                out: a.output.clone(),
                quiet: a.quiet,
            })
            .map_err(CliError)?;
            if !a.quiet {
                eprintln!(
                    "wrote {}/converge.csv, converge.png, converge.svg, summary.md",
                    a.output.display()
                );
            }
            print!("{}", r.summary);
            Ok(())
        }
        Command::Costs {
            scenes,
            spp,
            runs,
            size,
        } => {
            let mut set = Vec::new();
            if let Some((w, h)) = size {
                set.push(("render.width".to_string(), w.to_string()));
                set.push(("render.height".to_string(), h.to_string()));
            }
            let t = crate::report::costs::effect_costs(&scenes, &set, spp.max(1), runs.max(1))
                .map_err(CliError)?;
            print!("{t}");
            Ok(())
        }
        Command::Merge { parts, output } => {
            let (spp, offset) = farm::merge(&parts, &output)?;
            eprintln!(
                "wrote {} ({} parts, samples {}..{})",
                output.display(),
                parts.len(),
                offset,
                offset + spp as u64
            );
            Ok(())
        }
        Command::Compare { a, b } => {
            let m = film::compare_files(&a, &b)?;
            println!("RMSE: {:.6e}", m.rmse);
            println!("relMSE: {:.6e}", m.relmse);
            println!("max error: {:.6e}", m.max_abs);
            Ok(())
        }
    }
}

/// Loads a scene with the command line's overrides folded into `--set` form.
fn load_scene(
    path: &Path,
    set: &[(String, String)],
    extra: &[(String, String)],
) -> Result<LoadedScene, CliError> {
    let mut all = set.to_vec();
    all.extend_from_slice(extra);
    Ok(scene_file::load(path, &all)?)
}

fn prepare(scene: &LoadedScene, force: &[String], frame: u32) -> Result<RenderScene, CliError> {
    let mut rs = systems::prepare_frame(scene, &KdParams::default(), frame);
    force_effects(&mut rs, force)?;
    Ok(rs)
}

fn force_effects(rs: &mut RenderScene, force: &[String]) -> Result<(), CliError> {
    for f in force {
        let e = Effect::parse(f).ok_or_else(|| {
            CliError(format!(
                "--force {f}: unknown effect; valid: {}",
                Effect::ALL
                    .iter()
                    .map(|e| e.name().to_ascii_lowercase())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        rs.effects.force(e).map_err(CliError)?;
    }
    Ok(())
}

fn render(a: RenderArgs) -> Result<(), CliError> {
    let mut extra = Vec::new();
    if let Some(spp) = a.spp {
        extra.push(("render.spp".to_string(), spp.to_string()));
    }
    if let Some(seed) = a.seed {
        extra.push(("render.seed".to_string(), seed.to_string()));
    }
    if let Some((w, h)) = a.size {
        extra.push(("render.width".to_string(), w.to_string()));
        extra.push(("render.height".to_string(), h.to_string()));
    }
    if let Some(t) = a.time_limit
        && !(t.is_finite() && t > 0.0)
    {
        return Err(CliError(format!(
            "--time-limit must be a positive number of seconds, got {t}"
        )));
    }
    if a.threads == Some(0) {
        return Err(CliError("--threads must be at least 1".into()));
    }
    let scene = load_scene(&a.scene, &a.set, &extra)?;
    let stem = a
        .scene
        .file_stem()
        .map_or("render".to_string(), |s| s.to_string_lossy().to_string());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.unwrap_or(0))
        .build()
        .map_err(|e| CliError(format!("cannot start worker threads: {e}")))?;
    if let Some(range) = a.frames.clone() {
        let template = a
            .output
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("frames/{stem}_####.png")));
        frames::check_template(&template)?;
        film::ImageFormat::from_path(&template)?;
        return render_frames(&a, &scene, &pool, range, &template);
    }
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{stem}.png")));
    // Fail on a bad output name before spending time on the render.
    film::ImageFormat::from_path(&output)?;
    let rs = prepare(&scene, &a.force, 0)?;
    if !a.quiet {
        for w in rs.warnings() {
            eprintln!("warning: {w}");
        }
    }
    let out = render_to_file(&a, &scene, &rs, &pool, &output, "")?;
    if a.stats {
        print_stats(&rs, &out, &output, pool.current_num_threads());
    } else if !a.quiet {
        eprintln!(
            "wrote {} ({} spp, {:.2} s)",
            output.display(),
            out.spp,
            out.seconds
        );
    }
    Ok(())
}

/// Renders one frame of a prepared scene and writes it atomically.
fn render_to_file(
    a: &RenderArgs,
    scene: &LoadedScene,
    rs: &RenderScene,
    pool: &rayon::ThreadPool,
    output: &Path,
    label: &str,
) -> Result<integrator::RenderOutput, CliError> {
    let spp = rs.settings.spp;
    let choice = if a.reference {
        crate::simd::SimdChoice::W1
    } else {
        a.simd.unwrap_or(rs.settings.simd)
    };
    let lanes = crate::simd::Lanes::resolve(choice).map_err(|e| CliError(e.to_string()))?;
    let opts = RenderOptions {
        sample_offset: a.sample_offset,
        spp,
        time_limit: a.time_limit,
        lanes,
        monochromatic: None,
    };
    let total = rs.settings.width as u64 * rs.settings.height as u64 * spp as u64;
    let bar = progress::Progress::new(total, a.quiet, label);
    let out = pool.install(|| integrator::render(rs, &opts, &|n| bar.add(n)));
    bar.finish();
    let meta = ImageMeta {
        spp: out.spp,
        sample_offset: a.sample_offset as u64,
        scene_hash: scene.hash,
        simd: Some(out.lanes.width() as u32),
    };
    film::write_image(
        output,
        &out.image(),
        &meta,
        &PngOptions {
            exposure: a.exposure,
        },
    )?;
    Ok(out)
}

fn render_frames(
    a: &RenderArgs,
    scene: &LoadedScene,
    pool: &rayon::ThreadPool,
    range: std::ops::Range<u32>,
    template: &Path,
) -> Result<(), CliError> {
    let list: Vec<u32> = match (&a.shard, &a.shard_from_env) {
        (Some((i, n)), _) => farm::shard_frames(range.clone(), *i, *n),
        (None, Some(var)) => {
            let (i, n) = farm::shard_from_env(var, a.shard_count)?;
            farm::shard_frames(range.clone(), i, n)
        }
        (None, None) => range.clone().collect(),
    };
    let n = list.len();
    let mut rs: Option<RenderScene> = None;
    let start = std::time::Instant::now();
    let mut rendered = 0u32;
    let mut written = Vec::with_capacity(n);
    for (k, f) in list.iter().copied().enumerate() {
        let path = frames::frame_path(template, f);
        written.push(path.clone());
        if a.resume && path.is_file() {
            if !a.quiet {
                eprintln!(
                    "frame {f} ({}/{n}): {} exists, skipped",
                    k + 1,
                    path.display()
                );
            }
            continue;
        }
        // The scene is prepared once; later frames move the camera and rebuild the kd-tree
        // only if primitives move.
        let scene_for_frame = match rs.as_mut() {
            None => {
                let r = rs.insert(prepare(scene, &a.force, f)?);
                if !a.quiet {
                    for w in r.warnings() {
                        eprintln!("warning: {w}");
                    }
                }
                r
            }
            Some(r) => {
                r.set_frame(scene, &KdParams::default(), f);
                force_effects(r, &a.force)?;
                r
            }
        };
        scene_for_frame.settings.seed = frames::frame_seed(scene.render.seed, f);
        let eta = if rendered > 0 {
            let per = start.elapsed().as_secs_f64() / rendered as f64;
            format!(", range eta {:.0}s", per * (n - k) as f64)
        } else {
            String::new()
        };
        let label = format!("frame {f} ({}/{n}{eta})", k + 1);
        let out = render_to_file(a, scene, scene_for_frame, pool, &path, &label)?;
        rendered += 1;
        if a.stats {
            print_stats(scene_for_frame, &out, &path, pool.current_num_threads());
        } else if !a.quiet {
            eprintln!(
                "frame {f} ({}/{n}): wrote {} ({:.2} s, {:.2} Msamples/s)",
                k + 1,
                path.display(),
                out.seconds,
                out.stats.samples as f64 / out.seconds.max(1e-9) * 1e-6
            );
        }
    }
    if let Some(gif) = &a.gif {
        let fps = scene.camera_path.as_ref().map_or(24, |p| p.fps);
        frames::write_gif(&written, fps, gif)?;
        if !a.quiet {
            eprintln!("wrote {}", gif.display());
        }
    }
    Ok(())
}

fn print_stats(rs: &RenderScene, out: &integrator::RenderOutput, output: &Path, threads: usize) {
    let s = &out.stats;
    let sps = s.samples as f64 / out.seconds.max(1e-9);
    eprintln!(
        "image: {} ({}x{}, {} spp)",
        output.display(),
        out.width,
        out.height,
        out.spp
    );
    eprintln!("time: {:.3} s on {} threads", out.seconds, threads);
    eprintln!(
        "samples: {} ({:.0} samples/s, {:.0} samples/s per thread)",
        s.samples,
        sps,
        sps / threads as f64
    );
    eprintln!("dropped samples: {}", s.dropped);
    eprintln!(
        "simd: width {}, mean lane occupancy {:.3}",
        out.lanes.describe(),
        s.rays as f64 / s.lane_slots.max(1) as f64
    );
    eprintln!(
        "rays: {} closest-hit, {} shadow ({:.2} Mrays/s)",
        s.rays,
        s.shadow_rays,
        (s.rays + s.shadow_rays) as f64 / out.seconds.max(1e-9) * 1e-6
    );
    let r = &s.revolution;
    if r.rays > 0 {
        eprintln!(
            "surfaces of revolution: {} rays, {} candidate spans, {} brackets, {} Newton iterations ({:.2} per bracket), {} not converged",
            r.rays,
            r.candidate_spans,
            r.brackets,
            r.newton_iterations,
            r.newton_iterations as f64 / r.brackets.max(1) as f64,
            r.non_converged
        );
    }
    let k = rs.accel.stats();
    eprintln!(
        "kd-tree: {} primitives, {} nodes, depth {}, {:.2} primitives per leaf, built in {:.3} ms",
        k.primitives,
        k.nodes,
        k.max_depth,
        k.mean_leaf_prims,
        rs.accel_seconds * 1e3
    );
}

fn info(a: InfoArgs) -> Result<(), CliError> {
    let scene = load_scene(&a.scene, &a.set, &[])?;
    let rs = prepare(&scene, &a.force, 0)?;
    let s = &rs.settings;
    println!("scene: {}", a.scene.display());
    println!(
        "render: {}x{}, {} spp, max depth {}, seed {}, {:?} light sampling, rr depth {}, {:?} Fresnel, {:?} sampler, {:?} filter",
        s.width,
        s.height,
        s.spp,
        s.max_depth,
        s.seed,
        s.light_sampling,
        s.rr_depth,
        s.fresnel,
        s.sampler,
        s.filter
    );
    match crate::simd::Lanes::resolve(s.simd) {
        Ok(lanes) => println!("simd: {}", integrator::describe_lanes(lanes)),
        Err(e) => println!("simd: {e}"),
    }
    println!("entities: {}", rs.prims.len());
    for i in 0..rs.prims.len() {
        let m = rs.prims.materials[rs.prims.material[i] as usize];
        println!("  \"{}\": {:?}, {m}", rs.prims.names[i], rs.prims.kind[i]);
    }
    for w in rs.warnings() {
        println!("warning: {w}");
    }
    println!("effects:");
    for line in rs.effects.to_string().lines() {
        println!("  {line}");
    }
    let counts = rs
        .prims
        .counts()
        .iter()
        .map(|(k, n)| format!("{n} {k:?}"))
        .collect::<Vec<_>>()
        .join(", ");
    println!("primitives: {} ({counts})", rs.prims.len());
    println!(
        "lights: {} ({} area{})",
        rs.lights.lights.len(),
        rs.lights.lights.len() - rs.lights.environment.is_some() as usize,
        if rs.lights.environment.is_some() {
            ", environment"
        } else {
            ""
        }
    );
    for (i, m) in rs.prims.meshes.iter().enumerate() {
        let b = m.shape.bounds();
        println!(
            "mesh {i}: {}; object bounds ({:.4}, {:.4}, {:.4})..({:.4}, {:.4}, {:.4})",
            m.shape.stats(),
            b.min.x,
            b.min.y,
            b.min.z,
            b.max.x,
            b.max.y,
            b.max.z
        );
    }
    let k = rs.accel.stats();
    println!(
        "kd-tree: {} nodes ({} leaves, {} empty), depth {}, {:.2} primitives per leaf, {} references, built in {:.3} ms",
        k.nodes,
        k.leaves,
        k.empty_leaves,
        k.max_depth,
        k.mean_leaf_prims,
        k.prim_refs,
        rs.accel_seconds * 1e3
    );
    Ok(())
}
