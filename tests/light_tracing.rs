//! Light tracing against the path tracer: the same image within noise, pixel by pixel, on
//! scenes of every emitter kind, a thin lens, motion, textures with normal maps and glossy
//! materials; the same bits on any thread count; clear refusals of what it does not handle.

mod common;

use assert_cmd::cargo::CommandCargoExt;
use prism::film::Image;
use prism::integrator::{RenderOptions, render};
use prism::kdtree::KdParams;
use prism::scene::RenderScene;
use prism::simd::Lanes;
use std::path::Path;
use std::process::Command;

/// Independent batches per estimator. With 8, the variance estimate's own noise (a t
/// distribution of about 7 degrees of freedom) alone puts 1.3 % of pixels beyond |z| = 3.29;
/// with 32, 0.25 %.
const BATCHES: u32 = 32;

/// `text` (a scene file's text, or a shipped scene's name) at `size`² with `overrides`.
fn load(text: &str, size: u32, overrides: &[(&str, &str)]) -> RenderScene {
    let s = size.to_string();
    let mut o: Vec<(String, String)> = vec![
        ("render.width".into(), s.clone()),
        ("render.height".into(), s),
    ];
    o.extend(
        overrides
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string())),
    );
    let loaded = if text.ends_with(".ron") {
        prism::scene_file::load(&Path::new("scenes").join(text), &o)
    } else {
        prism::scene_file::load_str(text, Path::new("scenes/test.ron"), &o)
    }
    .expect("scene loads");
    prism::systems::prepare(&loaded, &KdParams::default())
}

/// Batch `b` of `spp` samples per pixel (sample indices from b·2²⁴: disjoint batches).
fn batch(rs: &RenderScene, spp: u32, b: u32) -> Image {
    let mut o = RenderOptions::new(spp, Lanes::auto());
    o.sample_offset = b << 24;
    render(rs, &o, &|_| {}).image()
}

/// Per pixel, the mean of the channels over [`BATCHES`] batches, and the variance of that
/// mean.
fn batch_stats(rs: &RenderScene, spp: u32) -> Vec<(f64, f64)> {
    let images: Vec<Image> = (0..BATCHES).map(|b| batch(rs, spp, b)).collect();
    let n = f64::from(BATCHES);
    (0..images[0].pixels.len())
        .map(|i| {
            let v: Vec<f64> = images
                .iter()
                .map(|im| im.pixels[i].iter().map(|&c| f64::from(c)).sum::<f64>())
                .collect();
            assert!(v.iter().all(|x| x.is_finite()), "non-finite pixel {i}");
            let mean = v.iter().sum::<f64>() / n;
            let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, var / n)
        })
        .collect()
}

/// The path tracer (`path_spp` per batch) and light tracing (`light_spp`) on scene `text`:
/// the share of pixels with |z| ≤ 3.29 (pixels where both are exactly equal count as
/// passing), and the two image means.
fn agreement(
    name: &str,
    text: &str,
    size: u32,
    overrides: &[(&str, &str)],
    path_spp: u32,
    light_spp: u32,
) {
    let path = load(text, size, overrides);
    let mut o = overrides.to_vec();
    o.push(("render.integrator.kind", "LightTracing"));
    let light = load(text, size, &o);
    let (a, b) = (batch_stats(&path, path_spp), batch_stats(&light, light_spp));
    let mut pass = 0usize;
    let mut worst = Vec::new();
    for (i, (&(ma, va), &(mb, vb))) in a.iter().zip(&b).enumerate() {
        let z = if ma == mb {
            0.0
        } else {
            (ma - mb) / (va + vb).sqrt()
        };
        if z.abs() <= 3.29 {
            pass += 1;
        } else {
            worst.push((i, z, ma, mb));
        }
    }
    let share = pass as f64 / a.len() as f64;
    let mean = |v: &[(f64, f64)]| v.iter().map(|p| p.0).sum::<f64>() / v.len() as f64;
    let var = |v: &[(f64, f64)]| v.iter().map(|p| p.1).sum::<f64>() / (v.len() as f64).powi(2);
    let (ia, ib) = (mean(&a), mean(&b));
    // The image means' difference against the noise of both (pixels taken as independent).
    let z_img = (ia - ib) / (var(&a) + var(&b)).sqrt();
    println!(
        "{name}: |z| ≤ 3.29 on {:.2} % of pixels; image means {ia:.5} (path) {ib:.5} (light), z {z_img:.2}",
        100.0 * share
    );
    worst.sort_by(|x, y| y.1.abs().total_cmp(&x.1.abs()));
    assert!(
        share >= 0.995,
        "{name}: only {:.2} % of pixels agree; worst (pixel, z, path, light): {:?}",
        100.0 * share,
        &worst[..worst.len().min(8)]
    );
    assert!(
        z_img.abs() <= 4.0,
        "{name}: image means differ, z = {z_img}"
    );
}

const NO_SKY: (&str, &str) = ("environment", "Constant(Rgb(0.0, 0.0, 0.0))");

/// Diffuse walls under a one-sided area light.
#[test]
fn cornell_box() {
    agreement("cornell", "cornell.ron", 48, &[], 32, 32);
}

