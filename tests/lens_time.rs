//! Depth of field, motion blur and frame series.

mod common;
use common::render::{image, run, scene, scene_file};
use prism::film::Image;
use prism::scene::Effect;
use std::path::Path;

/// Intensity-weighted centroid and second moments of channel 1 (pixel-centre coordinates).
fn moments(img: &Image) -> (f64, f64, f64, f64, f64) {
    let (mut s, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for y in 0..img.height {
        for x in 0..img.width {
            let v = img.pixels[(y * img.width + x) as usize][1] as f64;
            s += v;
            sx += v * (x as f64 + 0.5);
            sy += v * (y as f64 + 0.5);
        }
    }
    let (cx, cy) = (sx / s, sy / s);
    let (mut vx, mut vy) = (0.0, 0.0);
    for y in 0..img.height {
        for x in 0..img.width {
            let v = img.pixels[(y * img.width + x) as usize][1] as f64;
            vx += v * (x as f64 + 0.5 - cx).powi(2);
            vy += v * (y as f64 + 0.5 - cy).powi(2);
        }
    }
    (s, cx, cy, vx / s, vy / s)
}

/// Variance per axis of the tent filter of radius 1 px: ∫ x² (1 − |x|) dx = 1/6.
const TENT_VAR: f64 = 1.0 / 6.0;

/// Angular radius of the emitter of [`point_image`] in radians: 0.33 px on the film, less than
/// half a pixel, so in focus at a pixel corner only the four pixels around it see it, each
/// with the same probability whatever its size. It is as large as that so enough samples hit
/// it: the measured moments' standard errors fall as one over the square root of the hits.
const POINT_ANGLE: f32 = 0.0012;

/// A small emitter at depth `z` seen through a lens of radius `a` focused at `f`; 96×96 px,
/// 20° vertical field of view, 4096 spp (about 1,400 hits whatever the focus).
fn point_image(z: f32, a: f32, f: f32) -> Image {
    image(&format!(
        r#"Scene(
    render: (width: 96, height: 96, spp: 4096, max_depth: 0, seed: 5),
    camera: (position: (0.0, 0.0, 0.0), look_at: (0.0, 0.0, -1.0), fov_y: 20.0,
             lens: (aperture_radius: {a}, focus_distance: {f})),
    entities: [ (name: "point", shape: Sphere(center: (0.0, 0.0, -{z}), radius: {r}),
                 material: Light(emission: Rgb(1.0, 1.0, 1.0))) ],
)"#,
        r = z * POINT_ANGLE
    ))
}

#[test]
fn a_point_on_the_focal_plane_images_to_a_point() {
    let img = point_image(10.0, 0.5, 10.0);
    let (_, cx, cy, vx, vy) = moments(&img);
    assert!(
        (cx - 48.0).abs() < 0.05 && (cy - 48.0).abs() < 0.05,
        "centre {cx} {cy}"
    );
    // Only the film filter spreads it. The point sits on a pixel corner (the image centre of
    // an even-sized film), so the tent of radius 1 px gives the two pixels on each side
    // weight 1/2 each: variance exactly 1/4 per axis, RMS radius √(1/2) ≈ 0.71 px.
    let rms = (vx + vy).sqrt();
    assert!(rms <= 1.0, "spread {rms} px");
    assert!(
        (vx - 0.25).abs() < 0.01 && (vy - 0.25).abs() < 0.01,
        "{vx} {vy}"
    );
}

