//! The daylight sky: the model against Mitsuba 3's `sunsky` tables, the sun's disc and its
//! sampling, the irradiance a plane receives against quadrature, spectral against RGB
//! transport, and located errors.

mod common;

use common::colour::lab;
use common::render::{mean_where, run, scene};
use glam::{Vec2, Vec3};
use prism::scene::sky::{Sky, SkyParams};

fn params(elevation: f32, azimuth: f32, turbidity: f32, albedo: f32, sun: bool) -> SkyParams {
    SkyParams {
        sun_elevation: elevation,
        sun_azimuth: azimuth,
        turbidity,
        ground_albedo: Vec3::splat(albedo),
        sun,
        scale: 1.0,
    }
}

/// `tests/data/sky_mitsuba.csv` (written by `scripts/sky_reference.py` from Mitsuba 3.9's
/// `sunsky` emitter): at 20 directions × 3 settings × 8 wavelengths the sky's radiance is
/// within 2 % of Mitsuba's, and the sun's (its disc's radiance at 3 settings) within 1 %.
/// Both evaluate the same fitted model; the sun differs by Mitsuba's single-precision solid
/// angle (0.2 %).
#[test]
fn sky_and_sun_match_mitsuba_sunsky() {
    let text = include_str!("data/sky_mitsuba.csv");
    let (mut sky_rows, mut sun_rows) = (0, 0);
    let mut worst = [(0.0f32, String::new()), (0.0f32, String::new())];
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let v: Vec<f32> = f[1..].iter().map(|x| x.parse().unwrap()).collect();
        let p = params(v[0], v[1], v[2], v[3], true);
        let sky = Sky::new(p);
        let d = Vec3::new(v[4], v[5], v[6]).normalize();
        let (lambda, expect) = (v[7], v[8]);
        let (got, tol) = match f[0] {
            "sky" => {
                sky_rows += 1;
                (sky.radiance(d, [lambda; 4])[0], 0.02)
            }
            "sun" => {
                sun_rows += 1;
                (sky.sun_radiance([lambda; 4])[0], 0.01)
            }
            k => panic!("unknown row kind {k}"),
        };
        let rel = (got / expect - 1.0).abs();
        assert!(rel <= tol, "{line}: prism {got}, relative difference {rel}");
        let w = &mut worst[usize::from(f[0] == "sun")];
        if rel > w.0 {
            *w = (rel, line.to_owned());
        }
    }
    assert_eq!((sky_rows, sun_rows), (480, 24));
    for (kind, (rel, line)) in ["sky", "sun"].iter().zip(&worst) {
        eprintln!("{kind}: largest relative difference {rel:.2e} at {line}");
    }
}

/// The disc is 0.5358° across: 2π(1 − cos 0.2679°) = 6.8683·10⁻⁵ sr, within 1 % of the
/// issue's ≈ 6.8·10⁻⁵ and within 1e-4 of the exact value.
#[test]
fn sun_disc_has_the_sun_s_solid_angle() {
    let sky = Sky::new(params(30.0, 120.0, 3.0, 0.3, true));
    let exact = 2.0 * std::f64::consts::PI * (1.0 - (0.5358f64 / 2.0).to_radians().cos());
    let omega = f64::from(sky.sun_solid_angle());
    assert!((omega / exact - 1.0).abs() < 1e-4, "{omega} vs {exact}");
    assert!((omega / 6.8e-5 - 1.0).abs() < 0.02, "{omega}");
}

