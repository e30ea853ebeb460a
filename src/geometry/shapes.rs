//! The analytic shapes in the form the hot loop wants: world-space data, intersection that
//! returns a small record, surface data for the winning hit only, and area-light sampling with
//! its pdf beside it.

use super::{Aabb, Ray};
use crate::simd::{Float, Mask, V3};
use glam::{Affine3A, Mat3, Vec2, Vec3};

/// Where on a surface a ray hit, and the frame there.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// Hit point, re-projected onto the surface to keep its error small.
    pub p: Vec3,
    /// Unit geometric normal: outward for closed shapes, `normalize(u × v)` for planar ones.
    pub n: Vec3,
    /// Unit shading normal on the same side as `n` (interpolated on meshes; `n` elsewhere).
    pub ns: Vec3,
    /// Whether the ray arrived from the side `n` points to. Decided from the intersection's
    /// topology (origin outside a closed shape, sign of the plane crossing), not from the sign
    /// of a dot product that rounding can flip at grazing angles.
    pub front: bool,
}

impl SurfacePoint {
    /// The normal on the side the ray came from.
    #[inline]
    pub fn facing(&self) -> Vec3 {
        if self.front { self.n } else { -self.n }
    }

    /// The shading normal on the side the ray came from.
    #[inline]
    pub fn shading_facing(&self) -> Vec3 {
        if self.front { self.ns } else { -self.ns }
    }
}

/// A point sampled on an emitter, as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct ShapeSample {
    /// The sampled point, world space.
    pub p: Vec3,
    /// Unit surface normal at `p` (either side).
    pub n: Vec3,
    /// Density with respect to solid angle at the reference point.
    pub pdf: f32,
}

/// Dot product without fused multiply-adds: intersection runs in the per-ray kd-tree walk,
/// outside the lane entry points, where a `mul_add` would be a call into `fmaf`.
#[inline(always)]
fn dot<F: Float>(a: V3<F>, b: V3<F>) -> F {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// IEEE minNum, as `f32::min`: a NaN operand gives the other one.
#[inline(always)]
fn min_num<F: Float>(a: F, b: F) -> F {
    // The SSE rule already returns `b` when `a` is NaN.
    F::select(b.is_nan(), a, a.min(b))
}

/// IEEE maxNum, as `f32::max`.
#[inline(always)]
fn max_num<F: Float>(a: F, b: F) -> F {
    F::select(b.is_nan(), a, a.max(b))
}

/// Bounds padding: the relative error of a few float operations on the coordinates, so the
/// kd-tree never culls a hit the exact surface has.
const PAD_REL: f32 = 4.0 * f32::EPSILON;

#[inline]
fn solid_angle_pdf(pdf_area: f32, ref_p: Vec3, p: Vec3, n: Vec3) -> f32 {
    let d = p - ref_p;
    let dist2 = d.length_squared();
    let cos = n.dot(d).abs() / dist2.sqrt();
    if cos <= 0.0 || dist2 <= 0.0 {
        0.0
    } else {
        pdf_area * dist2 / cos
    }
}

/// [`solid_angle_pdf`] over lanes, in glam's operation order.
#[inline(always)]
fn solid_angle_pdf_lanes<F: Float>(pdf_area: F, ref_p: V3<F>, p: V3<F>, n: V3<F>) -> F {
    let d = p - ref_p;
    let dist2 = dot(d, d);
    let cos = dot(n, d).abs() / dist2.sqrt();
    let zero = F::zero();
    let degenerate = cos.le(zero) | dist2.le(zero);
    F::select(degenerate, zero, pdf_area * dist2 / cos)
}

/// A sphere in world space. Spheres take similarity transforms only, so centre and radius
/// describe them fully.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    /// Centre, world space.
    pub center: Vec3,
    /// Radius, world units.
    pub radius: f32,
}

