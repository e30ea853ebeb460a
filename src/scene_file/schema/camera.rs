//! The camera: position, aim, field of view, thin lens and shutter.

use super::{Blades, FovY, NonNegative, Positive, V3};
use serde::Deserialize;

/// A pinhole or thin-lens camera; the image's right is `forward × up`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// Eye point (lens centre), world space.
    pub position: V3,
    /// Point the camera looks at; must differ from `position`.
    pub look_at: V3,
    /// Up direction; need not be orthogonal to the view, must not be parallel to it. Default
    /// (0, 1, 0).
    #[serde(default = "default_up")]
    pub up: V3,
    /// Vertical field of view in degrees, in (0, 180); default 40.
    #[serde(default = "default_fov")]
    pub fov_y: FovY,
    /// Thin lens for depth of field; absent, a pinhole.
    #[serde(default)]
    pub lens: Option<Lens>,
    /// When the shutter is open within each frame; absent, the whole frame (0 to 1).
    #[serde(default)]
    pub shutter: Option<Shutter>,
}

fn default_up() -> V3 {
    V3([0.0, 1.0, 0.0])
}
fn default_fov() -> FovY {
    FovY(40.0)
}

/// A thin lens: the plane `focus_distance` in front of it is sharp, the rest blurs with the
/// aperture.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lens {
    /// Lens radius in scene units, >= 0; 0 is a pinhole.
    pub aperture_radius: NonNegative,
    /// Distance from the eye to the plane in focus, scene units, > 0.
    pub focus_distance: Positive,
    /// Aperture shape: 0 (default) round, 3..=64 a polygon with that many sides.
    #[serde(default)]
    pub blades: Blades,
}

/// The open part of each frame, for motion blur: frame f covers [f, f + 1), and the shutter
/// is open over [f + open, f + close], with `0 <= open <= close <= 1`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "ShutterSpec")]
pub struct Shutter {
    /// When the shutter opens, as a fraction of the frame.
    pub open: f32,
    /// When the shutter closes, as a fraction of the frame; `open == close` freezes motion.
    pub close: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ShutterSpec {
    open: f32,
    close: f32,
}

impl TryFrom<ShutterSpec> for Shutter {
    type Error = String;
    fn try_from(s: ShutterSpec) -> Result<Self, String> {
        if !(s.open.is_finite()
            && s.close.is_finite()
            && 0.0 <= s.open
            && s.open <= s.close
            && s.close <= 1.0)
        {
            return Err(format!(
                "shutter must satisfy 0 <= open <= close <= 1 (a fraction of a frame), got open {} close {}",
                s.open, s.close
            ));
        }
        Ok(Shutter {
            open: s.open,
            close: s.close,
        })
    }
}
