//! `prism converge`: error against a converged reference, per second of render, for one or
//! more configurations of a scene.

use crate::film::{self, Image, ImageMeta, PngOptions};
use crate::integrator::{RenderOptions, render};
use crate::kdtree::KdParams;
use crate::scene::Effect;
use crate::scene_file::{self, LoadedScene};
use crate::systems;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One configuration: a name and the settings that differ from the scene's.
#[derive(Clone, Debug)]
pub struct Config {
    /// Label in the table and plots, e.g. `spp=4 rr_depth=3` (`baseline` for the scene as is).
    pub name: String,
    /// `--set` keys and values applied on top of the scene.
    pub overrides: Vec<(String, String)>,
    /// Effects forced on regardless of what the scene needs.
    pub force: Vec<Effect>,
    /// Kd-tree build parameters.
    pub kd: KdParams,
    /// Sample counts to render instead of the doubling ladder.
    pub spp: Option<Vec<u32>>,
    /// Target errors to render to (adaptively) instead of a ladder of sample counts.
    pub targets: Option<Vec<f64>>,
}

/// One rung of a configuration's ladder.
#[derive(Clone, Debug)]
pub struct Row {
    /// Name of the configuration.
    pub config: String,
    /// Samples per pixel.
    pub spp: u32,
    /// Wall-clock seconds of the render, preparation included.
    pub seconds: f64,
    /// Root-mean-square error against the reference ([`film::Metrics::rmse`]).
    pub rmse: f64,
    /// Relative mean squared error against the reference ([`film::Metrics::relmse`]).
    pub relmse: f64,
    /// Structural similarity to the reference (1 is identical).
    pub ssim: f64,
    /// relMSE without the worst 0.1 % of pixels ([`film::relmse_trimmed`]).
    pub relmse_trimmed: f64,
    /// The target relMSE of an adaptive rung.
    pub target: Option<f64>,
    /// The render's own estimate of its relMSE (adaptive rungs), to set beside `relmse`.
    pub estimate: Option<f64>,
}

/// What `prism converge` is asked to do.
pub struct ConvergeOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// `--set` overrides applied to every configuration and to the reference.
    pub set: Vec<(String, String)>,
    /// A reference image to use instead of rendering one.
    pub reference: Option<PathBuf>,
    /// Samples per pixel of a reference prism renders; ladders stop at a quarter of it.
    pub reference_spp: u32,
    /// Seconds each configuration may spend on its ladder.
    pub budget: f64,
    /// `--vary` knobs: each key with the values to try.
    pub vary: Vec<(String, Vec<String>)>,
    /// Directory the CSV, plots, summary and cached reference go to.
    pub out: PathBuf,
    /// Print no progress.
    pub quiet: bool,
}

/// What a study produced.
pub struct ConvergeResult {
    /// Every rung of every configuration, in render order.
    pub rows: Vec<Row>,
    /// The reference's own estimated relMSE (from two independent halves), when prism
    /// rendered it.
    pub reference_relmse: Option<f64>,
    /// The Markdown summary written to `summary.md`.
    pub summary: String,
}

/// Keys `--vary` understands besides every `--set` key.
pub const VARY_ALIASES: &[(&str, &str)] = &[
    ("max_depth", "render.max_depth"),
    ("rr_depth", "render.integrator.rr_depth"),
    ("light_sampling", "render.integrator.light_sampling"),
    ("fresnel", "render.integrator.fresnel"),
    ("wavelengths", "render.integrator.wavelengths"),
    ("sampler", "render.integrator.sampler"),
    ("newton_tolerance", "render.newton_tolerance"),
    ("equiangular", "render.integrator.equiangular"),
    ("kind", "render.integrator.kind"),
    ("integrator.kind", "render.integrator.kind"),
];

/// The `--vary` keys of the target error: a ladder of targets, as `spp` is of counts.
const TARGET_KEYS: [&str; 2] = ["target_error", "render.target_error"];

