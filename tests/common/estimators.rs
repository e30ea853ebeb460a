//! Two estimators against each other, pixel by pixel: per-pixel means and variances of the
//! mean over independent sample batches, and a z-test of their difference.

use prism::film::Image;
use prism::integrator::{RenderOptions, render};
use prism::kdtree::KdParams;
use prism::scene::RenderScene;
use prism::simd::Lanes;
use std::path::Path;

/// A thin lens with a hexagonal aperture, focused on [`LAMPS`]' ball.
pub const THIN_LENS: [(&str, &str); 3] = [
    ("camera.lens.aperture_radius", "0.15"),
    ("camera.lens.focus_distance", "5.1"),
    ("camera.lens.blades", "6"),
];

/// An environment that does not emit.
pub const NO_SKY: (&str, &str) = ("environment", "Constant(Rgb(0.0, 0.0, 0.0))");

/// Independent batches per estimator. With 8, the variance estimate's own noise (a t
/// distribution of about 7 degrees of freedom) alone puts 1.3 % of pixels beyond |z| = 3.29;
/// with 32, 0.25 %.
pub const BATCHES: u32 = 32;

/// The per-pixel bound on |z|: the two-sided 0.1 % point of Student's t with
/// `BATCHES - 1` = 31 degrees of freedom (each variance is estimated from the batches), so
/// about 0.1 % of pixels of two equal estimators lie beyond it.
pub const Z_PIXEL: f64 = 3.633;

/// `text` (a scene file's text, or a shipped scene's name) at `size`² with `overrides`.
pub fn load(text: &str, size: u32, overrides: &[(&str, &str)]) -> RenderScene {
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
pub fn batch(rs: &RenderScene, spp: u32, b: u32) -> Image {
    batch_of(rs, spp, b, None)
}

/// [`batch`] of BDPT's strategy (s, t) alone, unweighted, when `strategy` names one.
pub fn batch_of(rs: &RenderScene, spp: u32, b: u32, strategy: Option<(u32, u32)>) -> Image {
    let mut o = RenderOptions::new(spp, Lanes::auto());
    o.sample_offset = b << 24;
    o.strategy = strategy.map(|(s, t)| prism::integrator::bdpt::Strategies::Only { s, t });
    render(rs, &o, &|_| {}).image()
}

/// Per pixel, the mean of the channels over [`BATCHES`] batches, and the variance of that
/// mean.
pub fn batch_stats(rs: &RenderScene, spp: u32) -> Vec<(f64, f64)> {
    stats_of(rs, spp, None)
}

/// [`batch_stats`] of BDPT's strategy `strategy` alone.
pub fn stats_of(rs: &RenderScene, spp: u32, strategy: Option<(u32, u32)>) -> Vec<(f64, f64)> {
    let images: Vec<Image> = (0..BATCHES)
        .map(|b| batch_of(rs, spp, b, strategy))
        .collect();
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

/// One side of a comparison: an estimator (`render.integrator.kind`), its samples per pixel
/// per batch, and a BDPT strategy alone when it names one.
#[derive(Clone, Copy)]
pub struct Side<'a> {
    pub kind: &'a str,
    pub spp: u32,
    pub strategy: Option<(u32, u32)>,
}

/// `kind` at `spp` samples per pixel per batch.
pub fn side(kind: &str, spp: u32) -> Side<'_> {
    Side {
        kind,
        spp,
        strategy: None,
    }
}

/// Estimators `a` and `b` on scene `text` (with `overrides`): on the pixels `mask` keeps
/// (every pixel without one), the share with |z| ≤ [`Z_PIXEL`] must be ≥ 99.5 % (pixels where both
/// are exactly equal count as passing), and the kept pixels' means within |z| ≤ 4.
#[allow(clippy::too_many_arguments)]
pub fn agree(
    name: &str,
    text: &str,
    size: u32,
    overrides: &[(&str, &str)],
    a: Side,
    b: Side,
    mask: Option<&[bool]>,
) {
    let scene = |s: &Side| {
        let mut o = overrides.to_vec();
        o.push(("render.integrator.kind", s.kind));
        load(text, size, &o)
    };
    let (ra, rb) = (scene(&a), scene(&b));
    let keep = |i: usize| mask.is_none_or(|m| m[i]);
    let sa = stats_of(&ra, a.spp, a.strategy);
    let sb = stats_of(&rb, b.spp, b.strategy);
    let kept: Vec<usize> = (0..sa.len()).filter(|&i| keep(i)).collect();
    let sa: Vec<_> = kept.iter().map(|&i| sa[i]).collect();
    let sb: Vec<_> = kept.iter().map(|&i| sb[i]).collect();
    let mut pass = 0usize;
    let mut worst = Vec::new();
    for (&i, (&(ma, va), &(mb, vb))) in kept.iter().zip(sa.iter().zip(&sb)) {
        let z = if ma == mb {
            0.0
        } else {
            (ma - mb) / (va + vb).sqrt()
        };
        if z.abs() <= Z_PIXEL {
            pass += 1;
        } else {
            worst.push((i, z, ma, mb));
        }
    }
    let share = pass as f64 / sa.len() as f64;
    let mean = |v: &[(f64, f64)]| v.iter().map(|p| p.0).sum::<f64>() / v.len() as f64;
    let var = |v: &[(f64, f64)]| v.iter().map(|p| p.1).sum::<f64>() / (v.len() as f64).powi(2);
    let (ia, ib) = (mean(&sa), mean(&sb));
    // The image means' difference against the noise of both (pixels taken as independent).
    let z_img = (ia - ib) / (var(&sa) + var(&sb)).sqrt();
    println!(
        "{name}: |z| ≤ {Z_PIXEL} on {:.2} % of {} pixels; means {ia:.5} ({}) {ib:.5} ({}), z {z_img:.2}",
        100.0 * share,
        sa.len(),
        a.kind,
        b.kind,
    );
    worst.sort_by(|x, y| y.1.abs().total_cmp(&x.1.abs()));
    assert!(
        share >= 0.995,
        "{name}: only {:.2} % of pixels agree; worst (pixel, z, a, b): {:?}",
        100.0 * share,
        &worst[..worst.len().min(8)]
    );
    assert!(
        z_img.abs() <= 4.0,
        "{name}: image means differ, z = {z_img}"
    );
}

