//! Warps from the unit square to common sampling domains, each next to the
//! density it produces (with respect to length, area, or solid angle).

use std::f32::consts::{FRAC_1_PI, TAU};

use glam::{Vec2, Vec3};

/// Tent of radius 1 on [-1, 1] by inverting its CDF; density `1 - |x|`.
#[inline]
pub fn sample_tent(u: f32) -> f32 {
    lanes::sample_tent(u)
}

/// Density of [`sample_tent`] at `x`; zero outside [-1, 1].
#[inline]
pub fn tent_pdf(x: f32) -> f32 {
    (1.0 - x.abs()).max(0.0)
}

/// Shirley–Chiu concentric map onto the unit disk: area preserving with low
/// distortion, so it keeps the stratification of its input.
#[inline]
pub fn square_to_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let (x, y) = lanes::square_to_uniform_disk_concentric(u.x, u.y);
    Vec2::new(x, y)
}

/// Density of [`square_to_uniform_disk_concentric`] per unit area.
#[inline]
pub fn uniform_disk_pdf() -> f32 {
    FRAC_1_PI
}

/// Cosine-weighted hemisphere about +z (Malley: lift a uniform disk point).
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    lanes::square_to_cosine_hemisphere(u.x, u.y).into()
}

/// Solid-angle density of [`square_to_cosine_hemisphere`]; zero below the
/// horizon.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Uniform over the unit sphere (Archimedes: z is uniform on [-1, 1]).
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    lanes::square_to_uniform_sphere(u.x, u.y).into()
}

/// Solid-angle density of [`square_to_uniform_sphere`]: 1/(4π).
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// Uniform over the hemisphere about +z.
#[inline]
pub fn square_to_uniform_hemisphere(u: Vec2) -> Vec3 {
    lanes::square_to_uniform_hemisphere(u.x, u.y).into()
}

/// Solid-angle density of [`square_to_uniform_hemisphere`]: 1/(2π).
#[inline]
pub fn uniform_hemisphere_pdf() -> f32 {
    0.5 * FRAC_1_PI
}

/// Uniform over the cone of directions within the angle whose cosine is
/// `cos_max`, about +z.
///
/// Works with `1 - cos θ` throughout (see
/// [`square_to_uniform_cone_one_minus_cos`]); `1 - cos_max` is itself exact
/// for `cos_max ≥ 0.5`, so narrow cones lose nothing here. If the caller can
/// compute `1 - cos_max` more accurately than `cos_max` (e.g. from a
/// sin² for a tiny, distant sphere), call that variant directly.
#[inline]
pub fn square_to_uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    square_to_uniform_cone_one_minus_cos(u, 1.0 - cos_max)
}

/// Solid-angle density of [`square_to_uniform_cone`] inside the cone
/// (infinite for a degenerate cone, `cos_max = 1`).
#[inline]
pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    uniform_cone_pdf_one_minus_cos(1.0 - cos_max)
}

/// [`square_to_uniform_cone`] given `one_minus_cos_max = 1 - cos_max` in
/// [0, 2] directly.
#[inline]
pub fn square_to_uniform_cone_one_minus_cos(u: Vec2, one_minus_cos_max: f32) -> Vec3 {
    lanes::square_to_uniform_cone_one_minus_cos(u.x, u.y, one_minus_cos_max).into()
}

/// Solid-angle density of [`square_to_uniform_cone_one_minus_cos`].
#[inline]
pub fn uniform_cone_pdf_one_minus_cos(one_minus_cos_max: f32) -> f32 {
    1.0 / (TAU * one_minus_cos_max)
}

/// Uniform barycentrics `(b0, b1)` over a triangle (`b2 = 1 - b0 - b1`),
/// using Heitz's low-distortion square-to-triangle map: the square's two
/// halves each shear onto half the triangle with constant Jacobian, so
/// strata stay compact (unlike the square-root map).
#[inline]
pub fn square_to_uniform_triangle(u: Vec2) -> Vec2 {
    let (b0, b1) = lanes::square_to_uniform_triangle(u.x, u.y);
    Vec2::new(b0, b1)
}

/// Density of [`square_to_uniform_triangle`] per unit area of the
/// `(b0, b1)` parameter plane (that triangle has area 1/2); divide by the
/// world-space triangle area to convert a barycentric density to area.
#[inline]
pub fn uniform_triangle_pdf() -> f32 {
    2.0
}

/// Orthonormal basis around a unit normal (Duff et al. 2017, branchless):
/// returns (t, b) with t × b = n.
///
/// Continuous everywhere except across the z = 0 plane, where the sign
/// switch avoids the singularity of the single-branch form.
#[inline]
pub fn coordinate_system(n: Vec3) -> (Vec3, Vec3) {
    let (t, b) = lanes::coordinate_system(n.into());
    (t.into(), b.into())
}

