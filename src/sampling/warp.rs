//! Warps from the unit square to common sampling domains, each next to the
//! density it produces (with respect to length, area, or solid angle).

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, TAU};

use glam::{Vec2, Vec3};

/// Tent of radius 1 on [-1, 1] by inverting its CDF; density `1 - |x|`.
#[inline]
pub fn sample_tent(u: f32) -> f32 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        // 1 - u is exact for u ≥ 0.5, so the right half is as precise as
        // the left.
        1.0 - (2.0 * (1.0 - u)).sqrt()
    }
}

#[inline]
pub fn tent_pdf(x: f32) -> f32 {
    (1.0 - x.abs()).max(0.0)
}

/// Shirley–Chiu concentric map onto the unit disk: area preserving with low
/// distortion, so it keeps the stratification of its input.
#[inline]
pub fn square_to_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // Square rings map to circles; the angle advances linearly along each
    // ring side.
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    let (s, c) = theta.sin_cos();
    r * Vec2::new(c, s)
}

/// Density of [`square_to_uniform_disk_concentric`] per unit area.
#[inline]
pub fn uniform_disk_pdf() -> f32 {
    FRAC_1_PI
}

/// Cosine-weighted hemisphere about +z (Malley: lift a uniform disk point).
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = square_to_uniform_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
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
    let z = 1.0 - 2.0 * u.x;
    // 1 - z² factored as (1 - z)(1 + z) = 4u(1 - u): no cancellation at
    // the poles.
    let r = 2.0 * (u.x * (1.0 - u.x)).max(0.0).sqrt();
    let (s, c) = (TAU * u.y).sin_cos();
    Vec3::new(r * c, r * s, z)
}

#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// Uniform over the hemisphere about +z.
#[inline]
pub fn square_to_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
    let (s, c) = (TAU * u.y).sin_cos();
    Vec3::new(r * c, r * s, z)
}

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
    // 1 - cos θ is uniform on [0, 1 - cos_max]. sin²θ = t (2 - t) keeps full
    // relative precision for tiny t, where 1 - cos²θ would cancel to zero.
    let t = u.x * one_minus_cos_max;
    let cos_theta = 1.0 - t;
    let sin_theta = (t * (2.0 - t)).max(0.0).sqrt();
    let (s, c) = (TAU * u.y).sin_cos();
    Vec3::new(sin_theta * c, sin_theta * s, cos_theta)
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
    if u.x < u.y {
        let b0 = 0.5 * u.x;
        Vec2::new(b0, u.y - b0)
    } else {
        let b1 = 0.5 * u.y;
        Vec2::new(u.x - b1, b1)
    }
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
    // n.z = -0 takes the -1 branch, which is just as valid there.
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
    (t, bt)
}
