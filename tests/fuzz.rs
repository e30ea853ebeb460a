//! A seeded fuzz harness over what prism reads: the shipped scenes, meshes (OBJ, PLY) and
//! image headers (PNG, EXR, HDR, JPEG), mutated byte by byte and token by token.
//!
//! In process, each case calls the loader (and, for a scene that loads, a 4×4 one-sample
//! render) under a counting allocator and a watchdog: a panic, a case that allocates more
//! than [`BUDGET`] bytes, a case that runs longer than [`HANG`] or an error message of more
//! than one line fails the test. Through the binary, each case must exit 0 or 1 with at most
//! one line on stderr (no abort, no panic, no signal).
//!
//! `PRISM_FUZZ_CASES=N` (in-process cases, default 10,000; binary cases are a thirtieth, at
//! least 300) and `PRISM_FUZZ_SEED=S` run a longer or different campaign locally:
//! `PRISM_FUZZ_CASES=1000000 cargo test --release --test fuzz -- --nocapture`.

use prism::film;
use prism::geometry::mesh_io;
use prism::integrator::{RenderOptions, render};
use prism::kdtree::KdParams;
use prism::scene_file::load_str;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};
use std::alloc::System;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// The most bytes one in-process case may allocate in all.
const BUDGET: usize = 1 << 30;
/// The longest one case may run.
const HANG: Duration = Duration::from_secs(30);

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Number tokens that reach the edges of every type a scene or file uses.
const EXTREMES: &[&str] = &[
    "0",
    "-0.0",
    "-1",
    "1e39",
    "-1e39",
    "1e-45",
    "NaN",
    "inf",
    "-inf",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "2147483648",
    "65536",
    "65537",
    "1025",
    "3.4028235e38",
    "0.5",
    "1000000000",
];

/// Tokens inserted into scene text.
const TOKENS: &[&str] = &[
    "(",
    ")",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "Some(",
    "None",
    "-",
    "//",
    "/*",
    "r#\"",
    "\u{0}",
    "\u{1b}[2J",
    "é",
    "🦀",
    "#![enable(implicit_some)]",
    "Mesh(path: \"x.ply\")",
    "Revolution(profile: [])",
    "Rgb(",
    "Blackbody(kelvin: 1e9, scale: 1.0)",
    "transform: (scale: 0.0)",
    "entities: []",
    "max_depth: 1024",
    "motion: (velocity: (1e30, 0.0, 0.0))",
    "name: \"",
    "material: Light(",
    "medium: (sigma_a: Rgb(1e30, 0.0, 0.0), sigma_s: Rgb(0.0, 0.0, 0.0), g: 0.99)",
];

/// `seed` changed by one or two mutations (text) or up to four (binary): numbers replaced by
/// extremes, tokens inserted, bytes changed, ranges deleted or duplicated, a truncation.
fn mutate(seed: &[u8], rng: &mut Pcg64, text: bool) -> Vec<u8> {
    let mut v = seed.to_vec();
    for _ in 0..rng.random_range(1..=if text { 2 } else { 4 }) {
        if v.is_empty() {
            v.push(b'(');
        }
        let at = rng.random_range(0..v.len());
        // Numbers made extreme most often: they reach the checks behind the parser.
        let op = match rng.random_range(0..20) {
            0..=7 => 3,
            8..=10 => 4,
            11..=13 => 0,
            14..=15 => 1,
            16..=18 => 2,
            _ => 5,
        };
        match op {
            0 => {
                v[at] = if text {
                    rng.random_range(32..127)
                } else {
                    rng.random()
                }
            }
            1 => {
                let end = (at + rng.random_range(1..40)).min(v.len());
                v.drain(at..end);
            }
            2 => {
                let end = (at + rng.random_range(1..200)).min(v.len());
                let chunk = v[at..end].to_vec();
                let to = rng.random_range(0..=v.len());
                v.splice(to..to, chunk);
            }
            3 => {
                // The number (or word) around `at`, replaced by an extreme.
                let is_num = |c: u8| c.is_ascii_alphanumeric() || c == b'.' || c == b'-';
                let (mut s, mut e) = (at, at);
                while s > 0 && is_num(v[s - 1]) {
                    s -= 1;
                }
                while e < v.len() && is_num(v[e]) {
                    e += 1;
                }
                let x = EXTREMES[rng.random_range(0..EXTREMES.len())];
                v.splice(s..e, x.bytes());
            }
            4 => {
                let t = TOKENS[rng.random_range(0..TOKENS.len())];
                v.splice(at..at, t.bytes());
            }
            _ => {
                let n = rng.random_range(0..v.len().max(1));
                v.truncate(n);
            }
        }
    }
    v
}

