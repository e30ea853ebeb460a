//! Frame series: resume after a kill, and frame N the same alone or in a range.

use assert_cmd::cargo::CommandCargoExt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

const SCENE: &str = r#"Scene(
    render: (width: 64, height: 64, spp: 64, max_depth: 4, seed: 3),
    camera: (position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0), fov_y: 40.0, shutter: (open: 0.0, close: 0.5)),
    animation: (fps: 12, keyframes: [
        (frame: 0, position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0)),
        (frame: 5, position: (3.0, 2.0, 4.0), look_at: (0.0, 0.5, 0.0), fov_y: 30.0),
    ]),
    environment: Constant(Rgb(0.3, 0.3, 0.3)),
    entities: [
        (name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5),
         material: Diffuse(albedo: Rgb(0.6, 0.2, 0.2)), motion: (velocity: (0.2, 0.0, 0.0))),
        (name: "lamp", shape: Rect(center: (0.0, 3.0, 0.0), u: (0.5, 0.0, 0.0), v: (0.0, 0.0, -0.5)),
         material: Light(emission: Rgb(8.0, 8.0, 8.0))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (5.0, 0.0, 0.0), v: (0.0, 0.0, -5.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#;

fn prism() -> Command {
    Command::cargo_bin("prism").unwrap()
}

fn render(scene: &Path, range: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut c = prism();
    c.args(["render", scene.to_str().unwrap(), "--frames", range, "-o"])
        .arg(out.join("f_###.png"))
        .arg("--quiet")
        .args(extra);
    c.output().unwrap()
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

#[test]
fn killed_series_resumes_to_the_same_files() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("anim.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let (whole, resumed, alone) = (
        d.path().join("whole"),
        d.path().join("resumed"),
        d.path().join("alone"),
    );
    assert!(
        render(
            &scene,
            "0..6",
            &whole,
            &["--gif", d.path().join("whole.gif").to_str().unwrap()]
        )
        .status
        .success()
    );
    assert_eq!(files(&whole).len(), 6);
    assert!(d.path().join("whole.gif").is_file());

    // Start the same series on one thread and kill it once two frames are on disk.
    let mut child = prism()
        .args([
            "render",
            scene.to_str().unwrap(),
            "--frames",
            "0..6",
            "--threads",
            "1",
            "--quiet",
            "-o",
        ])
        .arg(resumed.join("f_###.png"))
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !resumed.join("f_001.png").exists() && t0.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    let _ = child.kill();
    let _ = child.wait();
    // Whatever is on disk under a final name is a complete image.
    for f in files(&resumed) {
        if f.extension().is_some_and(|e| e == "png")
            && !f.file_name().unwrap().to_string_lossy().starts_with('.')
        {
            prism::film::read_image(&f).expect("a frame on disk is complete");
        }
    }
    assert!(
        render(&scene, "0..6", &resumed, &["--resume"])
            .status
            .success()
    );
    let pngs = |dir: &Path| -> Vec<PathBuf> {
        files(dir)
            .into_iter()
            .filter(|f| !f.file_name().unwrap().to_string_lossy().starts_with('.'))
            .collect()
    };
    // The killed process's temporary file, if it was writing, was swept by the resumed run.
    for f in files(&resumed) {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        assert!(!name.starts_with('.'), "temporary file left: {name}");
    }
    let (a, b) = (pngs(&whole), pngs(&resumed));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(
            std::fs::read(x).unwrap(),
            std::fs::read(y).unwrap(),
            "{}",
            y.display()
        );
    }

    // Frame 3 rendered alone equals frame 3 of the range.
    assert!(render(&scene, "3..=3", &alone, &[]).status.success());
    assert_eq!(
        std::fs::read(alone.join("f_003.png")).unwrap(),
        std::fs::read(whole.join("f_003.png")).unwrap()
    );
}

#[test]
fn frame_output_needs_a_number_pattern() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("anim.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let out = prism()
        .args([
            "render",
            scene.to_str().unwrap(),
            "--frames",
            "0..2",
            "-o",
            "x.png",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("'#'"));
}