/// Point, spot, sphere, disk and two-sided emitters over diffuse surfaces, in spectral
/// transport (a blackbody lamp).
pub const LAMPS: &str = r#"Scene(
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

/// Rough plastics, a rough dielectric and an anisotropic rough conductor (no delta lobe: a
/// light path cannot reach the camera through one).
pub const GLOSSY: &str = r#"Scene(
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

/// Outdoors under the spectral daylight sky and its sun: diffuse blocks and a rough plastic
/// ball on a ground of finite size. Other environments replace the sky with an override.
pub const OUTDOOR: &str = r#"Scene(
    render: (width: 24, height: 24, spp: 16, max_depth: 6, seed: 1),
    camera: (position: (0.0, 1.4, -4.0), look_at: (0.0, 0.5, 0.0), fov_y: 45.0),
    environment: Sky(sun_elevation: 35.0, sun_azimuth: 150.0, turbidity: 3.0,
                     ground_albedo: Rgb(0.3, 0.3, 0.3), sun: true, scale: 2.0),
    entities: [
        (name: "ground", shape: Rect(center: (0.0, 0.0, 0.0), u: (3.0, 0.0, 0.0), v: (0.0, 0.0, -3.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.48, 0.45))),
        (name: "block", shape: Box(min: (0.4, 0.0, 0.2), max: (1.4, 1.2, 1.2)),
         material: Diffuse(albedo: Rgb(0.7, 0.45, 0.3))),
        (name: "ball", shape: Sphere(center: (-0.7, 0.5, 0.0), radius: 0.5),
         material: Plastic(albedo: Rgb(0.1, 0.3, 0.6), roughness: 0.3)),
    ],
)"#;

/// The studio's environment map in place of [`OUTDOOR`]'s sky.
pub const STUDIO_MAP: (&str, &str) = (
    "environment",
    r#"Image(path: "../assets/env/studio.exr", scale: 1.0, rotate: (0.0, 40.0, 0.0))"#,
);

/// A constant environment in place of [`OUTDOOR`]'s sky.
pub const GREY_SKY: (&str, &str) = ("environment", "Constant(Rgb(0.6, 0.7, 0.8))");

/// Fog in a box on the floor, lit by a point light and a spot outside it and a disk lamp
/// inside; the camera outside. A diffuse ball stands in the fog, and a glass ball filled
/// with a coloured scattering medium (a dielectric that is also a medium's boundary) floats
/// in it (media nest: a shape's outside is one medium): connections and light subpaths cross
/// both kinds of boundary, and vertices in either medium connect through the phase function.
/// The fog's floor lies just below the floor's surface, so no ray meets both at once.
/// Chromatic coefficients exercise the per-channel free-flight weights.
pub const FOG_BOX: &str = r#"Scene(
    render: (width: 24, height: 24, spp: 16, max_depth: 8, seed: 1),
    camera: (position: (0.0, 1.4, 5.5), look_at: (0.0, 0.8, 0.0), fov_y: 45.0),
    entities: [
        (name: "fog", shape: Box(min: (-1.6, -0.01, -1.6), max: (1.6, 1.5, 1.6)),
         medium: (sigma_a: Rgb(0.05, 0.1, 0.2), sigma_s: Rgb(0.6, 0.45, 0.3), g: 0.4)),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (3.0, 0.0, 0.0), v: (0.0, 0.0, -3.0)),
         material: Diffuse(albedo: Rgb(0.6, 0.6, 0.6))),
        (name: "wall", shape: Rect(center: (0.0, 1.5, -2.0), u: (3.0, 0.0, 0.0), v: (0.0, 1.5, 0.0)),
         material: Diffuse(albedo: Rgb(0.3, 0.5, 0.7))),
        (name: "ball", shape: Sphere(center: (-0.7, 0.45, 0.0), radius: 0.45),
         material: Diffuse(albedo: Rgb(0.8, 0.4, 0.2))),
        (name: "glass", shape: Sphere(center: (0.7, 0.9, 0.4), radius: 0.4),
         material: Dielectric(ior: Constant(1.5)),
         medium: (sigma_a: Rgb(0.2, 0.8, 1.2), sigma_s: Rgb(1.0, 1.0, 1.0), g: -0.3)),
        (name: "lamp", shape: Disk(center: (0.4, 1.2, -1.0), normal: (0.0, -1.0, 0.3), radius: 0.2),
         material: Light(emission: Rgb(4.0, 4.0, 4.0))),
        (name: "point", light: Point(position: (1.2, 2.6, 1.5), intensity: Rgb(6.0, 6.0, 6.0))),
        (name: "spot", light: Spot(position: (-1.5, 2.8, 0.5), direction: (0.4, -1.0, -0.2), cone: 25.0,
         falloff: 5.0, intensity: Rgb(8.0, 7.0, 6.0))),
    ],
)"#;

/// [`FOG_BOX`] with a rough glass ball, which light tracing connects through.
pub fn rough_fog_box() -> String {
    FOG_BOX.replace(
        "Dielectric(ior: Constant(1.5))",
        "Dielectric(ior: Constant(1.5), alpha: 0.3)",
    )
}
