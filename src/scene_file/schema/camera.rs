//! The camera: position, aim, field of view, thin lens and shutter.

use super::{Blades, FovY, NonNegative, Positive, V3};
use serde::Deserialize;

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub position: V3,
    pub look_at: V3,
    #[serde(default = "default_up")]
    pub up: V3,
    #[serde(default = "default_fov")]
    pub fov_y: FovY,
    #[serde(default)]
    pub lens: Option<Lens>,
    #[serde(default)]
    pub shutter: Option<Shutter>,
}

fn default_up() -> V3 {
    V3([0.0, 1.0, 0.0])
}
fn default_fov() -> FovY {
    FovY(40.0)
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lens {
    pub aperture_radius: NonNegative,
    pub focus_distance: Positive,
    #[serde(default)]
    pub blades: Blades,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "ShutterSpec")]
pub struct Shutter {
    pub open: f32,
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
