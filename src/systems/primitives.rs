//! `gather_primitives`: flattens the world's shapes into per-kind arrays for the hot loop,
//! keeping each primitive's entity for messages and statistics.

use crate::components::{Material, Motion, Name, Shape, Transform};
use crate::geometry::{Aabb, OrientedBox, Planar, Ray, RigidMotion, Sphere, SurfacePoint};
use crate::kdtree::KdPrimitives;
use glam::Vec3;

/// The closed list of primitive kinds; the hot loop matches on it once per test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum PrimKind {
    Sphere,
    Rect,
    Disk,
    Box,
}

/// What the intersect stage records: small, so the stage streams through memory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub prim: u32,
    pub u: f32,
    pub v: f32,
}

pub const NO_LIGHT: u32 = u32::MAX;
pub const NO_MOTION: u32 = u32::MAX;

/// Structure-of-arrays primitive store. Index `i` addresses `kind`, `local`, `material`,
/// `light` and `entity`; `local[i]` indexes the array of its kind.
#[derive(Default)]
pub struct Primitives {
    pub kind: Vec<PrimKind>,
    pub local: Vec<u32>,
    pub material: Vec<u32>,
    /// Index into the light list when the primitive emits, else `NO_LIGHT`.
    pub light: Vec<u32>,
    pub entity: Vec<hecs::Entity>,
    /// Index into `motions` for moving primitives, else `NO_MOTION`.
    pub motion: Vec<u32>,
    pub motions: Vec<RigidMotion>,
    /// The time interval the kd-tree's bounds must cover (frames).
    pub sweep: (f32, f32),
    pub spheres: Vec<Sphere>,
    pub planars: Vec<Planar>,
    pub boxes: Vec<OrientedBox>,
    pub materials: Vec<Material>,
    pub names: Vec<String>,
}

