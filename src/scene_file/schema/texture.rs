//! serde types of an entity's `texture:` field.
//!
//! As in the scene schema, value ranges are checked while parsing (`#[serde(try_from)]`
//! newtypes) so that a bad value is reported at its own line and column.
//!
//! ```ron
//! texture: (
//!     albedo: Image(path: "../assets/earth.jpg", wrap: Repeat),
//!     normal_map: Image(path: "n.png", flip_y: false),
//!     roughness: Checker(a: 0.2, b: 0.6, size: 0.1),
//!     scale: (1.0, 1.0),
//!     offset: (0.0, 0.0),
//! )
//! ```

use std::path::Path;

use glam::{Vec2, Vec3};
use serde::Deserialize;

use super::{Albedo, NonNegative, Positive, Unit};
use crate::texture::image_tex::{ColorSpace, TextureCache, TextureError, Wrap};
use crate::texture::procedural::{Bricks, Checker, Wood};
use crate::texture::{AlbedoTexture, NormalMap, ScalarTexture, Texture};

/// The `texture:` field; every part is optional. `scale` and `offset` map surface uv before
/// lookup: `uv' = uv * scale + offset` (defaults (1, 1) and (0, 0)).
///
/// ```ron
/// texture: (albedo: Checker(a: Rgb(0.9, 0.9, 0.9), b: Rgb(0.1, 0.1, 0.1), size: 0.1),
///           normal_map: FromHeight(strength: 1.0), scale: (2.0, 2.0))
/// ```
///
/// `normal_map: FromHeight(..)` needs an `albedo` to take heights from.
#[derive(Clone, Debug, Deserialize)]
#[serde(try_from = "TextureSpecFields")]
pub struct TextureSpec {
    /// Multiplies the material's colour (Diffuse albedo, Mirror tint, Light emission).
    pub albedo: Option<AlbedoSpec>,
    /// Perturbs the shading normal.
    pub normal_map: Option<NormalMapSpec>,
    /// The perceptual roughness r (α = r²) of a Conductor, Dielectric or Plastic.
    pub roughness: Option<RoughnessSpec>,
    /// Multiplies surface uv before lookup; default (1, 1).
    pub scale: Option<UvScale>,
    /// Added to surface uv after `scale`; default (0, 0).
    pub offset: Option<UvOffset>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TextureSpecFields {
    #[serde(default)]
    albedo: Option<AlbedoSpec>,
    #[serde(default)]
    normal_map: Option<NormalMapSpec>,
    #[serde(default)]
    roughness: Option<RoughnessSpec>,
    #[serde(default)]
    scale: Option<UvScale>,
    #[serde(default)]
    offset: Option<UvOffset>,
}

impl TryFrom<TextureSpecFields> for TextureSpec {
    type Error = String;
    fn try_from(f: TextureSpecFields) -> Result<Self, String> {
        if matches!(f.normal_map, Some(NormalMapSpec::FromHeight { .. })) && f.albedo.is_none() {
            return Err(
                "normal_map: FromHeight takes its heights from the albedo; add an `albedo`".into(),
            );
        }
        Ok(TextureSpec {
            albedo: f.albedo,
            normal_map: f.normal_map,
            roughness: f.roughness,
            scale: f.scale,
            offset: f.offset,
        })
    }
}

/// Where reflectance comes from.
///
/// ```ron
/// Image(path: "../assets/earth.jpg", wrap: Repeat)   // wrap: Repeat | Clamp | Mirror, default Repeat
/// Checker(a: Rgb(0.9, 0.9, 0.9), b: Rgb(0.1, 0.1, 0.1), size: 0.1)
/// Bricks(brick: Rgb(0.5, 0.15, 0.1), mortar: Rgb(0.8, 0.8, 0.75), size: (0.4, 0.2), joint: 0.1)
/// Wood(light: Rgb(0.75, 0.52, 0.3), dark: Rgb(0.45, 0.25, 0.12), rings: 8.0, noise: 0.5)
/// ```
///
/// - `Image`: an sRGB-encoded photo (PNG, JPEG) or linear HDR/EXR; relative paths are
///   resolved against the scene file's directory.
/// - `Checker`: squares of side `size` (uv units).
/// - `Bricks`: `size` is the brick pitch (width, height) including one joint; `joint`
///   (optional, default 0.1) is the mortar width as a fraction of the shorter side, < 0.5.
/// - `Wood`: `rings` growth rings per uv unit (optional, default 8), `noise` their
///   distortion in ring widths (optional, default 0.5); the grain runs along u.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum AlbedoSpec {
    /// An image file, sampled bilinearly.
    Image {
        /// The image file, relative to the scene file's directory.
        path: ImagePath,
        /// How uv outside [0, 1]² folds back; default `Repeat`.
        #[serde(default)]
        wrap: Wrap,
    },
    /// A checkerboard of two reflectances.
    Checker {
        /// Reflectance of the square touching the uv origin from above-right, channels in
        /// [0, 1].
        a: Albedo,
        /// Reflectance of the other squares, channels in [0, 1].
        b: Albedo,
        /// Side of a square in uv units, > 0.
        size: Positive,
    },
    /// Bricks in running bond with mortar joints.
    Bricks {
        /// Reflectance of the bricks, channels in [0, 1].
        brick: Albedo,
        /// Reflectance of the joints, channels in [0, 1].
        mortar: Albedo,
        /// Brick pitch (width, height) in uv units, joint included; both > 0.
        size: PositivePair,
        /// Mortar width as a fraction of the shorter side of `size`, in (0, 0.5); default 0.1.
        #[serde(default = "default_joint")]
        joint: JointFraction,
    },
    /// Growth rings with the grain along u.
    Wood {
        /// Reflectance of the earlywood, channels in [0, 1].
        light: Albedo,
        /// Reflectance of the latewood, channels in [0, 1].
        dark: Albedo,
        /// Growth rings per uv unit across the grain (along v), > 0; default 8.
        #[serde(default = "default_rings")]
        rings: Positive,
        /// Distortion of the rings in ring widths, >= 0; default 0.5.
        #[serde(default = "default_noise")]
        noise: NonNegative,
    },
}

