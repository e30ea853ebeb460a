//! Participating media in rendered scenes, against closed forms.

mod common;
use common::render::{image, mean_where, run, scene};

fn on_sphere(x: u32, y: u32) -> bool {
    let (dx, dy) = (x as f32 + 0.5 - 16.0, y as f32 + 0.5 - 16.0);
    (dx * dx + dy * dy).sqrt() < 12.0
}

#[test]
fn a_white_medium_in_a_furnace_disappears() {
    // Albedo-1 medium (σa = 0) inside a pure boundary, lit by a constant environment L: every
    // path leaves with radiance L, so the sphere vanishes (within 1 %).
    for g in [-0.5f32, 0.0, 0.7] {
        let img = image(&format!(
            r#"Scene(
    render: (width: 32, height: 32, spp: 64, max_depth: 256, seed: 3, integrator: (rr_depth: 5)),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    environment: Constant(Rgb(0.8, 0.8, 0.8)),
    entities: [ (name: "cloud", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
                 medium: (sigma_a: Rgb(0.0, 0.0, 0.0), sigma_s: Rgb(2.0, 2.0, 2.0), g: {g})) ],
)"#
        ));
        let m = mean_where(&img, 1, on_sphere);
        assert!((m / 0.8 - 1.0).abs() < 0.01, "g {g}: {m}");
    }
}

#[test]
fn an_absorbing_slab_transmits_exp_of_minus_sigma_a_d() {
    // Camera → slab of thickness 1 (σs = 0) → emitter of radiance 1 filling the view.
    let s = r#"Scene(
    render: (width: 32, height: 32, spp: 512, max_depth: 8, seed: 8),
    camera: (position: (0.0, 0.0, 3.0), look_at: (0.0, 0.0, 0.0), fov_y: 20.0),
    entities: [
        (name: "slab", shape: Box(min: (-5.0, -5.0, -0.5), max: (5.0, 5.0, 0.5)),
         medium: (sigma_a: Rgb(0.2, 0.7, 1.5), sigma_s: Rgb(0.0, 0.0, 0.0))),
        (name: "emitter", shape: Rect(center: (0.0, 0.0, -2.0), u: (20.0, 0.0, 0.0), v: (0.0, 20.0, 0.0)),
         material: Light(emission: Rgb(1.0, 1.0, 1.0))),
    ],
)"#;
    let img = image(s);
    // A pixel's ray crosses the slab along 1/cos θ; average the closed form over the pixel
    // centres (the film filter averages a function this smooth to the same within 1e-5).
    let half = (10.0f64).to_radians().tan();
    let path = |x: u32, y: u32| {
        let sx = (2.0 * (x as f64 + 0.5) / 32.0 - 1.0) * half;
        let sy = (2.0 * (y as f64 + 0.5) / 32.0 - 1.0) * half;
        (1.0 + sx * sx + sy * sy).sqrt()
    };
    for (c, sa) in [0.2f64, 0.7, 1.5].into_iter().enumerate() {
        let mut expect = 0.0;
        for y in 0..32 {
            for x in 0..32 {
                expect += (-sa * path(x, y)).exp() / 1024.0;
            }
        }
        let m = mean_where(&img, c, |_, _| true);
        assert!(
            (m / expect - 1.0).abs() < 0.005,
            "channel {c}: {m} vs {expect}"
        );
    }
}

#[test]
fn a_medium_with_no_extinction_changes_nothing() {
    let text = |medium: &str| {
        format!(
            r#"Scene(
    render: (width: 32, height: 32, spp: 32, max_depth: 8, seed: 5),
    camera: (position: (0.0, 1.0, 5.0), look_at: (0.0, 0.5, 0.0), fov_y: 40.0),
    environment: Constant(Rgb(0.3, 0.3, 0.3)),
    entities: [
        {medium}
        (name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5), material: Diffuse(albedo: Rgb(0.7, 0.3, 0.2))),
        (name: "lamp", shape: Rect(center: (0.0, 3.0, 0.0), u: (0.5, 0.0, 0.0), v: (0.0, 0.0, 0.5)), material: Light(emission: Rgb(6.0, 6.0, 6.0))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (5.0, 0.0, 0.0), v: (0.0, 0.0, -5.0)), material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#
        )
    };
    let plain = run(&scene(&text(""))).image();
    let empty = run(&scene(&text(
        r#"(name: "air", shape: Box(min: (-3.0, -0.1, -3.0), max: (3.0, 3.5, 3.0)), medium: (sigma_a: Rgb(0.0, 0.0, 0.0), sigma_s: Rgb(0.0, 0.0, 0.0))),"#,
    )));
    assert_eq!(empty.stats.dropped, 0);
    // The same samples drive both (boundaries only re-spawn rays a rounding step further),
    // so the difference must lie far below the noise between two independent renders.
    let m = prism::film::compare(&empty.image(), &plain).unwrap().relmse;
    let other = run(&scene(&text("").replace("seed: 5", "seed: 6"))).image();
    let noise = prism::film::compare(&other, &plain).unwrap().relmse;
    assert!(m < 0.1 * noise, "{m} vs noise {noise}");
}

#[test]
fn equiangular_sampling_changes_noise_not_the_answer() {
    // A point light over thin fog: with and without equiangular sampling the estimators
    // differ, the expectation does not. The light sits 0.5 above the fog, so no scattering
    // point comes nearer than that and every light sample is bounded: inside the fog, the
    // free-flight estimator's second moment would diverge like ∫ d⁻⁴ near the light, its
    // mean would mostly fall low with rare overshoots, and no tolerance would be safe. Over
    // seeds 10–19 the two image means differ by 0.2 % (one standard deviation), so 1 % is
    // 4.5σ; and the combined estimator is the less noisy one.
    let text = |eq: bool| {
        format!(
            r#"Scene(
    render: (width: 32, height: 32, spp: 128, max_depth: 4, seed: 12, integrator: (equiangular: {eq})),
    camera: (position: (0.0, 1.0, 4.0), look_at: (0.0, 1.0, 0.0), fov_y: 50.0),
    entities: [
        (name: "fog", shape: Box(min: (-3.0, -0.01, -3.0), max: (3.0, 3.0, 5.0)),
         medium: (sigma_a: Rgb(0.02, 0.02, 0.02), sigma_s: Rgb(0.15, 0.15, 0.15), g: 0.3)),
        (name: "bulb", light: Point(position: (0.3, 3.5, 0.0), intensity: Rgb(4.0, 4.0, 4.0))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (3.0, 0.0, 0.0), v: (0.0, 0.0, -3.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#
        )
    };
    let on = image(&text(true));
    let off = image(&text(false));
    let (a, b) = (
        mean_where(&on, 1, |_, _| true),
        mean_where(&off, 1, |_, _| true),
    );
    assert!((a / b - 1.0).abs() < 0.01, "with {a}, without {b}");
    let reference = image(&text(true).replace("spp: 128", "spp: 2048"));
    let e_on = prism::film::compare(&on, &reference).unwrap().relmse;
    let e_off = prism::film::compare(&off, &reference).unwrap().relmse;
    assert!(
        e_on < e_off,
        "equiangular {e_on} vs free-flight only {e_off}"
    );
}
