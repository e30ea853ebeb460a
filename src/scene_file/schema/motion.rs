//! Motion: an entity's linear motion over the shutter, and the camera's keyframed animation.

use super::{FovY, Positive, V3};
use serde::Deserialize;

/// Rigid motion of an entity: scene units per frame, and degrees per frame about the object
/// origin (the transform's translation), applied as R = Rz·Ry·Rx of the angles times time.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motion {
    #[serde(default)]
    pub velocity: Option<V3>,
    #[serde(default)]
    pub angular_velocity: Option<V3>,
}

/// A camera path: keyframes indexed by frame, interpolated smoothly between them.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "AnimationSpec")]
pub struct Animation {
    pub fps: u32,
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

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    pub frame: u32,
    pub position: V3,
    pub look_at: V3,
    #[serde(default)]
    pub up: Option<V3>,
    #[serde(default)]
    pub fov_y: Option<FovY>,
    #[serde(default)]
    pub focus_distance: Option<Positive>,
}

impl TryFrom<AnimationSpec> for Animation {
    type Error = String;
    fn try_from(a: AnimationSpec) -> Result<Self, String> {
        if !(1..=1000).contains(&a.fps) {
            return Err(format!("fps must be in 1..=1000, got {}", a.fps));
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