fn default_joint() -> JointFraction {
    JointFraction(0.1)
}
fn default_rings() -> Positive {
    Positive(8.0)
}
fn default_noise() -> NonNegative {
    NonNegative(0.5)
}

/// Where the shading normal's perturbation comes from.
///
/// ```ron
/// Image(path: "n.png", flip_y: false)   // flip_y: true for DirectX-style maps; wrap as for albedo
/// FromHeight(strength: 1.0)             // bumps from the albedo's height; default strength 1
/// ```
///
/// Normal map images are read linearly (never sRGB-decoded), components encoded `2c − 1`,
/// +y along +v.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum NormalMapSpec {
    /// A tangent-space normal map image.
    Image {
        /// The image file, relative to the scene file's directory.
        path: ImagePath,
        /// Negate the green component, for DirectX-style maps; default `false`.
        #[serde(default)]
        flip_y: bool,
        /// How uv outside [0, 1]² folds back; default `Repeat`.
        #[serde(default)]
        wrap: Wrap,
    },
    /// Bumps from the albedo texture's relief height.
    FromHeight {
        /// Relief scale, any finite number (negative inverts the relief); default 1.
        #[serde(default = "default_strength")]
        strength: Strength,
    },
}

/// Where a surface's roughness comes from: a perceptual roughness r in [0, 1], α = r² (as
/// the material's `roughness:` field, glTF and Blender).
///
/// ```ron
/// Checker(a: 0.2, b: 0.6, size: 0.1)
/// Image(path: "rough.png", channel: R)   // channel: R | G | B, default R; wrap as for albedo
/// ```
///
/// Images are read linearly (never sRGB-decoded): a texel of 8-bit value v is r = v/255.
/// On an anisotropic material the texture sets √(αx·αy) and keeps αx/αy.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum RoughnessSpec {
    /// One channel of an image file, sampled bilinearly.
    Image {
        /// The image file, relative to the scene file's directory.
        path: ImagePath,
        /// The channel holding the roughness; default `R`.
        #[serde(default)]
        channel: crate::texture::Channel,
        /// How uv outside [0, 1]² folds back; default `Repeat`.
        #[serde(default)]
        wrap: Wrap,
    },
    /// A checkerboard of two roughnesses.
    Checker {
        /// Roughness of the square touching the uv origin from above-right, in [0, 1].
        a: Unit,
        /// Roughness of the other squares, in [0, 1].
        b: Unit,
        /// Side of a square in uv units, > 0.
        size: Positive,
    },
}