/// A header field of a binary image, overwritten with an extreme 32-bit value.
fn mutate_header(seed: &[u8], rng: &mut Pcg64) -> Vec<u8> {
    let mut v = seed.to_vec();
    let end = v.len().min(96);
    if end >= 4 {
        let at = rng.random_range(0..end - 3);
        let x: u32 =
            [0, 1, 0xffff_ffff, 0x7fff_ffff, 65_536, 200_000, 0x8000_0000][rng.random_range(0..7)];
        let bytes = if rng.random() {
            x.to_le_bytes()
        } else {
            x.to_be_bytes()
        };
        v[at..at + 4].copy_from_slice(&bytes);
    }
    if rng.random_range(0..3) == 0 {
        mutate(&v, rng, false)
    } else {
        v
    }
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scene_seeds() -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(repo().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

const PLY_ASCII: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
property float z\nproperty float u\nproperty float v\nelement face 2\n\
property list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n\
3 0 1 2\n3 0 2 3\n";

fn ply_binary() -> Vec<u8> {
    let mut v = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\n\
end_header\n"
        .to_vec();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            v.extend(c.to_le_bytes());
        }
    }
    v.push(3);
    for i in [0u32, 1, 2] {
        v.extend(i.to_le_bytes());
    }
    v
}

fn mesh_seeds() -> Vec<(&'static str, Vec<u8>)> {
    let bunny = std::fs::read(repo().join("assets/bunny.obj")).unwrap();
    let cut = bunny[..4000.min(bunny.len())]
        .iter()
        .rposition(|&b| b == b'\n')
        .unwrap_or(0);
    vec![
        (
            "obj",
            std::fs::read(repo().join("assets/prism.obj")).unwrap(),
        ),
        ("obj", bunny[..cut].to_vec()),
        ("ply", PLY_ASCII.as_bytes().to_vec()),
        ("ply", ply_binary()),
    ]
}

fn image_seeds(dir: &Path) -> Vec<(&'static str, Vec<u8>)> {
    let img = film::Image {
        width: 5,
        height: 3,
        pixels: (0..15).map(|i| [i as f32 * 0.1, 0.5, 2.0]).collect(),
    };
    let meta = film::ImageMeta {
        spp: 4,
        sample_offset: 0,
        scene_hash: 7,
        simd: Some(8),
        complete: true,
        settings: None,
    };
    let mut out = Vec::new();
    for ext in ["png", "exr"] {
        let p = dir.join(format!("seed.{ext}"));
        film::write_image(&p, &img, &meta, &film::PngOptions::default()).unwrap();
        out.push((ext, std::fs::read(&p).unwrap()));
    }
    let rgb = image::Rgb32FImage::from_pixel(5, 3, image::Rgb([0.5, 1.5, 0.25]));
    let p = dir.join("seed.hdr");
    rgb.save(&p).unwrap();
    out.push(("hdr", std::fs::read(&p).unwrap()));
    let p = dir.join("seed.jpg");
    image::RgbImage::from_pixel(9, 7, image::Rgb([200, 30, 90]))
        .save(&p)
        .unwrap();
    out.push(("jpg", std::fs::read(&p).unwrap()));
    out
}

/// Small stand-ins for the assets the shipped scenes name (`../assets/…` from `scenes/`), so
/// that mutated scenes load and render quickly: a few hundred triangles of the bunny, the
/// prism, a 16×8 earth.
fn stand_in_assets(root: &Path) {
    let assets = root.join("assets");
    std::fs::create_dir_all(&assets).unwrap();
    for (ext, bytes) in mesh_seeds().into_iter().take(2) {
        let name = if bytes.len() > 1000 { "bunny" } else { "prism" };
        std::fs::write(assets.join(format!("{name}.{ext}")), bytes).unwrap();
    }
    image::RgbImage::from_fn(16, 8, |x, y| {
        image::Rgb([(x * 16) as u8, (y * 32) as u8, 90])
    })
    .save(assets.join("earth.jpg"))
    .unwrap();
}