/// Point, spot, sphere, disk and two-sided emitters over diffuse surfaces, in spectral
/// transport (a blackbody lamp).
const LAMPS: &str = r#"Scene(
    render: (width: 24, height: 24, spp: 16, max_depth: 6, seed: 1),
    camera: (position: (0.0, 1.5, 5.0), look_at: (0.0, 0.8, 0.0), fov_y: 50.0),
    entities: [
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (3.0, 0.0, 0.0), v: (0.0, 0.0, -3.0)),
         material: Diffuse(albedo: Rgb(0.6, 0.6, 0.6))),
        (name: "wall", shape: Rect(center: (0.0, 1.5, -2.0), u: (3.0, 0.0, 0.0), v: (0.0, 1.5, 0.0)),
         material: Diffuse(albedo: Rgb(0.3, 0.5, 0.7))),
        (name: "ball", shape: Sphere(center: (-0.8, 0.5, 0.0), radius: 0.5),
         material: Diffuse(albedo: Rgb(0.8, 0.4, 0.2))),
        (name: "bulb", shape: Sphere(center: (1.2, 1.8, 0.3), radius: 0.15),
         material: Light(emission: Blackbody(kelvin: 3000.0, scale: 8.0))),
        (name: "panel", shape: Disk(center: (0.0, 2.6, 0.0), normal: (0.0, -1.0, 0.0), radius: 0.4),
         material: Light(emission: Rgb(3.0, 3.0, 3.0), two_sided: true)),
        (name: "spot", light: Spot(position: (-1.5, 2.5, 1.0), direction: (0.5, -1.0, -0.3), cone: 30.0,
         falloff: 10.0, intensity: Rgb(6.0, 5.0, 4.0))),
        (name: "point", light: Point(position: (1.0, 0.8, 1.5), intensity: Rgb(1.0, 1.2, 1.5))),
    ],
)"#;

#[test]
fn every_emitter_kind_in_spectral_transport() {
    agreement("lamps", LAMPS, 48, &[], 32, 32);
}

/// A thin lens with a hexagonal aperture, focused on the ball.
#[test]
fn thin_lens() {
    let lens = [
        ("camera.lens.aperture_radius", "0.15"),
        ("camera.lens.focus_distance", "5.1"),
        ("camera.lens.blades", "6"),
    ];
    agreement("thin lens", LAMPS, 48, &lens, 32, 32);
}

/// Moving objects within the shutter.
#[test]
fn motion_blur() {
    agreement("motion blur", "motion_blur.ron", 48, &[NO_SKY], 32, 32);
}

/// Textured albedo and normal maps (shading normals: the adjoint correction), a textured,
/// two-sided lamp.
#[test]
fn textures_and_normal_maps() {
    agreement("textures", "textures.ron", 48, &[NO_SKY], 32, 32);
}

/// Rough plastics, a rough dielectric and an anisotropic rough conductor (no delta lobe: a
/// light path cannot reach the camera through one).
const GLOSSY: &str = r#"Scene(
    render: (width: 24, height: 24, spp: 16, max_depth: 8, seed: 1),
    camera: (position: (0.0, 1.6, -4.2), look_at: (0.0, 0.45, 0.0), fov_y: 42.0),
    entities: [
        (name: "lamp", shape: Rect(center: (0.0, 3.2, -0.8), u: (1.6, 0.0, 0.0), v: (0.0, 0.0, 0.7)),
         material: Light(emission: Rgb(9.0, 8.6, 8.0))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 2.0), u: (8.0, 0.0, 0.0), v: (0.0, 0.0, 8.0)),
         material: Diffuse(albedo: Rgb(0.8, 0.8, 0.8))),
        (name: "wall", shape: Rect(center: (0.0, 2.0, 3.0), u: (8.0, 0.0, 0.0), v: (0.0, 2.0, 0.0)),
         material: Diffuse(albedo: Rgb(0.25, 0.3, 0.35))),
        (name: "frosted", shape: Sphere(center: (1.65, 0.5, 0.0), radius: 0.5),
         material: Dielectric(ior: Constant(1.5), alpha: 0.3)),
        (name: "red", shape: Sphere(center: (0.55, 0.5, 0.0), radius: 0.5),
         material: Plastic(albedo: Rgb(0.7, 0.06, 0.04), roughness: 0.3)),
        (name: "blue", shape: Sphere(center: (-0.55, 0.5, 0.0), radius: 0.5),
         material: Plastic(albedo: Rgb(0.05, 0.15, 0.6), roughness: 0.5)),
        (name: "nickel", shape: Sphere(center: (-1.65, 0.5, 0.0), radius: 0.5),
         material: Conductor(metal: Ni, alpha: (0.2, 0.4))),
    ],
)"#;

#[test]
fn glossy_materials() {
    agreement("glossy", GLOSSY, 48, &[], 32, 128);
}

/// The image is the same bits on one thread and on two: splats are summed in fixed point.
#[test]
fn same_image_on_one_and_two_threads() {
    let rs = load(LAMPS, 24, &[("render.integrator.kind", "LightTracing")]);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| batch(&rs, 8, 0))
    };
    assert_eq!(on(1).pixels, on(2).pixels);
}

/// Media, an emitting environment and a target error are refused with one clear line.
#[test]
fn unsupported_scenes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run = |scene: &str, extra: &[&str]| {
        let out = Command::cargo_bin("prism")
            .unwrap()
            .args(["render", scene, "--quiet", "--spp", "1", "-o"])
            .arg(dir.path().join("x.png"))
            .args(["--set", "render.integrator.kind=LightTracing"])
            .args(extra)
            .output()
            .unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{err}");
        err
    };
    let e = run("scenes/fog_lamps.ron", &[]);
    assert!(e.contains("LightTracing") && e.contains("media"), "{e}");
    let e = run("scenes/textures.ron", &[]);
    assert!(e.contains("environment"), "{e}");
    let e = run(
        "scenes/cornell.ron",
        &["--target-error", "0.05", "--set", "render.width=8"],
    );
    assert!(e.contains("target error"), "{e}");
}
