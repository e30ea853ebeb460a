//! The environment map: furnace and hemisphere radiance in closed form, the orientation
//! convention, and the sampling density against its samples.

mod common;
#[allow(dead_code)]
#[path = "common/splitmix.rs"]
mod splitmix;

use common::chi2::Chi2;
use common::render::{mean_where, run};
use glam::{Vec2, Vec3};
use prism::film::{Image, ImageMeta};
use prism::scene::envmap::{EnvMap, local_of_uv, uv_of_local};
use std::path::{Path, PathBuf};

/// Writes `w × h` texels `f(x, y)` as an EXR in `dir`, and returns its file name.
fn write_map(dir: &Path, name: &str, w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 3]) {
    let pixels = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| f(x, y))
        .collect();
    let img = Image {
        width: w,
        height: h,
        pixels,
    };
    let meta = ImageMeta {
        spp: 1,
        sample_offset: 0,
        scene_hash: 0,
        simd: None,
        complete: true,
        settings: None,
    };
    prism::film::write_image(&dir.join(name), &img, &meta, &Default::default()).unwrap();
}

/// Writes `text` as a scene beside the maps in `dir` and prepares it.
fn scene_in(dir: &Path, text: &str, spectral: bool) -> prism::scene::RenderScene {
    let path: PathBuf = dir.join("scene.ron");
    std::fs::write(&path, text).unwrap();
    let mut s = common::render::scene_file(&path, &[]);
    if spectral {
        s.effects
            .force(prism::scene::Effect::Spectral)
            .expect("spectral can be forced");
    }
    s
}

/// The furnace of `tests/furnace.rs` with `environment` in place of the constant.
fn furnace(environment: &str, albedo: f32, mode: &str) -> String {
    format!(
        r#"#![enable(implicit_some)]
Scene(
    render: (width: 32, height: 32, spp: 64, max_depth: 64, seed: 7, integrator: (rr_depth: 3, light_sampling: {mode})),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    environment: {environment},
    entities: [ (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
                 material: Diffuse(albedo: Rgb({albedo}, {albedo}, {albedo}))) ],
)"#
    )
}

fn on_sphere(x: u32, y: u32) -> bool {
    let (dx, dy) = (x as f32 + 0.5 - 16.0, y as f32 + 0.5 - 16.0);
    (dx * dx + dy * dy).sqrt() < 12.0
}

/// A map of one value everywhere lights like `Constant` of that value: the background is
/// the value exactly (a bilinear blend of equal texels), a grey sphere reflects albedo ×
/// value (the image mean of 32·32·64 samples has a standard error far below 1 %), with and
/// without light sampling, in RGB and spectral transport.
#[test]
fn constant_map_renders_like_constant() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "grey.exr", 16, 8, |_, _| [0.8; 3]);
    for spectral in [false, true] {
        for mode in ["Nee", "Path"] {
            let text = furnace(r#"Image(path: "grey.exr")"#, 0.5, mode);
            let img = run(&scene_in(dir.path(), &text, spectral)).image();
            for c in 0..3 {
                let bg = mean_where(&img, c, |x, y| {
                    !(3..=28).contains(&x) && !(3..=28).contains(&y)
                });
                let sphere = mean_where(&img, c, on_sphere);
                let bg_tol = if spectral { 0.01 } else { 1e-5 };
                assert!(
                    (bg / 0.8 - 1.0).abs() < bg_tol,
                    "{mode} spectral {spectral}: background {bg}"
                );
                assert!(
                    (sphere / 0.4 - 1.0).abs() < 0.01,
                    "{mode} spectral {spectral}: sphere {sphere}, expected 0.4"
                );
            }
        }
    }
}

/// A map of 1 above the horizon and 0 below: a diffuse plane of albedo ρ facing up sees
/// irradiance π and renders ρ; facing down it renders 0. The bilinear blend across the
/// horizon row pair softens the step over one texel (±1.4° at 64 rows), which moves the
/// result by about δ²/6 ≈ 1e-4 relative: far inside the 1 % tolerance.
#[test]
fn upper_hemisphere_lights_an_upward_plane_only() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "upper.exr", 128, 64, |_, y| {
        if y < 32 { [1.0; 3] } else { [0.0; 3] }
    });
    let rho = 0.6;
    for (up, camera_y, expect) in [(true, 1.0, rho), (false, -1.0, 0.0)] {
        for mode in ["Nee", "Path"] {
            let text = format!(
                r#"#![enable(implicit_some)]
Scene(
    render: (width: 16, height: 16, spp: 256, max_depth: 8, seed: 5, integrator: (light_sampling: {mode})),
    camera: (position: (0.0, {camera_y}, 0.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 0.0, -1.0), fov_y: 20.0),
    environment: Image(path: "upper.exr"),
    entities: [ (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (100.0, 0.0, 0.0), v: (0.0, 0.0, {v})),
                 material: Diffuse(albedo: Rgb({rho}, {rho}, {rho}))) ],
)"#,
                v = if up { -100.0 } else { 100.0 }
            );
            let img = run(&scene_in(dir.path(), &text, false)).image();
            let m = mean_where(&img, 1, |_, _| true);
            if up {
                assert!((m / expect - 1.0).abs() < 0.01, "{mode} up: {m}");
            } else {
                assert!(m.abs() < 1e-3, "{mode} down: {m}");
            }
        }
    }
}

