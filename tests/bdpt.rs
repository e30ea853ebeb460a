//! Bidirectional path tracing against the path tracer and light tracing, pixel by pixel: the
//! same image within noise on scenes of every emitter kind, a thin lens, motion, textures with
//! normal maps, glossy materials and media; on caustic scenes (a glass ball, the smooth-shaded
//! glass bunny, a dispersive ball) against light tracing where both see the same paths; each
//! strategy alone converging to the same image; the same bits on any thread count.

mod common;

use assert_cmd::cargo::CommandCargoExt;
use common::estimators::{
    FOG_BOX, GLOSSY, GREY_SKY, LAMPS, NO_SKY, OUTDOOR, STUDIO_MAP, Side, THIN_LENS, agree, batch,
    load, rough_fog_box, side,
};
use prism::components::Material;
use prism::geometry::Ray;
use std::process::Command;

/// The path tracer (`path_spp` per batch) and BDPT (`bdpt_spp`) on every pixel.
fn against_path(
    name: &str,
    text: &str,
    size: u32,
    overrides: &[(&str, &str)],
    path_spp: u32,
    bdpt_spp: u32,
) {
    let (a, b) = (side("Path", path_spp), side("Bdpt", bdpt_spp));
    agree(name, text, size, overrides, a, b, None);
}

/// Diffuse walls under a one-sided area light.
#[test]
fn cornell_box() {
    against_path("cornell", "cornell.ron", 32, &[], 32, 16);
}

#[test]
fn every_emitter_kind_in_spectral_transport() {
    against_path("lamps", LAMPS, 32, &[], 32, 16);
}

/// The camera vertex lies on a hexagonal thin lens.
#[test]
fn thin_lens() {
    against_path("thin lens", LAMPS, 32, &THIN_LENS, 32, 16);
}

/// One time per pair of subpaths, moving objects within the shutter.
#[test]
fn motion_blur() {
    against_path("motion blur", "motion_blur.ron", 32, &[NO_SKY], 32, 16);
}

/// Normal maps: shading normals on both subpaths (the adjoint correction on the light's).
#[test]
fn textures_and_normal_maps() {
    against_path("textures", "textures.ron", 32, &[NO_SKY], 32, 16);
}

/// Rough plastics, a rough dielectric (connections through it) and an anisotropic rough
/// conductor.
#[test]
fn glossy_materials() {
    against_path("glossy", GLOSSY, 32, &[], 32, 16);
}

/// Light paths from the environment (a disc at infinity): the spectral sky and its sun, an
/// importance-sampled map and a constant environment, every strategy.
#[test]
fn environment_lights() {
    against_path("sky and sun", OUTDOOR, 24, &[], 32, 16);
    against_path("environment map", OUTDOOR, 24, &[STUDIO_MAP], 32, 16);
    against_path("constant environment", OUTDOOR, 24, &[GREY_SKY], 32, 16);
}

/// The pixels of `text` at `size`² whose filter footprint sees no delta surface (dielectric,
/// mirror, conductor) first, through media's boundaries: there light tracing reaches every path BDPT does. Camera rays
/// through a 5 × 5 grid over the two pixels of the tent's reach, at the shutter's opening.
fn diffuse_first(text: &str, size: u32, overrides: &[(&str, &str)]) -> Vec<bool> {
    let rs = load(text, size, overrides);
    let c = &rs.camera;
    let n = size as f32;
    let seen_delta = |fx: f32, fy: f32| {
        let (sx, sy) = (2.0 * fx / n - 1.0, 1.0 - 2.0 * fy / n);
        let d = (c.forward + c.right * (sx * c.half.x) + c.up * (sy * c.half.y)).normalize();
        let mut o = c.origin;
        // Through media's boundaries, which do not scatter.
        for _ in 0..8 {
            let Some(h) = rs.intersect::<true>(&Ray::new(o, d), f32::INFINITY, rs.shutter.0) else {
                return false;
            };
            let m = rs.prims.materials[rs.prims.material[h.prim as usize] as usize];
            if m != Material::Boundary {
                return matches!(
                    m,
                    Material::Dielectric { .. }
                        | Material::Mirror { .. }
                        | Material::Conductor { .. }
                );
            }
            o += d * (h.t + 1e-4);
        }
        false
    };
    (0..size * size)
        .map(|i| {
            let (x, y) = ((i % size) as f32 + 0.5, (i / size) as f32 + 0.5);
            (0..25).all(|k| {
                let (dx, dy) = ((k % 5) as f32 * 0.5 - 1.0, (k / 5) as f32 * 0.5 - 1.0);
                !seen_delta(x + dx, y + dy)
            })
        })
        .collect()
}

