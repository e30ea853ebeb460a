//! Rigid motion over time: how a moving primitive is intersected in its rest pose.
//!
//! A moving entity's world position at time t (in frames) is
//! `x(t) = pivot + v·t + R(ω·t)·(x₀ − pivot)`, with x₀ its position at t = 0 and R the
//! rotation Rz·Ry·Rx of the angles ω·t. Rays are carried into the rest pose instead of moving
//! the shape: a rigid map keeps ray parameters, so hits, normals and pdfs need no rescaling.

use super::{Aabb, Ray};
use glam::{Quat, Vec3};

/// A constant linear and angular velocity about a pivot (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidMotion {
    /// Centre of rotation, world space (the object origin at rest).
    pub pivot: Vec3,
    /// World units per frame.
    pub velocity: Vec3,
    /// Radians per frame about x, y, z.
    pub angular: Vec3,
}

impl RigidMotion {
    #[inline]
    fn rotation(&self, t: f32) -> Quat {
        let a = self.angular * t;
        Quat::from_rotation_z(a.z) * Quat::from_rotation_y(a.y) * Quat::from_rotation_x(a.x)
    }

    /// Whether the motion has any rotation.
    pub fn rotates(&self) -> bool {
        self.angular != Vec3::ZERO
    }

    /// The ray at time `t`, carried into the rest pose.
    #[inline]
    pub fn ray_to_rest(&self, ray: &Ray, t: f32) -> Ray {
        let inv = self.rotation(t).inverse();
        Ray::new(
            self.pivot + inv * (ray.o - self.pivot - self.velocity * t),
            inv * ray.d,
        )
    }

    /// World point at time `t` carried into the rest pose.
    #[inline]
    pub fn point_to_rest(&self, p: Vec3, t: f32) -> Vec3 {
        self.pivot + self.rotation(t).inverse() * (p - self.pivot - self.velocity * t)
    }

    /// Rest-pose point carried to its world position at time `t`.
    #[inline]
    pub fn point_to_world(&self, p: Vec3, t: f32) -> Vec3 {
        self.pivot + self.velocity * t + self.rotation(t) * (p - self.pivot)
    }

    /// World direction or normal at time `t` carried into the rest pose.
    #[inline]
    pub fn vector_to_rest(&self, v: Vec3, t: f32) -> Vec3 {
        self.rotation(t).inverse() * v
    }

    /// Rest-pose direction or normal carried to world space at time `t`.
    #[inline]
    pub fn vector_to_world(&self, v: Vec3, t: f32) -> Vec3 {
        self.rotation(t) * v
    }

    /// A box holding everything the rest-pose box `b` sweeps over `[t0, t1]`. Translation
    /// alone sweeps linearly, so the union of the end poses is exact; with rotation, the box is
    /// bounded by the sphere around the pivot that holds its corners, swept along the path.
    pub fn sweep_bounds(&self, b: &Aabb, t0: f32, t1: f32) -> Aabb {
        if b.is_empty() {
            return *b;
        }
        if !self.rotates() {
            let at = |t: f32| Aabb {
                min: b.min + self.velocity * t,
                max: b.max + self.velocity * t,
            };
            return at(t0).union(&at(t1));
        }
        let mut r2 = 0.0f32;
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            r2 = r2.max((c - self.pivot).length_squared());
        }
        let r = r2.sqrt() * (1.0 + 1e-5);
        let at = |t: f32| {
            let c = self.pivot + self.velocity * t;
            Aabb::new(c - r, c + r)
        };
        at(t0).union(&at(t1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rest_and_world_are_inverse() {
        let m = RigidMotion {
            pivot: Vec3::new(1.0, 2.0, 3.0),
            velocity: Vec3::new(0.5, 0.0, -0.25),
            angular: Vec3::new(0.1, 0.7, -0.3),
        };
        let p = Vec3::new(-2.0, 0.5, 4.0);
        for t in [0.0f32, 0.3, 7.5] {
            let q = m.point_to_world(m.point_to_rest(p, t), t);
            assert!((q - p).length() < 1e-4, "{t}: {q:?}");
        }
    }

    #[test]
    fn sweep_holds_every_pose() {
        let m = RigidMotion {
            pivot: Vec3::new(0.0, 1.0, 0.0),
            velocity: Vec3::new(2.0, 0.0, 0.0),
            angular: Vec3::new(0.0, 0.9, 0.4),
        };
        let b = Aabb::new(Vec3::new(-0.5, 0.5, -0.2), Vec3::new(0.7, 1.5, 0.3));
        let s = m.sweep_bounds(&b, 0.0, 1.0);
        for k in 0..=20 {
            let t = k as f32 / 20.0;
            for i in 0..8 {
                let c = Vec3::new(
                    if i & 1 == 0 { b.min.x } else { b.max.x },
                    if i & 2 == 0 { b.min.y } else { b.max.y },
                    if i & 4 == 0 { b.min.z } else { b.max.z },
                );
                let w = m.point_to_world(c, t);
                assert!(w.cmpge(s.min - 1e-5).all() && w.cmple(s.max + 1e-5).all());
            }
        }
    }
}