/// A `--vary target_error` value: a relMSE in (0, 1], or `none` for uniform sampling.
fn parse_target(v: &str) -> Result<Option<f64>, String> {
    if matches!(v, "none" | "off" | "uniform") {
        return Ok(None);
    }
    match v.parse::<f64>() {
        Ok(t) if t > 0.0 && t <= 1.0 => Ok(Some(t)),
        _ => Err(format!(
            "--vary target_error: '{v}' is not a relative MSE in (0, 1] (or none)"
        )),
    }
}

fn apply_knob(c: &mut Config, key: &str, value: &str) -> Result<(), String> {
    let num = |v: &str| -> Result<f32, String> {
        v.parse::<f32>()
            .map_err(|_| format!("--vary {key}: '{v}' is not a number"))
    };
    match key {
        "spp" => {
            let n: u32 = value
                .parse()
                .map_err(|_| format!("--vary spp: '{value}' is not a sample count"))?;
            c.spp = Some(vec![n]);
        }
        "spectral" => match value {
            "auto" | "none" | "off" => {}
            "forced" | "force" | "on" => c.force.push(Effect::Spectral),
            _ => return Err(format!("--vary spectral: '{value}' is not auto or forced")),
        },
        "force" | "effect" => {
            if !matches!(value, "none" | "auto") {
                let e = Effect::parse(value)
                    .ok_or_else(|| format!("--vary {key}: unknown effect '{value}'"))?;
                c.force.push(e);
            }
        }
        "kd.intersect_cost" => c.kd.intersect_cost = num(value)?,
        "kd.traversal_cost" => c.kd.traversal_cost = num(value)?,
        "kd.empty_bonus" => c.kd.empty_bonus = num(value)?,
        "kd.max_leaf_prims" => c.kd.max_leaf_prims = num(value)? as u32,
        _ => {
            let full = VARY_ALIASES
                .iter()
                .find(|(a, _)| *a == key)
                .map_or(key, |(_, f)| f);
            c.overrides.push((full.to_string(), value.to_string()));
        }
    }
    Ok(())
}

/// The configurations: the cartesian product of every `--vary` list (the scene as it is when
/// there is none).
pub fn configs(vary: &[(String, Vec<String>)]) -> Result<Vec<Config>, String> {
    // Target errors make one ladder per configuration of the other knobs (`none` adds the
    // uniform configuration beside it).
    let (target_vary, vary): (Vec<_>, Vec<_>) = vary
        .iter()
        .cloned()
        .partition(|(k, _)| TARGET_KEYS.contains(&k.as_str()));
    let mut targets = Vec::new();
    let mut uniform_too = false;
    for v in target_vary.iter().flat_map(|(_, v)| v) {
        match parse_target(v)? {
            Some(t) => targets.push(t),
            None => uniform_too = true,
        }
    }
    let mut out = configs_of(&vary)?;
    if targets.is_empty() {
        return Ok(out);
    }
    let mut with = Vec::new();
    for c in out.drain(..) {
        if uniform_too {
            let mut u = c.clone();
            u.name = join_name(&c.name, "uniform");
            with.push(u);
        }
        let mut a = c.clone();
        a.name = join_name(&c.name, "adaptive");
        a.targets = Some(targets.clone());
        with.push(a);
    }
    Ok(with)
}

/// `base` and `tag`, or `tag` alone in place of `baseline`.
fn join_name(base: &str, tag: &str) -> String {
    if base.is_empty() || base == "baseline" {
        tag.to_string()
    } else {
        format!("{base} {tag}")
    }
}