/// Light tracing (`light_spp`) and BDPT (`bdpt_spp`) where the camera sees no delta surface
/// first: caustics, which the path tracer finds only by chance (its per-pixel error is
/// heavy-tailed there, and its variance estimate too low).
fn against_light(name: &str, text: &str, size: u32, light_spp: u32, bdpt_spp: u32) {
    against_light_with(name, text, size, &[NO_SKY], light_spp, bdpt_spp);
}

/// [`against_light`] with `o` as the overrides.
fn against_light_with(
    name: &str,
    text: &str,
    size: u32,
    o: &[(&str, &str)],
    light_spp: u32,
    bdpt_spp: u32,
) {
    let mask = diffuse_first(text, size, o);
    let kept = mask.iter().filter(|&&m| m).count();
    assert!(kept * 3 >= mask.len(), "{name}: only {kept} pixels kept");
    let (a, b) = (side("LightTracing", light_spp), side("Bdpt", bdpt_spp));
    agree(name, text, size, o, a, b, Some(&mask));
}

/// A small lamp's caustic through a glass ball.
#[test]
fn caustics() {
    against_light("caustics", "caustics.ron", 24, 64, 64);
}

/// The smooth-shaded glass bunny: interpolated normals on a refracting mesh.
#[test]
fn smooth_shaded_glass_bunny() {
    against_light("glass bunny", "glass_bunny.ron", 24, 32, 16);
}

/// A dispersive glass ball's coloured caustic: a connection keeps the hero wavelength alone
/// once either subpath has crossed the glass.
const DISPERSIVE: &str = r#"Scene(
    render: (width: 24, height: 24, spp: 16, max_depth: 8, seed: 1),
    camera: (position: (0.0, 2.2, -3.0), look_at: (0.0, 0.3, 0.2), fov_y: 40.0),
    entities: [
        (name: "lamp", shape: Rect(center: (-0.6, 2.5, 0.0), u: (0.3, 0.0, 0.0), v: (0.0, 0.0, 0.3)),
         material: Light(emission: Rgb(60.0, 60.0, 60.0))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (4.0, 0.0, 0.0), v: (0.0, 0.0, -4.0)),
         material: Diffuse(albedo: Rgb(0.8, 0.8, 0.8))),
        (name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5),
         material: Dielectric(ior: Cauchy(a: 1.6, b: 0.04))),
    ],
)"#;

#[test]
fn dispersion() {
    against_light("dispersion", DISPERSIVE, 24, 32, 16);
}

/// The sun's caustic through a glass ball, and the sky seen past it.
const SUN_CAUSTIC: &str = r#"Scene(
    render: (width: 24, height: 24, spp: 16, max_depth: 8, seed: 1),
    camera: (position: (0.0, 2.0, -3.0), look_at: (0.0, 0.3, 0.3), fov_y: 45.0),
    environment: Sky(sun_elevation: 60.0, sun_azimuth: 180.0, turbidity: 3.0,
                     ground_albedo: Rgb(0.3, 0.3, 0.3), sun: true, scale: 1.0),
    entities: [
        (name: "ground", shape: Rect(center: (0.0, 0.0, 0.0), u: (2.0, 0.0, 0.0), v: (0.0, 0.0, -2.0)),
         material: Diffuse(albedo: Rgb(0.8, 0.8, 0.8))),
        (name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5),
         material: Dielectric(ior: Constant(1.5))),
    ],
)"#;

#[test]
fn sun_caustic() {
    against_light_with("sun caustic", SUN_CAUSTIC, 24, &[], 32, 16);
}

