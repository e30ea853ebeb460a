//! The README's Slurm jobs, run verbatim on a real one-node cluster.
//!
//! Runs when `SLURM_CONF` names a running cluster, as `scripts/slurm-local.sh` provides:
//! `scripts/slurm-local.sh cargo test --release --test slurm`. Elsewhere it prints one line and
//! passes, unless `PRISM_REQUIRE_SLURM` is set (CI sets it: there the test must run).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The ```sh block after `<!-- slurm:NAME -->` in the README.
fn readme_script(name: &str) -> String {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md"))
        .expect("README.md");
    let marker = format!("<!-- slurm:{name} -->");
    let at = readme
        .find(&marker)
        .unwrap_or_else(|| panic!("README has no {marker}"));
    let rest = &readme[at + marker.len()..];
    let start = rest.find("```sh\n").expect("a sh block after the marker") + 6;
    let end = rest[start..].find("```").expect("the block ends");
    rest[start..start + end].to_string()
}

fn cluster() -> bool {
    let up = std::env::var_os("SLURM_CONF").is_some()
        && Command::new("sinfo")
            .arg("-h")
            .output()
            .is_ok_and(|o| o.status.success());
    if !up {
        assert!(
            std::env::var_os("PRISM_REQUIRE_SLURM").is_none(),
            "PRISM_REQUIRE_SLURM is set but no Slurm cluster answers (SLURM_CONF unset or sinfo fails)"
        );
        println!("slurm: no cluster (run under scripts/slurm-local.sh): skipped");
    }
    up
}

/// A command in `dir` with the tested `prism` first on PATH (jobs inherit it).
fn in_dir(dir: &Path, program: &str) -> Command {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_prism"));
    let path = std::env::join_paths(std::iter::once(bin.parent().unwrap().to_path_buf()).chain(
        std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()),
    ))
    .unwrap();
    let mut c = Command::new(program);
    c.current_dir(dir).env("PATH", path);
    c
}