fn configs_of(vary: &[(String, Vec<String>)]) -> Result<Vec<Config>, String> {
    let mut out = vec![Config {
        name: String::new(),
        overrides: Vec::new(),
        force: Vec::new(),
        kd: KdParams::default(),
        spp: None,
        targets: None,
    }];
    for (key, values) in vary {
        if values.is_empty() {
            return Err(format!("--vary {key}: no values"));
        }
        let mut next = Vec::new();
        for c in &out {
            for v in values {
                let mut c = c.clone();
                apply_knob(&mut c, key, v)?;
                if !c.name.is_empty() {
                    c.name.push(' ');
                }
                write!(c.name, "{key}={v}").unwrap();
                next.push(c);
            }
        }
        out = next;
    }
    if out.len() > 24 {
        return Err(format!(
            "{} configurations: vary fewer knobs at once (at most 24)",
            out.len()
        ));
    }
    // Several `--vary spp=` values make one ladder, not one curve each.
    let spp_only = vary.iter().all(|(k, _)| k == "spp") && !vary.is_empty();
    if spp_only {
        let ladder: Vec<u32> = out
            .iter()
            .filter_map(|c| c.spp.as_ref().map(|s| s[0]))
            .collect();
        return Ok(vec![Config {
            name: "baseline".into(),
            overrides: Vec::new(),
            force: Vec::new(),
            kd: KdParams::default(),
            spp: Some(ladder),
            targets: None,
        }]);
    }
    if out.len() == 1 && out[0].name.is_empty() {
        out[0].name = "baseline".into();
    }
    Ok(out)
}