/// A floor and a wall that stops short of it, lit from above without shadows on what the
/// camera sees: every strategy alone has finite variance (no connection shrinks to zero
/// length) and reaches every pixel.
const OPEN: &str = r#"Scene(
    render: (width: 16, height: 16, spp: 16, max_depth: 6, seed: 1),
    camera: (position: (0.0, 1.2, 3.5), look_at: (0.0, 0.8, -1.5), fov_y: 40.0),
    entities: [
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (3.0, 0.0, 0.0), v: (0.0, 0.0, -3.0)),
         material: Diffuse(albedo: Rgb(0.7, 0.7, 0.7))),
        (name: "wall", shape: Rect(center: (0.0, 1.8, -1.5), u: (3.0, 0.0, 0.0), v: (0.0, 1.5, 0.0)),
         material: Diffuse(albedo: Rgb(0.8, 0.5, 0.3))),
        (name: "panel", shape: Rect(center: (0.0, 2.5, 0.5), u: (1.5, 0.0, 0.0), v: (0.0, 0.0, 1.0)),
         material: Light(emission: Rgb(1.0, 1.0, 1.0))),
    ],
)"#;

/// Each strategy alone, unweighted, renders the paths of its length: paths of two bounces by
/// (0, 4), (2, 2) and (3, 1) agree with (1, 3).
#[test]
fn each_strategy_alone_renders_the_same_paths() {
    let only = |s: u32, t: u32, spp: u32| Side {
        kind: "Bdpt",
        spp,
        strategy: Some((s, t)),
    };
    for (s, t) in [(0, 4), (2, 2), (3, 1)] {
        let name = format!("strategy ({s}, {t}) against (1, 3)");
        agree(&name, OPEN, 24, &[], only(1, 3, 64), only(s, t, 64), None);
    }
}

/// The image is the same bits on one thread and on two: splats are summed in fixed point.
#[test]
fn same_image_on_one_and_two_threads() {
    let rs = load(LAMPS, 24, &[("render.integrator.kind", "Bdpt")]);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| batch(&rs, 4, 0))
    };
    assert_eq!(on(1).pixels, on(2).pixels);
}

/// Media: vertices in fog and in a glass ball's medium, lights outside and inside the fog.
/// Against the path tracer with the ball rough (connections through it into its medium); with
/// it smooth, against light tracing where the camera sees no delta surface first: the path
/// tracer cannot find the light a point or spot light sends through smooth glass (no
/// direction it samples hits a point), which BDPT joins inside the ball.
#[test]
fn media_with_lights_outside_and_inside() {
    let rough = rough_fog_box();
    against_path("fog box, rough glass", &rough, 24, &[NO_SKY], 32, 16);
    against_light_with("fog box, smooth glass", FOG_BOX, 24, &[NO_SKY], 32, 64);
}

/// Media around the camera too: the shipped lamps in fog (area emitters inside the haze).
#[test]
fn media_around_the_camera() {
    let depth = [("render.max_depth", "6")];
    against_path("fog lamps", "fog_lamps.ron", 24, &depth, 32, 16);
}

/// Every shipped scene under every estimator, at 12² and 2 samples per pixel: no NaN or
/// infinite pixel, no dropped sample. (A scene an estimator cannot take yet is path traced.)
#[test]
fn no_nan_and_no_dropped_sample_on_shipped_scenes() {
    use prism::integrator::{RenderOptions, render};
    use prism::scene_file::schema::Estimator;
    let mut names: Vec<_> = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".ron") && !n.starts_with('_'))
        .collect();
    names.sort();
    assert!(names.len() >= 15, "{names:?}");
    for name in &names {
        let mut rs = load(name, 12, &[]);
        for kind in [Estimator::Path, Estimator::LightTracing, Estimator::Bdpt] {
            rs.settings.kind = kind;
            let out = render(
                &rs,
                &RenderOptions::new(2, prism::simd::Lanes::auto()),
                &|_| {},
            );
            let bad = out.image().pixels.iter().flatten().any(|c| !c.is_finite());
            assert!(!bad, "{name} under {kind:?}: a non-finite pixel");
            assert_eq!(
                out.stats.dropped, 0,
                "{name} under {kind:?}: dropped samples"
            );
        }
    }
}

