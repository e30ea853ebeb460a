//! Furnace and analytic-radiance tests: scenes whose radiance is known in closed form.

mod common;
use common::render::{image, mean_where};

/// A camera at distance 4 looking at a unit sphere; 32×32 pixels, fov 30°: the sphere covers
/// the central disc of radius ~15 px.
fn furnace(material: &str, env: f32, spp: u32, extra: &str) -> String {
    format!(
        r#"#![enable(implicit_some)]
Scene(
    render: (width: 32, height: 32, spp: {spp}, max_depth: 64, seed: 7, integrator: (rr_depth: 3{extra})),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    environment: Constant(Rgb({env}, {env}, {env})),
    entities: [ (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), material: {material}) ],
)"#
    )
}

/// Pixels whose centre ray hits the sphere well inside its silhouette.
fn on_sphere(x: u32, y: u32) -> bool {
    let (dx, dy) = (x as f32 + 0.5 - 16.0, y as f32 + 0.5 - 16.0);
    // Sphere radius in pixels: tan(asin(1/4)) / tan(15°) × 16 ≈ 15.4.
    (dx * dx + dy * dy).sqrt() < 12.0
}

// Each test checks the image mean: with ≥ 32·32·64 samples its standard error is far below
// the 1 % tolerance, so a failure means bias (lost or created energy), not noise.
fn assert_furnace(material: &str, expect_sphere: f64, extra: &str) {
    let l = 0.8f32;
    let img = image(&furnace(material, l, 64, extra));
    for c in 0..3 {
        let all = mean_where(&img, c, |_, _| true);
        let sphere = mean_where(&img, c, on_sphere);
        // Corner pixels: more than a filter radius away from the silhouette.
        let bg = mean_where(&img, c, |x, y| {
            !(3..=28).contains(&x) && !(3..=28).contains(&y)
        });
        assert!((bg / l as f64 - 1.0).abs() < 1e-6, "background {bg}");
        assert!(
            (sphere / (expect_sphere * l as f64) - 1.0).abs() < 0.01,
            "{material}: sphere mean {sphere}, expected {}",
            expect_sphere * l as f64
        );
        assert!(all.is_finite());
    }
}

#[test]
fn white_lambertian_sphere_disappears() {
    assert_furnace("Diffuse(albedo: Rgb(1.0, 1.0, 1.0))", 1.0, "");
}

#[test]
fn white_lambertian_sphere_disappears_without_light_sampling() {
    assert_furnace(
        "Diffuse(albedo: Rgb(1.0, 1.0, 1.0))",
        1.0,
        ", light_sampling: Path",
    );
}

#[test]
fn mirror_sphere_disappears() {
    assert_furnace("Mirror(tint: Rgb(1.0, 1.0, 1.0))", 1.0, "");
}

#[test]
fn glass_sphere_disappears() {
    assert_furnace("Dielectric(ior: Constant(1.5))", 1.0, "");
    assert_furnace("Dielectric(ior: Constant(2.4))", 1.0, ", fresnel: Schlick");
}

#[test]
fn grey_sphere_renders_albedo_times_environment() {
    // A convex sphere sees only the environment: one bounce, radiance ρL.
    assert_furnace("Diffuse(albedo: Rgb(0.5, 0.5, 0.5))", 0.5, "");
    assert_furnace(
        "Diffuse(albedo: Rgb(0.25, 0.25, 0.25))",
        0.25,
        ", light_sampling: Path",
    );
}

/// A diffuse sphere of albedo ρ inside a two-sided emitting sphere of radiance Le: the inner
/// sphere's irradiance is π·Le from every direction, so it reflects ρ·Le.
fn enclosed(rho: f32, mode: &str) -> f64 {
    let text = format!(
        r#"#![enable(implicit_some)]
Scene(
    render: (width: 32, height: 32, spp: 64, max_depth: 8, seed: 3, integrator: (light_sampling: {mode})),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    entities: [
        (name: "inner", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), material: Diffuse(albedo: Rgb({rho}, {rho}, {rho}))),
        (name: "shell", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 10.0), material: Light(emission: Rgb(2.0, 2.0, 2.0), two_sided: true)),
    ],
)"#
    );
    let img = image(&text);
    let shell = mean_where(&img, 1, |x, y| x < 2 && y < 2);
    assert!((shell - 2.0).abs() < 1e-6, "shell {shell}");
    mean_where(&img, 1, on_sphere)
}

#[test]
fn sphere_inside_emitting_sphere_with_light_sampling() {
    for rho in [0.3f32, 0.9] {
        let m = enclosed(rho, "Nee");
        assert!(
            (m / (rho as f64 * 2.0) - 1.0).abs() < 0.01,
            "rho {rho}: {m}"
        );
    }
}

#[test]
fn sphere_inside_emitting_sphere_by_path_tracing() {
    let m = enclosed(0.6, "Path");
    assert!((m / 1.2 - 1.0).abs() < 0.01, "{m}");
}

/// BDPT in the furnace: light paths start on the white environment (a disc at infinity) and
/// every strategy is weighted against the others; the spheres still vanish.
#[test]
fn spheres_disappear_under_bdpt() {
    let bdpt = ", kind: Bdpt";
    assert_furnace("Diffuse(albedo: Rgb(1.0, 1.0, 1.0))", 1.0, bdpt);
    assert_furnace("Mirror(tint: Rgb(1.0, 1.0, 1.0))", 1.0, bdpt);
    assert_furnace("Dielectric(ior: Constant(1.5))", 1.0, bdpt);
    assert_furnace("Diffuse(albedo: Rgb(0.5, 0.5, 0.5))", 0.5, bdpt);
}

/// Light tracing in the furnace: a white diffuse sphere, lit only by paths from the
/// environment's disc, vanishes against the environment the camera sees directly.
#[test]
fn white_sphere_disappears_under_light_tracing() {
    assert_furnace(
        "Diffuse(albedo: Rgb(1.0, 1.0, 1.0))",
        1.0,
        ", kind: LightTracing",
    );
}
