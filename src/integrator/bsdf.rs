//! Scattering at smooth surfaces: Fresnel terms, reflection and refraction.

use glam::Vec3;

/// Unpolarised Fresnel reflectance of a smooth dielectric interface. `cos_i` is the cosine of
/// the incident angle (≥ 0) and `eta` the relative IOR n_transmitted / n_incident. Returns 1
/// under total internal reflection.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Schlick's approximation, evaluated with the cosine on the optically thinner side (the
/// transmitted angle when leaving the denser medium), so it also reproduces total internal
/// reflection.
#[inline]
pub fn fresnel_schlick(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let c = if eta >= 1.0 {
        cos_i
    } else {
        let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
        if sin2_t >= 1.0 {
            return 1.0;
        }
        (1.0 - sin2_t).sqrt()
    };
    r0 + (1.0 - r0) * (1.0 - c).powi(5)
}

/// Mirror reflection of `wo` (pointing away from the surface) about `n`.
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * wo.dot(n) * n - wo
}

/// Refraction of `wo` (pointing away, on the side `n` faces) into the other side, with
/// relative IOR `eta` = n_transmitted / n_incident. `None` under total internal reflection.
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wo.dot(n);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + (cos_i / eta - cos_t) * n).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_matches_closed_form() {
        for eta in [1.0f32, 1.33, 1.5, 2.42] {
            let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, eta) - r0).abs() < 1e-6);
            assert!((fresnel_schlick(1.0, eta) - r0).abs() < 1e-6);
        }
    }

    #[test]
    fn refract_obeys_snell() {
        let n = Vec3::Z;
        for deg in [0.0f32, 10.0, 30.0, 60.0, 89.0] {
            let th = deg.to_radians();
            let wo = Vec3::new(th.sin(), 0.0, th.cos());
            let wt = refract(wo, n, 1.5).unwrap();
            let sin_t = (wt.x * wt.x + wt.y * wt.y).sqrt();
            assert!((th.sin() - 1.5 * sin_t).abs() < 1e-5, "{deg}");
            assert!(wt.z < 0.0 && (wt.length() - 1.0).abs() < 1e-5);
        }
    }
}
