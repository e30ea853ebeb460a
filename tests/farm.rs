//! Frame shards and mergeable sample batches.

use assert_cmd::cargo::CommandCargoExt;
use std::path::{Path, PathBuf};
use std::process::Command;

const SCENE: &str = r#"Scene(
    render: (width: 32, height: 24, spp: 8, max_depth: 4, seed: 5),
    camera: (position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0), fov_y: 40.0),
    animation: (fps: 12, keyframes: [
        (frame: 0, position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0)),
        (frame: 9, position: (3.0, 2.0, 4.0), look_at: (0.0, 0.5, 0.0)),
    ]),
    environment: Constant(Rgb(0.4, 0.4, 0.4)),
    entities: [
        (name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5), material: Diffuse(albedo: Rgb(0.6, 0.2, 0.2))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (5.0, 0.0, 0.0), v: (0.0, 0.0, -5.0)), material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#;

fn prism() -> Command {
    Command::cargo_bin("prism").unwrap()
}

fn ok(c: &mut Command) -> String {
    let out = c.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stderr).to_string()
}

fn fails(c: &mut Command) -> String {
    let out = c.output().unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    e
}

fn setup() -> (tempfile::TempDir, PathBuf) {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("s.ron");
    std::fs::write(&scene, SCENE).unwrap();
    (d, scene)
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().to_string())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn shards_render_the_range_exactly_once() {
    let (d, scene) = setup();
    let s = scene.to_str().unwrap();
    let all = d.path().join("all");
    let sh = d.path().join("sharded");
    ok(prism()
        .args(["render", s, "--frames", "2..=8", "--quiet", "-o"])
        .arg(all.join("f_##.png")));
    for i in 0..3 {
        ok(prism()
            .args([
                "render",
                s,
                "--frames",
                "2..=8",
                "--quiet",
                "--shard",
                &format!("{i}/3"),
                "-o",
            ])
            .arg(sh.join("f_##.png")));
    }
    assert_eq!(names(&all), names(&sh));
    assert_eq!(names(&all).len(), 7);
    for n in names(&all) {
        assert_eq!(
            std::fs::read(all.join(&n)).unwrap(),
            std::fs::read(sh.join(&n)).unwrap(),
            "{n}"
        );
    }
    // The index may come from the scheduler's environment.
    let env = d.path().join("env");
    ok(prism()
        .args([
            "render",
            s,
            "--frames",
            "0..6",
            "--quiet",
            "--shard-from-env",
            "PRISM_TEST_INDEX",
            "--shard-count",
            "4",
            "-o",
        ])
        .arg(env.join("f_##.png"))
        .env("PRISM_TEST_INDEX", "1"));
    assert_eq!(names(&env), ["f_01.png", "f_05.png"]);
    let e = fails(
        prism()
            .args([
                "render",
                s,
                "--frames",
                "0..6",
                "--shard-from-env",
                "PRISM_TEST_INDEX",
                "--shard-count",
                "4",
                "-o",
            ])
            .arg(env.join("f_##.png"))
            .env("PRISM_TEST_INDEX", "7"),
    );
    assert!(e.contains("outside 0..4"), "{e}");
}

#[test]
fn a_rerun_shard_skips_finished_frames() {
    let (d, scene) = setup();
    let s = scene.to_str().unwrap();
    let out = d.path().join("o");
    let run = |extra: &[&str]| {
        ok(prism()
            .args(["render", s, "--frames", "0..8", "--shard", "1/2", "-o"])
            .arg(out.join("f_##.png"))
            .args(extra))
    };
    run(&["--quiet"]);
    let before = std::fs::read(out.join("f_03.png")).unwrap();
    std::fs::remove_file(out.join("f_05.png")).unwrap();
    let log = run(&["--resume"]);
    assert_eq!(log.matches("skipped").count(), 3, "{log}");
    assert_eq!(
        names(&out),
        ["f_01.png", "f_03.png", "f_05.png", "f_07.png"]
    );
    assert_eq!(std::fs::read(out.join("f_03.png")).unwrap(), before);
}

fn exr(scene: &str, spp: u32, offset: u32, out: &Path, extra: &[&str]) {
    ok(prism()
        .args([
            "render",
            scene,
            "--quiet",
            "--spp",
            &spp.to_string(),
            "--sample-offset",
            &offset.to_string(),
            "-o",
        ])
        .arg(out)
        .args(extra));
}

