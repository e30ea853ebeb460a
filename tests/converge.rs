//! `prism converge` writes a well-formed study whose error falls with samples, and forcing an
//! absent effect leaves the image alone.

mod common;
use assert_cmd::cargo::CommandCargoExt;
use common::render::{run, scene_file};
use prism::scene::Effect;
use std::path::Path;
use std::process::Command;

/// Runs `prism converge` on the Cornell box at 32×32 with `args` into `out`, asserting
/// success; returns the scene's path.
fn cornell_study(args: &[&str], out: &Path) -> std::path::PathBuf {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let o = Command::cargo_bin("prism")
        .unwrap()
        .arg("converge")
        .arg(&scene)
        .args(["--size", "32x32", "--quiet"])
        .args(args)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    scene
}

#[test]
fn converge_writes_csv_plot_and_summary_with_falling_error() {
    let d = tempfile::tempdir().unwrap();
    let scene = cornell_study(
        &["--reference-spp", "256", "--vary", "spp=1,4,16"],
        d.path(),
    );
    for f in ["converge.csv", "converge.png", "converge.svg", "summary.md"] {
        assert!(d.path().join(f).is_file(), "{f}");
    }
    // The plot names its scene (plots get copied out of their folders).
    let stem = scene.file_stem().unwrap().to_string_lossy().into_owned();
    let svg = std::fs::read_to_string(d.path().join("converge.svg")).unwrap();
    assert!(
        svg.contains(&format!("{stem}: error vs render time")),
        "no title naming {stem}"
    );
    let csv = std::fs::read_to_string(d.path().join("converge.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("config,spp,seconds,rmse,relmse,ssim,relmse_trimmed")
    );
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    assert_eq!(rows.len(), 3);
    let num = |r: &Vec<String>, i: usize| r[i].parse::<f64>().unwrap();
    for r in &rows {
        assert_eq!(r.len(), 7);
        assert!(num(r, 2) > 0.0 && num(r, 3) >= 0.0 && num(r, 4) >= 0.0);
        assert!((0.0..=1.0).contains(&num(r, 5)));
        // Dropping the worst pixels can only lower the mean.
        assert!(num(r, 6) >= 0.0 && num(r, 6) <= num(r, 4), "{r:?}");
    }
    assert_eq!(
        rows.iter().map(|r| num(r, 1) as u32).collect::<Vec<_>>(),
        [1, 4, 16]
    );
    // Unbiased error falls as 1/spp: 16× the samples should cut relMSE by ~16, and noise in
    // the estimate over 3,072 pixel channels is far smaller than the factor 4 asked here.
    assert!(num(&rows[2], 4) < num(&rows[0], 4) / 4.0, "{csv}");
    let summary = std::fs::read_to_string(d.path().join("summary.md")).unwrap();
    assert!(summary.contains("| baseline |"), "{summary}");
    // A second run reuses the cached reference.
    assert_eq!(
        std::fs::read_dir(d.path())
            .unwrap()
            .filter(|e| e
                .as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with("reference_"))
            .count(),
        2
    );
}

#[test]
fn forcing_the_lens_on_a_pinhole_scene_changes_nothing_beyond_noise() {
    let small = [
        ("render.width", "32"),
        ("render.height", "32"),
        ("render.spp", "16"),
    ];
    for (name, factor) in [("cornell", 0.01), ("caustics", 1.0)] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.ron"));
        let mut s = scene_file(&path, &small);
        let plain = run(&s).image();
        s.effects.force(Effect::Lens).unwrap();
        let forced = run(&s).image();
        let m = prism::film::compare(&forced, &plain).unwrap().relmse;
        // A zero aperture only re-derives each direction through the focal point: rounding.
        // Diffuse transport carries that on smoothly; chains of glass and mirror bounces are
        // chaotic and turn it into different but equally likely paths. So the bound is a
        // fraction of the difference between two independent renders: 1 % for the diffuse
        // box, all of it for the glass.
        let other = scene_file(&path, &[small[0], small[1], small[2], ("render.seed", "2")]);
        let noise = prism::film::compare(&run(&other).image(), &plain)
            .unwrap()
            .relmse;
        let bound = factor * noise;
        assert!(m < bound, "{name}: {m} vs {bound}");
    }
}

#[test]
fn forcing_media_or_textures_on_a_scene_without_them_changes_nothing_beyond_noise() {
    // With no medium and no texture in the scene, the forced variants take the same decisions
    // on the same samples; the bound is 1 % of the difference between two independent renders,
    // far below noise yet above any rounding a reordered sum could bring.
    let small = [
        ("render.width", "32"),
        ("render.height", "32"),
        ("render.spp", "16"),
    ];
    for name in ["cornell", "caustics"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.ron"));
        let base = scene_file(&path, &small);
        let plain = run(&base).image();
        let other = scene_file(&path, &[small[0], small[1], small[2], ("render.seed", "2")]);
        let noise = prism::film::compare(&run(&other).image(), &plain)
            .unwrap()
            .relmse;
        for effect in [Effect::Media, Effect::Textures, Effect::NormalMaps] {
            let mut s = scene_file(&path, &small);
            assert!(!s.effects.has(effect));
            s.effects.force(effect).unwrap();
            let forced = run(&s).image();
            let m = prism::film::compare(&forced, &plain).unwrap().relmse;
            assert!(
                m < 0.01 * noise,
                "{name} with {effect:?} forced: {m} vs noise {noise}"
            );
        }
    }
}

/// `--vary target_error=none,...` makes a uniform curve and one adaptive curve over the
/// targets, whose rows carry the render's own estimate beside the true error (CSV, summary),
/// and whose true error falls as the target does.
#[test]
fn converge_sets_the_estimate_beside_the_true_error() {
    let d = tempfile::tempdir().unwrap();
    cornell_study(
        &[
            "--reference-spp",
            "1024",
            "--budget",
            "0.5",
            "--vary",
            "target_error=none,0.05,0.01",
        ],
        d.path(),
    );
    let csv = std::fs::read_to_string(d.path().join("converge.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("config,spp,seconds,rmse,relmse,ssim,relmse_trimmed,target_error,estimated_relmse")
    );
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let adaptive: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == "adaptive").collect();
    assert_eq!(adaptive.len(), 2, "{csv}");
    assert!(
        rows.iter().any(|r| r[0] == "uniform" && r[8].is_empty()),
        "{csv}"
    );
    let num = |r: &Vec<String>, i: usize| r[i].parse::<f64>().unwrap();
    for r in &adaptive {
        assert!(num(r, 8) <= num(r, 7), "estimate above its target: {csv}");
    }
    assert!(num(adaptive[1], 4) < num(adaptive[0], 4), "{csv}");
    let summary = std::fs::read_to_string(d.path().join("summary.md")).unwrap();
    assert!(
        summary.contains("## Estimated against true error"),
        "{summary}"
    );
}
