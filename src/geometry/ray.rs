//! Rays and the robust offset used to spawn them from surfaces.

use crate::simd::{Float, UInt, V3};
use glam::Vec3;

/// A ray `o + t d`. `d` need not be normalised: analytic shapes intersect in object space,
/// where the transformed direction keeps the world `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction; `t` is measured in multiples of it.
    pub d: Vec3,
}

impl Ray {
    /// The ray from `o` along `d`.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Self { o, d }
    }

    /// The point at parameter `t`, `o + t d`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

// Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing
// Gems, ch. 6). The offset grows with the magnitude of each coordinate, in integer ULPs, so it
// bounds the floating-point error of a hit point at any scene scale; near the origin, where
// ULPs vanish, a small absolute offset takes over.
const ORIGIN: f32 = 1.0 / 32.0;
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
const INT_SCALE: f32 = 256.0;

/// Moves `p` off the surface with geometric normal `n` to the side `n` points to.
/// Spawn with `offset_ray_origin(p, n)` for rays leaving on the normal's side and
/// `offset_ray_origin(p, -n)` for rays leaving through the surface.
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    let of_i = n * INT_SCALE;
    let step = |p: f32, o: f32| -> f32 {
        let oi = o as i32;
        let bits = p.to_bits() as i32;
        // Moving away from zero adds ULPs; the sign of p decides which way that is.
        f32::from_bits((if p < 0.0 { bits - oi } else { bits + oi }) as u32)
    };
    let p_i = Vec3::new(step(p.x, of_i.x), step(p.y, of_i.y), step(p.z, of_i.z));
    let pick = |p: f32, pi: f32, n: f32| -> f32 {
        if p.abs() < ORIGIN {
            p + FLOAT_SCALE * n
        } else {
            pi
        }
    };
    Vec3::new(
        pick(p.x, p_i.x, n.x),
        pick(p.y, p_i.y, n.y),
        pick(p.z, p_i.z, n.z),
    )
}

/// [`offset_ray_origin`] over lanes, bit for bit.
#[inline(always)]
pub fn offset_ray_origin_lanes<F: Float>(p: V3<F>, n: V3<F>) -> V3<F> {
    V3::new(
        offset_lanes(p.x, n.x),
        offset_lanes(p.y, n.y),
        offset_lanes(p.z, n.z),
    )
}

/// One coordinate of [`offset_ray_origin_lanes`] (a function, not a closure: closures are not
/// forced inline, and one left out of line calls the intrinsics out of line).
#[inline(always)]
fn offset_lanes<F: Float>(p: F, n: F) -> F {
    let oi = (n * F::splat(INT_SCALE)).to_i32_bits();
    let bits = p.to_bits();
    let neg = p.lt(F::zero());
    let pi = F::from_bits(F::U32::select(
        neg,
        bits.wrapping_sub(oi),
        bits.wrapping_add(oi),
    ));
    let small = p.abs().lt(F::splat(ORIGIN));
    F::select(small, p + F::splat(FLOAT_SCALE) * n, pi)
}

/// Spawns a ray from surface point `p` (geometric normal `ng`) in direction `d`, offset to
/// whichever side `d` leaves on.
#[inline]
pub fn spawn_ray(p: Vec3, ng: Vec3, d: Vec3) -> Ray {
    let n = if ng.dot(d) >= 0.0 { ng } else { -ng };
    Ray::new(offset_ray_origin(p, n), d)
}

/// Spawns a shadow ray from `p` towards the point `target` (itself on a surface with normal
/// `ng_target`); both ends are offset, and the returned `t_max` reaches the offset target
/// with the direction unnormalised (t = 1 at the target).
#[inline]
pub fn spawn_ray_to(p: Vec3, ng: Vec3, target: Vec3, ng_target: Vec3) -> (Ray, f32) {
    let d = target - p;
    let n = if ng.dot(d) >= 0.0 { ng } else { -ng };
    let o = offset_ray_origin(p, n);
    let nt = if ng_target.dot(d) <= 0.0 {
        ng_target
    } else {
        -ng_target
    };
    let t_end = offset_ray_origin(target, nt);
    (Ray::new(o, t_end - o), 1.0)
}