#[test]
fn merged_halves_equal_the_whole_render() {
    let (d, scene) = setup();
    let s = scene.to_str().unwrap();
    let p = |n: &str| d.path().join(n);
    exr(s, 8, 0, &p("a.exr"), &[]);
    exr(s, 4, 8, &p("b.exr"), &[]);
    exr(s, 4, 12, &p("c.exr"), &[]);
    exr(s, 16, 0, &p("whole.exr"), &[]);
    ok(prism()
        .args(["merge"])
        .args([p("c.exr"), p("a.exr"), p("b.exr")])
        .arg("-o")
        .arg(p("m.exr")));
    let (m, mm) = prism::film::read_image(&p("m.exr")).unwrap();
    let (w, wm) = prism::film::read_image(&p("whole.exr")).unwrap();
    let (mm, wm) = (mm.unwrap(), wm.unwrap());
    assert_eq!(
        (mm.spp, mm.sample_offset, mm.scene_hash),
        (wm.spp, wm.sample_offset, wm.scene_hash)
    );
    // Not bit for bit: each part stores its mean as f32, so the merge differs from the single
    // render by the rounding of those means (a few ulps), not by any sample.
    for (a, b) in m.pixels.iter().zip(&w.pixels) {
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() <= 4.0 * f32::EPSILON * b[c].abs().max(1e-3),
                "{} vs {}",
                a[c],
                b[c]
            );
        }
    }
}

#[test]
fn merge_refuses_parts_that_do_not_belong_together() {
    let (d, scene) = setup();
    let s = scene.to_str().unwrap();
    let p = |n: &str| d.path().join(n);
    exr(s, 4, 0, &p("a.exr"), &[]);
    exr(s, 4, 2, &p("overlap.exr"), &[]);
    exr(s, 4, 8, &p("gap.exr"), &[]);
    exr(s, 4, 4, &p("seed.exr"), &["--seed", "9"]);
    exr(s, 4, 4, &p("small.exr"), &["--size", "16x12"]);
    exr(s, 4, 4, &p("forced.exr"), &["--force", "lens"]);
    ok(prism()
        .args(["render", s, "--quiet", "--spp", "4", "-o"])
        .arg(p("a.png")));
    let merge = |x: &str, y: &str| {
        fails(
            prism()
                .arg("merge")
                .arg(p(x))
                .arg(p(y))
                .arg("-o")
                .arg(p("m.exr")),
        )
    };
    assert!(merge("a.exr", "overlap.exr").contains("overlap"));
    assert!(merge("a.exr", "gap.exr").contains("missing"));
    assert!(merge("a.exr", "seed.exr").contains("different scenes"));
    assert!(
        merge("a.exr", "small.exr").contains("different scenes")
            || merge("a.exr", "small.exr").contains("32x24")
    );
    assert!(merge("a.exr", "a.png").contains("header"));
    assert!(merge("a.exr", "forced.exr").contains("different --force settings"));
    // A part that claims no samples averaged to an all-NaN image.
    let (img, meta) = prism::film::read_image(&p("a.exr")).unwrap();
    let mut meta = meta.unwrap();
    (meta.spp, meta.sample_offset) = (0, 4);
    prism::film::write_image(&p("empty.exr"), &img, &meta, &Default::default()).unwrap();
    let err = merge("a.exr", "empty.exr");
    assert!(
        err.contains("empty.exr") && err.contains("no samples"),
        "{err}"
    );
    assert!(!p("m.exr").exists());
}

#[test]
fn parts_record_their_lane_width_and_merge_refuses_mixed_widths() {
    let (d, scene) = setup();
    let s = scene.to_str().unwrap();
    let p = |n: &str| d.path().join(n);
    exr(s, 4, 0, &p("w1.exr"), &["--simd", "1"]);
    exr(s, 4, 4, &p("auto.exr"), &["--simd", "auto"]);
    let width = |n: &str| prism::film::read_image(&p(n)).unwrap().1.unwrap().simd;
    let auto = prism::simd::Lanes::auto().width() as u32;
    assert_eq!(width("w1.exr"), Some(1));
    assert_eq!(width("auto.exr"), Some(auto));
    let merge = |x: &str, y: &str| {
        prism()
            .arg("merge")
            .arg(p(x))
            .arg(p(y))
            .arg("-o")
            .arg(p("m.exr"))
            .output()
            .unwrap()
    };
    if auto == 1 {
        println!("this CPU runs width 1 only: mixed widths not tested");
    } else {
        let out = merge("w1.exr", "auto.exr");
        assert!(!out.status.success());
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains("lane width") && e.contains("--simd"), "{e}");
    }
    exr(s, 4, 4, &p("w1b.exr"), &["--simd", "1"]);
    assert!(merge("w1.exr", "w1b.exr").status.success());
    assert_eq!(width("m.exr"), Some(1));
}

