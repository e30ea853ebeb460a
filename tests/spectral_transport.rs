//! Spectral transport against RGB transport: the same physics where it must be (grey scenes,
//! one coloured bounce under neutral light), white stays white, and dispersion ends the
//! secondary wavelengths without losing energy.

mod common;
use common::render::{run, scene};
use prism::film::Image;
use prism::scene::Effect;

fn render(text: &str, spectral: bool) -> Image {
    let mut s = scene(text);
    if spectral {
        s.effects.force(Effect::Spectral).unwrap();
    }
    assert_eq!(s.effects.has(Effect::Spectral), spectral);
    run(&s).image()
}

fn means(img: &Image) -> [f64; 3] {
    let mut m = [0.0; 3];
    for p in &img.pixels {
        for c in 0..3 {
            m[c] += p[c] as f64;
        }
    }
    m.map(|v| v / img.pixels.len() as f64)
}

/// A grey sphere on a grey floor under a grey area light and a grey sky: every reflectance
/// and emitter is flat, so RGB and spectral transport solve the same equation.
const GREY: &str = r#"#![enable(implicit_some)]
Scene(
    render: (width: 48, height: 48, spp: 128, max_depth: 8, seed: 3),
    camera: (position: (0.0, 1.0, 5.0), look_at: (0.0, 0.6, 0.0), fov_y: 40.0),
    environment: Constant(Rgb(0.2, 0.2, 0.2)),
    entities: [
        (name: "ball", shape: Sphere(center: (0.0, 0.7, 0.0), radius: 0.7),
         material: Diffuse(albedo: Rgb(0.6, 0.6, 0.6))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (3.0, 0.0, 0.0), v: (0.0, 0.0, -3.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
        (name: "lamp", shape: Rect(center: (0.0, 3.0, 0.0), u: (0.5, 0.0, 0.0), v: (0.0, 0.0, 0.5)),
         material: Light(emission: Rgb(8.0, 8.0, 8.0))),
    ],
)"#;

#[test]
fn grey_scene_agrees_with_rgb_transport() {
    let (rgb, spec) = (means(&render(GREY, false)), means(&render(GREY, true)));
    for c in 0..3 {
        // 48²·128 samples: the mean's standard error is a few 0.1 %, so 1 % is bias.
        assert!(
            (spec[c] / rgb[c] - 1.0).abs() < 0.01,
            "channel {c}: spectral {} vs rgb {}",
            spec[c],
            rgb[c]
        );
    }
}

/// One bounce off a coloured wall lit by a white lamp: RGB multiplies the albedo by white,
/// spectral integrates the upsampled albedo against the lamp's D65-shaped spectrum, which by
/// construction reproduces the albedo's sRGB colour.
#[test]
fn one_coloured_bounce_under_neutral_light_agrees() {
    for albedo in ["0.7, 0.2, 0.1", "0.1, 0.5, 0.2", "0.2, 0.3, 0.8"] {
        let text = format!(
            r#"#![enable(implicit_some)]
Scene(
    render: (width: 24, height: 24, spp: 256, max_depth: 1, seed: 5),
    camera: (position: (0.0, 0.0, 3.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    entities: [
        (name: "wall", shape: Rect(center: (0.0, 0.0, 0.0), u: (2.0, 0.0, 0.0), v: (0.0, 2.0, 0.0)),
         material: Diffuse(albedo: Rgb({albedo}))),
        (name: "lamp", shape: Disk(center: (0.0, 1.8, 1.5), normal: (0.0, -0.77, -0.64), radius: 0.6),
         material: Light(emission: Rgb(4.0, 4.0, 4.0))),
    ],
)"#
        );
        let (rgb, spec) = (means(&render(&text, false)), means(&render(&text, true)));
        for c in 0..3 {
            // The Jakob–Hanika fit reproduces a colour to well under 1 % of its largest
            // channel; allow that much of the brightest channel, plus noise.
            let scale = rgb.iter().cloned().fold(0.0, f64::max);
            assert!(
                (spec[c] - rgb[c]).abs() < 0.015 * scale,
                "albedo {albedo}, channel {c}: spectral {} vs rgb {}",
                spec[c],
                rgb[c]
            );
        }
    }
}

/// A D65 sky of luminance 1 seen directly, and a white sphere in it: both (1, 1, 1) in
/// linear sRGB, whose white point is D65. An equal-energy sky would come out pink.
#[test]
fn white_is_white_in_spectral_transport() {
    for sky in [
        "Illuminant(spectrum: D65, scale: 1.0)",
        "Rgb(1.0, 1.0, 1.0)",
    ] {
        let text = format!(
            r#"#![enable(implicit_some)]
Scene(
    render: (width: 16, height: 16, spp: 256, max_depth: 32, seed: 9, integrator: (rr_depth: 4)),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    environment: Constant({sky}),
    entities: [ (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
                 material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0))) ],
)"#
        );
        let img = render(&text, true);
        let m = means(&img);
        for (c, v) in m.iter().enumerate() {
            assert!((v - 1.0).abs() < 0.01, "{sky}: channel {c} = {v}");
        }
        // A background pixel sees the sky itself.
        let corner = img.pixels[0];
        for c in 0..3 {
            assert!(
                (corner[c] - 1.0).abs() < 0.01,
                "{sky}: sky pixel {corner:?}"
            );
        }
    }
}

/// A glass ball of dispersive glass in a white furnace: refraction ends the secondary
/// wavelengths, yet no energy is created or lost (the furnace stays at its radiance).
#[test]
fn dispersive_glass_in_a_furnace_keeps_energy() {
    let text = r#"#![enable(implicit_some)]
Scene(
    render: (width: 16, height: 16, spp: 512, max_depth: 64, seed: 2, integrator: (rr_depth: 8)),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    environment: Constant(Rgb(0.5, 0.5, 0.5)),
    entities: [ (name: "gem", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
                 material: Dielectric(ior: Preset(Diamond))) ],
)"#;
    let s = scene(text);
    assert!(
        s.effects.has(Effect::Spectral),
        "a dispersive IOR turns SPECTRAL on"
    );
    let img = run(&s).image();
    let m = means(&img);
    for (c, v) in m.iter().enumerate() {
        assert!((v / 0.5 - 1.0).abs() < 0.02, "channel {c}: {v}");
    }
    assert!(img.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));
}
