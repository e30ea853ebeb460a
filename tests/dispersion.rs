//! Dispersion: Snell's law per wavelength with Cauchy and Sellmeier indices.

use glam::Vec3;
use prism::spectrum::{IorModel, IorPreset};

#[test]
fn snell_per_wavelength_with_cauchy_and_sellmeier() {
    // Schott N-BK7: n_d = 1.5168 at the helium d line.
    let bk7 = IorPreset::Bk7.model();
    assert!(
        (bk7.eta(587.56) - 1.5168).abs() < 2e-4,
        "{}",
        bk7.eta(587.56)
    );
    // Refraction from air at 45° into BK7: sin θt = sin 45° / n(λ), bluer bends more.
    let cauchy = IorModel::Cauchy {
        a: 1.5046,
        b: 0.0042,
    };
    let wi = Vec3::new(45f32.to_radians().sin(), -45f32.to_radians().cos(), 0.0);
    let mut last = f32::INFINITY;
    for lambda in [400.0, 486.1, 587.6, 656.3, 700.0] {
        for m in [cauchy, bk7] {
            let n = m.eta(lambda);
            let wt = prism::integrator::bsdf::refract(-wi, Vec3::Y, n).unwrap();
            let theta_t = (-wt.y).acos();
            let expect = (45f32.to_radians().sin() / n).asin();
            assert!(
                (theta_t - expect).abs() < 1e-5,
                "{lambda} nm: {theta_t} vs {expect}"
            );
        }
        let theta = (45f32.to_radians().sin() / cauchy.eta(lambda)).asin();
        assert!(
            theta > last || last.is_infinite(),
            "refraction angle grows with λ"
        );
        last = theta;
    }
}