#[test]
fn a_width_the_cpu_lacks_or_does_not_know_is_refused_in_one_line() {
    let (d, scene) = setup();
    let s = scene.to_str().unwrap();
    let out = d.path().join("x.exr");
    let run = |args: &[&str]| {
        prism()
            .args(["render", s, "--quiet", "--spp", "1", "-o"])
            .arg(&out)
            .args(args)
            .output()
            .unwrap()
    };
    for (w, native) in [
        ("16", prism::simd::Lanes::native16()),
        ("8", prism::simd::Lanes::native8()),
    ] {
        let o = run(&["--simd", w]);
        if native.is_some() {
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        } else {
            let e = String::from_utf8_lossy(&o.stderr);
            assert!(!o.status.success());
            assert_eq!(e.trim_end().lines().count(), 1, "{e}");
            assert!(e.contains(&format!("--simd {w} needs")), "{e}");
        }
    }
    assert!(fails(prism().args(["render", s, "--simd", "4"])).contains("auto, 16, 8 or 1"));
    assert!(
        fails(prism().args(["render", s, "--set", "render.simd=4"])).contains("auto, 16, 8 or 1")
    );
    assert!(run(&["--set", "render.simd=auto"]).status.success());
    assert!(run(&["--set", "render.simd=1"]).status.success());
}

/// The ```yaml block of docs/farm.md.
fn kubernetes_job() -> String {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/farm.md"))
        .unwrap();
    let start = text
        .find("```yaml\n")
        .expect("docs/farm.md has a yaml block")
        + 8;
    let end = text[start..].find("```").unwrap();
    text[start..start + end].to_string()
}

#[test]
fn the_kubernetes_job_is_valid_yaml_whose_shards_cover_the_frames() {
    use yaml_rust2::YamlLoader;
    let docs = YamlLoader::load_from_str(&kubernetes_job()).expect("docs/farm.md's Job parses");
    assert_eq!(docs.len(), 1);
    let job = &docs[0];
    assert_eq!(job["apiVersion"].as_str(), Some("batch/v1"));
    assert_eq!(job["kind"].as_str(), Some("Job"));
    assert!(job["metadata"]["name"].as_str().is_some());
    let spec = &job["spec"];
    // JOB_COMPLETION_INDEX exists only in Indexed mode; it runs 0 .. completions - 1.
    assert_eq!(spec["completionMode"].as_str(), Some("Indexed"));
    let completions = spec["completions"].as_i64().expect("completions");
    assert!((1..=completions).contains(&spec["parallelism"].as_i64().expect("parallelism")));
    let pod = &spec["template"]["spec"];
    // Indexed Jobs allow only these two.
    assert!(
        matches!(pod["restartPolicy"].as_str(), Some("OnFailure" | "Never")),
        "{:?}",
        pod["restartPolicy"]
    );
    let container = &pod["containers"][0];
    let command: Vec<String> = container["command"]
        .as_vec()
        .expect("command is a list")
        .iter()
        .map(|v| v.as_str().expect("command words are strings").to_string())
        .collect();
    let after = |flag: &str| {
        let i = command
            .iter()
            .position(|w| w == flag)
            .unwrap_or_else(|| panic!("{flag}"));
        command[i + 1].clone()
    };
    assert_eq!(command[..2], ["prism", "render"]);
    assert_eq!(after("--shard-from-env"), "JOB_COMPLETION_INDEX");
    assert_eq!(after("--shard-count"), completions.to_string());
    assert!(command.iter().any(|w| w == "--resume"));
    // Frames go to a mounted volume that the pod declares.
    let output = after("-o");
    let mounts = container["volumeMounts"].as_vec().expect("volumeMounts");
    let mount = mounts
        .iter()
        .find(|m| output.starts_with(m["mountPath"].as_str().unwrap_or("\0")))
        .expect("the output lies on a mounted volume");
    let volumes = pod["volumes"].as_vec().expect("volumes");
    assert!(volumes.iter().any(|v| v["name"] == mount["name"]));

    // The same words run here: shard 0 of a small stand-in scene writes frames f ≡ 0 (mod N).
    let (d, scene) = setup();
    let out = d.path().join("out");
    let frames = after("--frames");
    let args: Vec<String> = command[1..]
        .iter()
        .map(|w| {
            if w.ends_with(".ron") {
                scene.to_str().unwrap().to_string()
            } else if w == &output {
                out.join(Path::new(w).file_name().unwrap())
                    .to_str()
                    .unwrap()
                    .to_string()
            } else if w == &frames {
                // The stand-in is ten frames long.
                "0..10".to_string()
            } else {
                w.clone()
            }
        })
        .collect();
    ok(prism().args(&args).env("JOB_COMPLETION_INDEX", "0"));
    let mut written: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    written.sort();
    let n = completions as usize;
    let want: Vec<String> = (0..10)
        .step_by(n)
        .map(|f| format!("flyby_{f:04}.png"))
        .collect();
    assert_eq!(written, want);
}
