//! Light tracing against the path tracer: the same image within noise, pixel by pixel, on
//! scenes of every emitter kind, a thin lens, motion, textures with normal maps and glossy
//! materials, media; the same bits on any thread count; a target error from the command line.

mod common;

use assert_cmd::cargo::CommandCargoExt;
use common::estimators::{
    GLOSSY, GREY_SKY, LAMPS, NO_SKY, OUTDOOR, STUDIO_MAP, THIN_LENS, agree, batch, load,
    rough_fog_box, side,
};
use std::process::Command;

/// The path tracer (`path_spp` per batch) and light tracing (`light_spp`) on every pixel.
fn agreement(
    name: &str,
    text: &str,
    size: u32,
    overrides: &[(&str, &str)],
    path_spp: u32,
    light_spp: u32,
) {
    let (a, b) = (side("Path", path_spp), side("LightTracing", light_spp));
    agree(name, text, size, overrides, a, b, None);
}

/// Diffuse walls under a one-sided area light.
#[test]
fn cornell_box() {
    agreement("cornell", "cornell.ron", 48, &[], 32, 32);
}

#[test]
fn every_emitter_kind_in_spectral_transport() {
    agreement("lamps", LAMPS, 48, &[], 32, 32);
}

/// A thin lens with a hexagonal aperture, focused on the ball.
#[test]
fn thin_lens() {
    agreement("thin lens", LAMPS, 48, &THIN_LENS, 32, 32);
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

#[test]
fn glossy_materials() {
    agreement("glossy", GLOSSY, 48, &[], 32, 128);
}

/// Paths from a disc at infinity: the spectral sky and its sun, an environment map, a
/// constant environment; the camera sees the environment itself along its rays. The ball is
/// diffuse here: light tracing finds a glossy reflection of a bright environment only through
/// rare light paths, an error too heavy-tailed for the z-test's variance estimate (at 8,192
/// samples per pixel some of the plastic ball's pixels still err by 10 to 25 %).
#[test]
fn environment_lights() {
    let ball = (
        r#"entities["ball"].material"#,
        "Diffuse(albedo: Rgb(0.1, 0.3, 0.6))",
    );
    agreement("sky and sun", OUTDOOR, 32, &[ball], 32, 64);
    agreement("environment map", OUTDOOR, 32, &[ball, STUDIO_MAP], 32, 64);
    agreement(
        "constant environment",
        OUTDOOR,
        32,
        &[ball, GREY_SKY],
        32,
        64,
    );
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

/// Media: light paths scatter in fog and in a rough glass ball's medium and connect to the
/// camera through both, from lights outside and inside the fog. (With the camera inside a
/// scattering medium, points that scatter next to the lens splat ∝ 1/r²: light tracing's
/// variance is unbounded there, and a z-test of its batches meaningless.)
#[test]
fn media() {
    agreement("fog box", &rough_fog_box(), 32, &[NO_SKY], 32, 32);
}

/// A target error renders from the command line too (uniform counts to the target,
/// `tests/target_error.rs`), with the sample-count and error channels in the EXR.
#[test]
fn a_target_error_renders() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("x.exr");
    let out = Command::cargo_bin("prism")
        .unwrap()
        .args(["render", "scenes/cornell.ron", "--quiet", "-o"])
        .arg(&out_path)
        .args(["--set", "render.integrator.kind=LightTracing"])
        .args(["--target-error", "0.05", "--size", "16x16"])
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{err}");
    let (_, _, aux) = prism::film::read_image_aux(&out_path).unwrap();
    let counts = aux.count.expect("a count channel");
    assert!(
        counts.iter().all(|&n| n == counts[0] && n % 2 == 0),
        "{counts:?}"
    );
    assert_eq!(aux.error.expect("an error channel").len(), 16 * 16);
}