fn fnv(bytes: &[u8], mut h: u64) -> u64 {
    for &b in bytes {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    h
}

fn load(opts: &ConvergeOptions, extra: &[(String, String)]) -> Result<LoadedScene, String> {
    let mut all = opts.set.clone();
    all.extend_from_slice(extra);
    scene_file::load(&opts.scene, &all).map_err(|e| e.to_string())
}

/// Renders `spp` samples from `offset` and returns the image and the seconds it took,
/// preparation included.
fn timed_render(
    scene: &LoadedScene,
    kd: &KdParams,
    force: &[Effect],
    spp: u32,
    offset: u32,
) -> Result<(Image, f64), String> {
    timed_render_to(scene, kd, force, spp, offset, None).map(|(i, t, _)| (i, t))
}

/// [`timed_render`], adaptive to `target` when given (with `spp` as the cap): the image, the
/// seconds, and the render's output (for its sample counts and estimate).
fn timed_render_to(
    scene: &LoadedScene,
    kd: &KdParams,
    force: &[Effect],
    spp: u32,
    offset: u32,
    target: Option<f64>,
) -> Result<(Image, f64, crate::integrator::RenderOutput), String> {
    let t0 = Instant::now();
    let mut rs = systems::prepare(scene, kd);
    for e in force {
        rs.effects.force(*e)?;
    }
    let out = render(
        &rs,
        &RenderOptions {
            sample_offset: offset,
            spp,
            time_limit: None,
            lanes: crate::simd::Lanes::auto(),
            monochromatic: None,
            stop: None,
            target_error: target,
            strategy: None,
        },
        &|_| {},
    );
    Ok((out.image(), t0.elapsed().as_secs_f64(), out))
}

/// The reference image: given, cached from an earlier run, or rendered now in two
/// independent halves whose difference estimates its own error.
fn reference(opts: &ConvergeOptions) -> Result<(Image, Option<f64>), String> {
    if let Some(p) = &opts.reference {
        let (img, _) = film::read_image(p).map_err(|e| e.to_string())?;
        return Ok((img, None));
    }
    let scene = load(opts, &[])?;
    let text = std::fs::read(&opts.scene)
        .map_err(|e| format!("cannot read '{}': {e}", opts.scene.display()))?;
    let mut h = fnv(&text, 0xcbf2_9ce4_8422_2325);
    for (k, v) in &opts.set {
        h = fnv(k.as_bytes(), fnv(v.as_bytes(), h));
    }
    h = fnv(&opts.reference_spp.to_le_bytes(), h);
    let path = opts.out.join(format!("reference_{h:016x}.exr"));
    let note = opts.out.join(format!("reference_{h:016x}.txt"));
    if path.is_file() {
        let (img, _) = film::read_image(&path).map_err(|e| e.to_string())?;
        let est = std::fs::read_to_string(&note)
            .ok()
            .and_then(|s| s.trim().parse().ok());
        if !opts.quiet {
            eprintln!("reference: cached {}", path.display());
        }
        return Ok((img, est));
    }
    let half = (opts.reference_spp / 2).max(1);
    if !opts.quiet {
        eprintln!("reference: rendering {} spp in two halves ...", 2 * half);
    }
    let kd = KdParams::default();
    let (a, _) = timed_render(&scene, &kd, &[], half, 0)?;
    let (b, _) = timed_render(&scene, &kd, &[], half, half)?;
    let mut img = a.clone();
    let mut est = 0.0f64;
    for ((p, pa), pb) in img.pixels.iter_mut().zip(&a.pixels).zip(&b.pixels) {
        for c in 0..3 {
            let r = 0.5 * (pa[c] as f64 + pb[c] as f64);
            p[c] = r as f32;
            // Var(mean of two halves) = Var(A − B) / 4.
            est += (pa[c] as f64 - pb[c] as f64).powi(2) / 4.0 / (r * r + 0.01);
        }
    }
    est /= (img.pixels.len() * 3) as f64;
    let meta = ImageMeta {
        spp: 2 * half,
        sample_offset: 0,
        scene_hash: scene.hash,
        simd: None,
        complete: true,
        settings: None,
    };
    film::write_image(&path, &img, &meta, &PngOptions::default()).map_err(|e| e.to_string())?;
    film::write_atomic(&note, format!("{est:e}\n").as_bytes()).map_err(|e| e.to_string())?;
    Ok((img, Some(est)))
}

/// Runs the study and writes `converge.csv`, `converge.png`, `converge.svg` and `summary.md`
/// into `opts.out`.
pub fn converge(opts: &ConvergeOptions) -> Result<ConvergeResult, String> {
    std::fs::create_dir_all(&opts.out)
        .map_err(|e| format!("cannot create '{}': {e}", opts.out.display()))?;
    let configs = configs(&opts.vary)?;
    let (reference, ref_est) = reference(opts)?;
    let mut rows = Vec::new();
    for c in &configs {
        let scene = load(opts, &c.overrides)?;
        if (scene.render.width, scene.render.height) != (reference.width, reference.height) {
            return Err(format!(
                "the reference is {}x{} but configuration '{}' renders {}x{}",
                reference.width, reference.height, c.name, scene.render.width, scene.render.height
            ));
        }
        // A ladder of sample counts, or of target errors (adaptive, uncapped).
        let ladder: Vec<(u32, Option<f64>)> = match (&c.targets, &c.spp) {
            (Some(t), _) => t
                .iter()
                .map(|&t| (crate::integrator::MAX_ADAPTIVE_SPP, Some(t)))
                .collect(),
            (None, Some(l)) => l.iter().map(|&n| (n, None)).collect(),
            (None, None) => (0..20).map(|k| (1u32 << k, None)).collect(),
        };
        let mut spent = 0.0;
        let mut last: Option<(u32, f64)> = None;
        for &(spp, target) in &ladder {
            if c.spp.is_none() && target.is_none() {
                // Stop before a rung that would overrun the budget (time grows with spp).
                if let Some((s0, t0)) = last
                    && spent + t0 * spp as f64 / s0 as f64 > opts.budget
                {
                    break;
                }
                if spp > opts.reference_spp / 4 {
                    break;
                }
            }
            let (img, secs, out) = timed_render_to(&scene, &c.kd, &c.force, spp, 0, target)?;
            spent += secs;
            last = Some((spp, secs));
            let m = film::compare(&img, &reference).map_err(|e| e.to_string())?;
            let row = Row {
                config: c.name.clone(),
                spp: out.mean_spp().round() as u32,
                seconds: secs,
                rmse: m.rmse,
                relmse: m.relmse,
                ssim: super::ssim::ssim(&img, &reference),
                relmse_trimmed: film::relmse_trimmed(&img, &reference, TRIM),
                target,
                estimate: out.estimate,
            };
            if !opts.quiet {
                let est = row
                    .estimate
                    .map_or(String::new(), |e| format!(" (estimated {e:.3e})"));
                eprintln!(
                    "{}: {} spp, {:.3} s, relMSE {:.3e}{est}",
                    row.config, row.spp, row.seconds, row.relmse
                );
            }
            rows.push(row);
        }
    }
    // The two columns of adaptive rungs only when there are any: the file keeps its old
    // form for studies without them.
    let adaptive = rows.iter().any(|r| r.estimate.is_some());
    let mut csv = String::from("config,spp,seconds,rmse,relmse,ssim,relmse_trimmed");
    csv.push_str(if adaptive {
        ",target_error,estimated_relmse\n"
    } else {
        "\n"
    });
    let opt = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x:.6e}"));
    for r in &rows {
        write!(
            csv,
            "{},{},{:.6},{:.6e},{:.6e},{:.6},{:.6e}",
            csv_field(&r.config),
            r.spp,
            r.seconds,
            r.rmse,
            r.relmse,
            r.ssim,
            r.relmse_trimmed,
        )
        .unwrap();
        if adaptive {
            write!(csv, ",{},{}", opt(r.target), opt(r.estimate)).unwrap();
        }
        csv.push('\n');
    }
    film::write_atomic(&opts.out.join("converge.csv"), csv.as_bytes())
        .map_err(|e| e.to_string())?;
    let names: Vec<String> = configs.iter().map(|c| c.name.clone()).collect();
    // The scene's name in the title: plots get copied out of their folders.
    let title = format!(
        "{}: error vs render time",
        opts.scene.file_stem().map_or_else(
            || opts.scene.display().to_string(),
            |s| s.to_string_lossy().into_owned()
        )
    );
    super::plot::plot(
        &title,
        &rows,
        &names,
        &opts.out.join("converge.png"),
        &opts.out.join("converge.svg"),
    )?;
    let summary = summary(&opts.scene, &rows, &names, ref_est);
    film::write_atomic(&opts.out.join("summary.md"), summary.as_bytes())
        .map_err(|e| e.to_string())?;
    Ok(ConvergeResult {
        rows,
        reference_relmse: ref_est,
        summary,
    })
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Least-squares slope and intercept of log10(relMSE) against log10(seconds).
pub fn fit(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(t, e)| *t > 0.0 && *e > 0.0)
        .map(|(t, e)| (t.log10(), e.log10()))
        .collect();
    if p.len() < 2 {
        return None;
    }
    let n = p.len() as f64;
    let (sx, sy) = p.iter().fold((0.0, 0.0), |a, q| (a.0 + q.0, a.1 + q.1));
    let (mx, my) = (sx / n, sy / n);
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for (x, y) in &p {
        sxx += (x - mx) * (x - mx);
        sxy += (x - mx) * (y - my);
    }
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    Some((slope, my - slope * mx))
}

