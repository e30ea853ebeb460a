//! The energy single scattering loses and what compensation restores, measured in a white
//! furnace: a white conductor and a glass sphere (η 1.5, paths of up to 256 bounces) in a
//! constant white environment, seen from far away, at α = 0.1, 0.3, 0.6 and 1, with and
//! without `multiscatter`. Prints a Markdown table of the sphere's mean radiance (1 = no
//! loss) for docs/accuracy.md.
//!
//! `cargo run --release --example furnace_energy`

use prism::integrator::{RenderOptions, render};
use prism::kdtree::KdParams;
use prism::scene_file::load_str;
use prism::systems::prepare;
use std::path::Path;

/// A unit sphere 400 units away: the view rays are parallel to 1/400, so its points are
/// seen at cosines distributed as 2μ dμ over its disc.
const DIST: f64 = 400.0;
const FOV_Y: f64 = 0.35;
const SIZE: u32 = 64;
const SPP: u32 = 256;

/// The mean radiance over the sphere's disc, from the image mean: the filter is a
/// partition of unity and the background is the environment's 1.
fn sphere_mean(material: &str) -> f64 {
    let text = format!(
        r#"#![enable(implicit_some)]
Scene(
    render: (width: {SIZE}, height: {SIZE}, spp: {SPP}, max_depth: 256, seed: 1),
    camera: (position: (0.0, 0.0, {DIST}), look_at: (0.0, 0.0, 0.0), fov_y: {FOV_Y}),
    environment: Constant(Rgb(1.0, 1.0, 1.0)),
    entities: [ (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), material: {material}) ],
)"#
    );
    let loaded = load_str(&text, Path::new("furnace.ron"), &[]).expect("furnace scene");
    let scene = prepare(&loaded, &KdParams::default());
    let out = render(
        &scene,
        &RenderOptions::new(SPP, prism::simd::Lanes::auto()),
        &|_| {},
    );
    let img = out.image();
    let mean = img.pixels.iter().map(|p| f64::from(p[0])).sum::<f64>() / img.pixels.len() as f64;
    let half = (FOV_Y.to_radians() / 2.0).tan();
    let r = (1.0 / DIST).asin().tan() / half * f64::from(SIZE) / 2.0;
    let fraction = std::f64::consts::PI * r * r / f64::from(SIZE * SIZE);
    1.0 - (1.0 - mean) / fraction
}

fn main() {
    println!("| material | α | single scattering | compensated |");
    println!("|---|---|---|---|");
    for (name, material) in [
        (
            "white conductor",
            "Conductor(reflectance: Rgb(1.0, 1.0, 1.0), alpha: {a}, multiscatter: {m})",
        ),
        (
            "glass sphere, η 1.5",
            "Dielectric(ior: Constant(1.5), alpha: {a}, multiscatter: {m})",
        ),
    ] {
        for alpha in ["0.1", "0.3", "0.6", "1.0"] {
            let at = |m: bool| {
                sphere_mean(
                    &material
                        .replace("{a}", alpha)
                        .replace("{m}", &m.to_string()),
                )
            };
            println!("| {name} | {alpha} | {:.4} | {:.4} |", at(false), at(true));
        }
    }
}