/// The warps over lanes: the one implementation, which the scalar functions above call at
/// width 1. Branches become selects, so lane `i` of a result is exactly the scalar result of
/// lane `i`'s input.
pub mod lanes {
    use crate::simd::{Float, V3, math};
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, TAU};

    /// See [`super::sample_tent`].
    #[inline(always)]
    pub fn sample_tent<F: Float>(u: F) -> F {
        let one = F::one();
        let two = F::splat(2.0);
        // 1 - u is exact for u ≥ 0.5, so the right half is as precise as the left.
        let left = (two * u).sqrt() - one;
        let right = one - (two * (one - u)).sqrt();
        F::select(u.lt(F::splat(0.5)), left, right)
    }

    /// See [`super::square_to_uniform_disk_concentric`].
    #[inline(always)]
    pub fn square_to_uniform_disk_concentric<F: Float>(ux: F, uy: F) -> (F, F) {
        let one = F::one();
        let ox = ux.mul_add(F::splat(2.0), -one);
        let oy = uy.mul_add(F::splat(2.0), -one);
        // Square rings map to circles; the angle advances linearly along each ring side.
        let x_major = ox.abs().gt(oy.abs());
        let r = F::select(x_major, ox, oy);
        let ratio = F::select(x_major, oy, ox) / r;
        let q = F::splat(FRAC_PI_4) * ratio;
        let theta = F::select(x_major, q, F::splat(FRAC_PI_2) - q);
        let (s, c) = math::sin_cos(theta);
        // The centre (0/0 above) maps to itself.
        let centre = ox.eq(F::zero()) & oy.eq(F::zero());
        (
            F::select(centre, F::zero(), r * c),
            F::select(centre, F::zero(), r * s),
        )
    }

    /// See [`super::square_to_cosine_hemisphere`].
    #[inline(always)]
    pub fn square_to_cosine_hemisphere<F: Float>(ux: F, uy: F) -> V3<F> {
        let (x, y) = square_to_uniform_disk_concentric(ux, uy);
        let z = (F::one() - x.mul_add(x, y * y)).max(F::zero()).sqrt();
        V3::new(x, y, z)
    }

    /// See [`super::square_to_uniform_sphere`].
    #[inline(always)]
    pub fn square_to_uniform_sphere<F: Float>(ux: F, uy: F) -> V3<F> {
        let one = F::one();
        let z = ux.mul_add(F::splat(-2.0), one);
        // 1 - z² factored as (1 - z)(1 + z) = 4u(1 - u): no cancellation at the poles.
        let r = F::splat(2.0) * (ux * (one - ux)).max(F::zero()).sqrt();
        let (s, c) = math::sin_cos(F::splat(TAU) * uy);
        V3::new(r * c, r * s, z)
    }

    /// See [`super::square_to_uniform_hemisphere`].
    #[inline(always)]
    pub fn square_to_uniform_hemisphere<F: Float>(ux: F, uy: F) -> V3<F> {
        let one = F::one();
        let r = ((one - ux) * (one + ux)).max(F::zero()).sqrt();
        let (s, c) = math::sin_cos(F::splat(TAU) * uy);
        V3::new(r * c, r * s, ux)
    }

    /// See [`super::square_to_uniform_cone_one_minus_cos`].
    #[inline(always)]
    pub fn square_to_uniform_cone_one_minus_cos<F: Float>(
        ux: F,
        uy: F,
        one_minus_cos_max: F,
    ) -> V3<F> {
        // 1 - cos θ is uniform on [0, 1 - cos_max]. sin²θ = t (2 - t) keeps full relative
        // precision for tiny t, where 1 - cos²θ would cancel to zero.
        let t = ux * one_minus_cos_max;
        let cos_theta = F::one() - t;
        let sin_theta = (t * (F::splat(2.0) - t)).max(F::zero()).sqrt();
        let (s, c) = math::sin_cos(F::splat(TAU) * uy);
        V3::new(sin_theta * c, sin_theta * s, cos_theta)
    }

    /// See [`super::square_to_uniform_triangle`].
    #[inline(always)]
    pub fn square_to_uniform_triangle<F: Float>(ux: F, uy: F) -> (F, F) {
        let half = F::splat(0.5);
        let upper = ux.lt(uy);
        let b0 = half * ux;
        let b1 = half * uy;
        (F::select(upper, b0, ux - b1), F::select(upper, uy - b0, b1))
    }

    /// See [`super::coordinate_system`].
    #[inline(always)]
    pub fn coordinate_system<F: Float>(n: V3<F>) -> (V3<F>, V3<F>) {
        // n.z = -0 takes the -1 branch, which is just as valid there.
        let sign = F::one().copysign(n.z);
        let a = -(sign + n.z).recip();
        let b = n.x * n.y * a;
        let t = V3::new(F::one() + sign * n.x * n.x * a, sign * b, -(sign * n.x));
        let bt = V3::new(b, sign + n.y * n.y * a, -n.y);
        (t, bt)
    }
}