fn default_strength() -> Strength {
    Strength(1.0)
}

/// A non-empty file path.
#[derive(Clone, Debug, Deserialize, PartialEq, Eq)]
#[serde(try_from = "String")]
pub struct ImagePath(pub String);

impl TryFrom<String> for ImagePath {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        if s.trim().is_empty() {
            Err("path must name an image file, got an empty string".into())
        } else {
            Ok(ImagePath(s))
        }
    }
}

/// `(su, sv)`: finite and non-zero (negative mirrors the texture).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(try_from = "(f32, f32)")]
pub struct UvScale(pub [f32; 2]);

impl TryFrom<(f32, f32)> for UvScale {
    type Error = String;
    fn try_from((u, v): (f32, f32)) -> Result<Self, String> {
        if [u, v].iter().all(|c| c.is_finite() && *c != 0.0) {
            Ok(UvScale([u, v]))
        } else {
            Err(format!(
                "texture scale must be finite and non-zero, got ({u}, {v})"
            ))
        }
    }
}

/// `(du, dv)`: finite.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(try_from = "(f32, f32)")]
pub struct UvOffset(pub [f32; 2]);

impl TryFrom<(f32, f32)> for UvOffset {
    type Error = String;
    fn try_from((u, v): (f32, f32)) -> Result<Self, String> {
        if u.is_finite() && v.is_finite() {
            Ok(UvOffset([u, v]))
        } else {
            Err(format!("texture offset must be finite, got ({u}, {v})"))
        }
    }
}

/// `(w, h)`: both finite and > 0.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(try_from = "(f32, f32)")]
pub struct PositivePair(pub [f32; 2]);

impl TryFrom<(f32, f32)> for PositivePair {
    type Error = String;
    fn try_from((w, h): (f32, f32)) -> Result<Self, String> {
        if [w, h].iter().all(|c| c.is_finite() && *c > 0.0) {
            Ok(PositivePair([w, h]))
        } else {
            Err(format!(
                "size must be finite and > 0 on both axes, got ({w}, {h})"
            ))
        }
    }
}

/// Mortar joint width as a fraction of the brick's shorter side, in (0, 0.5).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(try_from = "f32")]
pub struct JointFraction(pub f32);

impl TryFrom<f32> for JointFraction {
    type Error = String;
    fn try_from(x: f32) -> Result<Self, String> {
        if x.is_finite() && x > 0.0 && x < 0.5 {
            Ok(JointFraction(x))
        } else {
            Err(format!(
                "joint must be in (0, 0.5) (a fraction of the brick's shorter side), got {x}"
            ))
        }
    }
}

/// Bump strength: any finite number (negative inverts the relief).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(try_from = "f32")]
pub struct Strength(pub f32);

impl TryFrom<f32> for Strength {
    type Error = String;
    fn try_from(x: f32) -> Result<Self, String> {
        if x.is_finite() {
            Ok(Strength(x))
        } else {
            Err(format!("strength must be finite, got {x}"))
        }
    }
}