/// `Auto` takes BDPT where a light reaches a specular or dispersive surface and its caustics
/// carry a measured share of what the camera sees; the path tracer elsewhere; `prism info`
/// says which and why.
#[test]
fn auto_chooses_by_the_scene() {
    use prism::integrator::bdpt::choose;
    use prism::scene_file::schema::Estimator;
    let pick = |name: &str, extra: &[(&str, &str)]| {
        let mut o = vec![("render.integrator.kind", "Auto")];
        o.extend_from_slice(extra);
        choose(&load(name, 8, &o))
    };
    // A scene that names no estimator gets `Auto`.
    assert_eq!(load("caustics.ron", 8, &[]).settings.kind, Estimator::Auto);
    let (k, why) = pick("cornell.ron", &[]);
    assert_eq!(k, Estimator::Path, "{why}");
    assert!(why.contains("no light reaches"), "{why}");
    let (k, why) = pick("prism.ron", &[]);
    assert_eq!(k, Estimator::Bdpt, "{why}");
    assert!(
        why.contains(r#"entity "prism": dispersive Dielectric; light "lamp" reaches it"#),
        "{why}"
    );
    let (k, why) = pick("caustics.ron", &[]);
    assert_eq!(k, Estimator::Bdpt, "{why}");
    assert!(why.contains("sphere"), "{why}");
    assert!(why.contains("caustics carry"), "{why}");
    // The caustic beside the ball carries 16 % of the light seen on other surfaces.
    let (k, why) = pick("glass_ball.ron", &[]);
    assert_eq!(k, Estimator::Bdpt, "{why}");
    assert!(why.contains(r#"entity "ball""#), "{why}");
    // The sun shines on a glass sphere that no probe from the sun's scene-wide disc meets.
    for name in ["daylight.ron", "sunset.ron"] {
        let (k, why) = pick(name, &[]);
        assert_eq!(k, Estimator::Bdpt, "{name}: {why}");
        assert!(
            why.contains(r#"entity "glass": smooth Dielectric; the sun shines on it"#),
            "{name}: {why}"
        );
    }
    // A light reaches the glass, but its caustic is a small share of what the camera sees:
    // BDPT loses at equal time there (docs/accuracy.md).
    let (k, why) = pick("glass_bunny.ron", &[]);
    assert_eq!(k, Estimator::Path, "{why}");
    assert!(why.contains("where Bdpt pays"), "{why}");
    // A target error keeps the choice: BDPT renders to it with uniform counts.
    let (k, why) = pick("caustics.ron", &[("render.target_error", "0.05")]);
    assert_eq!(k, Estimator::Bdpt, "{why}");
    // Lamps inside fog: their glow is found from the lights.
    let (k, why) = pick("fog_lamps.ron", &[]);
    assert_eq!(k, Estimator::Bdpt, "{why}");
    assert!(
        why.contains(r#"light "bulb" shines inside the scattering medium of entity "haze""#),
        "{why}"
    );
    let (k, why) = pick("god_rays.ron", &[]);
    assert_eq!(k, Estimator::Bdpt, "{why}");
    assert!(why.contains(r#"point light shines inside"#), "{why}");
    // The same fog without scattering (absorption alone) leaves the choice to the probes, which
    // cross its boundary: no light there reaches a specular surface.
    let (k, why) = pick(
        "fog_lamps.ron",
        &[(r#"entities["haze"].medium.sigma_s"#, "Rgb(0.0, 0.0, 0.0)")],
    );
    assert_eq!(k, Estimator::Path, "{why}");
    assert!(why.contains("no light reaches"), "{why}");
    let out = Command::cargo_bin("prism")
        .unwrap()
        .args([
            "info",
            "scenes/prism.ron",
            "--set",
            "render.integrator.kind=Auto",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains(r#"estimator: Bdpt (Auto: entity "prism": dispersive Dielectric"#),
        "{text}"
    );
}