/// The case in flight and when it started, for the watchdog.
static CASE: AtomicU64 = AtomicU64::new(0);
static STARTED_MS: AtomicU64 = AtomicU64::new(0);

fn now_ms(t0: Instant) -> u64 {
    t0.elapsed().as_millis() as u64
}

/// Ends the process if one case runs longer than [`HANG`].
fn watchdog(t0: Instant) {
    std::thread::spawn(move || {
        loop {
            std::thread::sleep(Duration::from_millis(500));
            let started = STARTED_MS.load(Ordering::SeqCst);
            if started > 0 && now_ms(t0).saturating_sub(started) > HANG.as_millis() as u64 {
                eprintln!(
                    "fuzz: case {} ran longer than {HANG:?} (a hang)",
                    CASE.load(Ordering::SeqCst)
                );
                std::process::exit(3);
            }
        }
    });
}

fn one_line(what: &str, case: u64, msg: &str) {
    assert!(
        !msg.is_empty() && !msg.contains('\n'),
        "case {case} ({what}): the error is not one line: {msg:?}"
    );
}

#[test]
fn mutated_inputs_never_panic_hang_or_overallocate() {
    let cases = env_u64("PRISM_FUZZ_CASES", 10_000);
    let seed = env_u64("PRISM_FUZZ_SEED", 0x5eed);
    let dir = tempfile::tempdir().unwrap();
    let scenes = scene_seeds();
    let meshes = mesh_seeds();
    let images = image_seeds(dir.path());
    let scene_path = dir.path().join("scenes/case.ron");
    std::fs::create_dir_all(scene_path.parent().unwrap()).unwrap();
    stand_in_assets(dir.path());
    let t0 = Instant::now();
    watchdog(t0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let tiny = [
        ("render.width".to_string(), "4".to_string()),
        ("render.height".to_string(), "4".to_string()),
        ("render.spp".to_string(), "1".to_string()),
    ];
    let (mut loaded, mut rendered, mut refused, mut max_bytes) = (0u64, 0u64, 0u64, 0usize);
    for case in 0..cases {
        let mut rng = Pcg64::seed_from_u64(seed ^ case.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        CASE.store(case, Ordering::SeqCst);
        STARTED_MS.store(now_ms(t0).max(1), Ordering::SeqCst);
        let region = Region::new(GLOBAL);
        let kind = case % 10;
        if kind < 6 {
            let (name, text) = &scenes[rng.random_range(0..scenes.len())];
            let bytes = mutate(text, &mut rng, true);
            let text = String::from_utf8_lossy(&bytes);
            match load_str(&text, &scene_path, &tiny) {
                Ok(scene) => {
                    loaded += 1;
                    let rs = prism::systems::prepare(&scene, &KdParams::default());
                    let opts = RenderOptions::new(1, prism::simd::Lanes::auto());
                    let out = pool.install(|| render(&rs, &opts, &|_| {}));
                    assert!(out.image().pixels.len() == 16, "case {case} ({name})");
                    rendered += 1;
                }
                Err(e) => {
                    refused += 1;
                    one_line(name, case, &e.to_string());
                }
            }
        } else if kind < 8 {
            let (ext, seed_bytes) = &meshes[rng.random_range(0..meshes.len())];
            let text = *ext == "obj" || rng.random();
            let bytes = mutate(seed_bytes, &mut rng, text);
            let p = dir.path().join(format!("case.{ext}"));
            std::fs::write(&p, &bytes).unwrap();
            match mesh_io::load_mesh(&p) {
                Ok(_) => loaded += 1,
                Err(e) => {
                    refused += 1;
                    one_line(ext, case, &e.to_string());
                }
            }
        } else {
            let (ext, seed_bytes) = &images[rng.random_range(0..images.len())];
            let bytes = mutate_header(seed_bytes, &mut rng);
            let p = dir.path().join(format!("case.{ext}"));
            std::fs::write(&p, &bytes).unwrap();
            match film::read_image(&p) {
                Ok(_) => loaded += 1,
                Err(e) => {
                    refused += 1;
                    one_line(ext, case, &e.to_string());
                }
            }
        }
        let s = region.change();
        let bytes = s.bytes_allocated + s.bytes_reallocated.max(0) as usize;
        max_bytes = max_bytes.max(bytes);
        assert!(
            bytes <= BUDGET,
            "case {case} allocated {bytes} bytes, more than the {BUDGET} budget"
        );
    }
    STARTED_MS.store(0, Ordering::SeqCst);
    println!(
        "fuzz: {cases} cases in process in {:.1} s: {loaded} loaded ({rendered} scenes rendered), \
         {refused} refused with a one-line error, 0 panics, 0 hangs; the most any case allocated: \
         {:.1} MiB",
        t0.elapsed().as_secs_f64(),
        max_bytes as f64 / (1 << 20) as f64
    );
}

#[test]
fn mutated_inputs_through_the_binary_exit_cleanly() {
    let cases = (env_u64("PRISM_FUZZ_CASES", 10_000) / 30).max(300);
    let seed = env_u64("PRISM_FUZZ_SEED", 0x5eed) ^ 0xb1;
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    std::fs::create_dir_all(root.join("scenes")).unwrap();
    stand_in_assets(root);
    let scenes = scene_seeds();
    let meshes = mesh_seeds();
    let images = image_seeds(root);
    let bin = env!("CARGO_BIN_EXE_prism");
    let t0 = Instant::now();
    let mut outcomes = [0u64; 2];
    for case in 0..cases {
        let mut rng = Pcg64::seed_from_u64(seed ^ case.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let mut cmd = std::process::Command::new(bin);
        let what;
        match case % 6 {
            0..=3 => {
                let (name, text) = &scenes[rng.random_range(0..scenes.len())];
                what = name.clone();
                std::fs::write(root.join("scenes/case.ron"), mutate(text, &mut rng, true)).unwrap();
                cmd.args(["render", "scenes/case.ron", "--size", "4x4", "--spp", "1"]);
            }
            4 => {
                let (ext, seed_bytes) = &meshes[rng.random_range(0..meshes.len())];
                what = format!("mesh .{ext}");
                std::fs::write(
                    root.join(format!("scenes/m.{ext}")),
                    mutate(seed_bytes, &mut rng, false),
                )
                .unwrap();
                std::fs::write(
                    root.join("scenes/case.ron"),
                    format!(
                        "Scene(render: (width: 4, height: 4, spp: 1), camera: (position: (0.0, 0.5, 3.0), \
                         look_at: (0.0, 0.5, 0.0)), environment: Constant(Rgb(1.0, 1.0, 1.0)), entities: \
                         [(name: \"m\", shape: Mesh(path: \"m.{ext}\"), material: Diffuse(albedo: \
                         Rgb(0.5, 0.5, 0.5)))])"
                    ),
                )
                .unwrap();
                cmd.args(["render", "scenes/case.ron"]);
            }
            _ => {
                let (ext, seed_bytes) = &images[rng.random_range(0..images.len())];
                what = format!("image .{ext}");
                std::fs::write(
                    root.join(format!("a.{ext}")),
                    mutate_header(seed_bytes, &mut rng),
                )
                .unwrap();
                std::fs::write(root.join(format!("b.{ext}")), seed_bytes).unwrap();
                cmd.args(["compare", &format!("a.{ext}"), &format!("b.{ext}")]);
            }
        }
        let mut child = cmd
            .args(if case % 6 == 5 {
                &[][..]
            } else {
                &["--quiet", "-o", "out.png"][..]
            })
            .current_dir(root)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let started = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if started.elapsed() > HANG {
                let _ = child.kill();
                panic!("case {case} ({what}): prism ran longer than {HANG:?}");
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        let code = out.status.code();
        assert!(
            matches!(code, Some(0 | 1)),
            "case {case} ({what}): exit {:?} (a signal, an abort or a panic): {err}",
            out.status
        );
        assert!(
            err.lines().count() <= 1 && !err.contains("internal error"),
            "case {case} ({what}): {err}"
        );
        if code == Some(1) {
            assert!(err.starts_with("error: "), "case {case} ({what}): {err}");
        }
        outcomes[code.unwrap_or(1) as usize] += 1;
    }
    println!(
        "fuzz: {cases} cases through the binary in {:.1} s: {} exit 0, {} exit 1 with one line",
        t0.elapsed().as_secs_f64(),
        outcomes[0],
        outcomes[1]
    );
}