/// Every sample lies on the disc, and (1 − cos θ) / (1 − cos θ_max) of uniform samples over
/// the cone is uniform on [0, 1): its mean over n stratified-free samples is ½ within
/// 4 standard errors (1 / √(12 n)). The disc test agrees with the sampled cone's edge.
#[test]
fn sun_samples_fall_on_the_disc_uniformly() {
    for (e, a) in [(30.0, 120.0), (0.0, 0.0), (89.9, 250.0), (90.0, 0.0)] {
        let sky = Sky::new(params(e, a, 3.0, 0.3, true));
        let s = sky.sun_direction();
        let half = (0.5358f32 / 2.0).to_radians();
        let omc_max = 1.0 - f64::from(half).cos();
        let n = 20_000;
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut sum = 0.0f64;
        for _ in 0..n {
            let d = sky.sample_sun(Vec2::new(next(), next()));
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!(sky.on_sun(d), "elevation {e}: {d} off the disc");
            // 1 − cos θ from the cross product, exact for small angles.
            let sin2 = f64::from(d.cross(s).length_squared());
            let omc = sin2 / (1.0 + (1.0 - sin2).sqrt());
            sum += omc / omc_max;
        }
        let mean = sum / n as f64;
        let se = 1.0 / (12.0 * n as f64).sqrt();
        assert!((mean - 0.5).abs() < 4.0 * se, "elevation {e}: mean {mean}");
        // Just outside the edge is off the disc.
        let (t, _) = s.any_orthonormal_pair();
        let outside = (s * (half * 1.01).cos() + t * (half * 1.01).sin()).normalize();
        let inside = (s * (half * 0.99).cos() + t * (half * 0.99).sin()).normalize();
        assert!(!sky.on_sun(outside) && sky.on_sun(inside), "elevation {e}");
    }
}

/// E = ∫ L(ω) cos θ dω over the upper hemisphere by the midpoint rule in (cos θ, φ), fine
/// enough (1024 × 2048) that the circumsolar peak is resolved.
fn sky_irradiance(sky: &Sky) -> Vec3 {
    let (nu, nphi) = (1024, 2048);
    let mut e = glam::DVec3::ZERO;
    for i in 0..nu {
        let u = (i as f64 + 0.5) / nu as f64;
        let s = (1.0 - u * u).sqrt();
        for j in 0..nphi {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / nphi as f64;
            let d = Vec3::new((s * phi.cos()) as f32, u as f32, (s * phi.sin()) as f32);
            e += sky.rgb(d).as_dvec3() * u;
        }
    }
    (e * (2.0 * std::f64::consts::PI / (nu * nphi) as f64)).as_vec3()
}

fn plane_scene(env: &str, rho: f32) -> String {
    format!(
        r#"Scene(
    render: (width: 16, height: 16, spp: 256, max_depth: 4, seed: 3),
    camera: (position: (0.0, 1.0, 0.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 0.0, -1.0), fov_y: 20.0),
    environment: {env},
    entities: [ (name: "ground", shape: Rect(center: (0.0, 0.0, 0.0), u: (100.0, 0.0, 0.0), v: (0.0, 0.0, -100.0)),
                 material: Diffuse(albedo: Rgb({rho}, {rho}, {rho}))) ],
)"#
    )
}

/// An upward-facing diffuse plane of albedo ρ renders ρ E / π: E from quadrature of the sky
/// (RGB transport), plus the sun's L_sun Ω sin(elevation) when it shines. With NEE and MIS
/// over 16·16·256 samples the image mean's noise is far below the 1 % tolerance.
#[test]
fn a_plane_receives_the_sky_s_and_the_sun_s_irradiance() {
    let rho = 0.5;
    for (e, a, t, sun) in [
        (30.0, 120.0, 3.0, false),
        (30.0, 120.0, 3.0, true),
        (8.0, 250.0, 6.0, true),
    ] {
        let sky = Sky::new(params(e, a, t, 0.3, sun));
        let mut irradiance = sky_irradiance(&sky);
        if sun {
            irradiance += sky.sun_rgb() * sky.sun_solid_angle() * e.to_radians().sin();
        }
        let expect = irradiance * rho / std::f32::consts::PI;
        let env = format!(
            "Sky(sun_elevation: {e}, sun_azimuth: {a}, turbidity: {t}, ground_albedo: Rgb(0.3, 0.3, 0.3), sun: {sun})"
        );
        let mut s = scene(&plane_scene(&env, rho));
        // The sky turns spectral transport on; this test checks RGB against RGB quadrature.
        s.effects
            .set(prism::scene::Effect::Spectral, false, "test: RGB transport");
        let img = run(&s).image();
        for c in 0..3 {
            let m = mean_where(&img, c, |_, _| true) as f32;
            assert!(
                (m / expect[c] - 1.0).abs() < 0.01,
                "elevation {e}, sun {sun}, channel {c}: {m} vs {}",
                expect[c]
            );
        }
    }
}

