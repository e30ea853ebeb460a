//! Point and spot lights, and the environment seen by escaping rays.

use super::{Emission, V3};
use serde::Deserialize;

/// A light without a shape: a point or a spot. `intensity` is radiant intensity (radiance
/// times area per solid angle); `cone` is the half-angle of the spot's cone in degrees and
/// `falloff` the width of the soft edge inside it.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "LightSpecRaw")]
pub enum LightSpec {
    /// Emits equally in every direction.
    Point {
        /// Where the light is, object space (the entity's `transform` applies).
        position: V3,
        /// Radiant intensity.
        intensity: Emission,
    },
    /// Emits into a cone about `direction`.
    Spot {
        /// Where the light is, object space (the entity's `transform` applies).
        position: V3,
        /// Axis of the cone, object space; any non-zero length.
        direction: V3,
        /// Half-angle of the cone in degrees, in (0, 90].
        cone: f32,
        /// Width of the soft edge inside the cone in degrees, in [0, `cone`]; default 0 (a
        /// hard edge).
        falloff: f32,
        /// Radiant intensity within `cone - falloff` of the axis.
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
///
/// ```text
/// Constant(Rgb(0.1, 0.1, 0.1))
/// Image(path: "../assets/studio.exr", scale: 1.0, rotate: (0.0, 90.0, 0.0))
/// Sky(sun_elevation: 30.0, sun_azimuth: 120.0, turbidity: 3.0, ground_albedo: Rgb(0.3, 0.3, 0.3), sun: true, scale: 1.0)
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Environment {
    /// The same radiance from every direction.
    Constant(Emission),
    /// An equirectangular (latitude–longitude) map of linear RGB radiance, EXR or Radiance
    /// HDR (PNG and JPEG are read as sRGB): `+y` up, the map's centre column facing `-z`,
    /// turned by `rotate` (degrees about x, then y, then z, as a transform's rotation) and
    /// multiplied by `scale`. A relative path is relative to the scene file.
    Image {
        /// The image file.
        path: super::ImagePath,
        /// Multiplies every texel; default 1.
        #[serde(default)]
        scale: Option<super::NonNegative>,
        /// Rotation in degrees about x, y and z, applied x first; default zero.
        #[serde(default)]
        rotate: Option<V3>,
    },
    /// A spectral daylight sky (Hosek & Wilkie 2012) and the sun's disc: black below the
    /// horizon, `+y` up, azimuth measured from `-z` towards `+x` (as an `Image`'s columns).
    Sky {
        /// The sun's angle above the horizon in degrees, in [0, 90].
        sun_elevation: super::SunElevation,
        /// The sun's compass direction in degrees: 0 towards `-z`, 90 towards `+x`;
        /// default 0.
        #[serde(default)]
        sun_azimuth: Option<super::Finite>,
        /// Atmospheric turbidity in [1, 10] (2 a clear day, 10 haze); default 3.
        #[serde(default)]
        turbidity: Option<super::Turbidity>,
        /// Reflectance of the ground under the sky, each channel in [0, 1]; default
        /// `Rgb(0.3, 0.3, 0.3)`.
        #[serde(default)]
        ground_albedo: Option<super::Albedo>,
        /// Whether the sun's disc shines; default true.
        #[serde(default)]
        sun: Option<bool>,
        /// Multiplies sky and sun; default 1.
        #[serde(default)]
        scale: Option<super::NonNegative>,
    },
}