impl TextureSpec {
    /// Builds the runtime texture, loading images through `cache`; relative image paths are
    /// resolved against `base_dir` (the scene file's directory).
    pub fn build(
        &self,
        base_dir: &Path,
        cache: &mut TextureCache,
    ) -> Result<Texture, TextureError> {
        let albedo = match &self.albedo {
            None => None,
            Some(a) => Some(a.build(base_dir, cache)?),
        };
        let normal_map = match &self.normal_map {
            None => None,
            Some(n) => Some(n.build(base_dir, cache)?),
        };
        let roughness = match &self.roughness {
            None => None,
            Some(RoughnessSpec::Image {
                path,
                channel,
                wrap,
            }) => Some(ScalarTexture::Image {
                image: cache.get(&base_dir.join(&path.0), ColorSpace::Linear)?,
                channel: *channel,
                wrap: *wrap,
            }),
            Some(RoughnessSpec::Checker { a, b, size }) => Some(ScalarTexture::Checker(Checker {
                a: Vec3::splat(a.0),
                b: Vec3::splat(b.0),
                size: size.0,
            })),
        };
        Ok(Texture {
            albedo,
            normal_map,
            roughness,
            scale: self.scale.map_or(Vec2::ONE, |s| Vec2::from_array(s.0)),
            offset: self.offset.map_or(Vec2::ZERO, |o| Vec2::from_array(o.0)),
        })
    }
}

impl AlbedoSpec {
    /// Builds the runtime albedo, loading an image through `cache` (sRGB-decoded) from
    /// `base_dir` joined with its path.
    pub fn build(
        &self,
        base_dir: &Path,
        cache: &mut TextureCache,
    ) -> Result<AlbedoTexture, TextureError> {
        Ok(match self {
            AlbedoSpec::Image { path, wrap } => AlbedoTexture::Image {
                image: cache.get(&base_dir.join(&path.0), ColorSpace::Srgb)?,
                wrap: *wrap,
            },
            AlbedoSpec::Checker { a, b, size } => AlbedoTexture::Checker(Checker {
                a: a.0.vec(),
                b: b.0.vec(),
                size: size.0,
            }),
            AlbedoSpec::Bricks {
                brick,
                mortar,
                size,
                joint,
            } => {
                let size = Vec2::from_array(size.0);
                AlbedoTexture::Bricks(Bricks {
                    brick: brick.0.vec(),
                    mortar: mortar.0.vec(),
                    size,
                    joint: joint.0 * size.min_element(),
                })
            }
            AlbedoSpec::Wood {
                light,
                dark,
                rings,
                noise,
            } => AlbedoTexture::Wood(Wood {
                light: light.0.vec(),
                dark: dark.0.vec(),
                rings: rings.0,
                noise: noise.0,
            }),
        })
    }
}

