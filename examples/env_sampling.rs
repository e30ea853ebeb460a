//! What importance sampling the environment map buys: a scene lit by a map rendered with the
//! map's luminance-proportional light samples and with uniform ones (density 1/4π, everything
//! else equal), each against one converged reference. Prints a Markdown table per scene of
//! samples per pixel, seconds, relMSE and the time each would need to reach relMSE 0.01
//! (relMSE × time is constant once the error is noise: t₀.₀₁ = t · relMSE / 0.01), for
//! docs/performance.md.
//!
//! `cargo run --release --example env_sampling [SCENE...]` (default: scenes/studio.ron and the
//! same objects under the sunrise map, assets/env/sunrise.exr)

use prism::film::{Image, compare};
use prism::integrator::{RenderOptions, render};
use prism::kdtree::KdParams;
use prism::scene::RenderScene;
use prism::systems::prepare;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

const WIDTH: u32 = 160;
const HEIGHT: u32 = 90;
const REFERENCE_SPP: u32 = 8192;
const SPPS: [u32; 3] = [16, 64, 256];

fn scene(path: &Path, overrides: &[(&str, &str)]) -> RenderScene {
    let mut o: Vec<(String, String)> = overrides
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    o.push(("render.width".into(), WIDTH.to_string()));
    o.push(("render.height".into(), HEIGHT.to_string()));
    let loaded = prism::scene_file::load(path, &o).expect("scene loads");
    prepare(&loaded, &KdParams::default())
}

fn uniform(mut s: RenderScene) -> RenderScene {
    let map = s
        .lights
        .map
        .as_ref()
        .expect("the scene has an environment map");
    s.lights.map = Some(Arc::new((**map).clone().with_uniform_sampling()));
    s
}

fn timed(s: &RenderScene, spp: u32) -> (Image, f64) {
    let t = Instant::now();
    let out = render(
        s,
        &RenderOptions::new(spp, prism::simd::Lanes::auto()),
        &|_| {},
    );
    (out.image(), t.elapsed().as_secs_f64())
}

fn study(label: &str, path: &Path, overrides: &[(&str, &str)]) {
    let base = scene(path, overrides);
    let (reference, t_ref) = timed(&base, REFERENCE_SPP);
    println!(
        "\n{label} ({WIDTH}×{HEIGHT}, reference {REFERENCE_SPP} spp importance-sampled, {t_ref:.1} s)\n"
    );
    println!("| sampling | spp | seconds | relMSE | seconds to relMSE 0.01 |");
    println!("|---|---|---|---|---|");
    let mut at_most = Vec::new();
    for (name, s) in [
        ("importance", scene(path, overrides)),
        ("uniform", uniform(scene(path, overrides))),
    ] {
        for spp in SPPS {
            let (img, t) = timed(&s, spp);
            let e = compare(&img, &reference).expect("same size").relmse;
            // The reference's own noise adds its relMSE (≈ e·spp/REFERENCE_SPP for the
            // importance-sampled render it is made of) to every measurement.
            let t01 = t * e / 0.01;
            println!("| {name} | {spp} | {t:.3} | {e:.5} | {t01:.2} |");
            if spp == *SPPS.last().unwrap() {
                at_most.push(t01);
            }
        }
    }
    println!(
        "\nAt {} spp, uniform sampling needs {:.1}× the time of importance sampling to reach relMSE 0.01.",
        SPPS.last().unwrap(),
        at_most[1] / at_most[0]
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        study("studio.ron", Path::new("scenes/studio.ron"), &[]);
        study(
            "studio.ron under assets/env/sunrise.exr (a sun in the map)",
            Path::new("scenes/studio.ron"),
            &[("environment", r#"Image(path: "../assets/env/sunrise.exr")"#)],
        );
    } else {
        for a in &args {
            study(a, Path::new(a), &[]);
        }
    }
}
