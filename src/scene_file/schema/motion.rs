//! Motion: an entity's linear motion over the shutter, and the camera's keyframed animation.

use super::{FovY, Positive, V3};
use serde::Deserialize;

/// Rigid motion of an entity: scene units per frame, and degrees per frame about the object
/// origin (the transform's translation), applied as R = Rz·Ry·Rx of the angles times time.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motion {
    /// Translation per frame, in scene units; default zero.
    #[serde(default)]
    pub velocity: Option<V3>,
    /// Rotation per frame about the x, y and z axes, in degrees; default zero.
    #[serde(default)]
    pub angular_velocity: Option<V3>,
}

/// A camera path: keyframes indexed by frame, interpolated smoothly between them (position
/// and look-at on Catmull–Rom Hermite splines, up, field of view and focus linearly); before
/// the first key and after the last the camera holds still.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "AnimationSpec")]
pub struct Animation {
    /// Frames per second of the animated output, 1..=1000; default 24.
    pub fps: u32,
    /// At least one keyframe, in strictly increasing frame order.
    pub keyframes: Vec<Keyframe>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AnimationSpec {
    #[serde(default = "default_fps")]
    fps: u32,
    keyframes: Vec<Keyframe>,
}

fn default_fps() -> u32 {
    24
}

/// The camera at one frame; an optional field left out keeps the `camera`'s value.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// The frame this key pins down.
    pub frame: u32,
    /// Eye point, world space.
    pub position: V3,
    /// Point the camera looks at; must differ from `position`.
    pub look_at: V3,
    /// Up direction; default the camera's `up`.
    #[serde(default)]
    pub up: Option<V3>,
    /// Vertical field of view in degrees, in (0, 180); default the camera's `fov_y`.
    #[serde(default)]
    pub fov_y: Option<FovY>,
    /// Distance to the plane in focus, scene units, > 0; default the lens's (1 without a lens).
    #[serde(default)]
    pub focus_distance: Option<Positive>,
}

impl TryFrom<AnimationSpec> for Animation {
    type Error = String;
    fn try_from(a: AnimationSpec) -> Result<Self, String> {
        if !(1..=1000).contains(&a.fps) {
            return Err(format!("field `fps`: must be in 1..=1000, got {}", a.fps));
        }
        if a.keyframes.is_empty() {
            return Err("an animation needs at least one keyframe".into());
        }
        for w in a.keyframes.windows(2) {
            if w[1].frame <= w[0].frame {
                return Err(format!(
                    "keyframes must have increasing frame numbers, got {} after {}",
                    w[1].frame, w[0].frame
                ));
            }
        }
        Ok(Animation {
            fps: a.fps,
            keyframes: a.keyframes,
        })
    }
}
