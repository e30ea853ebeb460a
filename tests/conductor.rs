//! Conductors in the renderer: a white rough conductor in a white furnace reflects exactly the
//! single-scattering albedo of GGX (the f64 quadrature of `microfacet::ggx_albedo`) without
//! compensation and all the light with it, a smooth one is a mirror, light sampling and BSDF sampling agree on a lit rough sphere, and measured metals
//! render in both transports.

mod common;
use common::furnace::{sphere_mean, sphere_mean_in};
use common::render::z_between;
use prism::integrator::microfacet::ggx_average_albedo;

/// The geometry the furnace relies on: a black sphere removes exactly its disc's share of
/// the environment.
#[test]
fn far_sphere_covers_its_predicted_area() {
    let m = sphere_mean("Diffuse(albedo: Rgb(0.0, 0.0, 0.0))", 4, 1, "");
    for c in m {
        assert!(c.abs() < 2e-3, "black sphere renders {c}");
    }
}

/// Without energy compensation a white rough conductor reflects E(μ) of a single scattering,
/// so its disc's mean is E_avg(α); a smooth one is a perfect mirror.
#[test]
fn white_furnace_gives_the_single_scattering_albedo() {
    for (alpha, spp) in [(0.3, 32), (0.6, 64), (1.0, 64)] {
        let want = ggx_average_albedo(alpha);
        // Single scattering loses up to ~60 % at α = 1 (Heitz 2016, Kulla & Conty 2017).
        assert!(want < 1.0 && want > 0.35, "E_avg({alpha}) = {want}");
        let got = sphere_mean(
            &format!(
                "Conductor(reflectance: Rgb(1.0, 1.0, 1.0), alpha: {alpha}, multiscatter: false)"
            ),
            spp,
            1,
            "",
        );
        for c in got {
            assert!(
                (c / want - 1.0).abs() < 0.01,
                "α = {alpha}: sphere mean {c}, E_avg = {want}"
            );
        }
    }
    for m in [
        "Conductor(reflectance: Rgb(1.0, 1.0, 1.0))",
        "Conductor(eta: Rgb(0.2, 0.9, 1.3), k: Rgb(3.0, 2.0, 1.5), alpha: 0.0)",
    ] {
        let got = sphere_mean(m, 4, 1, "");
        let mirror = m.contains("reflectance");
        for c in got {
            if mirror {
                assert!((c - 1.0).abs() < 2e-3, "{m}: {c}");
            } else {
                assert!(c > 0.3 && c < 1.0, "{m}: {c}");
            }
        }
    }
}

/// With multiple-scattering compensation (the default) a white conductor reflects all the
/// light at every roughness: the sphere vanishes in the furnace, to the tables' 1 %.
#[test]
fn compensated_white_conductor_vanishes_in_the_furnace() {
    for (alpha, spp) in [(0.1, 32), (0.3, 32), (0.6, 64), (1.0, 64)] {
        let got = sphere_mean(
            &format!("Conductor(reflectance: Rgb(1.0, 1.0, 1.0), alpha: {alpha})"),
            spp,
            1,
            "",
        );
        for c in got {
            assert!((c - 1.0).abs() < 0.01, "α = {alpha}: sphere mean {c}");
        }
    }
    // A coloured metal keeps its colour and gains energy: more than single scattering, less
    // than one.
    let m = |ms: bool| {
        format!(
            "Conductor(eta: Rgb(0.2, 0.92, 1.1), k: Rgb(3.9, 2.45, 2.14), alpha: 0.8, multiscatter: {ms})"
        )
    };
    let (on, off) = (
        sphere_mean(&m(true), 32, 1, ""),
        sphere_mean(&m(false), 32, 1, ""),
    );
    for c in 0..3 {
        assert!(on[c] > off[c] * 1.05 && on[c] < 1.0, "{on:?} vs {off:?}");
    }
}

/// Roughness → 0 converges to the smooth conductor: α = 0.002 (the narrowest rough lobe)
/// against α = 0, on a complex IOR whose Fresnel term varies with angle.
#[test]
fn nearly_smooth_agrees_with_smooth() {
    let m =
        |a: f32| format!("Conductor(eta: Rgb(0.2, 0.9, 1.3), k: Rgb(3.0, 2.0, 1.5), alpha: {a})");
    let smooth = sphere_mean(&m(0.0), 16, 1, "");
    let rough = sphere_mean(&m(0.002), 16, 1, "");
    for c in 0..3 {
        assert!(
            (smooth[c] - rough[c]).abs() < 3e-3,
            "{:?} vs {:?}",
            smooth,
            rough
        );
    }
}

