//! Plastic: a dielectric coat over a Lambertian base. Its sampling follows its pdf, the
//! sampled weight is f·cos/pdf, it is reciprocal, a white plastic reflects all the light
//! (BSDF and renderer), the smooth coat is the closed form of Mitsuba's `plastic`, and light
//! sampling agrees with BSDF sampling.

mod common;
use common::chi2::Chi2;
use common::furnace::sphere_mean;
use common::quadrature::simpson;
use common::render::z_between;
use glam::Vec3;
use prism::integrator::bsdf::{Chan, lobe};
use prism::integrator::coat::{Plastic, coat_table_cached};
use prism::integrator::microfacet::Ggx;
use prism::simd::V3;

#[path = "common/splitmix.rs"]
mod splitmix;
use splitmix::SplitMix;

fn plastic(tables: &[f32], albedo: [f32; 3], eta: f32, alpha: f32) -> Plastic<'_, f32, 3> {
    Plastic {
        dist: Ggx::isotropic(alpha),
        smooth: alpha < 1e-3,
        eta,
        albedo: Chan(albedo),
        tables,
        base: 0,
    }
}

/// `wo` at `theta` degrees from the normal, azimuth 30°.
fn incident(theta: f32) -> V3<f32> {
    let (t, p) = (theta.to_radians(), 30f32.to_radians());
    V3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// The non-delta samples follow `pdf` (the smooth coat's mirror samples are the pdf's
/// missing mass, as are rejected ones), at 4 roughnesses × 3 incidences.
#[test]
fn plastic_sampling_follows_its_pdf() {
    let t = coat_table_cached(1.5);
    let alphas = [0.0f32, 0.05, 0.3, 1.0];
    let thetas = [0.0f32, 45.0, 85.0];
    let tests = alphas.len() * thetas.len();
    for (k, &alpha) in alphas.iter().enumerate() {
        for (j, &theta) in thetas.iter().enumerate() {
            let b = plastic(&t, [0.8, 0.4, 0.1], 1.5, alpha);
            let wo = incident(theta);
            let mut g = SplitMix((k * 10 + j) as u64);
            let sample = |u: glam::Vec2| {
                let uc = g.range(0.0, 1.0) as f32;
                let s = b.sample(wo, uc, u.x, u.y);
                (s.pdf > 0.0 && s.lobe != lobe::SPECULAR_REFLECTION).then(|| Vec3::from(s.wi))
            };
            let pdf = |w: Vec3| b.pdf(wo, w.into());
            if let Err(e) = Chi2::new(300_000, (k * 13 + j) as u64)
                .tests(tests)
                .directions([0.0, 1.0], sample, pdf)
            {
                panic!("α = {alpha}, θ = {theta}°: {e}");
            }
        }
    }
}

/// Each sample's weight is f·cos/pdf and its pdf `pdf(wo, wi)`; a smooth coat's mirror
/// sample carries F(μo) over the probability of choosing it.
#[test]
fn plastic_weight_is_f_cos_over_pdf_and_reciprocal() {
    let t = coat_table_cached(1.45);
    let mut g = SplitMix(5);
    for &alpha in &[0.0f32, 0.05, 0.4, 1.0] {
        let b = plastic(&t, [0.9, 0.5, 0.05], 1.45, alpha);
        for _ in 0..20_000 {
            let wo = incident(g.range(0.0, 89.0) as f32);
            let u = [0; 3].map(|_| g.range(0.0, 1.0) as f32);
            let s = b.sample(wo, u[0], u[1], u[2]);
            if s.pdf == 0.0 {
                assert_eq!(s.weight.0, [0.0; 3]);
                continue;
            }
            if s.lobe == lobe::SPECULAR_REFLECTION {
                assert!(alpha < 1e-3);
                assert_eq!(Vec3::from(s.wi), Vec3::new(-wo.x, -wo.y, wo.z));
                continue;
            }
            let pdf = b.pdf(wo, s.wi);
            assert!((s.pdf - pdf).abs() <= 1e-4 * pdf, "{} vs {pdf}", s.pdf);
            let f = b.eval(wo, s.wi);
            for c in 0..3 {
                let w = f.0[c] * s.wi.z / pdf;
                assert!(
                    (w - s.weight.0[c]).abs() <= 1e-4 * w.max(1e-3),
                    "α {alpha}: {w} vs {}",
                    s.weight.0[c]
                );
            }
            // Reciprocity, to f32 rounding: grazing lobes here reach 10⁴, where D rounds at 1e-5.
            let (fab, fba) = (b.eval(wo, s.wi), b.eval(s.wi, wo));
            for c in 0..3 {
                assert!(
                    (fab.0[c] - fba.0[c]).abs() <= 1e-4 * fab.0[c].max(1.0),
                    "α {alpha}: {:?} vs {:?}, wo {wo:?} wi {:?}",
                    fab.0,
                    fba.0,
                    s.wi
                );
            }
        }
    }
}

/// Smooth coat: the base's lobe is Mitsuba's `plastic` closed form
/// ρ(1 − F(μo))(1 − F(μi)) / (πη²(1 − ρ F_in)), with F_in the internal diffuse reflectance
/// 1 − (1 − 2∫F(μ)μ dμ)/η², computed here independently in f64.
#[test]
fn smooth_plastic_is_the_closed_form() {
    let eta = 1.5f64;
    let fresnel = |c: f64, eta: f64| {
        let s2 = (1.0 - c * c) / (eta * eta);
        if s2 >= 1.0 {
            return 1.0;
        }
        let ct = (1.0 - s2).sqrt();
        let rs = (c - eta * ct) / (c + eta * ct);
        let rp = (eta * c - ct) / (eta * c + ct);
        0.5 * (rs * rs + rp * rp)
    };
    // 2∫F(μ)μ dμ = ∫F(√x) dx.
    let avg = simpson(|x| fresnel(x.sqrt(), eta), 0.0, 1.0, 20_000);
    let f_in = 1.0 - (1.0 - avg) / (eta * eta);
    let t = coat_table_cached(eta as f32);
    let rho = [0.9f32, 0.5, 0.1];
    let b = plastic(&t, rho, eta as f32, 0.0);
    let mut g = SplitMix(9);
    for _ in 0..2000 {
        let (wo, wi) = (
            incident(g.range(0.0, 89.0) as f32),
            incident(g.range(0.0, 89.0) as f32),
        );
        let wi = V3::new(-wi.y, wi.x, wi.z);
        let f = b.eval(wo, wi);
        for (c, &r) in rho.iter().enumerate() {
            let r = f64::from(r);
            let want =
                r * (1.0 - fresnel(f64::from(wo.z), eta)) * (1.0 - fresnel(f64::from(wi.z), eta))
                    / (std::f64::consts::PI * eta * eta * (1.0 - r * f_in));
            assert!(
                (f64::from(f.0[c]) - want).abs() <= 2e-5 * want.max(1e-3),
                "{} vs {want}",
                f.0[c]
            );
        }
    }
}

/// A white plastic reflects all the light from every direction: the mean sampled weight
/// is 1 to its Monte Carlo error, smooth and rough.
#[test]
fn white_plastic_reflects_everything() {
    let t = coat_table_cached(1.5);
    let mut g = SplitMix(7);
    for &alpha in &[0.0f32, 0.1, 0.5, 1.0] {
        let b = plastic(&t, [1.0; 3], 1.5, alpha);
        for theta in [0.0f32, 50.0, 80.0] {
            let wo = incident(theta);
            let n = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let u = [0; 3].map(|_| g.range(0.0, 1.0) as f32);
                let w = f64::from(b.sample(wo, u[0], u[1], u[2]).weight.0[0]);
                sum += w;
                sum2 += w * w;
            }
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            // The coat's table is built on a grid: its albedo is E_table, the truth E, and
            // a white plastic reflects 1 + E − E_table; 3e-3 covers the grid's error.
            assert!(
                (mean - 1.0).abs() <= 4.0 * se + 3e-3,
                "α {alpha}, θ {theta}: {mean} ± {se}"
            );
        }
    }
}

