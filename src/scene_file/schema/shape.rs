//! Shapes and their placement (transforms).

use super::{Positive, Scale, V3};
use serde::Deserialize;

#[derive(Clone, Debug, Deserialize)]
#[serde(try_from = "ShapeSpec")]
pub enum Shape {
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
    /// A triangle mesh from an OBJ or PLY file, relative to the scene file.
    Mesh {
        path: String,
    },
    /// A cubic B-spline profile (radius, height) revolved about the local y axis.
    Revolution {
        profile: Vec<(f32, f32)>,
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
                    return Err("Disk: normal must be a non-zero vector".into());
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
    #[serde(default)]
    pub translate: Option<V3>,
    #[serde(default)]
    pub rotate: Option<V3>,
    #[serde(default)]
    pub scale: Option<Scale>,
}