impl Sphere {
    /// World bounds, padded for intersection rounding.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.center - self.radius, self.center + self.radius).padded(PAD_REL, 0.0)
    }

    /// Nearest `t` in (0, t_max). The discriminant is formed from the distance between the
    /// centre and the ray's closest point (Haines et al., Ray Tracing Gems ch. 7), which stays
    /// accurate for distant and tangent rays, and the roots use the stable quadratic form.
    /// Also says whether the ray starts outside (so meets the outer side).
    ///
    /// Hand-written scalar code beside [`Sphere::intersect_lanes`], which gives the same bits
    /// (`tests/lane_kernels.rs`): the lane form at width 1 made box-and-sphere scenes 9 %
    /// slower in the per-ray walk (`fog_lamps.ron`).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, bool)> {
        let f = ray.o - self.center;
        let a = ray.d.length_squared();
        let b = f.dot(ray.d);
        let c = f.length_squared() - self.radius * self.radius;
        let l = f - (b / a) * ray.d;
        let disc = a * (self.radius * self.radius - l.length_squared());
        if disc < 0.0 {
            return None;
        }
        let q = -b - b.signum() * disc.sqrt();
        let (mut t0, mut t1) = (c / q, q / a);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let outside = c > 0.0;
        if t0 > 0.0 && t0 < t_max {
            Some((t0, outside))
        } else if t1 > 0.0 && t1 < t_max {
            Some((t1, outside))
        } else {
            None
        }
    }

    /// [`Sphere::intersect`] of one ray per lane: `(t, hit, outside)`.
    #[inline(always)]
    pub fn intersect_lanes<F: Float>(&self, o: V3<F>, d: V3<F>, t_max: F) -> (F, F::Mask, F::Mask) {
        let zero = F::zero();
        let r2 = F::splat(self.radius * self.radius);
        let f = o - V3::splat(self.center);
        let a = dot(d, d);
        let b = dot(f, d);
        let c = dot(f, f) - r2;
        let l = f - d * (b / a);
        let disc = a * (r2 - dot(l, l));
        // Most rays a leaf tests miss: skip the square root and divisions when all lanes do.
        let real = disc.ge(zero);
        if real.none() {
            return (disc, real, real);
        }
        let q = -b - F::one().copysign(b) * disc.sqrt();
        let (ra, rb) = (c / q, q / a);
        let (t0, t1) = (ra.min(rb), ra.max(rb));
        let outside = c.gt(zero);
        let first = t0.gt(zero) & t0.lt(t_max);
        let second = t1.gt(zero) & t1.lt(t_max);
        // A negative discriminant gives NaN roots, which fail both tests.
        let hit = real & (first | second);
        (F::select(first, t0, t1), hit, outside)
    }

    /// Surface data of a hit at `t` found by [`Sphere::intersect`] (`front` is its `outside`).
    #[inline(always)]
    pub fn surface(&self, ray: &Ray, t: f32, front: bool) -> SurfacePoint {
        let rel = ray.at(t) - self.center;
        let n = rel.normalize_or(Vec3::Y);
        SurfacePoint {
            p: self.center + n * self.radius,
            n,
            ns: n,
            front,
        }
    }

    /// Surface area.
    pub fn area(&self) -> f32 {
        4.0 * std::f32::consts::PI * self.radius * self.radius
    }

    /// Samples the cone of directions the sphere subtends from `ref_p` (uniform in solid
    /// angle); from inside, uniformly by area. [`Sphere::sample_lanes`] at width 1.
    pub fn sample(&self, ref_p: Vec3, u: Vec2) -> Option<ShapeSample> {
        let (p, n, pdf, ok) = self.sample_lanes::<f32>(V3::splat(ref_p), u.x, u.y);
        ok.then_some(ShapeSample {
            p: p.into(),
            n: n.into(),
            pdf,
        })
    }

    /// [`Sphere::sample`] from one reference point per lane: the point, its normal, its
    /// solid-angle density, and the lanes that hold a sample. Both cases are computed in
    /// every lane and selected.
    #[inline(always)]
    pub fn sample_lanes<F: Float>(&self, ref_p: V3<F>, ux: F, uy: F) -> (V3<F>, V3<F>, F, F::Mask) {
        use crate::sampling::warp::lanes as warp;
        let (zero, one) = (F::zero(), F::one());
        let c = V3::splat(self.center);
        let radius = F::splat(self.radius);
        let rel = ref_p - c;
        let dc2 = dot(rel, rel);
        let r2 = F::splat(self.radius * self.radius);
        let inside = dc2.le(r2 * F::splat(1.0001));
        // Inside (or on) the sphere: uniform by area.
        let n_in = warp::square_to_uniform_sphere(ux, uy);
        let p_in = c + n_in * radius;
        let pdf_in = solid_angle_pdf_lanes(F::splat(1.0 / self.area()), ref_p, p_in, n_in);
        let ok_in = pdf_in.gt(zero) & pdf_in.is_finite();
        // Outside: uniform in the cone it subtends.
        let dc = dc2.sqrt();
        let sin2_max = r2 / dc2;
        let cos_max = max_num(one - sin2_max, zero).sqrt();
        let toward = c - ref_p;
        let w = V3::new(toward.x / dc, toward.y / dc, toward.z / dc);
        let local = warp::square_to_uniform_cone_one_minus_cos(ux, uy, one - cos_max);
        let (t, b) = warp::coordinate_system(w);
        let dir = t * local.x + b * local.y + w * local.z;
        // The point on the sphere along `dir`: the near root of the ray–sphere quadratic,
        // clamped to the tangent point when rounding puts the direction just outside.
        let bq = dot(rel, dir);
        let disc = max_num(bq * bq - (dc2 - r2), zero);
        let tq = -bq - disc.sqrt();
        let p_raw = ref_p + dir * tq;
        // glam's `normalize_or(-w)`.
        let v = p_raw - c;
        let rcp = one / dot(v, v).sqrt();
        let unit = rcp.is_finite() & rcp.gt(zero);
        let n_out = V3::select(unit, v * rcp, -w);
        let pdf_out = one / (F::splat(std::f32::consts::TAU) * (one - cos_max));
        let n = V3::select(inside, n_in, n_out);
        let p = V3::select(inside, p_in, c + n_out * radius);
        let pdf = F::select(inside, pdf_in, pdf_out);
        (p, n, pdf, ok_in | !inside)
    }

    /// Solid-angle density of `sample` for a direction from `ref_p` that hits at `p`.
    pub fn pdf(&self, ref_p: Vec3, p: Vec3, n: Vec3) -> f32 {
        let dc2 = (ref_p - self.center).length_squared();
        let r2 = self.radius * self.radius;
        if dc2 <= r2 * 1.0001 {
            return solid_angle_pdf(1.0 / self.area(), ref_p, p, n);
        }
        let cos_max = (1.0 - r2 / dc2).max(0.0).sqrt();
        crate::sampling::uniform_cone_pdf(cos_max)
    }
}