/// CIEDE2000 colour difference (Sharma, Wu and Dalal 2005, equations 1–22).
fn delta_e2000(l1: Vec3, l2: Vec3) -> f32 {
    let (l1, l2) = (l1.as_dvec3(), l2.as_dvec3());
    let c1 = (l1.y * l1.y + l1.z * l1.z).sqrt();
    let c2 = (l2.y * l2.y + l2.z * l2.z).sqrt();
    let cbar7 = ((c1 + c2) / 2.0).powi(7);
    let g = 0.5 * (1.0 - (cbar7 / (cbar7 + 25f64.powi(7))).sqrt());
    let (a1, a2) = ((1.0 + g) * l1.y, (1.0 + g) * l2.y);
    let (c1, c2) = (
        (a1 * a1 + l1.z * l1.z).sqrt(),
        (a2 * a2 + l2.z * l2.z).sqrt(),
    );
    let hue = |b: f64, a: f64| {
        if a == 0.0 && b == 0.0 {
            0.0
        } else {
            b.atan2(a).to_degrees().rem_euclid(360.0)
        }
    };
    let (h1, h2) = (hue(l1.z, a1), hue(l2.z, a2));
    let dl = l2.x - l1.x;
    let dc = c2 - c1;
    let dh = if c1 * c2 == 0.0 {
        0.0
    } else if (h2 - h1).abs() <= 180.0 {
        h2 - h1
    } else if h2 - h1 > 180.0 {
        h2 - h1 - 360.0
    } else {
        h2 - h1 + 360.0
    };
    let dhh = 2.0 * (c1 * c2).sqrt() * (dh / 2.0).to_radians().sin();
    let lbar = (l1.x + l2.x) / 2.0;
    let cbar = (c1 + c2) / 2.0;
    let hbar = if c1 * c2 == 0.0 {
        h1 + h2
    } else if (h1 - h2).abs() <= 180.0 {
        (h1 + h2) / 2.0
    } else if h1 + h2 < 360.0 {
        (h1 + h2 + 360.0) / 2.0
    } else {
        (h1 + h2 - 360.0) / 2.0
    };
    let t = 1.0 - 0.17 * (hbar - 30.0).to_radians().cos()
        + 0.24 * (2.0 * hbar).to_radians().cos()
        + 0.32 * (3.0 * hbar + 6.0).to_radians().cos()
        - 0.20 * (4.0 * hbar - 63.0).to_radians().cos();
    let dtheta = 30.0 * (-((hbar - 275.0) / 25.0).powi(2)).exp();
    let cbar7 = cbar.powi(7);
    let rc = 2.0 * (cbar7 / (cbar7 + 25f64.powi(7))).sqrt();
    let sl = 1.0 + 0.015 * (lbar - 50.0).powi(2) / (20.0 + (lbar - 50.0).powi(2)).sqrt();
    let sc = 1.0 + 0.045 * cbar;
    let sh = 1.0 + 0.015 * cbar * t;
    let rt = -(2.0 * dtheta).to_radians().sin() * rc;
    ((dl / sl).powi(2) + (dc / sc).powi(2) + (dhh / sh).powi(2) + rt * (dc / sc) * (dhh / sh))
        .sqrt() as f32
}

/// Sharma et al.'s published test pairs 1, 7 and 17 (ΔE00 = 2.0425, 2.3669 and 2.0373).
#[test]
fn delta_e2000_matches_published_pairs() {
    for (a, b, expect) in [
        (
            Vec3::new(50.0, 2.6772, -79.7751),
            Vec3::new(50.0, 0.0, -82.7485),
            2.0425,
        ),
        (
            Vec3::new(50.0, 0.0, 0.0),
            Vec3::new(50.0, -1.0, 2.0),
            2.3669,
        ),
        (
            Vec3::new(22.7233, 20.0904, -46.6940),
            Vec3::new(23.0331, 14.9730, -42.5619),
            2.0373,
        ),
    ] {
        let d = delta_e2000(a, b);
        assert!((d - expect).abs() < 1e-3, "{a} {b}: {d} vs {expect}");
    }
}

