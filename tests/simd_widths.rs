//! Every lane width renders the same image: each shipped scene at 64², 16 spp, at width 1 and
//! at every other width this CPU runs (the portable forms of 8 and 16 everywhere, the native
//! ones where the CPU has them). Widths draw the same samples, so they may differ only by
//! rounding: image means within 1e-4 relative, at least 99 % of pixels within 1e-4 relative
//! (or 1e-6 absolute, for black pixels), ray counts within 0.1 %, no non-finite pixel.

mod common;

use prism::integrator::{RenderOptions, RenderOutput, render};
use prism::scene::RenderScene;
use prism::simd::Lanes;
use std::path::Path;

fn run(scene: &RenderScene, lanes: Lanes) -> RenderOutput {
    render(
        scene,
        &RenderOptions::new(scene.settings.spp, lanes),
        &|_| {},
    )
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-4 * a.abs().max(b.abs()) || (a - b).abs() <= 1e-6
}

#[test]
fn every_width_renders_every_shipped_scene_alike() {
    let mut widths = vec![Lanes::portable(8), Lanes::portable(16)];
    for (w, native) in [(8, Lanes::native8()), (16, Lanes::native16())] {
        match native {
            Some(l) => widths.push(l),
            None => println!("width {w} native: skipped, this CPU lacks its instructions"),
        }
    }
    let mut scenes: Vec<_> = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 10, "shipped scenes not found");
    let mut compared = 0;
    for path in &scenes {
        let name = path.file_stem().unwrap().to_string_lossy();
        let scene = common::render::scene_file(
            Path::new(path),
            &[
                ("render.width", "64"),
                ("render.height", "64"),
                ("render.spp", "16"),
            ],
        );
        let base = run(&scene, Lanes::scalar());
        let img0 = base.image();
        assert_eq!(base.lanes.width(), 1);
        for &lanes in &widths {
            let out = run(&scene, lanes);
            // Every effect variant runs at the width asked for.
            assert_eq!(out.lanes, lanes, "{name}");
            compared += 1;
            let img = out.image();
            let n = img.pixels.len();
            let mut bad = Vec::new();
            let (mut m0, mut m1) = (0.0f64, 0.0f64);
            for (i, (a, b)) in img0.pixels.iter().zip(&img.pixels).enumerate() {
                assert!(
                    b.iter().all(|v| v.is_finite()),
                    "{name}: pixel {i} not finite"
                );
                m0 += a.iter().map(|&v| v as f64).sum::<f64>();
                m1 += b.iter().map(|&v| v as f64).sum::<f64>();
                if !(0..3).all(|c| close(a[c], b[c])) {
                    bad.push((i % 64, i / 64, *a, *b));
                }
            }
            let rel = (m0 - m1).abs() / m0.abs().max(1e-12);
            assert!(
                rel <= 1e-4,
                "{name} at {}: mean differs by {rel:e}",
                lanes.describe()
            );
            assert!(
                bad.len() * 100 <= n,
                "{name} at {}: {} of {n} pixels differ: {:?}",
                lanes.describe(),
                bad.len(),
                &bad[..bad.len().min(10)]
            );
            for (x, y, a, b) in &bad {
                println!(
                    "{name} at {}: pixel ({x}, {y}) {a:?} vs {b:?}",
                    lanes.describe()
                );
            }
            let rays = |o: &RenderOutput| o.stats.rays + o.stats.shadow_rays;
            let dr = (rays(&base) as f64 - rays(&out) as f64).abs() / rays(&base) as f64;
            assert!(dr <= 1e-3, "{name}: ray counts differ by {dr:e}");
            assert_eq!(out.stats.samples + out.stats.dropped, 64 * 64 * 16);
            let occupancy = out.stats.rays as f64 / out.stats.lane_slots as f64;
            assert!(
                occupancy > 0.5 && occupancy <= 1.0,
                "{name}: occupancy {occupancy}"
            );
            println!(
                "{name} at {}: {} of {n} pixels identical, mean lane occupancy {occupancy:.3}",
                lanes.describe(),
                img0.pixels
                    .iter()
                    .zip(&img.pixels)
                    .filter(|(a, b)| a == b)
                    .count()
            );
        }
    }
    assert!(compared >= 8, "only {compared} scene/width pairs compared");
}

/// The same width gives the same bits on one thread or several.
#[test]
fn a_width_is_deterministic_across_thread_counts() {
    let scene = common::render::scene_file(
        Path::new("scenes/cornell.ron"),
        &[
            ("render.width", "48"),
            ("render.height", "40"),
            ("render.spp", "8"),
        ],
    );
    for lanes in [Lanes::portable(8), Lanes::auto()] {
        let pool = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
        };
        let one = pool(1).install(|| run(&scene, lanes)).image();
        let three = pool(3).install(|| run(&scene, lanes)).image();
        assert!(
            one.pixels == three.pixels,
            "{}: 1 and 3 threads differ",
            lanes.describe()
        );
    }
}