/// A map black but for one bright texel: the light comes from the direction the convention
/// predicts. The texel at three quarters of the width on the equator faces +x: a diffuse
/// sphere seen from +z is lit on its right half. Turned 180° about y it faces −x (lit on the
/// left); turned 90° about z, +x goes to +y (lit on top).
#[test]
fn one_bright_texel_lights_from_the_predicted_direction() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (64u32, 32u32);
    write_map(dir.path(), "dot.exr", w, h, |x, y| {
        if x == 3 * w / 4 && y == h / 2 {
            [1000.0; 3]
        } else {
            [0.0; 3]
        }
    });
    let side = |rotate: &str| {
        let text = format!(
            r#"#![enable(implicit_some)]
Scene(
    render: (width: 32, height: 32, spp: 16, max_depth: 2, seed: 1),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    environment: Image(path: "dot.exr", rotate: {rotate}),
    entities: [ (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
                 material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))) ],
)"#
        );
        let img = run(&scene_in(dir.path(), &text, false)).image();
        let region =
            |f: &dyn Fn(u32, u32) -> bool| mean_where(&img, 1, |x, y| on_sphere(x, y) && f(x, y));
        (
            region(&|x, _| x < 11),
            region(&|x, _| x > 20),
            region(&|_, y| y < 11),
            region(&|_, y| y > 20),
        )
    };
    let (left, right, top, bottom) = side("(0.0, 0.0, 0.0)");
    assert!(right > 0.0 && left == 0.0, "left {left} right {right}");
    assert!(
        (top / bottom - 1.0).abs() < 0.2,
        "top {top} bottom {bottom}"
    );
    let (left, right, ..) = side("(0.0, 180.0, 0.0)");
    assert!(left > 0.0 && right == 0.0, "left {left} right {right}");
    let (left, right, top, bottom) = side("(0.0, 0.0, 90.0)");
    assert!(top > 0.0 && bottom == 0.0, "top {top} bottom {bottom}");
    assert!(
        (left / right - 1.0).abs() < 0.2,
        "left {left} right {right}"
    );
}

/// A map with structure at every scale: a bright spot, zero rows and columns, a gradient.
fn test_map(rotate: Vec3) -> EnvMap {
    let (w, h) = (24u32, 12u32);
    let texels: Vec<[f32; 3]> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            if (x, y) == (5, 3) {
                [200.0, 150.0, 100.0]
            } else if y == 8 || x == 17 || (x + y) % 7 == 0 {
                [0.0; 3]
            } else {
                [0.1 + x as f32 * 0.05, 0.2, 0.3 + y as f32 * 0.1]
            }
        })
        .collect();
    EnvMap::new(w, h, &texels, 1.5, rotate).unwrap()
}

/// χ² of the map's samples against its density, with the map's pole along +z (the harness
/// bins about +z) and turned obliquely; the density of each sampled direction equals the
/// density evaluated there, and no sample lands where the map is black.
#[test]
fn map_sampling_matches_its_density() {
    for rotate in [Vec3::new(90.0, 0.0, 0.0), Vec3::new(30.0, 70.0, -20.0)] {
        let map = test_map(rotate);
        let result = Chi2::new(2_000_000, 11)
            .res(24, 48)
            .tests(2)
            .max_depth(6)
            .directions(
                [0.0, 2.0],
                |u| map.sample(u).map(|(d, _, _)| d),
                |d| map.pdf(d),
            );
        if let Err(e) = result {
            panic!("rotate {rotate}: {e}");
        }
        let mut rng = splitmix::SplitMix(3);
        for _ in 0..200_000 {
            let u = Vec2::new(rng.unit() as f32, rng.unit() as f32);
            let Some((d, l, pdf)) = map.sample(u) else {
                continue;
            };
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!(
                l.max_element() > 0.0 && map.eval(d).max_element() > 0.0,
                "black sample {d}"
            );
            // Every sample lies where the evaluated density is above zero (MIS and light
            // tracing need it); equality is checked below.
            assert!(pdf > 0.0 && map.pdf(d) > 0.0, "density 0 at sample {d}");
        }
    }
}

