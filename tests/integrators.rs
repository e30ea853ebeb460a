//! The wavefront integrator against the per-path reference, determinism across thread
//! counts, and every shipped scene rendering without a dropped sample.

mod common;
use common::render::{run, run_at, scene_file};
use prism::integrator::Integrator;
use std::path::{Path, PathBuf};

fn shipped_scenes() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "ron"))
            .collect();
    v.sort();
    assert!(v.len() >= 2, "scenes/ holds the shipped scenes");
    v
}

const SMALL: &[(&str, &str)] = &[
    ("render.width", "48"),
    ("render.height", "48"),
    ("render.spp", "8"),
];

/// Both integrators draw the same samples in the same dimensions, so at width 1 their images
/// agree up to the order in which each pixel's samples are summed (float rounding, ~1e-7
/// relative). Wider packets are held to width 1 by `tests/simd_widths.rs`: there a
/// revolution surface's Newton search may stop at a slightly different point, because the
/// packet walk offers it a different distance limit.
#[test]
fn wavefront_matches_reference_on_every_scene() {
    for path in shipped_scenes() {
        let scene = scene_file(&path, SMALL);
        let a = run_at(&scene, Integrator::Wavefront, prism::simd::Lanes::scalar());
        let b = run(&scene, Integrator::Reference);
        assert_eq!(a.stats.samples, b.stats.samples);
        assert_eq!(a.stats.rays, b.stats.rays, "{}", path.display());
        for (pa, pb) in a.sums.iter().zip(&b.sums) {
            for c in 0..3 {
                let tol = 1e-5 * (1.0 + pa[c].abs());
                assert!(
                    (pa[c] - pb[c]).abs() <= tol,
                    "{}: {} vs {}",
                    path.display(),
                    pa[c],
                    pb[c]
                );
            }
        }
    }
}

#[test]
fn same_image_on_one_and_two_threads() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let scene = scene_file(&path, SMALL);
    let render = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| run(&scene, Integrator::Wavefront))
    };
    let (one, two) = (render(1), render(2));
    assert!(
        one.sums
            .iter()
            .zip(&two.sums)
            .all(|(a, b)| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()))
    );
    let other_seed = scene_file(&path, &[SMALL[0], SMALL[1], SMALL[2], ("render.seed", "2")]);
    assert_ne!(
        one.sums,
        run(&other_seed, Integrator::Wavefront).sums,
        "the seed matters"
    );
}

#[test]
fn every_shipped_scene_renders_without_dropped_samples() {
    for path in shipped_scenes() {
        let scene = scene_file(
            &path,
            &[
                ("render.width", "64"),
                ("render.height", "64"),
                ("render.spp", "16"),
            ],
        );
        let out = run(&scene, Integrator::Wavefront);
        assert_eq!(out.stats.dropped, 0, "{}", path.display());
        assert_eq!(out.stats.samples, 64 * 64 * 16);
    }
}