/// A parallelogram (`Rect`) or an ellipse (`Disk`) in world space: `center + α u + β v` with
/// |α|, |β| ≤ 1 or α² + β² ≤ 1. An affine transform maps either onto the same form, so both
/// are baked to world space and never transform rays.
#[derive(Clone, Copy, Debug)]
pub struct Planar {
    /// Centre, world space.
    pub center: Vec3,
    /// Half edge (or semi-axis) along α.
    pub u: Vec3,
    /// Half edge (or semi-axis) along β.
    pub v: Vec3,
    /// Unit normal `normalize(u × v)`.
    pub n: Vec3,
    /// `(u × v) / |u × v|²`: turns a point's offset into its (α, β) coordinates.
    w: Vec3,
    area: f32,
}

impl Planar {
    /// From centre and half edges; `disk` chooses the ellipse, for its area.
    pub fn new(center: Vec3, u: Vec3, v: Vec3, disk: bool) -> Self {
        let nn = u.cross(v);
        let len2 = nn.length_squared();
        let area = len2.sqrt() * if disk { std::f32::consts::PI } else { 4.0 };
        Self {
            center,
            u,
            v,
            n: nn / len2.sqrt(),
            w: nn / len2,
            area,
        }
    }

    /// World bounds of the parallelogram, or of the ellipse if `disk`, padded for rounding.
    pub fn bounds(&self, disk: bool) -> Aabb {
        let ext = if disk {
            // An ellipse's extent along each axis is |(u_a, v_a)|.
            Vec3::new(
                self.u.x.hypot(self.v.x),
                self.u.y.hypot(self.v.y),
                self.u.z.hypot(self.v.z),
            )
        } else {
            self.u.abs() + self.v.abs()
        };
        Aabb::new(self.center - ext, self.center + ext).padded(PAD_REL, 0.0)
    }