fn run(c: &mut Command) -> String {
    let out = c.output().unwrap();
    assert!(
        out.status.success(),
        "{c:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Waits until none of this user's jobs is pending or running.
fn wait_for_jobs(dir: &Path, limit: Duration) {
    let start = Instant::now();
    loop {
        let q = run(in_dir(dir, "squeue").args(["-h", "--me", "-o", "%i %T"]));
        if q.trim().is_empty() {
            return;
        }
        assert!(
            start.elapsed() < limit,
            "jobs still queued after {limit:?}:\n{q}"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

const FLYBY: &str = r#"Scene(
    render: (width: 24, height: 16, spp: 4, max_depth: 4, seed: 3),
    camera: (position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0), fov_y: 40.0),
    animation: (fps: 24, keyframes: [
        (frame: 0, position: (0.0, 1.0, 6.0), look_at: (0.0, 0.5, 0.0)),
        (frame: 47, position: (4.0, 2.0, 3.0), look_at: (0.0, 0.5, 0.0)),
    ]),
    environment: Constant(Rgb(0.4, 0.4, 0.4)),
    entities: [
        (name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5),
         material: Diffuse(albedo: Rgb(0.6, 0.2, 0.2))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (5.0, 0.0, 0.0), v: (0.0, 0.0, -5.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#;

#[test]
fn the_readme_slurm_jobs_run_on_a_real_cluster() {
    if !cluster() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::create_dir(dir.join("scenes")).unwrap();
    // Small stand-ins under the names the README's scripts use.
    std::fs::write(dir.join("scenes/flyby.ron"), FLYBY).unwrap();
    std::fs::write(
        dir.join("scenes/caustics.ron"),
        FLYBY.replace("width: 24, height: 16", "width: 16, height: 12"),
    )
    .unwrap();
    for name in ["frames.sh", "batches.sh", "submit.sh"] {
        std::fs::write(dir.join(name), readme_script(name)).unwrap();
    }
    let t0 = Instant::now();

    // Frame shards: every frame once, each equal to the single-machine render.
    run(in_dir(dir, "timeout").args([
        "600",
        "sbatch",
        "--wait",
        "-o",
        "frames-%a.log",
        "frames.sh",
    ]));
    let mut names: Vec<String> = std::fs::read_dir(dir.join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let want: Vec<String> = (0..48).map(|f| format!("flyby_{f:04}.png")).collect();
    assert_eq!(names, want, "the shards' frames (and nothing else)");
    for k in 0..4 {
        let log = std::fs::read_to_string(dir.join(format!("frames-{k}.log"))).unwrap();
        assert!(log.trim().is_empty(), "task {k} printed: {log}");
    }
    run(in_dir(dir, "prism").args([
        "render",
        "scenes/flyby.ron",
        "--frames",
        "0..48",
        "-o",
        "single/flyby_####.png",
        "--quiet",
    ]));
    for n in &want {
        let a = std::fs::read(dir.join("out").join(n)).unwrap();
        let b = std::fs::read(dir.join("single").join(n)).unwrap();
        assert!(a == b, "{n} differs from the single-machine render");
    }

    // Sample batches, merged by a job that depends on both.
    run(in_dir(dir, "bash").arg("submit.sh"));
    wait_for_jobs(dir, Duration::from_secs(600));
    run(in_dir(dir, "prism").args([
        "render",
        "scenes/caustics.ron",
        "--spp",
        "512",
        "-o",
        "whole.exr",
        "--quiet",
    ]));
    let (m, mm) =
        prism::film::read_image(&dir.join("full.exr")).expect("the merge job wrote full.exr");
    let (w, wm) = prism::film::read_image(&dir.join("whole.exr")).unwrap();
    let (mm, wm) = (mm.unwrap(), wm.unwrap());
    assert_eq!((mm.spp, mm.scene_hash), (wm.spp, wm.scene_hash));
    // The README's bound: a few ulps from the f32 means of the parts.
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
    // No temporary file of any write is left behind.
    for sub in [dir.to_path_buf(), dir.join("out")] {
        assert_no_temporaries(&sub);
    }
    let t1 = t0.elapsed().as_secs_f64();
    cancelled_task_resumes(&dir.join("cancel"));
    println!(
        "slurm: frames and batches jobs done in {t1:.1} s; cancel and resume in {:.1} s",
        t0.elapsed().as_secs_f64() - t1
    );
}

fn assert_no_temporaries(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let n = e.unwrap().file_name().into_string().unwrap();
        assert!(!n.starts_with('.'), "stray temporary file {n} in {dir:?}");
    }
}

/// The README's frame job with slower frames: array task 1 is cancelled (`scancel`, which
/// sends SIGTERM) after its first frame, then the job is submitted again, as is, and its
/// `--resume` finishes the series: every frame of the cancelled shard equals a single-machine
/// render of that shard, and no temporary file is left.
fn cancelled_task_resumes(dir: &Path) {
    std::fs::create_dir_all(dir.join("scenes")).unwrap();
    std::fs::write(
        dir.join("scenes/flyby.ron"),
        FLYBY.replace("spp: 4,", "spp: 2048,"),
    )
    .unwrap();
    std::fs::write(dir.join("frames.sh"), readme_script("frames.sh")).unwrap();
    let job = run(in_dir(dir, "sbatch").args(["--parsable", "-o", "cancel-%a.log", "frames.sh"]));
    let job = job.trim().split(';').next().unwrap().to_string();
    // Shard 1 renders frames 1, 5, 9, …: cancel it once its first frame is on disk.
    let start = Instant::now();
    while !dir.join("out/flyby_0001.png").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "task 1 never wrote its first frame"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    run(in_dir(dir, "scancel").arg(format!("{job}_1")));
    wait_for_jobs(dir, Duration::from_secs(600));
    let shard1: Vec<String> = (1..48)
        .step_by(4)
        .map(|f| format!("flyby_{f:04}.png"))
        .collect();
    let done = shard1
        .iter()
        .filter(|n| dir.join("out").join(n).exists())
        .count();
    assert!(
        done < shard1.len(),
        "task 1 finished before the cancel reached it"
    );
    let log = std::fs::read_to_string(dir.join("cancel-1.log")).unwrap_or_default();
    assert!(
        log.contains("interrupted by SIGTERM") || log.contains("CANCELLED"),
        "task 1's log: {log}"
    );
    // Submitted again as is: --resume renders what is missing.
    run(in_dir(dir, "timeout").args([
        "600",
        "sbatch",
        "--wait",
        "-o",
        "resume-%a.log",
        "frames.sh",
    ]));
    run(in_dir(dir, "prism").args([
        "render",
        "scenes/flyby.ron",
        "--frames",
        "0..48",
        "--shard",
        "1/4",
        "-o",
        "single/flyby_####.png",
        "--quiet",
    ]));
    for n in &shard1 {
        let a = std::fs::read(dir.join("out").join(n)).unwrap();
        let b = std::fs::read(dir.join("single").join(n)).unwrap();
        assert!(a == b, "{n} differs from the single-machine render");
    }
    let all = std::fs::read_dir(dir.join("out")).unwrap().count();
    assert_eq!(all, 48, "every frame once, nothing else");
    assert_no_temporaries(&dir.join("out"));
}
