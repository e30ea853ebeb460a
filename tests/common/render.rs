//! Rendering helpers shared by the integration tests.

use prism::film::Image;
use prism::integrator::{RenderOptions, RenderOutput, render};
use prism::kdtree::KdParams;
use prism::scene::RenderScene;
use prism::scene_file::load_str;
use prism::systems::prepare;
use std::path::Path;

/// The estimator these helpers render with unless a scene or an override names one: the
/// tests that use them check the path tracer's kernels, which `Auto` would replace by BDPT on
/// scenes with caustics.
const KIND: &str = "render.integrator.kind";

/// Parses scene text (as if it lived in `scenes/`) and runs the systems, with the path
/// tracer unless the text names an estimator.
pub fn scene(text: &str) -> RenderScene {
    let pin = [(KIND.to_string(), "Path".to_string())];
    let o: &[(String, String)] = if text.contains("kind:") { &[] } else { &pin };
    let loaded = load_str(text, Path::new("scenes/test.ron"), o).expect("test scene parses");
    prepare(&loaded, &KdParams::default())
}

/// Loads a scene file with `overrides`, with the path tracer unless they name an estimator.
pub fn scene_file(path: &Path, overrides: &[(&str, &str)]) -> RenderScene {
    let mut o: Vec<(String, String)> = overrides
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    if !o.iter().any(|(k, _)| k == KIND) {
        o.insert(0, (KIND.to_string(), "Path".to_string()));
    }
    let loaded = prism::scene_file::load(path, &o).expect("scene loads");
    prepare(&loaded, &KdParams::default())
}

pub fn run(scene: &RenderScene) -> RenderOutput {
    run_at(scene, prism::simd::Lanes::auto())
}

/// [`run`] at a given lane width.
#[allow(dead_code)]
pub fn run_at(scene: &RenderScene, lanes: prism::simd::Lanes) -> RenderOutput {
    render(
        scene,
        &RenderOptions::new(scene.settings.spp, lanes),
        &|_| {},
    )
}

pub fn image(text: &str) -> Image {
    run(&scene(text)).image()
}

/// Mean of one channel over the pixels selected by `keep(x, y)`.
pub fn mean_where(img: &Image, c: usize, keep: impl Fn(u32, u32) -> bool) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for y in 0..img.height {
        for x in 0..img.width {
            if keep(x, y) {
                s += img.pixels[(y * img.width + x) as usize][c] as f64;
                n += 1;
            }
        }
    }
    assert!(n > 0, "no pixel selected");
    s / n as f64
}

/// The image mean of channel 0 over 8 seeds (100 to 107) of `scene(seed)`, and the variance
/// of that mean.
pub fn seeds_mean(scene: impl Fn(u32) -> String) -> (f64, f64) {
    let v: Vec<f64> = (0..8)
        .map(|s| mean_where(&image(&scene(100 + s)), 0, |_, _| true))
        .collect();
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
    (mean, var / v.len() as f64)
}

/// Two estimators of the same image, over 8 seeds each: their means and the z-score of their
/// difference.
pub fn z_between(a: impl Fn(u32) -> String, b: impl Fn(u32) -> String) -> (f64, f64, f64) {
    let ((ma, va), (mb, vb)) = (seeds_mean(a), seeds_mean(b));
    (ma, mb, (ma - mb) / (va + vb).sqrt())
}