    /// Nearest hit in (0, t_max) with its (α, β) coordinates. Scalar code beside
    /// [`Planar::intersect_lanes`], with the same bits (see [`Sphere::intersect`]).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32, disk: bool) -> Option<(f32, f32, f32)> {
        let denom = self.n.dot(ray.d);
        let t = self.n.dot(self.center - ray.o) / denom;
        // A ray in the plane (denom 0) gives an infinite or NaN t and fails here.
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let rel = ray.at(t) - self.center;
        let a = self.w.dot(rel.cross(self.v));
        let b = self.w.dot(self.u.cross(rel));
        let inside = if disk {
            a * a + b * b <= 1.0
        } else {
            a.abs() <= 1.0 && b.abs() <= 1.0
        };
        inside.then_some((t, a, b))
    }

    /// [`Planar::intersect`] of one ray per lane: `(t, α, β, hit)`.
    #[inline(always)]
    pub fn intersect_lanes<F: Float>(
        &self,
        o: V3<F>,
        d: V3<F>,
        t_max: F,
        disk: bool,
    ) -> (F, F, F, F::Mask) {
        let (n, c) = (V3::splat(self.n), V3::splat(self.center));
        let (u, v, w) = (V3::splat(self.u), V3::splat(self.v), V3::splat(self.w));
        let t = dot(n, c - o) / dot(n, d);
        // A ray in the plane (denominator 0) gives an infinite or NaN t and fails here.
        let in_range = t.gt(F::zero()) & t.lt(t_max);
        if in_range.none() {
            return (t, t, t, in_range);
        }
        let rel = o + d * t - c;
        let a = dot(w, rel.cross(v));
        let b = dot(w, u.cross(rel));
        let one = F::one();
        let inside = if disk {
            (a * a + b * b).le(one)
        } else {
            a.abs().le(one) & b.abs().le(one)
        };
        (t, a, b, in_range & inside)
    }

    /// (α, β) of a point in the plane.
    #[inline]
    pub fn coords(&self, p: Vec3) -> (f32, f32) {
        let rel = p - self.center;
        (self.w.dot(rel.cross(self.v)), self.w.dot(self.u.cross(rel)))
    }

    /// Surface data at the (α, β) a hit returned; `front` when the ray meets the side `n` faces.
    #[inline(always)]
    pub fn surface(&self, ray: &Ray, a: f32, b: f32) -> SurfacePoint {
        SurfacePoint {
            p: self.center + a * self.u + b * self.v,
            n: self.n,
            ns: self.n,
            front: ray.d.dot(self.n) < 0.0,
        }
    }

    /// Surface area.
    pub fn area(&self) -> f32 {
        self.area
    }

    /// Uniform by area. (Solid-angle sampling of spherical rectangles only applies to true
    /// rectangles; affine transforms make general parallelograms and ellipses, so area
    /// sampling serves every planar emitter.) [`Planar::sample_lanes`] at width 1.
    pub fn sample(&self, ref_p: Vec3, u: Vec2, disk: bool) -> Option<ShapeSample> {
        let (p, pdf) = self.sample_lanes::<f32>(V3::splat(ref_p), u.x, u.y, disk);
        (pdf > 0.0).then_some(ShapeSample {
            p: p.into(),
            n: self.n,
            pdf,
        })
    }

    /// Solid-angle density of [`Planar::sample`] at `p` seen from `ref_p`.
    pub fn pdf(&self, ref_p: Vec3, p: Vec3) -> f32 {
        solid_angle_pdf(1.0 / self.area, ref_p, p, self.n)
    }

    /// [`Planar::sample`] from one reference point per lane: the point and its solid-angle
    /// density, 0 where there is no sample.
    #[inline(always)]
    pub fn sample_lanes<F: Float>(&self, ref_p: V3<F>, ux: F, uy: F, disk: bool) -> (V3<F>, F) {
        let (a, b) = if disk {
            crate::sampling::warp::lanes::square_to_uniform_disk_concentric(ux, uy)
        } else {
            let (one, two) = (F::one(), F::splat(2.0));
            (two * ux - one, two * uy - one)
        };
        let p = V3::splat(self.center) + V3::splat(self.u) * a + V3::splat(self.v) * b;
        let pdf = solid_angle_pdf_lanes(F::splat(1.0 / self.area), ref_p, p, V3::splat(self.n));
        let ok = pdf.gt(F::zero()) & pdf.is_finite();
        (p, F::select(ok, pdf, F::zero()))
    }
}

