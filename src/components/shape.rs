//! `Shape`: the geometry of an entity, in object space.
//!
//! ```
//! # use prism::scene_file::schema::Shape;
//! let s: Shape = ron::from_str("Sphere(center: (0.0, 1.0, 0.0), radius: 1.0)").unwrap();
//! # let _ = s;
//! let s: Shape = ron::from_str("Rect(center: (0.0, 3.0, 0.0), u: (0.5, 0.0, 0.0), v: (0.0, 0.0, 0.5))").unwrap();
//! # let _ = s;
//! let s: Shape = ron::from_str("Disk(center: (0.0, 0.0, 0.0), normal: (0.0, 1.0, 0.0), radius: 2.0)").unwrap();
//! # let _ = s;
//! let s: Shape = ron::from_str("Box(min: (0.0, 0.0, 0.0), max: (1.0, 2.0, 1.0))").unwrap();
//! # let _ = s;
//! ```
//! `Rect` spans `center ± u ± v` (half edges) and faces `normalize(u × v)`; `Box` is closed.
//! `Mesh(path: "../assets/bunny.obj")` loads an OBJ or PLY file (relative to the scene file).
//! `Revolution(profile: [(radius, height), ...], tolerance: 1e-6)` revolves a clamped uniform
//! cubic B-spline about the local y axis; a profile that starts and ends on the axis is closed.

use glam::Vec3;
use std::sync::Arc;

/// The geometry of an entity, in object space.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre, object space.
        center: Vec3,
        /// Radius, scene units.
        radius: f32,
    },
    /// A parallelogram spanning `center ± u ± v`, facing `normalize(u × v)`.
    Rect {
        /// Centre, object space.
        center: Vec3,
        /// Half edge along the first side.
        u: Vec3,
        /// Half edge along the second side.
        v: Vec3,
    },
    /// A flat disk.
    Disk {
        /// Centre, object space.
        center: Vec3,
        /// Direction the disk faces.
        normal: Vec3,
        /// Radius, scene units.
        radius: f32,
    },
    /// A closed axis-aligned box.
    Box {
        /// Corner with the smallest coordinates.
        min: Vec3,
        /// Corner with the largest coordinates.
        max: Vec3,
    },
    /// A revolved B-spline profile, shared by every entity with the same profile.
    Revolution(Arc<crate::geometry::Revolution>),
    /// A triangle mesh with its kd-tree, loaded and built once per file however many entities
    /// use it.
    Mesh(Arc<crate::geometry::TriangleMesh>),
}

impl Shape {
    /// The variant's name as the scene file spells it, for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Shape::Sphere { .. } => "Sphere",
            Shape::Rect { .. } => "Rect",
            Shape::Disk { .. } => "Disk",
            Shape::Box { .. } => "Box",
            Shape::Revolution(_) => "Revolution",
            Shape::Mesh(_) => "Mesh",
        }
    }

    /// Closed shapes have an inside (media and dielectrics rely on it).
    pub fn is_closed(&self) -> bool {
        match self {
            Shape::Sphere { .. } | Shape::Box { .. } => true,
            Shape::Revolution(r) => r.is_closed(),
            Shape::Mesh(m) => m.is_closed(),
            _ => false,
        }
    }
}
