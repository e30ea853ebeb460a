//! Axis-aligned bounding boxes.

use super::Ray;
use glam::{Vec3, Vec3A};

/// An axis-aligned box, closed on every side; empty when `min` exceeds `max` on an axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Corner with the smallest coordinates.
    pub min: Vec3,
    /// Corner with the largest coordinates.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box: the identity of `union`.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box spanned by two opposite corners, in any order.
    #[inline]
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The smallest box holding every point ([`Aabb::EMPTY`] for none).
    #[inline]
    pub fn from_points(points: &[Vec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.union_point(p))
    }

    /// The smallest box holding both boxes.
    #[inline]
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// The smallest box holding this box and `p`.
    #[inline]
    pub fn union_point(&self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The part common to both boxes; empty if they do not overlap.
    #[inline]
    pub fn intersection(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.max(o.min),
            max: self.max.min(o.max),
        }
    }

    /// Whether the box holds no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// `max - min`.
    #[inline]
    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }

    /// Midpoint of the box.
    #[inline]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Total area of the six faces; 0 for an empty box.
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Grows the box by a relative and an absolute margin on every side, so that a
    /// primitive's rounded bounds still contain every point its intersection can report.
    #[inline]
    pub fn padded(&self, rel: f32, abs: f32) -> Aabb {
        // One margin for all axes, from the largest coordinate: a flat box at 0 on one axis
        // still gets thickness from the others' magnitude.
        let m = self.min.abs().max(self.max.abs()).max_element();
        let pad = Vec3::splat(m * rel + abs);
        Aabb {
            min: self.min - pad,
            max: self.max + pad,
        }
    }

    /// Parametric range `[t0, t1]` of `ray` inside the box, clipped to `[0, t_max]`.
    /// `inv_d` is `1 / ray.d` (infinite components for axis-parallel rays are handled).
    #[inline]
    pub fn intersect_p(&self, ray: &Ray, inv_d: Vec3, t_max: f32) -> Option<(f32, f32)> {
        let mut t0 = 0.0f32;
        let mut t1 = t_max;
        for a in 0..3 {
            let inv = inv_d[a];
            let mut tn = (self.min[a] - ray.o[a]) * inv;
            let mut tf = (self.max[a] - ray.o[a]) * inv;
            if tn > tf {
                std::mem::swap(&mut tn, &mut tf);
            }
            // 0 * inf = NaN for an axis-parallel ray starting on a slab plane: treat as inside.
            if tn.is_nan() {
                tn = f32::NEG_INFINITY;
            }
            if tf.is_nan() {
                tf = f32::INFINITY;
            }
            // Conservative rounding (pbrt's gamma(3)) keeps grazing rays from slipping past.
            tf *= 1.0 + 2.0 * GAMMA3;
            t0 = t0.max(tn);
            t1 = t1.min(tf);
            if t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }

    /// [`Aabb::intersect_p`] for a ray whose origin and `inv_d` are finite (no direction
    /// component is zero), so that no slab distance is NaN: the same range, computed without
    /// branches, which matters for the many incoherent rays that miss a mesh's box.
    /// Takes the origin and `inv_d` in SIMD registers (`Vec3A`): as `Vec3` each step is three.
    #[inline]
    pub fn intersect_oblique(&self, o: Vec3A, inv_d: Vec3A, t_max: f32) -> Option<(f32, f32)> {
        let a = (Vec3A::from(self.min) - o) * inv_d;
        let b = (Vec3A::from(self.max) - o) * inv_d;
        let t0 = a.min(b).max_element().max(0.0);
        let t1 = (a.max(b) * (1.0 + 2.0 * GAMMA3)).min_element().min(t_max);
        (t0 <= t1).then_some((t0, t1))
    }
}

/// pbrt's γ(3) = 3u / (1 − 3u), u the unit roundoff of f32.
pub const GAMMA3: f32 = 3.0 * (f32::EPSILON * 0.5) / (1.0 - 3.0 * (f32::EPSILON * 0.5));

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oblique_slab_test_equals_the_general_one() {
        // Deterministic xorshift: no dev-dependency in unit tests.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut f = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let b = Aabb::new(Vec3::new(-1.0, -0.5, 0.0), Vec3::new(2.0, 0.5, 0.25));
        let (mut checked, mut hits) = (0, 0);
        for _ in 0..100_000 {
            let o = Vec3::new(f(), f(), f()) * 3.0;
            // Half aimed at a point of the box (hits, some from inside), half anywhere.
            let aim = Vec3::new(f(), f(), f()) * 0.5 + 0.5;
            let target = b.min + (b.max - b.min) * aim;
            let d = if f() < 0.0 {
                target - o
            } else {
                Vec3::new(f(), f(), f())
            };
            if d.x == 0.0 || d.y == 0.0 || d.z == 0.0 {
                continue;
            }
            let ray = Ray::new(o, d);
            let inv = Vec3::ONE / d;
            for t_max in [f32::INFINITY, 1.0] {
                let want = b.intersect_p(&ray, inv, t_max);
                assert_eq!(
                    b.intersect_oblique(ray.o.into(), inv.into(), t_max),
                    want,
                    "{ray:?}"
                );
                checked += 1;
                hits += usize::from(want.is_some());
            }
        }
        // Both outcomes must be exercised for the comparison to mean anything.
        assert!(
            hits > checked / 10 && hits < checked * 9 / 10,
            "{hits} of {checked}"
        );
    }
}