/// In the white furnace a white plastic sphere vanishes: smooth within 1 %, rough never
/// above 1.01 (and not below 0.99).
#[test]
fn white_plastic_in_the_furnace() {
    for (m, spp) in [
        ("Plastic(albedo: Rgb(1.0, 1.0, 1.0))", 16),
        (
            "Plastic(albedo: Rgb(1.0, 1.0, 1.0), ior: 1.8, alpha: 0.05)",
            32,
        ),
        ("Plastic(albedo: Rgb(1.0, 1.0, 1.0), alpha: 0.3)", 32),
        ("Plastic(albedo: Rgb(1.0, 1.0, 1.0), roughness: 1.0)", 32),
    ] {
        for c in sphere_mean(m, spp, 1, "") {
            assert!((0.99..=1.01).contains(&c), "{m}: {c}");
        }
    }
    // A coloured one keeps its colour: the red channel reflects more than the blue.
    let c = sphere_mean("Plastic(albedo: Rgb(0.8, 0.5, 0.1), alpha: 0.2)", 16, 1, "");
    assert!(c[0] > c[1] && c[1] > c[2] && c[0] < 1.0, "{c:?}");
}

/// A lamp and a plastic ball on a floor, by light sampling with MIS and by BSDF sampling
/// alone: the same image (z-test over 8 seeds each), smooth and rough.
#[test]
fn light_sampling_and_bsdf_sampling_agree_on_plastic() {
    let scene = |m: &str, seed: u32, extra: &str| {
        format!(
            r#"#![enable(implicit_some)]
Scene(
    render: (width: 24, height: 24, spp: 16, max_depth: 6, seed: {seed}{extra}),
    camera: (position: (0.0, 0.5, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 36.0),
    entities: [
        (name: "lamp", shape: Rect(center: (1.0, 2.0, 1.2), u: (0.3, 0.0, 0.0), v: (0.0, 0.0, 0.3)),
         material: Light(emission: Rgb(40.0, 40.0, 40.0), two_sided: true)),
        (name: "floor", shape: Rect(center: (0.0, -1.0, 0.0), u: (3.0, 0.0, 0.0), v: (0.0, 0.0, -3.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
        (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), material: {m}),
    ],
)"#
        )
    };
    for m in [
        "Plastic(albedo: Rgb(0.7, 0.2, 0.1))",
        "Plastic(albedo: Rgb(0.7, 0.2, 0.1), alpha: 0.1)",
        "Plastic(albedo: Rgb(0.2, 0.3, 0.7), ior: 1.3, roughness: 0.7)",
    ] {
        let (a, b, z) = z_between(
            |s| scene(m, s, ""),
            |s| scene(m, s, ", integrator: (light_sampling: Path)"),
        );
        assert!(a > 0.0 && b > 0.0);
        assert!(z.abs() < 4.0, "{m}: MIS {a} vs BSDF only {b}, z = {z}");
    }
}
