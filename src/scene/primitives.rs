//! The scene's primitives in flat per-kind arrays, each with its entity: ray tests (one ray,
//! or the lanes of a packet), surface reconstruction at a hit, UV frames for textures, and
//! the media the primitives bound. Built by `systems::gather_primitives`.

use crate::components::{Material, Texture};
use crate::geometry::{
    Aabb, MeshHit, OrientedBox, Planar, Ray, Revolution, RevolutionHit, RevolutionStats,
    RigidMotion, Sphere, SurfacePoint, TriangleMesh,
};
use crate::kdtree::KdPrimitives;
use crate::simd::Float;
use glam::{Affine3A, Mat3};
use glam::{Quat, Vec2, Vec3};
use std::cell::Cell;
use std::sync::Arc;

/// The closed list of primitive kinds; the hot loop matches on it once per test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum PrimKind {
    /// A sphere, in `spheres`.
    Sphere,
    /// A parallelogram, in `planars`.
    Rect,
    /// A disk (an ellipse once transformed), in `planars`.
    Disk,
    /// An oriented box, in `boxes`.
    Box,
    /// A surface of revolution, in `revolutions`.
    Revolution,
    /// A triangle mesh, in `meshes`.
    Mesh,
}

/// An object-space shape placed by an affine transform: rays go in, surface data comes out.
#[derive(Clone, Debug)]
pub struct Placed<T> {
    /// The shape in object space, shared between entities.
    pub shape: Arc<T>,
    /// Object-to-world transform.
    pub to_world: Affine3A,
    /// World-to-object transform, the inverse of `to_world`.
    pub to_object: Affine3A,
    /// Inverse transpose of the linear part: carries normals to world space.
    pub normal_matrix: Mat3,
}

impl<T> Placed<T> {
    /// `shape` placed by `to_world`.
    pub fn new(shape: Arc<T>, to_world: Affine3A) -> Self {
        let to_object = to_world.inverse();
        Self {
            shape,
            to_world,
            to_object,
            normal_matrix: Mat3::from(to_object.matrix3).transpose(),
        }
    }

    /// A world ray in object space (the same `t` along it).
    #[inline]
    pub fn ray_to_object(&self, ray: &Ray) -> Ray {
        Ray::new(
            self.to_object.transform_point3(ray.o),
            self.to_object.transform_vector3(ray.d),
        )
    }

    /// World bounds of the object-space box `b`, from its eight corners.
    pub fn world_bounds(&self, b: &Aabb) -> Aabb {
        let mut w = Aabb::EMPTY;
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            w = w.union_point(self.to_world.transform_point3(c));
        }
        w.padded(1e-6, 0.0)
    }

    /// Object-space surface data to world space.
    #[inline]
    pub fn surface_to_world(&self, sp: SurfacePoint) -> SurfacePoint {
        SurfacePoint {
            p: self.to_world.transform_point3(sp.p),
            n: (self.normal_matrix * sp.n).normalize(),
            ns: (self.normal_matrix * sp.ns).normalize(),
            front: sp.front,
        }
    }
}

thread_local! {
    // Newton statistics of surfaces of revolution: counted per worker thread without locks,
    // collected by each tile into its render statistics.
    static REVOLUTION_STATS: Cell<RevolutionStats> = Cell::new(RevolutionStats::default());
}

/// Takes the calling thread's revolution counters, leaving zeros.
pub fn take_revolution_stats() -> RevolutionStats {
    REVOLUTION_STATS.with(|c| c.replace(RevolutionStats::default()))
}

#[inline]
fn with_rev_stats<R>(f: impl FnOnce(&mut RevolutionStats) -> R) -> R {
    REVOLUTION_STATS.with(|c| {
        let mut s = c.get();
        let r = f(&mut s);
        c.set(s);
        r
    })
}

/// What the intersect stage records: small, so the stage streams through memory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Primitive index.
    pub prim: u32,
    /// The part of the primitive that was hit (a mesh's triangle).
    pub sub: u32,
    /// First hit coordinate: a planar shape's α, a mesh's barycentric b1, a revolution's curve
    /// parameter; for spheres and boxes, 1 if the ray started outside, else 0.
    pub u: f32,
    /// Second hit coordinate: a planar shape's β, a mesh's b2, a revolution's span parameter.
    pub v: f32,
}