#[test]
fn a_point_off_axis_on_the_focal_plane_images_to_a_point() {
    // The focal surface of a thin lens is the plane at `focus_distance` in front of the lens,
    // not a sphere of that radius: a point 30° off axis on the plane (11.5 units away) must be
    // as sharp as one on the axis. Were the focus a sphere, a lens of radius 4 would spread
    // it over a disc of about 3 px radius.
    let (f, a) = (10.0f32, 4.0f32);
    let x = f * 30f32.to_radians().tan();
    let img = image(&format!(
        r#"Scene(
    render: (width: 96, height: 96, spp: 4096, max_depth: 0, seed: 5),
    camera: (position: (0.0, 0.0, 0.0), look_at: (0.0, 0.0, -1.0), fov_y: 90.0,
             lens: (aperture_radius: {a}, focus_distance: {f})),
    entities: [ (name: "point", shape: Sphere(center: ({x}, 0.0, -{f}), radius: 0.08),
                 material: Light(emission: Rgb(1.0, 1.0, 1.0))) ],
)"#
    ));
    let (_, cx, cy, vx, vy) = moments(&img);
    // Pinhole image of the point: x_ndc = tan 30° / tan 45°, 48 px per unit.
    let expect_x = 48.0 + f64::from(30f32.to_radians().tan()) * 48.0;
    assert!(
        (cx - expect_x).abs() < 0.1 && (cy - 48.0).abs() < 0.1,
        "centre {cx} {cy}, expected {expect_x} 48"
    );
    // The tent filter gives at most 1/4 per axis (t(1 − t) for a point at t within a pixel),
    // the emitter's own image (0.44 px radius along x, 0.38 along y) under 0.05: at most
    // 0.77 px together.
    let rms = (vx + vy).sqrt();
    assert!(rms <= 1.0, "spread {rms} px (vx {vx}, vy {vy})");
}

#[test]
fn a_point_off_the_focal_plane_images_to_the_circle_of_confusion() {
    let (a, f, z) = (0.25f64, 10.0f64, 5.0f64);
    let img = point_image(z as f32, a as f32, f as f32);
    // Thin lens: rays through the lens point l cross the focal plane at l·(1 − f/z) from the
    // pinhole image, so the disc on the film has radius a·|1 − f/z| / (f·tan(fov/2)) · H/2.
    let half = (10.0f64).to_radians().tan();
    let r_px = a * (1.0 - f / z).abs() / (f * half) * 48.0;
    let (_, _, _, vx, vy) = moments(&img);
    // A uniform disc of radius R has variance R²/4 per axis; the tent filter adds its own, and
    // the emitter's own image (radius ρ) its ρ²/4.
    let rho = f64::from(POINT_ANGLE) / (half / 48.0);
    let r_measured = (2.0 * (vx + vy - 2.0 * TENT_VAR - rho * rho / 2.0)).sqrt();
    assert!(
        r_px > 5.0,
        "the test needs a disc of several pixels: {r_px}"
    );
    assert!(
        (2.0 * r_measured / (2.0 * r_px) - 1.0).abs() < 0.05,
        "diameter {} px, thin lens predicts {} px",
        2.0 * r_measured,
        2.0 * r_px
    );
}

/// An emissive disc facing the camera, moving along x by `v` units per frame.
fn moving_disc(v: f32) -> String {
    format!(
        r#"Scene(
    render: (width: 128, height: 64, spp: 256, max_depth: 0, seed: 9),
    camera: (position: (0.0, 0.0, 10.0), look_at: (0.0, 0.0, 0.0), fov_y: 20.0,
             shutter: (open: 0.0, close: 0.5)),
    entities: [ (name: "disc", shape: Disk(center: (-0.8, 0.0, 0.0), normal: (0.0, 0.0, 1.0), radius: 0.3),
                 material: Light(emission: Rgb(1.0, 1.0, 1.0)),
                 motion: (velocity: ({v}, 0.0, 0.0))) ],
)"#
    )
}

#[test]
fn motion_blur_keeps_energy_and_streaks_by_the_displacement() {
    let still = image(&moving_disc(0.0));
    let moving = image(&moving_disc(2.4));
    let (s0, cx0, cy0, vx0, _) = moments(&still);
    let (s1, cx1, cy1, vx1, _) = moments(&moving);
    assert!((s1 / s0 - 1.0).abs() < 0.01, "image integral {s1} vs {s0}");
    // Over half a frame the disc moves 1.2 units; the image plane at distance 10 with a 20°
    // field over 64 px maps one unit to 32 / (10 tan 10°) px.
    let px_per_unit = 32.0 / (10.0 * (10.0f64).to_radians().tan());
    let d = 1.2 * px_per_unit;
    assert!(
        (cx1 - cx0 - d / 2.0).abs() < 0.25,
        "centroid moved {} px, expected {}",
        cx1 - cx0,
        d / 2.0
    );
    assert!((cy1 - cy0).abs() < 0.05);
    // Uniform motion convolves the image with a box of width d: variance grows by d²/12.
    let grown = vx1 - vx0;
    assert!(
        (grown / (d * d / 12.0) - 1.0).abs() < 0.05,
        "streak variance {grown}, expected {}",
        d * d / 12.0
    );
}

