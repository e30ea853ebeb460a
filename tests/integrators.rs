//! Determinism across thread counts, and every shipped scene rendering without a dropped
//! sample. (Every width against width 1, the reference: `tests/simd_widths.rs`.)

mod common;
use common::render::{run, scene_file};
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

#[test]
fn same_image_on_one_and_two_threads() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let scene = scene_file(&path, SMALL);
    let render = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| run(&scene))
    };
    let (one, two) = (render(1), render(2));
    assert!(
        one.sums
            .iter()
            .zip(&two.sums)
            .all(|(a, b)| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()))
    );
    let other_seed = scene_file(&path, &[SMALL[0], SMALL[1], SMALL[2], ("render.seed", "2")]);
    assert_ne!(one.sums, run(&other_seed).sums, "the seed matters");
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
        let out = run(&scene);
        assert_eq!(out.stats.dropped, 0, "{}", path.display());
        assert_eq!(out.stats.samples, 64 * 64 * 16);
    }
}