/// Sentinel of [`Primitives::light`]: the primitive does not emit.
pub const NO_LIGHT: u32 = u32::MAX;
/// Sentinel of [`Primitives::motion`]: the primitive does not move.
pub const NO_MOTION: u32 = u32::MAX;
/// Sentinel of [`Primitives::texture`]: the primitive has no texture.
pub const NO_TEXTURE: u32 = u32::MAX;
/// Sentinel of medium indices: no medium (vacuum).
pub const NO_MEDIUM: u32 = u32::MAX;

/// Structure-of-arrays primitive store. Index `i` addresses `kind`, `local`, `material`,
/// `light` and `entity`; `local[i]` indexes the array of its kind.
#[derive(Default)]
pub struct Primitives {
    /// Kind of each primitive.
    pub kind: Vec<PrimKind>,
    /// Index of each primitive in the array of its kind.
    pub local: Vec<u32>,
    /// Material index of each primitive, into `materials`.
    pub material: Vec<u32>,
    /// Index into the light list when the primitive emits, else `NO_LIGHT`.
    pub light: Vec<u32>,
    /// The entity each primitive came from.
    pub entity: Vec<hecs::Entity>,
    /// Index into `motions` for moving primitives, else `NO_MOTION`.
    pub motion: Vec<u32>,
    /// Rigid motions of the moving primitives.
    pub motions: Vec<RigidMotion>,
    /// The time interval the kd-tree's bounds must cover (frames).
    pub sweep: (f32, f32),
    /// The medium inside the primitive (index into `media`), else `NO_MEDIUM`.
    pub medium_inside: Vec<u32>,
    /// The medium around it: the innermost other medium shape holding it, else `NO_MEDIUM`.
    pub medium_outside: Vec<u32>,
    /// Every medium of the scene.
    pub media: Vec<crate::medium::HomogeneousMedium>,
    /// Index into `textures`, else `NO_TEXTURE`.
    pub texture: Vec<u32>,
    /// Every texture of the scene.
    pub textures: Vec<Texture>,
    /// Spheres, world space.
    pub spheres: Vec<Sphere>,
    /// Each sphere's rotation: its UVs turn with it (a globe's longitude).
    pub sphere_rotation: Vec<Quat>,
    /// Rects and disks, world space.
    pub planars: Vec<Planar>,
    /// Oriented boxes.
    pub boxes: Vec<OrientedBox>,
    /// Surfaces of revolution with their placement.
    pub revolutions: Vec<Placed<Revolution>>,
    /// Triangle meshes with their placement.
    pub meshes: Vec<Placed<TriangleMesh>>,
    /// Every material of the scene.
    pub materials: Vec<Material>,
    /// The coat tables of the scene's plastics, one per coat IOR
    /// ([`crate::energy::coat_table`]).
    pub coat: Vec<f32>,
    /// Each material's offset into `coat` (0 for other materials).
    pub coat_offset: Vec<u32>,
    /// Entity name of each primitive, for messages.
    pub names: Vec<String>,
}