/// Seconds to reach `target` relMSE: interpolated between the rungs that straddle it, or
/// extrapolated from the fit (marked) when the ladder stopped above it.
fn time_to(points: &[(f64, f64)], target: f64) -> String {
    for w in points.windows(2) {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if e0 > target && e1 <= target && t0 > 0.0 && e1 > 0.0 {
            let f = (target.log10() - e0.log10()) / (e1.log10() - e0.log10());
            return format!(
                "{:.3} s",
                10f64.powf(t0.log10() + f * (t1.log10() - t0.log10()))
            );
        }
    }
    if let Some(&(t, e)) = points.first()
        && e <= target
    {
        return format!("≤ {t:.3} s");
    }
    match fit(points) {
        Some((slope, b)) if slope < -0.05 => {
            let t = 10f64.powf((target.log10() - b) / slope);
            if t.is_finite() {
                format!("~{} (extrapolated)", long_seconds(t))
            } else {
                "not reached (error floor)".into()
            }
        }
        _ => "not reached (error floor)".into(),
    }
}

/// A duration that may be far beyond any render: seconds in fixed point up to 10⁴ s, then
/// in scientific notation with a unit a reader can picture, so a shallow slope's absurd
/// extrapolation reads as absurd instead of as a wall of digits.
fn long_seconds(t: f64) -> String {
    if t < 1e4 {
        return format!("{t:.3} s");
    }
    let (v, unit) = if t < 86_400.0 * 2.0 {
        (t / 3600.0, "hours")
    } else if t < 86_400.0 * 365.25 * 2.0 {
        (t / 86_400.0, "days")
    } else {
        (t / (86_400.0 * 365.25), "years")
    };
    if v < 1e4 {
        format!("{t:.2e} s ≈ {v:.0} {unit}")
    } else {
        format!("{t:.2e} s ≈ {v:.1e} {unit}")
    }
}

