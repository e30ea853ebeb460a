//! `prism render`: stills and frame series (with shards), written atomically, with progress
//! and statistics on stderr.

use super::args::RenderArgs;
use super::scene::{force_effects, load_scene, prepare};
use super::{CliError, farm, frames, progress};
use crate::film::{self, ImageMeta, PngOptions};
use crate::integrator::{self, RenderOptions};
use crate::kdtree::KdParams;
use crate::scene::RenderScene;
use crate::scene_file::LoadedScene;
use std::path::{Path, PathBuf};

/// The most worker threads `--threads` may ask for (starting 100,000 threads took most of a
/// minute to fail).
pub const MAX_THREADS: usize = 1024;

/// `prism render`: a still image, or a frame series with `--frames`.
pub(super) fn render(a: RenderArgs) -> Result<(), CliError> {
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
        return Err(CliError::TimeLimit(t));
    }
    if let Some(t) = a.threads
        && !(1..=MAX_THREADS).contains(&t)
    {
        return Err(CliError::Threads(t));
    }
    if let Some(t) = a.target_error {
        if !(t > 0.0 && t <= 1.0) {
            return Err(CliError::TargetError(t));
        }
        extra.push(("render.target_error".to_string(), format!("{t:?}")));
    }
    if let Some(b) = a.batch
        && b > 255
    {
        return Err(CliError::Batch(b));
    }
    let scene = load_scene(&a.scene, &a.set, &extra)?;
    // From here on, SIGINT and SIGTERM stop the render and keep what it has.
    film::signals::install();
    let stem = a
        .scene
        .file_stem()
        .map_or("render".to_string(), |s| s.to_string_lossy().to_string());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.unwrap_or(0))
        .build()
        .map_err(CliError::ThreadPool)?;
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
    let out = render_to_file(&a, &scene, &rs, &pool, &output, "", Partial::Write)?;
    if a.stats {
        print_stats(&rs, &out, &output, pool.current_num_threads());
    } else if !a.quiet {
        eprintln!("wrote {} ({})", output.display(), summary(&out));
    }
    Ok(())
}

use crate::integrator::MAX_ADAPTIVE_SPP;

/// The first sample index: `--batch B` is `--sample-offset B·2²⁴`.
fn sample_offset(a: &RenderArgs) -> u32 {
    a.batch.map_or(a.sample_offset, |b| b << 24)
}

/// Samples and time of a render, and with a target error its estimate.
fn summary(out: &integrator::RenderOutput) -> String {
    match out.estimate {
        Some(e) => format!(
            "estimated relMSE {e:.3e}, {:.1} spp on average, {} at most, {:.2} s",
            out.mean_spp(),
            out.spp,
            out.seconds
        ),
        None => format!("{} spp, {:.2} s", out.spp, out.seconds),
    }
}

/// What a render stopped by a signal does with the samples it has.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Partial {
    /// A still: written under its final name, marked incomplete, with its true sample count.
    Write,
    /// A frame of a series: dropped, so no frame on disk is partial.
    Drop,
}

/// The lane width this command renders at.
fn lanes_for(
    a: &RenderArgs,
    rs_simd: crate::simd::SimdChoice,
) -> Result<crate::simd::Lanes, CliError> {
    let choice = if a.reference {
        crate::simd::SimdChoice::W1
    } else {
        a.simd.unwrap_or(rs_simd)
    };
    Ok(crate::simd::Lanes::resolve(choice)?)
}