#[test]
fn static_pinhole_scenes_draw_no_lens_or_time_samples() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let s = scene_file(
        &path,
        &[
            ("render.width", "24"),
            ("render.height", "24"),
            ("render.spp", "8"),
        ],
    );
    assert!(!s.effects.has(Effect::Lens) && !s.effects.has(Effect::Motion));
    // The image is bit for bit the one the renderer made before lens and time sampling
    // existed: absent effects leave every other sample dimension where it was.
    let out = run(&s);
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in out.image().pixels {
        for c in p {
            for b in c.to_bits().to_le_bytes() {
                h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    assert_eq!(h, GOLDEN_CORNELL_24, "{h:#x}");
}

/// Hash of the pixels of `cornell.ron` at 24×24 and 8 spp. It was first taken before the LENS
/// and MOTION effects existed, and again when the sampler moved to 32-bit lane hashes and the BSDFs to the
/// local shading frame; a
/// change that shifts any sample dimension changes it.
const GOLDEN_CORNELL_24: u64 = 0xbcbd_2f59_a431_6ccd;

#[test]
fn forcing_motion_on_a_static_scene_changes_nothing() {
    let text = moving_disc(0.0);
    let mut a = scene(&text);
    let plain = run(&a);
    a.effects.force(Effect::Motion).unwrap();
    let forced = run(&a);
    assert_eq!(plain.sums, forced.sums);
}

/// A small emitter (radius 0.2 px) whose image is centred at (15.75, 15.75) on a 32×32 film:
/// 0.25 px right of and below pixel (15, 15)'s centre, wholly inside that pixel.
fn off_centre_point(filter: &str) -> Image {
    let px = 2.0 * 10f32.to_radians().tan() / 32.0 * 10.0;
    image(&format!(
        r#"Scene(
    render: (width: 32, height: 32, spp: 4096, max_depth: 0, seed: 3, filter: {filter}),
    camera: (position: (0.0, 0.0, 0.0), look_at: (0.0, 0.0, -1.0), fov_y: 20.0),
    entities: [ (name: "point", shape: Sphere(center: ({x}, {y}, -10.0), radius: {r}),
                 material: Light(emission: Rgb(1.0, 1.0, 1.0))) ],
)"#,
        x = -0.25 * px,
        y = 0.25 * px,
        r = 0.2 * px
    ))
}

#[test]
fn a_box_filter_keeps_a_point_in_its_pixel_and_the_tent_spreads_it() {
    // Box: only pixel (15, 15) draws samples over the emitter, so the pixel-centre moments
    // have no spread at all. Tent: pixels 15 and 16 of each axis see it with the tent's
    // weights at 0.25 and 0.75 px, 3/4 and 1/4 (the tent is linear over the emitter), so the
    // variance per axis is 3/16, and the centroid sits on the emitter.
    let boxed = moments(&off_centre_point("Box"));
    let tent = moments(&off_centre_point("Tent"));
    assert!(boxed.3 < 1e-9 && boxed.4 < 1e-9, "box spread {boxed:?}");
    assert!((boxed.1 - 15.5).abs() < 1e-9 && (boxed.2 - 15.5).abs() < 1e-9);
    // About 500 hits (π·0.2² of 4096 samples): the far pixel's share is 1/4 ± 0.02 (1σ), so
    // 0.06 is 3σ for the centroid and 6σ for the variance (3/16 ± 0.01).
    assert!(
        (tent.3 - 0.1875).abs() < 0.06 && (tent.4 - 0.1875).abs() < 0.06,
        "{tent:?}"
    );
    assert!(
        (tent.1 - 15.75).abs() < 0.06 && (tent.2 - 15.75).abs() < 0.06,
        "{tent:?}"
    );
    // Both filters integrate to one: the same power reaches the film (two counts of about
    // 500 hits: 20 % is over 3σ).
    assert!(
        (tent.0 / boxed.0 - 1.0).abs() < 0.2,
        "{} vs {}",
        tent.0,
        boxed.0
    );
}