/// Fraction of pixels the trimmed relMSE leaves out.
const TRIM: f64 = 0.001;

/// relMSE at `t` seconds, interpolated log–log between the rungs that straddle it.
fn error_at(points: &[(f64, f64)], t: f64) -> Option<f64> {
    points.windows(2).find_map(|w| {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if t0 <= t && t <= t1 && t0 > 0.0 && t1 > t0 && e0 > 0.0 && e1 > 0.0 {
            let f = (t.log10() - t0.log10()) / (t1.log10() - t0.log10());
            Some(10f64.powf(e0.log10() + f * (e1.log10() - e0.log10())))
        } else {
            None
        }
    })
}

fn summary(scene: &Path, rows: &[Row], names: &[String], ref_est: Option<f64>) -> String {
    let mut s = format!("# Convergence of `{}`\n\n", scene.display());
    match ref_est {
        Some(e) => writeln!(
            s,
            "Reference: rendered by prism in two independent halves; its own estimated relMSE is {e:.2e}, so errors within a few times that are reference noise.\n"
        )
        .unwrap(),
        None => writeln!(s, "Reference: supplied with `--reference`.\n").unwrap(),
    }
    let points_of = |name: &String, trimmed: bool| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| &r.config == name)
            .map(|r| {
                let e = if trimmed { r.relmse_trimmed } else { r.relmse };
                (r.seconds, e)
            })
            .collect()
    };
    let points = |name: &String| points_of(name, false);
    // Error at equal time: at the longest time every configuration's ladder reached.
    let equal_t = names
        .iter()
        .filter_map(|n| points(n).last().map(|p| p.0))
        .fold(f64::INFINITY, f64::min);
    s.push_str(&format!(
        "| configuration | rungs | slope (log relMSE / log s) | time to 1 % relMSE | time to 0.1 % relMSE | relMSE at {equal_t:.2} s (equal time) | same, worst 0.1 % of pixels dropped | last relMSE | note |\n"
    ));
    s.push_str("|---|---|---|---|---|---|---|---|---|\n");
    for name in names {
        let pts = points(name);
        let slope = fit(&pts).map_or("–".into(), |(k, _)| format!("{k:.2}"));
        // Unbiased Monte Carlo error falls as 1/time (slope −1); a bias flattens the tail.
        let tail = if pts.len() >= 3 {
            fit(&pts[pts.len() - 3..])
        } else {
            None
        };
        let floor = match tail {
            Some((k, _)) if k > -0.3 => pts.last().map(|p| p.1),
            _ => None,
        };
        let note = floor.map_or(String::new(), |f| format!("error floor ≈ {f:.2e}: bias"));
        // Past a floor, extrapolating the fit would promise what the bias forbids.
        let reach = |target: f64| match floor {
            Some(f) if f > target => format!("not reached (floor {f:.1e})"),
            _ => time_to(&pts, target),
        };
        writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            name,
            pts.len(),
            slope,
            reach(0.01),
            reach(0.001),
            error_at(&pts, equal_t).map_or("–".into(), |e| format!("{e:.2e}")),
            error_at(&points_of(name, true), equal_t).map_or("–".into(), |e| format!("{e:.2e}")),
            pts.last().map_or("–".into(), |p| format!("{:.2e}", p.1)),
            note
        )
        .unwrap();
    }
    s.push_str("\nrelMSE = mean((x − r)² / (r² + 0.01)) over pixels and channels; seconds include scene preparation. Rare bright samples (caustics found by chance) can dominate relMSE for thousands of samples; the trimmed column drops the 0.1 % of pixels with the largest error.\n");
    let adaptive: Vec<&Row> = rows.iter().filter(|r| r.estimate.is_some()).collect();
    if !adaptive.is_empty() {
        s.push_str("\n## Estimated against true error\n\nAdaptive renders stop when their own estimate of relMSE (two independent halves per pixel) reaches the target; the true relMSE is measured against the reference (whose own noise, above, adds to it).\n\n| configuration | target | estimated relMSE | true relMSE | true / estimated | mean spp | seconds |\n|---|---|---|---|---|---|---|\n");
        for r in adaptive {
            let e = r.estimate.unwrap_or(f64::NAN);
            writeln!(
                s,
                "| {} | {} | {e:.3e} | {:.3e} | {:.2} | {} | {:.2} |",
                r.config,
                r.target.map_or("–".into(), |t| format!("{t:.1e}")),
                r.relmse,
                r.relmse / e,
                r.spp,
                r.seconds
            )
            .unwrap();
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_power_law() {
        let pts: Vec<(f64, f64)> = (0..6).map(|k| (2f64.powi(k), 0.5 / 2f64.powi(k))).collect();
        let (slope, b) = fit(&pts).unwrap();
        assert!((slope + 1.0).abs() < 1e-12 && (b - 0.5f64.log10()).abs() < 1e-12);
        assert_eq!(time_to(&pts, 0.1), "5.000 s");
        // Beyond the rungs the fit extrapolates; a shallow slope gives years, said as such.
        assert_eq!(time_to(&pts, 1e-3), "~500.000 s (extrapolated)");
        let flat: Vec<(f64, f64)> = (0..6)
            .map(|k| (2f64.powi(k), 0.5 / 2f64.powf(0.1 * f64::from(k))))
            .collect();
        assert_eq!(
            time_to(&flat, 0.01),
            "~9.77e16 s ≈ 3.1e9 years (extrapolated)"
        );
        assert_eq!(long_seconds(7200.0), "7200.000 s");
        assert_eq!(long_seconds(36_000.0), "3.60e4 s ≈ 10 hours");
        assert_eq!(long_seconds(864_000.0), "8.64e5 s ≈ 10 days");
        // Halfway between rungs in log time is halfway in log error on a power law.
        let e = error_at(&pts, 2f64.powf(2.5)).unwrap();
        assert!((e / (0.5 / 2f64.powf(2.5)) - 1.0).abs() < 1e-12);
        let last = error_at(&pts, 32.0).unwrap();
        assert!((last / (0.5 / 32.0) - 1.0).abs() < 1e-12);
        assert_eq!(error_at(&pts, 64.0), None);
    }

    #[test]
    fn vary_builds_the_product() {
        let c = configs(&[
            ("fresnel".into(), vec!["Exact".into(), "Schlick".into()]),
            ("max_depth".into(), vec!["2".into(), "12".into()]),
        ])
        .unwrap();
        assert_eq!(c.len(), 4);
        assert_eq!(c[1].name, "fresnel=Exact max_depth=12");
        assert_eq!(c[1].overrides[1], ("render.max_depth".into(), "12".into()));
        let l = configs(&[("spp".into(), vec!["1".into(), "4".into()])]).unwrap();
        assert_eq!(l.len(), 1);
        assert_eq!(l[0].spp, Some(vec![1, 4]));
    }
}