impl NormalMapSpec {
    /// Builds the runtime normal map, loading an image through `cache` (read linearly) from
    /// `base_dir` joined with its path.
    pub fn build(
        &self,
        base_dir: &Path,
        cache: &mut TextureCache,
    ) -> Result<NormalMap, TextureError> {
        Ok(match self {
            NormalMapSpec::Image { path, flip_y, wrap } => NormalMap::Image {
                image: cache.get(&base_dir.join(&path.0), ColorSpace::Linear)?,
                flip_y: *flip_y,
                wrap: *wrap,
            },
            NormalMapSpec::FromHeight { strength } => NormalMap::FromHeight {
                strength: strength.0,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `implicit_some` as the scene loader enables it, so `albedo: Image(..)` needs no `Some`.
    fn parse<T: for<'de> Deserialize<'de>>(text: &str) -> Result<T, ron::error::SpannedError> {
        ron::from_str(&format!("#![enable(implicit_some)]\n{text}"))
    }

    #[test]
    fn parses_contract_example() {
        let t: TextureSpec = parse(
            r#"(albedo: Image(path: "../assets/earth.jpg", wrap: Repeat),
                normal_map: Image(path: "n.png", flip_y: false),
                scale: (1.0, 1.0), offset: (0.0, 0.0))"#,
        )
        .unwrap();
        assert!(matches!(
            t.albedo,
            Some(AlbedoSpec::Image { ref path, wrap: Wrap::Repeat }) if path.0 == "../assets/earth.jpg"
        ));
        assert!(matches!(
            t.normal_map,
            Some(NormalMapSpec::Image { ref path, flip_y: false, wrap: Wrap::Repeat }) if path.0 == "n.png"
        ));
        assert_eq!(t.scale, Some(UvScale([1.0, 1.0])));
        assert_eq!(t.offset, Some(UvOffset([0.0, 0.0])));
    }

    #[test]
    fn doc_examples_parse() {
        for text in [
            r#"Image(path: "../assets/earth.jpg", wrap: Repeat)"#,
            "Checker(a: Rgb(0.9, 0.9, 0.9), b: Rgb(0.1, 0.1, 0.1), size: 0.1)",
            "Bricks(brick: Rgb(0.5, 0.15, 0.1), mortar: Rgb(0.8, 0.8, 0.75), size: (0.4, 0.2), joint: 0.1)",
            "Wood(light: Rgb(0.75, 0.52, 0.3), dark: Rgb(0.45, 0.25, 0.12), rings: 8.0, noise: 0.5)",
        ] {
            ron::from_str::<AlbedoSpec>(text).unwrap_or_else(|e| panic!("{text}: {e}"));
        }
        for text in [
            r#"Image(path: "n.png", flip_y: false)"#,
            "FromHeight(strength: 1.0)",
        ] {
            ron::from_str::<NormalMapSpec>(text).unwrap_or_else(|e| panic!("{text}: {e}"));
        }
        parse::<TextureSpec>(
            "(albedo: Checker(a: Rgb(0.9, 0.9, 0.9), b: Rgb(0.1, 0.1, 0.1), size: 0.1),
              normal_map: FromHeight(strength: 1.0), scale: (2.0, 2.0))",
        )
        .unwrap();
    }

    #[test]
    fn every_field_is_optional() {
        let t: TextureSpec = parse("()").unwrap();
        assert!(t.albedo.is_none() && t.normal_map.is_none());
        assert!(t.scale.is_none() && t.offset.is_none());
        let built = t.build(Path::new("."), &mut TextureCache::new()).unwrap();
        assert_eq!((built.scale, built.offset), (Vec2::ONE, Vec2::ZERO));
    }

    #[test]
    fn parses_every_albedo_variant() {
        for (text, wrap) in [
            (r#"Image(path: "a.png")"#, Wrap::Repeat),
            (r#"Image(path: "a.png", wrap: Clamp)"#, Wrap::Clamp),
            (r#"Image(path: "a.png", wrap: Mirror)"#, Wrap::Mirror),
        ] {
            let a: AlbedoSpec = ron::from_str(text).unwrap();
            assert!(
                matches!(a, AlbedoSpec::Image { wrap: w, .. } if w == wrap),
                "{text}"
            );
        }
        let a: AlbedoSpec =
            ron::from_str("Checker(a: Rgb(1.0, 1.0, 1.0), b: Rgb(0.0, 0.0, 0.0), size: 0.1)")
                .unwrap();
        assert!(matches!(a, AlbedoSpec::Checker { size: Positive(s), .. } if s == 0.1));
        let a: AlbedoSpec = ron::from_str(
            "Bricks(brick: Rgb(0.5, 0.15, 0.1), mortar: Rgb(0.8, 0.8, 0.75), size: (0.4, 0.2))",
        )
        .unwrap();
        assert!(matches!(
            a,
            AlbedoSpec::Bricks { size: PositivePair([0.4, 0.2]), joint: JointFraction(j), .. } if j == 0.1
        ));
        let a: AlbedoSpec = ron::from_str(
            "Wood(light: Rgb(0.8, 0.6, 0.4), dark: Rgb(0.4, 0.2, 0.1), rings: 12.0, noise: 0.0)",
        )
        .unwrap();
        assert!(matches!(
            a,
            AlbedoSpec::Wood { rings: Positive(r), noise: NonNegative(n), .. } if r == 12.0 && n == 0.0
        ));
        let a: AlbedoSpec =
            ron::from_str("Wood(light: Rgb(0.8, 0.6, 0.4), dark: Rgb(0.4, 0.2, 0.1))").unwrap();
        assert!(matches!(
            a,
            AlbedoSpec::Wood {
                rings: Positive(8.0),
                noise: NonNegative(0.5),
                ..
            }
        ));
    }

    #[test]
    fn parses_every_normal_map_variant() {
        let n: NormalMapSpec = ron::from_str(r#"Image(path: "n.png", flip_y: true)"#).unwrap();
        assert!(matches!(n, NormalMapSpec::Image { flip_y: true, .. }));
        let n: NormalMapSpec = ron::from_str(r#"Image(path: "n.png")"#).unwrap();
        assert!(matches!(
            n,
            NormalMapSpec::Image {
                flip_y: false,
                wrap: Wrap::Repeat,
                ..
            }
        ));
        let n: NormalMapSpec = ron::from_str("FromHeight(strength: -2.5)").unwrap();
        assert!(matches!(
            n,
            NormalMapSpec::FromHeight {
                strength: Strength(-2.5)
            }
        ));
        let n: NormalMapSpec = ron::from_str("FromHeight()").unwrap();
        assert!(matches!(
            n,
            NormalMapSpec::FromHeight {
                strength: Strength(1.0)
            }
        ));
    }

    /// The error message of a failed parse, and its line.
    fn error<T: for<'de> Deserialize<'de> + std::fmt::Debug>(text: &str) -> (String, usize) {
        let e = parse::<T>(text).unwrap_err();
        (e.code.to_string(), e.span.start.line)
    }

    #[test]
    fn out_of_range_values_are_refused_where_they_stand() {
        let cases: &[(&str, &str)] = &[
            (
                "(albedo: Checker(a: Rgb(1.0, 1.0, 1.0), b: Rgb(0.0, 0.0, 0.0),\n size: 0.0))",
                "> 0",
            ),
            (
                "(albedo: Checker(\n a: Rgb(1.5, 1.0, 1.0), b: Rgb(0.0, 0.0, 0.0), size: 1.0))",
                "[0, 1]",
            ),
            (
                "(albedo: Checker(a: Rgb(1.0, 1.0, 1.0),\n b: Rgb(0.0, -0.1, 0.0), size: 1.0))",
                "[0, 1]",
            ),
            (
                "(albedo: Bricks(brick: Rgb(0.5, 0.1, 0.1), mortar: Rgb(0.8, 0.8, 0.8),\n size: (0.4, -0.2)))",
                "> 0",
            ),
            (
                "(albedo: Bricks(brick: Rgb(0.5, 0.1, 0.1), mortar: Rgb(0.8, 0.8, 0.8),\n size: (0.4, 0.2), joint: 0.5))",
                "(0, 0.5)",
            ),
            (
                "(albedo: Wood(light: Rgb(0.5, 0.1, 0.1), dark: Rgb(0.8, 0.8, 0.8),\n rings: 0.0))",
                "> 0",
            ),
            (
                "(albedo: Wood(light: Rgb(0.5, 0.1, 0.1), dark: Rgb(0.8, 0.8, 0.8),\n noise: -1.0))",
                ">= 0",
            ),
            (
                "(albedo: Checker(a: Rgb(1, 1, 1), b: Rgb(0, 0, 0), size: 1.0),\n normal_map: FromHeight(strength: inf))",
                "finite",
            ),
            (
                "(albedo: Image(path: \"a.png\"),\n scale: (1.0, 0.0))",
                "non-zero",
            ),
            (
                "(albedo: Image(path: \"a.png\"),\n offset: (NaN, 0.0))",
                "finite",
            ),
            ("(albedo: Image(path: \"a.png\",\n wrap: Tile))", "Tile"),
            ("(\nalbedo: Image(path: \"\"))", "empty"),
        ];
        for (text, needle) in cases {
            let (msg, line) = error::<TextureSpec>(text);
            assert!(msg.contains(needle), "{text}: {msg}");
            // The offending value sits on the second line of each case.
            assert_eq!(line, 3, "{text}: {msg}");
        }
    }

    #[test]
    fn unknown_fields_are_refused() {
        let (msg, _) = error::<TextureSpec>("(albedo: None, glossiness: 0.5)");
        assert!(msg.contains("glossiness"), "{msg}");
        let (msg, _) =
            error::<TextureSpec>("(roughness: Checker(a: 0.1, b: 0.2, size: 1.0, c: 3))");
        assert!(msg.contains("`c`"), "{msg}");
        let (msg, _) = error::<TextureSpec>(
            "(albedo: Checker(a: Rgb(1, 1, 1), b: Rgb(0, 0, 0), size: 1.0, colour: 2))",
        );
        assert!(msg.contains("colour"), "{msg}");
        let (msg, _) = error::<TextureSpec>("(normal_map: Image(path: \"n.png\", flip: true))");
        assert!(msg.contains("flip"), "{msg}");
    }

    #[test]
    fn from_height_needs_an_albedo() {
        let (msg, _) = error::<TextureSpec>("(normal_map: FromHeight(strength: 1.0))");
        assert!(msg.contains("albedo"), "{msg}");
    }

    #[test]
    fn build_converts_joint_and_mapping() {
        let t: TextureSpec = parse(
            "(albedo: Bricks(brick: Rgb(0.5, 0.15, 0.1), mortar: Rgb(0.8, 0.8, 0.75), size: (0.4, 0.2), joint: 0.25),
              normal_map: FromHeight(strength: 2.0), scale: (2.0, -1.0), offset: (0.5, 0.25))",
        )
        .unwrap();
        let built = t.build(Path::new("."), &mut TextureCache::new()).unwrap();
        let Some(AlbedoTexture::Bricks(b)) = built.albedo else {
            panic!("{built:?}")
        };
        assert!((b.joint - 0.05).abs() < 1e-7);
        assert_eq!(
            built.normal_map,
            Some(NormalMap::FromHeight { strength: 2.0 })
        );
        assert_eq!(built.map_uv(Vec2::new(1.0, 1.0)), Vec2::new(2.5, -0.75));
    }

    /// `prism info` prints a texture as the scene file writes it: the printed form parses back
    /// and builds the same texture.
    #[test]
    fn built_textures_print_in_scene_syntax() {
        for text in [
            "(albedo: Bricks(brick: Rgb(0.5, 0.15, 0.1), mortar: Rgb(0.8, 0.8, 0.75), size: (0.4, 0.2), joint: 0.25),
              normal_map: FromHeight(strength: 2.0), scale: (2.0, -1.0), offset: (0.5, 0.25))",
            "(albedo: Checker(a: Rgb(0.9, 0.9, 0.9), b: Rgb(0.1, 0.2, 0.6), size: 0.0625))",
            "(albedo: Wood(light: Rgb(0.75, 0.55, 0.32), dark: Rgb(0.45, 0.28, 0.14), rings: 3.0, noise: 0.25))",
        ] {
            let mut cache = TextureCache::new();
            let built = parse::<TextureSpec>(text)
                .unwrap()
                .build(Path::new("."), &mut cache)
                .unwrap();
            let printed = built.to_string();
            let again = parse::<TextureSpec>(&printed)
                .unwrap_or_else(|e| panic!("{printed}: {e}"))
                .build(Path::new("."), &mut cache)
                .unwrap();
            // The joint goes through a fraction and back: equal to rounding.
            match (&built.albedo, &again.albedo) {
                (Some(AlbedoTexture::Bricks(a)), Some(AlbedoTexture::Bricks(b))) => {
                    assert!((a.joint - b.joint).abs() < 1e-6, "{printed}");
                    assert_eq!((a.brick, a.mortar, a.size), (b.brick, b.mortar, b.size));
                    assert_eq!(
                        (&built.normal_map, built.scale, built.offset),
                        (&again.normal_map, again.scale, again.offset)
                    );
                }
                _ => assert_eq!(built, again, "{printed}"),
            }
        }
    }

    #[test]
    fn build_reports_missing_image_with_resolved_path() {
        let t: TextureSpec = parse(r#"(albedo: Image(path: "nope/missing.png"))"#).unwrap();
        let err = t
            .build(Path::new("/scenes"), &mut TextureCache::new())
            .unwrap_err();
        assert!(matches!(err, TextureError::Missing { .. }), "{err:?}");
        assert_eq!(
            err.to_string(),
            "texture '/scenes/nope/missing.png' not found"
        );
    }
}