impl Primitives {
    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.kind.len()
    }

    /// Whether there are no primitives.
    pub fn is_empty(&self) -> bool {
        self.kind.is_empty()
    }

    /// Bounds of primitive `i` over the whole `sweep` interval.
    pub fn bounds_of(&self, i: u32) -> Aabb {
        let rest = self.rest_bounds(i);
        match self.motion_of(i) {
            Some(m) => m.sweep_bounds(&rest, self.sweep.0, self.sweep.1),
            None => rest,
        }
    }

    fn rest_bounds(&self, i: u32) -> Aabb {
        let l = self.local[i as usize] as usize;
        match self.kind[i as usize] {
            PrimKind::Sphere => self.spheres[l].bounds(),
            PrimKind::Rect => self.planars[l].bounds(false),
            PrimKind::Disk => self.planars[l].bounds(true),
            PrimKind::Box => self.boxes[l].bounds(),
            PrimKind::Revolution => {
                let r = &self.revolutions[l];
                r.world_bounds(&r.shape.bounds())
            }
            PrimKind::Mesh => {
                let m = &self.meshes[l];
                m.world_bounds(&m.shape.bounds())
            }
        }
    }

    /// Primitive `i`'s motion, if it moves.
    #[inline]
    pub fn motion_of(&self, i: u32) -> Option<&RigidMotion> {
        let m = self.motion[i as usize];
        (m != NO_MOTION).then(|| &self.motions[m as usize])
    }

    /// Whether any primitive moves.
    pub fn has_motion(&self) -> bool {
        !self.motions.is_empty()
    }

    /// Intersects primitive `i` at `time`: a moving primitive is tested in its rest pose.
    /// Without MOTION no time is looked at. A mesh screens its leaves `F::WIDTH` at a time.
    #[inline]
    pub fn intersect_at<F: Float, const MOTION: bool>(
        &self,
        i: u32,
        ray: &Ray,
        t_max: f32,
        time: f32,
    ) -> Option<(f32, f32, f32)> {
        if MOTION && let Some(m) = self.motion_of(i) {
            return self.intersect::<F>(i, &m.ray_to_rest(ray, time), t_max);
        }
        self.intersect::<F>(i, ray, t_max)
    }

    /// `intersect_at` with the part of the primitive that was hit.
    #[inline]
    pub fn intersect_sub_at<F: Float, const MOTION: bool>(
        &self,
        i: u32,
        ray: &Ray,
        t_max: f32,
        time: f32,
    ) -> Option<(f32, f32, f32, u32)> {
        if MOTION && let Some(m) = self.motion_of(i) {
            return self.intersect_sub::<F>(i, &m.ray_to_rest(ray, time), t_max);
        }
        self.intersect_sub::<F>(i, ray, t_max)
    }

    /// Whether primitive `i` blocks `ray` in (0, t_max) at `time`: `intersect_at(..).is_some()`,
    /// but meshes and revolution surfaces stop at their first hit instead of the nearest.
    #[inline]
    pub fn occluded_at<F: Float, const MOTION: bool>(
        &self,
        i: u32,
        ray: &Ray,
        t_max: f32,
        time: f32,
    ) -> bool {
        if MOTION && let Some(m) = self.motion_of(i) {
            return self.occluded::<F>(i, &m.ray_to_rest(ray, time), t_max);
        }
        self.occluded::<F>(i, ray, t_max)
    }

    #[inline]
    fn occluded<F: Float>(&self, i: u32, ray: &Ray, t_max: f32) -> bool {
        let l = self.local[i as usize] as usize;
        match self.kind[i as usize] {
            PrimKind::Revolution => {
                let r = &self.revolutions[l];
                with_rev_stats(|st| r.shape.occluded(&r.ray_to_object(ray), t_max, st))
            }
            PrimKind::Mesh => {
                let m = &self.meshes[l];
                m.shape.occluded_lanes::<F>(&m.ray_to_object(ray), t_max)
            }
            _ => self.intersect::<F>(i, ray, t_max).is_some(),
        }
    }

    /// Surface data at `time` (see `intersect_at`). Always inlined, with the analytic
    /// shapes' surfaces, into the kernels' entry points: out of line it was 14 % of the
    /// Cornell box's time at width 16, in calls and code compiled for the baseline CPU.
    #[inline(always)]
    pub fn surface_at<const MOTION: bool>(&self, ray: &Ray, hit: &Hit, time: f32) -> SurfacePoint {
        if MOTION && let Some(m) = self.motion_of(hit.prim) {
            let sp = self.surface(&m.ray_to_rest(ray, time), hit);
            return SurfacePoint {
                p: m.point_to_world(sp.p, time),
                n: m.vector_to_world(sp.n, time),
                ns: m.vector_to_world(sp.ns, time),
                front: sp.front,
            };
        }
        self.surface(ray, hit)
    }

    /// Intersects primitive `i` in the pose of time 0: `Some((t, u, v))` for a hit in
    /// (0, t_max).
    #[inline]
    pub fn intersect<F: Float>(&self, i: u32, ray: &Ray, t_max: f32) -> Option<(f32, f32, f32)> {
        let l = self.local[i as usize] as usize;
        match self.kind[i as usize] {
            // Closed shapes keep "started outside" in u for the surface stage.
            PrimKind::Sphere => self.spheres[l]
                .intersect(ray, t_max)
                .map(|(t, out)| (t, out as u32 as f32, 0.0)),
            PrimKind::Rect => self.planars[l].intersect(ray, t_max, false),
            PrimKind::Disk => self.planars[l].intersect(ray, t_max, true),
            PrimKind::Box => self.boxes[l]
                .intersect(ray, t_max)
                .map(|(t, out)| (t, out as u32 as f32, 0.0)),
            // The hit keeps the curve parameter in u, the span parameter in v; the span goes
            // through `intersect_sub`.
            PrimKind::Revolution | PrimKind::Mesh => self
                .intersect_sub::<F>(i, ray, t_max)
                .map(|(t, u, v, _)| (t, u, v)),
        }
    }

    /// Like `intersect`, with the part of the primitive that was hit (a revolution's span).
    #[inline]
    pub fn intersect_sub<F: Float>(
        &self,
        i: u32,
        ray: &Ray,
        t_max: f32,
    ) -> Option<(f32, f32, f32, u32)> {
        let l = self.local[i as usize] as usize;
        match self.kind[i as usize] {
            PrimKind::Revolution => {
                let r = &self.revolutions[l];
                let h = with_rev_stats(|st| r.shape.intersect(&r.ray_to_object(ray), t_max, st))?;
                Some((h.t, h.s, h.u, h.span))
            }
            // The bottom-level kd-tree in object space: barycentrics in (u, v), the triangle
            // in `sub`.
            PrimKind::Mesh => {
                let m = &self.meshes[l];
                let h = m.shape.intersect_lanes::<F>(&m.ray_to_object(ray), t_max)?;
                Some((h.t, h.b1, h.b2, h.tri))
            }
            _ => self
                .intersect::<F>(i, ray, t_max)
                .map(|(t, u, v)| (t, u, v, 0)),
        }
    }

    fn mesh_hit(hit: &Hit) -> MeshHit {
        MeshHit {
            t: hit.t,
            tri: hit.sub,
            b1: hit.u,
            b2: hit.v,
        }
    }

    fn revolution_hit(hit: &Hit) -> RevolutionHit {
        RevolutionHit {
            t: hit.t,
            s: hit.u,
            span: hit.sub,
            u: hit.v,
        }
    }

    /// Full surface data, computed for the winning hit only.
    #[inline(always)]
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> SurfacePoint {
        let l = self.local[hit.prim as usize] as usize;
        match self.kind[hit.prim as usize] {
            PrimKind::Sphere => self.spheres[l].surface(ray, hit.t, hit.u > 0.5),
            PrimKind::Rect | PrimKind::Disk => self.planars[l].surface(ray, hit.u, hit.v),
            PrimKind::Box => self.boxes[l].surface(ray, hit.t, hit.u > 0.5),
            PrimKind::Revolution => {
                let r = &self.revolutions[l];
                let (sp, _, _, _) = r
                    .shape
                    .surface(&r.ray_to_object(ray), &Self::revolution_hit(hit));
                r.surface_to_world(sp)
            }
            PrimKind::Mesh => {
                let m = &self.meshes[l];
                let ms = m.shape.surface(&Self::mesh_hit(hit));
                let d = m.ray_to_object(ray).d;
                m.surface_to_world(SurfacePoint {
                    p: ms.p,
                    n: ms.ng,
                    ns: ms.ns,
                    // A triangle is crossed once: the side is the sign of the crossing.
                    front: d.dot(ms.ng) < 0.0,
                })
            }
        }
    }

    /// Surface coordinates and their derivatives at a hit (TEXTURES and NORMAL_MAPS only):
    /// `(uv, ∂p/∂u, ∂p/∂v)` in world space. `sp` is the hit's surface point.
    pub fn uv_frame<const MOTION: bool>(
        &self,
        ray: &Ray,
        hit: &Hit,
        sp: &SurfacePoint,
        time: f32,
    ) -> (Vec2, Vec3, Vec3) {
        let motion = if MOTION {
            self.motion_of(hit.prim)
        } else {
            None
        };
        let l = self.local[hit.prim as usize] as usize;
        let (p_rest, ray_rest) = match motion {
            Some(m) => (m.point_to_rest(sp.p, time), m.ray_to_rest(ray, time)),
            None => (sp.p, *ray),
        };
        let (uv, dpdu, dpdv) = match self.kind[hit.prim as usize] {
            PrimKind::Sphere => {
                let s = &self.spheres[l];
                let rot = self.sphere_rotation[l];
                let d = (rot.inverse() * (p_rest - s.center)).normalize_or(Vec3::Y);
                let phi = d.x.atan2(d.z);
                let theta = d.y.clamp(-1.0, 1.0).asin();
                let uv = Vec2::new(
                    0.5 + phi * std::f32::consts::FRAC_1_PI * 0.5,
                    0.5 + theta * std::f32::consts::FRAC_1_PI,
                );
                let tau = std::f32::consts::TAU * s.radius;
                let dpdu = Vec3::new(d.z, 0.0, -d.x) * tau;
                let (st, ct) = theta.sin_cos();
                let dpdv = Vec3::new(-phi.sin() * st, ct, -phi.cos() * st)
                    * (std::f32::consts::PI * s.radius);
                (uv, rot * dpdu, rot * dpdv)
            }
            PrimKind::Rect | PrimKind::Disk => {
                let q = &self.planars[l];
                (
                    Vec2::new(0.5 * (hit.u + 1.0), 0.5 * (hit.v + 1.0)),
                    2.0 * q.u,
                    2.0 * q.v,
                )
            }
            PrimKind::Box => self.boxes[l].uv_frame(&ray_rest, hit.t),
            PrimKind::Mesh => {
                let m = &self.meshes[l];
                let ms = m.shape.surface(&Self::mesh_hit(hit));
                (
                    ms.uv,
                    m.to_world.transform_vector3(ms.dpdu),
                    m.to_world.transform_vector3(ms.dpdv),
                )
            }
            PrimKind::Revolution => {
                let r = &self.revolutions[l];
                let (_, uv, dpdu, dpdv) = r
                    .shape
                    .surface(&r.ray_to_object(&ray_rest), &Self::revolution_hit(hit));
                (
                    uv,
                    r.to_world.transform_vector3(dpdu),
                    r.to_world.transform_vector3(dpdv),
                )
            }
        };
        match motion {
            Some(m) => (
                uv,
                m.vector_to_world(dpdu, time),
                m.vector_to_world(dpdv, time),
            ),
            None => (uv, dpdu, dpdv),
        }
    }

    /// UV of a rest-pose point on an emitter (sphere, rect or disk), for textured emission
    /// seen through light sampling.
    pub fn uv_at(&self, i: u32, p: Vec3) -> Vec2 {
        let l = self.local[i as usize] as usize;
        match self.kind[i as usize] {
            PrimKind::Sphere => {
                let s = &self.spheres[l];
                let d = (self.sphere_rotation[l].inverse() * (p - s.center)).normalize_or(Vec3::Y);
                Vec2::new(
                    0.5 + d.x.atan2(d.z) * std::f32::consts::FRAC_1_PI * 0.5,
                    0.5 + d.y.clamp(-1.0, 1.0).asin() * std::f32::consts::FRAC_1_PI,
                )
            }
            PrimKind::Rect | PrimKind::Disk => {
                let (a, b) = self.planars[l].coords(p);
                Vec2::new(0.5 * (a + 1.0), 0.5 * (b + 1.0))
            }
            PrimKind::Box | PrimKind::Revolution | PrimKind::Mesh => Vec2::ZERO,
        }
    }

    /// Whether point `p` lies inside closed primitive `i` (spheres and boxes, the shapes
    /// that can hold a medium), and the primitive's volume for picking the innermost.
    pub(crate) fn contains(&self, i: u32, p: Vec3) -> Option<f32> {
        let l = self.local[i as usize] as usize;
        match self.kind[i as usize] {
            PrimKind::Sphere => {
                let s = &self.spheres[l];
                ((p - s.center).length_squared() < s.radius * s.radius).then(|| s.radius.powi(3))
            }
            PrimKind::Box => {
                let b = &self.boxes[l];
                let q = b.to_object.transform_point3(p);
                let d = b.max - b.min;
                (q.cmpgt(b.min).all() && q.cmplt(b.max).all())
                    .then(|| d.x * d.y * d.z * b.to_world.matrix3.determinant().abs())
            }
            _ => None,
        }
    }

    /// The primitives that hold a medium, for [`Self::medium_among`].
    pub fn medium_holders(&self) -> Vec<u32> {
        (0..self.len() as u32)
            .filter(|&i| self.medium_inside[i as usize] != NO_MEDIUM)
            .collect()
    }

    /// [`Self::medium_at`] over `holders` ([`Self::medium_holders`]) alone: no pass over
    /// every primitive.
    pub fn medium_among(&self, p: Vec3, holders: &[u32]) -> u32 {
        self.smallest_medium(p, holders.iter().copied())
    }

    /// The medium at point `p`: that of the smallest medium shape containing it.
    pub fn medium_at(&self, p: Vec3) -> u32 {
        self.medium_at_excluding(p, None)
    }

    pub(crate) fn medium_at_excluding(&self, p: Vec3, skip: Option<u32>) -> u32 {
        let holders = (0..self.len() as u32)
            .filter(|&i| Some(i) != skip && self.medium_inside[i as usize] != NO_MEDIUM);
        self.smallest_medium(p, holders)
    }

    /// The medium inside the smallest of `holders` (medium-holding primitives) that contains
    /// `p`, or [`NO_MEDIUM`].
    fn smallest_medium(&self, p: Vec3, holders: impl Iterator<Item = u32>) -> u32 {
        let mut best = (f32::INFINITY, NO_MEDIUM);
        for i in holders {
            if let Some(v) = self.contains(i, p)
                && v < best.0
            {
                best = (v, self.medium_inside[i as usize]);
            }
        }
        best.1
    }

    /// The medium a ray is in after crossing primitive `i`'s surface: its inside when
    /// entering (arriving on the front), its outside when leaving.
    #[inline]
    pub fn medium_after_crossing(&self, i: u32, front: bool, current: u32) -> u32 {
        let inside = self.medium_inside[i as usize];
        if inside == NO_MEDIUM {
            return current;
        }
        if front {
            inside
        } else {
            self.medium_outside[i as usize]
        }
    }

    /// Primitive `i`'s texture, if it has one.
    #[inline]
    pub fn texture_of(&self, i: u32) -> Option<&Texture> {
        let t = self.texture[i as usize];
        (t != NO_TEXTURE).then(|| &self.textures[t as usize])
    }

    /// Number of primitives of each kind, for `prism info`.
    pub fn counts(&self) -> [(PrimKind, usize); 6] {
        let n = |k| self.kind.iter().filter(|&&x| x == k).count();
        [
            (PrimKind::Sphere, n(PrimKind::Sphere)),
            (PrimKind::Rect, n(PrimKind::Rect)),
            (PrimKind::Disk, n(PrimKind::Disk)),
            (PrimKind::Box, n(PrimKind::Box)),
            (PrimKind::Revolution, n(PrimKind::Revolution)),
            (PrimKind::Mesh, n(PrimKind::Mesh)),
        ]
    }
}

impl KdPrimitives for Primitives {
    fn len(&self) -> usize {
        self.kind.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        self.bounds_of(i)
    }
}

/// Radiance leaving an emissive primitive towards `wo` from a point with normal `n`.
#[inline]
pub fn emitted(material: &Material, n: Vec3, wo: Vec3) -> Vec3 {
    match *material {
        Material::Light {
            emission,
            two_sided,
            ..
        } if two_sided || n.dot(wo) > 0.0 => emission,
        _ => Vec3::ZERO,
    }
}
