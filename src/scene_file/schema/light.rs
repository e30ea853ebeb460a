//! Point and spot lights, and the environment seen by escaping rays.

use super::{Emission, V3};
use serde::Deserialize;

/// A light without a shape: a point or a spot. `intensity` is radiant intensity (radiance
/// times area per solid angle); `cone` is the half-angle of the spot's cone in degrees and
/// `falloff` the width of the soft edge inside it.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "LightSpecRaw")]
pub enum LightSpec {
    Point {
        position: V3,
        intensity: Emission,
    },
    Spot {
        position: V3,
        direction: V3,
        cone: f32,
        falloff: f32,
        intensity: Emission,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
enum LightSpecRaw {
    Point {
        position: V3,
        intensity: Emission,
    },
    Spot {
        position: V3,
        direction: V3,
        cone: f32,
        #[serde(default)]
        falloff: f32,
        intensity: Emission,
    },
}

impl TryFrom<LightSpecRaw> for LightSpec {
    type Error = String;
    fn try_from(l: LightSpecRaw) -> Result<Self, String> {
        Ok(match l {
            LightSpecRaw::Point {
                position,
                intensity,
            } => LightSpec::Point {
                position,
                intensity,
            },
            LightSpecRaw::Spot {
                position,
                direction,
                cone,
                falloff,
                intensity,
            } => {
                if direction.vec().length_squared() == 0.0 {
                    return Err("Spot: direction must be a non-zero vector".into());
                }
                if !(cone > 0.0 && cone <= 90.0) {
                    return Err(format!(
                        "Spot: cone must be in (0, 90] degrees (a half-angle), got {cone}"
                    ));
                }
                if !(0.0..=cone).contains(&falloff) {
                    return Err(format!(
                        "Spot: falloff must be in [0, cone] = [0, {cone}] degrees, got {falloff}"
                    ));
                }
                LightSpec::Spot {
                    position,
                    direction,
                    cone,
                    falloff,
                    intensity,
                }
            }
        })
    }
}

/// Background radiance seen by escaping rays.
#[derive(Clone, Debug, Deserialize)]
pub enum Environment {
    Constant(Emission),
}
