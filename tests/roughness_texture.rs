//! Roughness textures: the looked-up roughness is the material's roughness (bit for bit for
//! a constant texture), images are read linearly from the chosen channel, and light
//! sampling and BSDF sampling agree on a surface whose roughness varies.

mod common;
use common::render::{image, z_between};
use image::ImageEncoder;
use prism::film::Image;

/// A lit sphere of `material`, with `texture` on it.
fn scene(material: &str, texture: &str, seed: u32, extra: &str) -> String {
    format!(
        r#"#![enable(implicit_some)]
Scene(
    render: (width: 24, height: 24, spp: 8, max_depth: 6, seed: {seed}{extra}),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 32.0),
    environment: Constant(Rgb(0.2, 0.2, 0.2)),
    entities: [
        (name: "lamp", shape: Rect(center: (1.2, 1.8, 1.5), u: (0.3, 0.0, 0.0), v: (0.0, 0.0, 0.3)),
         material: Light(emission: Rgb(40.0, 40.0, 40.0), two_sided: true)),
        (name: "floor", shape: Rect(center: (0.0, -1.0, 0.0), u: (4.0, 0.0, 0.0), v: (0.0, 0.0, -4.0)),
         material: Diffuse(albedo: Rgb(0.6, 0.6, 0.6))),
        (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
         material: {material}{texture}),
    ],
)"#
    )
}

const MATERIALS: [&str; 4] = [
    "Conductor(metal: Au",
    "Conductor(metal: Ni, alpha: (0.1, 0.5)",
    "Dielectric(ior: Constant(1.5)",
    "Plastic(albedo: Rgb(0.2, 0.4, 0.8)",
];

/// `material` closed with its roughness: `alpha: (..)` materials get the texture's mean.
fn with_roughness(material: &str, r: Option<f32>) -> String {
    match r {
        Some(r) if !material.contains("alpha") => format!("{material}, roughness: {r:?})"),
        _ => format!("{material})"),
    }
}

/// Mean over pixels of |a − b| relative to the mean of a, all channels.
fn relative_difference(a: &Image, b: &Image) -> f64 {
    let (mut d, mut s) = (0.0f64, 0.0f64);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            d += f64::from((p[c] - q[c]).abs());
            s += f64::from(p[c]);
        }
    }
    d / s
}

/// A checkerboard of one roughness r renders exactly as the material's `roughness: r`: the
/// texture's α (r²) is the one the sampler, the light samples and both MIS weights use.
#[test]
fn constant_texture_is_the_material_roughness() {
    for material in MATERIALS {
        let r = 0.45f32;
        let plain = image(&scene(&with_roughness(material, Some(r)), "", 3, ""));
        let textured = image(&scene(
            &with_roughness(material, None),
            &format!(", texture: (roughness: Checker(a: {r:?}, b: {r:?}, size: 0.1))"),
            3,
            "",
        ));
        if material.contains("alpha") {
            // (0.1, 0.5) with √(αx·αy) set to r², its ratio kept.
            let m = (0.1f32 * 0.5).sqrt();
            let (ax, ay) = (0.1 * r * r / m, 0.5 * r * r / m);
            let want = image(&scene(
                &format!("Conductor(metal: Ni, alpha: ({ax:?}, {ay:?}))"),
                "",
                3,
                "",
            ));
            let d = relative_difference(&want, &textured);
            assert!(
                d < 1e-4,
                "{material}: anisotropic mean kept, differs by {d}"
            );
            continue;
        }
        assert_eq!(plain.pixels, textured.pixels, "{material}");
        let other = image(&scene(&with_roughness(material, Some(0.2)), "", 3, ""));
        assert!(relative_difference(&plain, &other) > 0.01, "{material}");
    }
}

/// An 8-bit image's channel is the roughness, read linearly (v/255, never sRGB-decoded).
#[test]
fn image_roughness_is_a_linear_channel() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rough.png");
    // R = 0.2, G = 0.8, B = 0.6 everywhere.
    let raw = [51u8, 204, 153].repeat(16);
    let file = std::fs::File::create(&path).unwrap();
    image::codecs::png::PngEncoder::new(file)
        .write_image(&raw, 4, 4, image::ExtendedColorType::Rgb8)
        .unwrap();
    for (channel, value) in [("R", 51.0f32), ("G", 204.0), ("B", 153.0)] {
        let r = value / 255.0;
        let textured = image(&scene(
            "Conductor(metal: Au)",
            &format!(", texture: (roughness: Image(path: {path:?}, channel: {channel}))"),
            3,
            "",
        ));
        let want = image(&scene(
            &format!("Conductor(metal: Au, roughness: {r:?})"),
            "",
            3,
            "",
        ));
        // Bilinear weights may round the constant texel by an ulp.
        let d = relative_difference(&want, &textured);
        assert!(d < 1e-3, "channel {channel}: differs by {d}");
    }
}

/// On a checkerboard of two roughnesses, light sampling with MIS and BSDF sampling alone
/// estimate the same image (z-test over 8 seeds each): both pdfs see the texture's α.
#[test]
fn light_and_bsdf_sampling_agree_on_textured_roughness() {
    for material in [
        "Conductor(metal: Cu)",
        "Plastic(albedo: Rgb(0.3, 0.6, 0.2))",
    ] {
        let texture = ", texture: (roughness: Checker(a: 0.25, b: 0.7, size: 0.125))";
        let (a, b, z) = z_between(
            |s| scene(material, texture, s, ""),
            |s| scene(material, texture, s, ", integrator: (light_sampling: Path)"),
        );
        assert!(a > 0.0 && b > 0.0);
        assert!(
            z.abs() < 4.0,
            "{material}: MIS {a} vs BSDF only {b}, z = {z}"
        );
    }
}
