//! Signals and `--resume`: SIGINT or SIGTERM during a still writes it with its true sample
//! count, marked incomplete; during a series the frame in flight is dropped; `--resume` keeps
//! only frames that are complete renders of the same request, and says why it redoes the rest.
#![cfg(unix)]

use assert_cmd::cargo::CommandCargoExt;
use prism::film::{self, ImageMeta, PngOptions};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output};
use std::time::{Duration, Instant};

const STILL: &str = r#"Scene(
    render: (width: 32, height: 32, spp: 1000000, max_depth: 4, seed: 3),
    camera: (position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0), fov_y: 40.0),
    environment: Constant(Rgb(0.3, 0.3, 0.3)),
    entities: [
        (name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5),
         material: Diffuse(albedo: Rgb(0.6, 0.2, 0.2))),
        (name: "lamp", shape: Rect(center: (0.0, 3.0, 0.0), u: (0.5, 0.0, 0.0), v: (0.0, 0.0, -0.5)),
         material: Light(emission: Rgb(8.0, 8.0, 8.0))),
    ],
)"#;

const SERIES: &str = r#"Scene(
    render: (width: 64, height: 64, spp: 64, max_depth: 4, seed: 3),
    camera: (position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0), fov_y: 40.0),
    animation: (fps: 12, keyframes: [
        (frame: 0, position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0)),
        (frame: 5, position: (3.0, 2.0, 4.0), look_at: (0.0, 0.5, 0.0), fov_y: 30.0),
    ]),
    environment: Constant(Rgb(0.3, 0.3, 0.3)),
    entities: [
        (name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5),
         material: Diffuse(albedo: Rgb(0.6, 0.2, 0.2))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (5.0, 0.0, 0.0), v: (0.0, 0.0, -5.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#;

fn prism() -> Command {
    Command::cargo_bin("prism").unwrap()
}

fn signal(child: &Child, name: &str) {
    let ok = Command::new("kill")
        .args([format!("-{name}"), child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok, "kill -{name} failed");
}

/// The child's output once it exits, or a failure after `limit`.
fn finish(mut child: Child, limit: Duration) -> Output {
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > limit {
            let _ = child.kill();
            panic!("prism did not stop within {limit:?} of the signal");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A still of [`STILL`] to `out`, stopped by `sig` after a second: the image is on disk under
/// its name, readable, finite, marked incomplete with a sample count of whole passes, and no
/// temporary file is left.
fn still_stopped_by(sig: &str, out_name: &str, status: i32) -> ImageMeta {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("still.ron");
    std::fs::write(&scene, STILL).unwrap();
    let out_dir = d.path().join("out");
    let out = out_dir.join(out_name);
    let child = prism()
        .args(["render", scene.to_str().unwrap(), "--quiet", "-o"])
        .arg(&out)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, sig);
    let o = finish(child, Duration::from_secs(60));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(status), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("interrupted by") && err.contains("of 1000000 samples per pixel"),
        "{err}"
    );
    assert_eq!(names(&out_dir), [out_name]);
    let h = film::read_header(&out).unwrap();
    let meta = h.meta.expect("provenance");
    assert!(!meta.complete);
    assert!(meta.spp >= 1 && meta.spp < 1_000_000);
    // Whole passes: 16, then 128, 256, … samples per pixel.
    assert!(
        meta.spp == 16 || meta.spp.is_multiple_of(128),
        "spp {}",
        meta.spp
    );
    assert!(err.contains(&format!("with {} of", meta.spp)), "{err}");
    let (img, _) = film::read_image(&out).unwrap();
    assert!(img.pixels.iter().flatten().all(|v| v.is_finite()));
    assert!(img.pixels.iter().flatten().any(|&v| v > 0.0));
    meta
}

#[test]
fn sigint_during_a_still_writes_it_with_its_true_sample_count() {
    still_stopped_by("INT", "still.png", 130);
}

#[test]
fn sigterm_during_a_still_writes_an_exr_marked_incomplete() {
    let m = still_stopped_by("TERM", "still.exr", 143);
    assert_eq!(m.sample_offset, 0);
}

fn series(scene: &Path, range: &str, out: &Path, extra: &[&str]) -> Output {
    prism()
        .args(["render", scene.to_str().unwrap(), "--frames", range, "-o"])
        .arg(out.join("f_###.png"))
        .arg("--quiet")
        .args(extra)
        .output()
        .unwrap()
}

fn frames_in(dir: &Path) -> Vec<PathBuf> {
    names(dir).into_iter().map(|n| dir.join(n)).collect()
}

#[test]
fn sigint_during_a_series_keeps_whole_frames_and_resume_finishes_it() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("anim.ron");
    std::fs::write(&scene, SERIES).unwrap();
    let (whole, stopped) = (d.path().join("whole"), d.path().join("stopped"));
    assert!(series(&scene, "0..6", &whole, &[]).status.success());

    let child = prism()
        .args(["render", scene.to_str().unwrap(), "--frames", "0..6"])
        .args(["--threads", "1", "--quiet", "-o"])
        .arg(stopped.join("f_###.png"))
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !stopped.join("f_001.png").exists() && t0.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    signal(&child, "INT");
    let o = finish(child, Duration::from_secs(60));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("--resume"), "{err}");
    // Every file under a final name is a complete frame; nothing else is left.
    let left = frames_in(&stopped);
    assert!(left.len() >= 2 && left.len() < 6, "{left:?}");
    for f in &left {
        let name = f.file_name().unwrap().to_string_lossy();
        assert!(!name.starts_with('.'), "temporary file left: {name}");
        assert!(film::read_header(f).unwrap().meta.unwrap().complete);
    }
    let o = series(&scene, "0..6", &stopped, &["--resume"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (a, b) = (frames_in(&whole), frames_in(&stopped));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(
            std::fs::read(x).unwrap(),
            std::fs::read(y).unwrap(),
            "{y:?}"
        );
    }
}

#[test]
fn resume_redoes_incomplete_and_mismatched_frames_and_says_which() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("anim.ron");
    std::fs::write(&scene, SERIES).unwrap();
    let (whole, mixed) = (d.path().join("whole"), d.path().join("mixed"));
    assert!(series(&scene, "0..5", &whole, &[]).status.success());
    std::fs::create_dir_all(&mixed).unwrap();
    for f in frames_in(&whole) {
        std::fs::copy(&f, mixed.join(f.file_name().unwrap())).unwrap();
    }
    // Frame 1: the same pixels, but marked incomplete.
    let f1 = mixed.join("f_001.png");
    let h = film::read_header(&f1).unwrap();
    let (img, _) = film::read_image(&f1).unwrap();
    let meta = ImageMeta {
        complete: false,
        ..h.meta.unwrap()
    };
    film::write_image(&f1, &img, &meta, &PngOptions::default()).unwrap();
    // Frame 2 with fewer samples, frame 3 at another exposure, frame 4 from another scene
    // text (a --set), frame 0 from a file without provenance.
    assert!(
        series(&scene, "2", &mixed, &["--spp", "16"])
            .status
            .success()
    );
    assert!(
        series(&scene, "3", &mixed, &["--exposure", "1"])
            .status
            .success()
    );
    assert!(
        series(&scene, "4", &mixed, &["--set", "render.max_depth=3"])
            .status
            .success()
    );
    image::RgbImage::new(64, 64)
        .save(mixed.join("f_000.png"))
        .unwrap();

    let o = series(&scene, "0..5", &mixed, &["--resume"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let expect = [
        ("frame 0 (1/5): re-rendering", "no prism provenance"),
        ("frame 1 (2/5): re-rendering", "incomplete"),
        ("frame 2 (3/5): re-rendering", "it has 16 spp, not 64"),
        ("frame 3 (4/5): re-rendering", "--exposure"),
        ("frame 4 (5/5): re-rendering", "another scene text"),
    ];
    for (head, why) in expect {
        assert!(
            err.lines().any(|l| l.starts_with(head) && l.contains(why)),
            "{head} … {why}:\n{err}"
        );
    }
    assert_eq!(err.lines().count(), 5, "{err}");
    for (x, y) in frames_in(&whole).iter().zip(&frames_in(&mixed)) {
        assert_eq!(
            std::fs::read(x).unwrap(),
            std::fs::read(y).unwrap(),
            "{y:?}"
        );
    }
    // A second resume keeps everything.
    let o = series(&scene, "0..5", &mixed, &["--resume"]);
    assert!(o.status.success() && o.stderr.is_empty());
}
