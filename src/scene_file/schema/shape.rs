//! Shapes and their placement (transforms).

use super::{Positive, Scale, V3};
use serde::Deserialize;

/// An entity's surface, in object space (the entity's `transform` places it).
#[derive(Clone, Debug, Deserialize)]
#[serde(try_from = "ShapeSpec")]
pub enum Shape {
    /// A sphere; it takes a uniform scale only.
    Sphere {
        /// Centre, object space.
        center: V3,
        /// Radius in scene units, > 0.
        radius: Positive,
    },
    /// A parallelogram spanning `center ± u ± v`, facing `normalize(u × v)`.
    Rect {
        /// Centre, object space.
        center: V3,
        /// Half of one side; non-zero.
        u: V3,
        /// Half of the other side; non-zero and not parallel to `u`.
        v: V3,
    },
    /// A flat disk.
    Disk {
        /// Centre, object space.
        center: V3,
        /// The side the disk faces; any non-zero length.
        normal: V3,
        /// Radius in scene units, > 0.
        radius: Positive,
    },
    /// An axis-aligned box (before the transform).
    Box {
        /// The lowest corner; below `max` on every axis.
        min: V3,
        /// The highest corner.
        max: V3,
    },
    /// A triangle mesh from an OBJ or PLY file, relative to the scene file.
    Mesh {
        /// Path of the `.obj` or `.ply` file, relative to the scene file's directory; not
        /// blank.
        path: String,
    },
    /// A cubic B-spline profile (radius, height) revolved about the local y axis.
    Revolution {
        /// Control points (radius, height) of a clamped uniform cubic B-spline: at least 4,
        /// finite, radii >= 0 and not all 0.
        profile: Vec<(f32, f32)>,
        /// Newton convergence threshold in the curve parameter, in (0, 0.1); default 1e-6
        /// (`render.newton_tolerance` overrides it).
        tolerance: Option<f32>,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
enum ShapeSpec {
    Sphere {
        center: V3,
        radius: Positive,
    },
    Rect {
        center: V3,
        u: V3,
        v: V3,
    },
    Disk {
        center: V3,
        normal: V3,
        radius: Positive,
    },
    Box {
        min: V3,
        max: V3,
    },
    Mesh {
        path: String,
    },
    Revolution {
        profile: Vec<(f32, f32)>,
        #[serde(default)]
        tolerance: Option<f32>,
    },
}

impl TryFrom<ShapeSpec> for Shape {
    type Error = String;
    fn try_from(s: ShapeSpec) -> Result<Self, String> {
        Ok(match s {
            ShapeSpec::Sphere { center, radius } => Shape::Sphere { center, radius },
            ShapeSpec::Rect { center, u, v } => {
                let (a, b) = (u.vec(), v.vec());
                if a.cross(b).length_squared() <= 0.0 {
                    return Err(format!(
                        "Rect: u {:?} and v {:?} must be non-zero and not parallel (they span center ± u ± v)",
                        u.0, v.0
                    ));
                }
                Shape::Rect { center, u, v }
            }
            ShapeSpec::Disk {
                center,
                normal,
                radius,
            } => {
                if normal.vec().length_squared() <= 0.0 {
                    return Err("field `normal`: a Disk's normal must be a non-zero vector".into());
                }
                Shape::Disk {
                    center,
                    normal,
                    radius,
                }
            }
            ShapeSpec::Box { min, max } => {
                let (a, b) = (min.vec(), max.vec());
                if !(a.x < b.x && a.y < b.y && a.z < b.z) {
                    return Err(format!(
                        "Box: min {:?} must be below max {:?} on every axis (a box needs a non-zero size)",
                        min.0, max.0
                    ));
                }
                Shape::Box { min, max }
            }
            ShapeSpec::Mesh { path } => {
                if path.trim().is_empty() {
                    return Err("Mesh: path must name an .obj or .ply file".into());
                }
                Shape::Mesh { path }
            }
            ShapeSpec::Revolution { profile, tolerance } => {
                if let Some(t) = tolerance
                    && !(t.is_finite() && t > 0.0 && t < 0.1)
                {
                    return Err(format!(
                        "Revolution: tolerance must be in (0, 0.1), got {t}"
                    ));
                }
                // Checked here so a bad profile keeps its line and column.
                crate::geometry::Revolution::new(
                    &profile,
                    tolerance.unwrap_or(crate::geometry::revolution::DEFAULT_TOLERANCE),
                )
                .map_err(|e| format!("Revolution: {e}"))?;
                Shape::Revolution { profile, tolerance }
            }
        })
    }
}

/// Object-to-world placement: scale, then rotation R = Rz·Ry·Rx (degrees), then translation.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    /// Offset in scene units; default zero.
    #[serde(default)]
    pub translate: Option<V3>,
    /// Rotation about the x, y and z axes in degrees, applied x first; default zero.
    #[serde(default)]
    pub rotate: Option<V3>,
    /// Per-axis scale, or one number for all three; finite and non-zero, default 1.
    #[serde(default)]
    pub scale: Option<Scale>,
}