/// Hash of the command-line settings that change an image's pixels without being part of the
/// scene's hash: the forced effects, and the exposure of a PNG (`prism:settings`).
fn settings_hash(a: &RenderArgs, output: &Path) -> u64 {
    let mut force: Vec<String> = a.force.iter().map(|f| f.to_ascii_lowercase()).collect();
    force.sort();
    force.dedup();
    let mut text = format!("force={}", force.join(","));
    if film::ImageFormat::from_path(output).is_ok_and(|f| f == film::ImageFormat::Png) {
        text.push_str(&format!(";exposure={:08x}", a.exposure.to_bits()));
    }
    // FNV-1a: the same in every build, so files from another build of prism still match.
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Renders one frame of a prepared scene and writes it atomically.
fn render_to_file(
    a: &RenderArgs,
    scene: &LoadedScene,
    rs: &RenderScene,
    pool: &rayon::ThreadPool,
    output: &Path,
    label: &str,
    partial: Partial,
) -> Result<integrator::RenderOutput, CliError> {
    let target = rs.settings.target_error;
    // With a target error the scene's sample count is not a cap (scenes name a few dozen);
    // only a count given on the command line is.
    let spp_given = a.spp.is_some() || a.set.iter().any(|(k, _)| k == "render.spp");
    let spp = match target {
        Some(_) if !spp_given => MAX_ADAPTIVE_SPP,
        _ => rs.settings.spp,
    };
    let lanes = lanes_for(a, rs.settings.simd)?;
    let offset = sample_offset(a);
    // Adaptive renders draw `spp / 2` indices in each of their two halves.
    let used = if target.is_some() {
        spp.div_ceil(2)
    } else {
        spp
    };
    if u64::from(offset) + u64::from(used) > 1 << 32 {
        return Err(CliError::SampleRange { offset, spp });
    }
    let opts = RenderOptions {
        sample_offset: offset,
        spp,
        time_limit: a.time_limit,
        lanes,
        monochromatic: None,
        stop: Some(film::signals::stop_flag()),
        target_error: target,
        strategy: None,
    };
    let total = rs.settings.width as u64 * rs.settings.height as u64 * spp as u64;
    let bar = progress::Progress::new(total, a.quiet, label, target);
    let out = pool.install(|| integrator::render_observed(rs, &opts, &bar));
    bar.finish();
    let interrupted = |written: Option<PathBuf>| {
        let (signal, name) = film::signals::received().unwrap_or((2, "a signal"));
        CliError::Interrupted {
            signal,
            name,
            written,
            series: partial == Partial::Drop,
            spp: out.spp,
            asked: spp,
        }
    };
    if out.interrupted && (partial == Partial::Drop || out.spp == 0) {
        return Err(interrupted(None));
    }
    let meta = ImageMeta {
        spp: out.spp,
        sample_offset: u64::from(offset),
        scene_hash: scene.hash,
        simd: Some(out.lanes.width() as u32),
        complete: !out.interrupted,
        settings: Some(settings_hash(a, output)),
    };
    let errors: Vec<f32> = out.errors().iter().map(|&e| e as f32).collect();
    let aux = film::AuxChannels {
        count: (!out.counts.is_empty()).then_some(&out.counts[..]),
        error: (!errors.is_empty()).then_some(&errors[..]),
    };
    film::write_image_aux(
        output,
        &out.image(),
        &meta,
        &PngOptions {
            exposure: a.exposure,
        },
        &aux,
    )?;
    if out.interrupted {
        return Err(interrupted(Some(output.to_path_buf())));
    }
    Ok(out)
}

/// Why the frame at `path` cannot be kept by `--resume` (`None`: it can): it must be a complete
/// render of this scene, these settings, size, width, sample range and sample count (with a
/// time limit, any positive count up to the one asked).
fn resume_mismatch(a: &RenderArgs, scene: &LoadedScene, path: &Path, simd: u32) -> Option<String> {
    let h = match film::read_header(path) {
        Ok(h) => h,
        Err(e) => return Some(format!("its header cannot be read ({e})")),
    };
    let Some(m) = h.meta else {
        return Some("it has no prism provenance (prism:* attributes)".into());
    };
    let r = &scene.render;
    // Adaptive frames reach their target with any count up to the cap.
    let adaptive = r.target_error.is_some();
    let cap = if adaptive && a.spp.is_none() && !a.set.iter().any(|(k, _)| k == "render.spp") {
        MAX_ADAPTIVE_SPP
    } else {
        r.spp
    };
    let spp_ok = match (a.time_limit, adaptive) {
        (None, false) => m.spp == r.spp,
        _ => (1..=cap).contains(&m.spp),
    };
    if !m.complete {
        Some(format!(
            "it is incomplete ({} of its samples were rendered)",
            m.spp
        ))
    } else if (h.width, h.height) != (r.width, r.height) {
        Some(format!(
            "it is {}x{}, not {}x{}",
            h.width, h.height, r.width, r.height
        ))
    } else if m.scene_hash != scene.hash {
        Some("it comes from another scene text or other --set/--size/--seed values".into())
    } else if m.settings != Some(settings_hash(a, path)) {
        Some("it was rendered with other --force or --exposure settings".into())
    } else if m.simd != Some(simd) {
        Some(match m.simd {
            Some(w) => format!("it was rendered at SIMD width {w}, not {simd}"),
            None => "its SIMD width is not recorded".into(),
        })
    } else if m.sample_offset != u64::from(sample_offset(a)) {
        Some(format!(
            "its samples start at {}, not {}",
            m.sample_offset,
            sample_offset(a)
        ))
    } else if !spp_ok {
        Some(format!("it has {} spp, not {}", m.spp, r.spp))
    } else {
        None
    }
}

/// The frames of `range` (this shard's, with `--shard`) rendered to `template`'s paths, then
/// the GIF if `--gif` asks for one.
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
    let simd = lanes_for(a, scene.render.simd)?.width() as u32;
    for (k, f) in list.iter().copied().enumerate() {
        if let Some((signal, name)) = film::signals::received() {
            return Err(CliError::Interrupted {
                signal,
                name,
                written: None,
                series: true,
                spp: 0,
                asked: scene.render.spp,
            });
        }
        let path = frames::frame_path(template, f);
        written.push(path.clone());
        if a.resume && path.exists() {
            match resume_mismatch(a, scene, &path, simd) {
                None => {
                    if !a.quiet {
                        eprintln!(
                            "frame {f} ({}/{n}): {} exists, skipped",
                            k + 1,
                            path.display()
                        );
                    }
                    continue;
                }
                // Said even with --quiet: the user asked to keep this file.
                Some(why) => eprintln!(
                    "frame {f} ({}/{n}): re-rendering {}: {why}",
                    k + 1,
                    path.display()
                ),
            }
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
        let out = render_to_file(
            a,
            scene,
            scene_for_frame,
            pool,
            &path,
            &label,
            Partial::Drop,
        )?;
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

/// The `--stats` report of one render, on stderr.
fn print_stats(rs: &RenderScene, out: &integrator::RenderOutput, output: &Path, threads: usize) {
    let s = &out.stats;
    let sps = s.samples as f64 / out.seconds.max(1e-9);
    eprintln!(
        "image: {} ({}x{}, {})",
        output.display(),
        out.width,
        out.height,
        summary(out)
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
