//! The Henyey–Greenstein phase function.
//!
//! Convention: `wo` and `wi` both point away from the scattering point, and θ is the
//! scattering angle between the incoming propagation direction `−wo` and the outgoing one
//! `wi`, so `cos θ = −wo·wi`. With density
//!
//! ```text
//! p(θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}),
//! ```
//!
//! the mean of `cos θ` is `g`: g > 0 scatters forward (`wi ≈ −wo`), g < 0 backward.
//!
//! Everything is written in terms of `1 − cos θ` and `1 + cos θ`, each computed without
//! cancellation, because the peak of a strongly forward (or backward) lobe sits where `cos θ`
//! is within a few ulps of ±1.

use std::f32::consts::{FRAC_1_PI, TAU};

use glam::{Vec2, Vec3};

use crate::sampling::coordinate_system;

/// Largest |g| used. At |g| = 1 the lobe is a Dirac delta with no density; clamping keeps
/// the peak value, about `2 / (4π (1 − |g|)²)` ≈ 1.7e11, finite in f32.
pub const HG_G_MAX: f32 = 1.0 - 1.0 / (1u32 << 20) as f32;

#[inline]
fn clamp_g(g: f32) -> f32 {
    g.clamp(-HG_G_MAX, HG_G_MAX)
}

/// Henyey–Greenstein density per steradian of scattering by an angle whose cosine is
/// `cos_theta = −wo·wi` (see the module docs). Values of `g` beyond ±[`HG_G_MAX`] are
/// clamped.
#[inline]
pub fn hg_phase(cos_theta: f32, g: f32) -> f32 {
    let c = cos_theta.clamp(-1.0, 1.0);
    hg_from_parts(1.0 - c, 1.0 + c, g)
}

/// [`hg_phase`] for unit directions `wo`, `wi` pointing away from the scattering point.
///
/// For unit vectors `1 + wo·wi = |wo + wi|² / 2`, which keeps full relative precision near
/// exact forward scattering, where the dot product would round to −1.
#[inline]
pub fn hg_phase_dirs(wo: Vec3, wi: Vec3, g: f32) -> f32 {
    hg_from_parts(
        0.5 * (wo + wi).length_squared(),
        0.5 * (wo - wi).length_squared(),
        g,
    )
}

/// HG from `1 − cos θ` and `1 + cos θ`.
#[inline]
fn hg_from_parts(one_minus_cos: f32, one_plus_cos: f32, g: f32) -> f32 {
    let g = clamp_g(g);
    // 1 + g² − 2g cos θ as a sum of two non-negative terms, picked by the sign of g, so the
    // lobe's peak ((1 − |g|)², tiny for |g| → 1) is not lost to cancellation.
    let denom = if g >= 0.0 {
        (1.0 - g) * (1.0 - g) + 2.0 * g * one_minus_cos
    } else {
        (1.0 + g) * (1.0 + g) - 2.0 * g * one_plus_cos
    };
    (1.0 - g) * (1.0 + g) * (0.25 * FRAC_1_PI) / (denom * denom.sqrt())
}

/// Samples `wi` from the Henyey–Greenstein lobe about `−wo` by inverting its CDF exactly;
/// returns `(wi, pdf)` with the pdf per steradian, equal to the phase value.
///
/// `u.x` selects the scattering angle, `u.y` the azimuth. The textbook inverse,
/// `cos θ = (1 + g² − ((1 − g²) / (1 − g + 2g ξ))²) / (2g)`, divides a difference of O(1)
/// terms by 2g and so loses all precision as g → 0. Factoring the numerator gives, with
/// `a = 1 − g + 2gξ`,
///
/// ```text
/// 1 − cos θ = 2 (1 − g)² (1 − ξ) (1 + gξ)       / a²
/// 1 + cos θ = 2 (1 + g)²  ξ      (1 − g (1 − ξ)) / a²
/// ```
///
/// where every factor is computed as a sum of non-negative terms. No special case is needed
/// for small |g| (g = 0 gives exactly `cos θ = 2ξ − 1`), and |g| → 1 stays finite.
pub fn sample_hg(wo: Vec3, g: f32, u: Vec2) -> (Vec3, f32) {
    let g = clamp_g(g);
    let xi = u.x;
    let om = 1.0 - xi;
    // a, 1 + gξ and 1 − g(1 − ξ), each rearranged for the sign of g so no term subtracts.
    let (a, b_minus, b_plus) = if g >= 0.0 {
        ((1.0 - g) + 2.0 * g * xi, 1.0 + g * xi, (1.0 - g) + g * xi)
    } else {
        ((1.0 + g) - 2.0 * g * om, om + xi * (1.0 + g), 1.0 - g * om)
    };
    let inv_a2 = 1.0 / (a * a);
    let one_minus_cos = (2.0 * (1.0 - g) * (1.0 - g) * om * b_minus * inv_a2).clamp(0.0, 2.0);
    let one_plus_cos = (2.0 * (1.0 + g) * (1.0 + g) * xi * b_plus * inv_a2).clamp(0.0, 2.0);
    // Take cos θ from whichever of the two is small, where it is exact.
    let cos_theta = if one_minus_cos <= one_plus_cos {
        1.0 - one_minus_cos
    } else {
        one_plus_cos - 1.0
    };
    let sin_theta = (one_minus_cos * one_plus_cos).sqrt();

    let forward = -wo;
    let (t, b) = coordinate_system(forward);
    let (s, c) = (TAU * u.y).sin_cos();
    let wi = (sin_theta * (c * t + s * b) + cos_theta * forward).normalize();
    (wi, hg_from_parts(one_minus_cos, one_plus_cos, g))
}
