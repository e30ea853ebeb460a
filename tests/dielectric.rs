//! Fresnel and refraction against the textbook formulas, written out independently here.

use glam::Vec3;
use prism::integrator::bsdf::{fresnel_dielectric, fresnel_schlick, reflect, refract};

/// Reflectance and transmittance of s- and p-polarised light from the Fresnel amplitude
/// coefficients, with n1 on the incident side.
fn textbook(theta_i: f64, n1: f64, n2: f64) -> Option<(f64, f64)> {
    let (ci, si) = (theta_i.cos(), theta_i.sin());
    let st = n1 / n2 * si;
    if st >= 1.0 {
        return None;
    }
    let ct = (1.0 - st * st).sqrt();
    let rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    let rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    let ts = 2.0 * n1 * ci / (n1 * ci + n2 * ct);
    let tp = 2.0 * n1 * ci / (n2 * ci + n1 * ct);
    // Transmitted power carries the ratio of beam cross-sections and impedances.
    let k = (n2 * ct) / (n1 * ci);
    let r = 0.5 * (rs * rs + rp * rp);
    let t = 0.5 * k * (ts * ts + tp * tp);
    Some((r, t))
}

#[test]
fn fresnel_matches_exact_formulas_and_conserves_energy() {
    for (n1, n2) in [(1.0, 1.5), (1.5, 1.0), (1.0, 2.42), (1.33, 1.0), (1.0, 1.0)] {
        for k in 0..=89 {
            let th = (k as f64).to_radians();
            let eta = (n2 / n1) as f32;
            let got = fresnel_dielectric(th.cos() as f32, eta) as f64;
            match textbook(th, n1, n2) {
                Some((r, t)) => {
                    assert!((got - r).abs() < 2e-6, "n {n1}->{n2} θ {k}°: {got} vs {r}");
                    assert!((r + t - 1.0).abs() < 1e-9, "energy at {k}°: R {r} + T {t}");
                }
                None => assert_eq!(got, 1.0, "TIR expected at {k}° for {n1}->{n2}"),
            }
        }
    }
}

#[test]
fn total_internal_reflection_past_the_critical_angle() {
    let eta = 1.0 / 1.5f32; // glass to air
    let critical = (1.0f32 / 1.5).asin();
    for d in [-0.02f32, 0.02, 0.2, 0.5] {
        let th = critical + d;
        let wo = Vec3::new(th.sin(), 0.0, th.cos());
        let r = fresnel_dielectric(th.cos(), eta);
        let s = fresnel_schlick(th.cos(), eta);
        let t = refract(wo, Vec3::Z, eta);
        if d > 0.0 {
            assert_eq!(r, 1.0);
            assert_eq!(s, 1.0);
            assert!(t.is_none());
        } else {
            assert!(r < 1.0 && s < 1.0);
            assert!(t.is_some());
        }
    }
}

#[test]
fn schlick_is_close_to_exact_for_glass() {
    // Schlick's error for n = 1.5 peaks near 0.04 around 83°; anything larger is a bug in it.
    for k in 0..90 {
        let c = (k as f32).to_radians().cos();
        let (e, s) = (fresnel_dielectric(c, 1.5), fresnel_schlick(c, 1.5));
        assert!((e - s).abs() < 0.05, "{k}°: exact {e} schlick {s}");
    }
}

#[test]
fn reflection_and_refraction_directions() {
    let n = Vec3::Y;
    let wo = Vec3::new(0.6, 0.8, 0.0);
    assert!((reflect(wo, n) - Vec3::new(-0.6, 0.8, 0.0)).length() < 1e-6);
    // Reversibility: light leaving along wt refracts back into wo.
    let wt = refract(wo, n, 1.5).unwrap();
    let back = refract(wt, -n, 1.0 / 1.5).unwrap();
    assert!((back - wo).length() < 1e-5, "{back:?}");
}