/// The sky seen directly, in spectral and in RGB transport, at three sun settings: each
/// pixel's colours (exposed so that the RGB render's luminance sits at L* = 90) differ by
/// ΔE2000 ≤ 2. RGB transport's colour is the band spectrum's exact projection; spectral
/// transport estimates the same projection with 4 hero wavelengths per sample, so the two
/// differ by the spectral estimate's noise alone. A pixel spans 6° of sky, whose colour
/// changes across it near the horizon and the sun: 4096 samples a pixel bring that noise to
/// ΔE2000 ≈ 1.2 at worst (5.5 at 256 samples, falling as 1/√n).
#[test]
fn spectral_and_rgb_skies_agree_within_delta_e_2() {
    let xyz = prism::spectrum::linear_srgb_to_xyz;
    let white = xyz(Vec3::ONE);
    for (e, a, t) in [(30.0, 120.0, 3.0), (5.0, 250.0, 6.0), (65.0, 10.0, 2.0)] {
        let text = format!(
            r#"Scene(
    render: (width: 16, height: 12, spp: 4096, max_depth: 1, seed: 9),
    camera: (position: (0.0, 0.0, 0.0), look_at: (0.3, 0.4, -1.0), fov_y: 90.0),
    environment: Sky(sun_elevation: {e}, sun_azimuth: {a}, turbidity: {t}, sun: false),
    entities: [],
)"#
        );
        let spectral = scene(&text);
        assert!(spectral.effects.has(prism::scene::Effect::Spectral));
        let mut rgb = scene(&text);
        rgb.effects
            .set(prism::scene::Effect::Spectral, false, "test: RGB transport");
        let (a_img, b_img) = (run(&spectral).image(), run(&rgb).image());
        let mut worst = 0.0f32;
        for (pa, pb) in a_img.pixels.iter().zip(&b_img.pixels) {
            let (xa, xb) = (xyz(Vec3::from(*pa)), xyz(Vec3::from(*pb)));
            if xb.y <= 0.0 {
                assert!(xa.y.abs() < 1e-6, "spectral sky below the horizon");
                continue;
            }
            // L* = 90 at Y = 0.7630.
            let k = 0.7630 / xb.y;
            let de = delta_e2000(lab(xa * k, white), lab(xb * k, white));
            worst = worst.max(de);
        }
        assert!(worst <= 2.0, "elevation {e}: worst ΔE2000 {worst}");
        eprintln!("elevation {e}: worst ΔE2000 {worst:.3}");
    }
}

/// Out-of-range parameters are located errors naming the field and its range.
#[test]
fn sky_parameters_are_checked_with_located_errors() {
    for (env, expect) in [
        ("Sky(sun_elevation: 95.0)", "in [0, 90] degrees"),
        ("Sky(sun_elevation: -1.0)", "in [0, 90] degrees"),
        ("Sky(sun_elevation: 30.0, turbidity: 0.5)", "in [1, 10]"),
        ("Sky(sun_elevation: 30.0, turbidity: 11.0)", "in [1, 10]"),
        (
            "Sky(sun_elevation: 30.0, ground_albedo: Rgb(1.5, 0.3, 0.3))",
            "[0, 1]",
        ),
        ("Sky(sun_elevation: 30.0, scale: -2.0)", ">= 0"),
        ("Sky(turbidity: 3.0)", "sun_elevation"),
    ] {
        let text = format!(
            "Scene(\n    render: (width: 8, height: 8, spp: 1),\n    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),\n    environment: {env},\n    entities: [],\n)"
        );
        let err = prism::scene_file::load_str(&text, std::path::Path::new("sky.ron"), &[])
            .err()
            .unwrap_or_else(|| panic!("{env} loaded"))
            .to_string();
        assert!(
            err.contains(expect) && err.contains("sky.ron:4:"),
            "{env}: {err}"
        );
    }
}