/// A box placed by an affine transform (rotated, sheared or scaled): intersected in object
/// space with a slab test.
#[derive(Clone, Copy, Debug)]
pub struct OrientedBox {
    /// Object-space corner with the smallest coordinates.
    pub min: Vec3,
    /// Object-space corner with the largest coordinates.
    pub max: Vec3,
    /// Object-to-world transform.
    pub to_world: Affine3A,
    /// World-to-object transform, the inverse of `to_world`.
    pub to_object: Affine3A,
    /// Inverse transpose of the linear part: carries normals to world space.
    pub normal_matrix: Mat3,
}

impl OrientedBox {
    /// The box `[min, max]` in object space, placed by `to_world`.
    pub fn new(min: Vec3, max: Vec3, to_world: Affine3A) -> Self {
        let to_object = to_world.inverse();
        let normal_matrix = Mat3::from(to_object.matrix3).transpose();
        Self {
            min,
            max,
            to_world,
            to_object,
            normal_matrix,
        }
    }

    /// World bounds of the transformed corners, padded for rounding.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            b = b.union_point(self.to_world.transform_point3(c));
        }
        b.padded(PAD_REL * 4.0, 0.0)
    }

    #[inline(always)]
    fn object_ray(&self, ray: &Ray) -> Ray {
        Ray::new(
            self.to_object.transform_point3(ray.o),
            self.to_object.transform_vector3(ray.d),
        )
    }

    /// Also says whether the ray starts outside the box. Scalar code beside
    /// [`OrientedBox::intersect_lanes`], with the same bits (see [`Sphere::intersect`]).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, bool)> {
        let r = self.object_ray(ray);
        let inv = r.d.recip();
        let t0 = (self.min - r.o) * inv;
        let t1 = (self.max - r.o) * inv;
        let tn = t0.min(t1);
        let tf = t0.max(t1);
        // NaN from 0·∞ (an axis-parallel ray on a slab plane) is dropped by max/min.
        let t_near = tn.x.max(tn.y).max(tn.z);
        let t_far = tf.x.min(tf.y).min(tf.z);
        if t_near > t_far {
            return None;
        }
        if t_near > 0.0 && t_near < t_max {
            Some((t_near, true))
        } else if t_near <= 0.0 && t_far > 0.0 && t_far < t_max {
            Some((t_far, false))
        } else {
            None
        }
    }

    /// [`OrientedBox::intersect`] of one ray per lane: `(t, hit, outside)`.
    #[inline(always)]
    pub fn intersect_lanes<F: Float>(&self, o: V3<F>, d: V3<F>, t_max: F) -> (F, F::Mask, F::Mask) {
        let m = &self.to_object.matrix3;
        let (mx, my, mz) = (
            V3::splat(m.x_axis.into()),
            V3::splat(m.y_axis.into()),
            V3::splat(m.z_axis.into()),
        );
        // glam's order of operations, so the scalar code's bits.
        let ro = mx * o.x + my * o.y + mz * o.z + V3::splat(self.to_object.translation.into());
        let rd = mx * d.x + my * d.y + mz * d.z;
        let inv = V3::new(rd.x.recip(), rd.y.recip(), rd.z.recip());
        let t0 = (V3::splat(self.min) - ro).mul_elem(inv);
        let t1 = (V3::splat(self.max) - ro).mul_elem(inv);
        // NaN from 0·∞ (an axis-parallel ray on a slab plane) is dropped by these min/max.
        let t_near = max_num(
            max_num(min_num(t0.x, t1.x), min_num(t0.y, t1.y)),
            min_num(t0.z, t1.z),
        );
        let t_far = min_num(
            min_num(max_num(t0.x, t1.x), max_num(t0.y, t1.y)),
            max_num(t0.z, t1.z),
        );
        let zero = F::zero();
        let overlap = t_near.le(t_far);
        if overlap.none() {
            return (t_near, overlap, overlap);
        }
        let enter = t_near.gt(zero) & t_near.lt(t_max);
        let leave = t_near.le(zero) & t_far.gt(zero) & t_far.lt(t_max);
        (
            F::select(enter, t_near, t_far),
            overlap & (enter | leave),
            enter,
        )
    }

    /// Planar UVs on the face that was hit, over [0, 1]², with world-space derivatives.
    pub fn uv_frame(&self, ray: &Ray, t: f32) -> (glam::Vec2, Vec3, Vec3) {
        let r = self.object_ray(ray);
        let p = r.at(t);
        let (axis, _, _) = self.face(p);
        // The two axes spanning the face, ordered so (u, v) is right-handed with the face's
        // outward normal on the +side faces.
        let (a, b) = match axis {
            0 => (2, 1),
            1 => (0, 2),
            _ => (0, 1),
        };
        let size = self.max - self.min;
        let uv = glam::Vec2::new(
            (p[a] - self.min[a]) / size[a],
            (p[b] - self.min[b]) / size[b],
        );
        let mut ea = Vec3::ZERO;
        ea[a] = size[a];
        let mut eb = Vec3::ZERO;
        eb[b] = size[b];
        (
            uv,
            self.to_world.transform_vector3(ea),
            self.to_world.transform_vector3(eb),
        )
    }

    /// The face nearest to object-space point `p`: (axis, plane coordinate, sign).
    #[inline(always)]
    fn face(&self, p: Vec3) -> (usize, f32, f32) {
        let size = (self.max - self.min).max(Vec3::splat(f32::MIN_POSITIVE));
        let mut best = (f32::INFINITY, 0usize, 0.0f32, 1.0f32);
        for a in 0..3 {
            let dmin = (p[a] - self.min[a]).abs() / size[a];
            let dmax = (p[a] - self.max[a]).abs() / size[a];
            if dmin < best.0 {
                best = (dmin, a, self.min[a], -1.0);
            }
            if dmax < best.0 {
                best = (dmax, a, self.max[a], 1.0);
            }
        }
        (best.1, best.2, best.3)
    }

    /// Surface data of a hit at `t` found by [`OrientedBox::intersect`] (`front` is its `outside`).
    #[inline(always)]
    pub fn surface(&self, ray: &Ray, t: f32, front: bool) -> SurfacePoint {
        let r = self.object_ray(ray);
        let mut p = r.at(t);
        // The face is the one the point lies closest to, relative to the box size; snapping
        // the point onto it removes the error along the normal.
        let (axis, plane, sign) = self.face(p);
        p[axis] = plane;
        p = p.clamp(self.min, self.max);
        let mut n_obj = Vec3::ZERO;
        n_obj[axis] = sign;
        let n = (self.normal_matrix * n_obj).normalize();
        SurfacePoint {
            p: self.to_world.transform_point3(p),
            n,
            ns: n,
            front,
        }
    }
}