/// A rough gold sphere under a small lamp, seen by light sampling with MIS and by BSDF
/// sampling alone: the two estimators of the same image agree (z-test over 8 seeds each).
#[test]
fn light_sampling_and_bsdf_sampling_agree_on_rough_metal() {
    let scene = |alpha: f32, seed: u32, extra: &str| {
        format!(
            r#"#![enable(implicit_some)]
Scene(
    render: (width: 24, height: 24, spp: 16, max_depth: 6, seed: {seed}{extra}),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 32.0),
    entities: [
        (name: "lamp", shape: Rect(center: (1.2, 1.8, 1.5), u: (0.3, 0.0, 0.0), v: (0.0, 0.0, 0.3)),
         transform: (rotate: (0.0, 0.0, 0.0)), material: Light(emission: Rgb(40.0, 40.0, 40.0), two_sided: true)),
        (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
         material: Conductor(metal: Au, alpha: {alpha})),
    ],
)"#
        )
    };
    for alpha in [0.08f32, 0.4] {
        let (a, b, z) = z_between(
            |s| scene(alpha, s, ""),
            |s| scene(alpha, s, ", integrator: (light_sampling: Path)"),
        );
        assert!(a > 0.0 && b > 0.0);
        assert!(
            z.abs() < 4.0,
            "α = {alpha}: MIS {a} vs BSDF only {b}, z = {z}"
        );
    }
}

/// Every named metal renders, finite and coloured as measured, in RGB and spectral
/// transport, and the two transports agree on the metal's brightness.
#[test]
fn measured_metals_render_in_both_transports() {
    for metal in ["Au", "Ag", "Cu", "Al", "Cr", "Ti", "Ni", "Pt"] {
        let m = format!("Conductor(metal: {metal}, alpha: 0.2)");
        let rgb = sphere_mean(&m, 16, 1, "");
        let sp = sphere_mean_in(&m, 16, 1, "", true, 16);
        for c in 0..3 {
            assert!(rgb[c].is_finite() && sp[c].is_finite());
            // Gold's red is near 1 at normal incidence, and compensation restores the rest.
            assert!(rgb[c] > 0.2 && rgb[c] < 1.01, "{metal} RGB {rgb:?}");
            assert!(
                (rgb[c] - sp[c]).abs() < 0.06,
                "{metal}: RGB {rgb:?} vs spectral {sp:?}"
            );
        }
    }
}

/// An anisotropic roughness runs along ∂p/∂u: the highlight of a small lamp on a brushed
/// plane is narrow along the axis with the small α and long along the other, whichever way
/// the plane's u axis points. The same surface written with u along x or along y renders the
/// same narrow-along-x highlight; swapping its α turns the highlight.
#[test]
fn anisotropic_highlight_follows_the_tangent() {
    let image = |u: &str, v: &str, ax: f32, ay: f32| {
        common::render::image(&format!(
            r#"#![enable(implicit_some)]
Scene(
    render: (width: 48, height: 48, spp: 16, max_depth: 2, seed: 5),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 40.0),
    entities: [
        (name: "lamp", shape: Rect(center: (0.0, 0.0, 4.6), u: (0.15, 0.0, 0.0), v: (0.0, 0.15, 0.0)),
         material: Light(emission: Rgb(200.0, 200.0, 200.0), two_sided: true)),
        (name: "plate", shape: Rect(center: (0.0, 0.0, 0.0), u: {u}, v: {v}),
         material: Conductor(reflectance: Rgb(0.9, 0.9, 0.9), alpha: ({ax}, {ay}), multiscatter: false)),
    ],
)"#
        ))
    };
    // Second moments of the image about its centre, along x and along y.
    let moments = |img: &prism::film::Image| {
        let (mut w, mut mx, mut my) = (0.0f64, 0.0f64, 0.0f64);
        for y in 0..img.height {
            for x in 0..img.width {
                let p = f64::from(img.pixels[(y * img.width + x) as usize][0]);
                let dx = f64::from(x) + 0.5 - f64::from(img.width) / 2.0;
                let dy = f64::from(y) + 0.5 - f64::from(img.height) / 2.0;
                w += p;
                mx += p * dx * dx;
                my += p * dy * dy;
            }
        }
        assert!(w > 0.0);
        (mx / w, my / w)
    };
    let (x, y) = ("(3.0, 0.0, 0.0)", "(0.0, 3.0, 0.0)");
    for (what, img) in [
        ("u along x", image(x, y, 0.03, 0.25)),
        ("u along y", image(y, x, 0.25, 0.03)),
    ] {
        let (vx, vy) = moments(&img);
        assert!(vy > 4.0 * vx, "{what}: spread² along x {vx}, along y {vy}");
    }
    let (vx, vy) = moments(&image(x, y, 0.25, 0.03));
    assert!(
        vx > 4.0 * vy,
        "swapped α: spread² along x {vx}, along y {vy}"
    );
}