impl Primitives {
    pub fn len(&self) -> usize {
        self.kind.len()
    }

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
        }
    }

    #[inline]
    pub fn motion_of(&self, i: u32) -> Option<&RigidMotion> {
        let m = self.motion[i as usize];
        (m != NO_MOTION).then(|| &self.motions[m as usize])
    }

    pub fn has_motion(&self) -> bool {
        !self.motions.is_empty()
    }

    /// Intersects primitive `i` at `time`: a moving primitive is tested in its rest pose.
    /// Without MOTION no time is looked at.
    #[inline]
    pub fn intersect_at<const MOTION: bool>(
        &self,
        i: u32,
        ray: &Ray,
        t_max: f32,
        time: f32,
    ) -> Option<(f32, f32, f32)> {
        if MOTION && let Some(m) = self.motion_of(i) {
            return self.intersect(i, &m.ray_to_rest(ray, time), t_max);
        }
        self.intersect(i, ray, t_max)
    }

    /// Surface data at `time` (see `intersect_at`).
    #[inline]
    pub fn surface_at<const MOTION: bool>(&self, ray: &Ray, hit: &Hit, time: f32) -> SurfacePoint {
        if MOTION && let Some(m) = self.motion_of(hit.prim) {
            let sp = self.surface(&m.ray_to_rest(ray, time), hit);
            return SurfacePoint {
                p: m.point_to_world(sp.p, time),
                n: m.vector_to_world(sp.n, time),
                front: sp.front,
            };
        }
        self.surface(ray, hit)
    }

    /// Intersects primitive `i` in the pose of time 0: `Some((t, u, v))` for a hit in
    /// (0, t_max).
    #[inline]
    pub fn intersect(&self, i: u32, ray: &Ray, t_max: f32) -> Option<(f32, f32, f32)> {
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
        }
    }

    /// Full surface data, computed for the winning hit only.
    #[inline]
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> SurfacePoint {
        let l = self.local[hit.prim as usize] as usize;
        match self.kind[hit.prim as usize] {
            PrimKind::Sphere => self.spheres[l].surface(ray, hit.t, hit.u > 0.5),
            PrimKind::Rect | PrimKind::Disk => self.planars[l].surface(ray, hit.u, hit.v),
            PrimKind::Box => self.boxes[l].surface(ray, hit.t, hit.u > 0.5),
        }
    }

    /// Number of primitives of each kind, for `prism info`.
    pub fn counts(&self) -> [(PrimKind, usize); 4] {
        let n = |k| self.kind.iter().filter(|&&x| x == k).count();
        [
            (PrimKind::Sphere, n(PrimKind::Sphere)),
            (PrimKind::Rect, n(PrimKind::Rect)),
            (PrimKind::Disk, n(PrimKind::Disk)),
            (PrimKind::Box, n(PrimKind::Box)),
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

/// Flattens every entity with a `Shape` into world-space primitives. Entities are taken in
/// spawn order so primitive indices, and thus images, are reproducible.
pub fn gather_primitives(world: &hecs::World) -> Primitives {
    let mut p = Primitives::default();
    type Row = (
        hecs::Entity,
        Shape,
        Transform,
        Material,
        String,
        Option<Motion>,
    );
    let mut rows: Vec<Row> = world
        .query::<(
            hecs::Entity,
            &Shape,
            &Transform,
            &Material,
            &Name,
            Option<&Motion>,
        )>()
        .iter()
        .map(|(e, s, t, m, n, mo)| (e, *s, *t, *m, n.0.clone(), mo.copied()))
        .collect();
    rows.sort_by_key(|r| r.0.id());
    for (entity, shape, transform, material, name, motion) in rows {
        let moving = motion.filter(|m| !m.is_static()).map(|m| {
            p.motions.push(RigidMotion {
                pivot: transform.to_world.translation.into(),
                velocity: m.velocity,
                angular: m.angular_velocity * (std::f32::consts::PI / 180.0),
            });
            (p.motions.len() - 1) as u32
        });
        p.motion.push(moving.unwrap_or(NO_MOTION));
        let m = p.materials.len() as u32;
        p.materials.push(material);
        let tw = transform.to_world;
        let (kind, local) = match shape {
            Shape::Sphere { center, radius } => {
                let scale = transform.uniform_scale.unwrap_or(1.0);
                p.spheres.push(Sphere {
                    center: tw.transform_point3(center),
                    radius: radius * scale,
                });
                (PrimKind::Sphere, p.spheres.len() - 1)
            }
            Shape::Rect { center, u, v } => {
                p.planars.push(Planar::new(
                    tw.transform_point3(center),
                    tw.transform_vector3(u),
                    tw.transform_vector3(v),
                    false,
                ));
                (PrimKind::Rect, p.planars.len() - 1)
            }
            Shape::Disk {
                center,
                normal,
                radius,
            } => {
                let (t, b) = crate::sampling::coordinate_system(normal);
                p.planars.push(Planar::new(
                    tw.transform_point3(center),
                    tw.transform_vector3(t * radius),
                    tw.transform_vector3(b * radius),
                    true,
                ));
                (PrimKind::Disk, p.planars.len() - 1)
            }
            Shape::Box { min, max } => {
                p.boxes.push(OrientedBox::new(min, max, tw));
                (PrimKind::Box, p.boxes.len() - 1)
            }
        };
        p.kind.push(kind);
        p.local.push(local as u32);
        p.material.push(m);
        p.light.push(NO_LIGHT);
        p.entity.push(entity);
        p.names.push(name);
    }
    p
}

/// Radiance leaving an emissive primitive towards `wo` from a point with normal `n`.
#[inline]
pub fn emitted(material: &Material, n: Vec3, wo: Vec3) -> Vec3 {
    match *material {
        Material::Light {
            emission,
            two_sided,
        } if two_sided || n.dot(wo) > 0.0 => emission,
        _ => Vec3::ZERO,
    }
}