/// The density integrates to one over the sphere, and the sampled density matches the
/// evaluated one on all but a vanishing share of samples (those on cell edges).
#[test]
fn map_density_is_normalised_and_consistent() {
    let map = test_map(Vec3::new(10.0, 20.0, 30.0));
    let (nt, np) = (600usize, 1200usize);
    let mut integral = 0.0f64;
    for i in 0..nt {
        let (c0, c1) = (
            1.0 - 2.0 * i as f64 / nt as f64,
            1.0 - 2.0 * (i + 1) as f64 / nt as f64,
        );
        let c = 0.5 * (c0 + c1);
        for j in 0..np {
            let phi = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
            let s = (1.0 - c * c).sqrt();
            let d = Vec3::new((s * phi.cos()) as f32, c as f32, (s * phi.sin()) as f32);
            integral += f64::from(map.pdf(d)) * (c0 - c1) * std::f64::consts::TAU / np as f64;
        }
    }
    assert!((integral - 1.0).abs() < 5e-3, "∫pdf = {integral}");
    let mut rng = splitmix::SplitMix(8);
    let (mut same, mut n) = (0usize, 0usize);
    for _ in 0..100_000 {
        let u = Vec2::new(rng.unit() as f32, rng.unit() as f32);
        if let Some((d, _, pdf)) = map.sample(u) {
            n += 1;
            same += usize::from((map.pdf(d) / pdf - 1.0).abs() < 1e-4);
        }
    }
    assert!(same as f64 >= 0.999 * n as f64, "{same} of {n} consistent");
}

/// The convention written out: pixel (u, v) ↔ direction, and `rotate` as a transform's.
#[test]
fn direction_to_pixel_convention() {
    assert!(local_of_uv(Vec2::new(0.5, 0.5)).abs_diff_eq(Vec3::NEG_Z, 1e-6));
    assert!(local_of_uv(Vec2::new(0.25, 0.5)).abs_diff_eq(Vec3::NEG_X, 1e-6));
    assert!(local_of_uv(Vec2::new(0.0, 0.5)).abs_diff_eq(Vec3::Z, 1e-6));
    assert!(local_of_uv(Vec2::new(0.5, 1.0)).abs_diff_eq(Vec3::NEG_Y, 1e-6));
    let uv = uv_of_local(Vec3::new(1.0, 1.0, 0.0).normalize());
    assert!(uv.abs_diff_eq(Vec2::new(0.75, 0.25), 1e-6), "{uv}");
    // Turned 90° about y, the map's centre (−z) faces −x: R_y(90°)·(0, 0, −1) = (−1, 0, 0).
    let m = EnvMap::new(4, 2, &[[1.0; 3]; 8], 1.0, Vec3::new(0.0, 90.0, 0.0)).unwrap();
    assert!(
        m.direction_of(Vec2::new(0.5, 0.5))
            .abs_diff_eq(Vec3::NEG_X, 1e-6)
    );
    assert!(m.uv_of(Vec3::NEG_X).abs_diff_eq(Vec2::new(0.5, 0.5), 1e-6));
}

/// What the user sees: `prism info` names the map, its size and its sampling; a missing
/// file, a NaN texel and a negative scale are located errors, not panics.
#[test]
fn info_and_errors_name_the_map() {
    use assert_cmd::Command;
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "small.exr", 8, 4, |x, _| [x as f32, 0.5, 0.25]);
    let scene = |env: &str| {
        let text = format!(
            r#"#![enable(implicit_some)]
Scene(
    render: (width: 8, height: 8, spp: 1),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    environment: {env},
    entities: [ (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
                 material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))) ],
)"#
        );
        let p = dir.path().join("s.ron");
        std::fs::write(&p, text).unwrap();
        p
    };
    let out = Command::cargo_bin("prism")
        .unwrap()
        .args(["info"])
        .arg(scene(
            r#"Image(path: "small.exr", scale: 2.0, rotate: (0.0, 90.0, 0.0))"#,
        ))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains(
            r#"environment: Image(path: "small.exr", scale: 2, rotate: (0, 90, 0)); 8×4 texels"#
        ) && text.contains("sampled by luminance × solid angle over 8×5 cells"),
        "{text}"
    );
    write_map(dir.path(), "nan.exr", 4, 2, |x, y| {
        if (x, y) == (3, 1) {
            [f32::NAN, 0.0, 0.0]
        } else {
            [1.0; 3]
        }
    });
    for (env, expect) in [
        (r#"Image(path: "missing.exr")"#, "missing.exr"),
        (
            r#"Image(path: "nan.exr")"#,
            "texel (3, 1) is not a finite number",
        ),
        (r#"Image(path: "small.exr", scale: -1.0)"#, ">= 0"),
        (
            r#"Image(path: "small.exr", rotation: (0.0, 1.0, 0.0))"#,
            "rotation",
        ),
    ] {
        let out = Command::cargo_bin("prism")
            .unwrap()
            .args(["info"])
            .arg(scene(env))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{env}");
        assert!(
            err.contains(expect) && err.contains("s.ron:5:") && !err.contains("panicked"),
            "{env}: {err}"
        );
    }
}
