//! Surface textures: albedo (image or procedural) and normal perturbation.
//!
//! # UV convention
//! Texture coordinates (u, v) span [0, 1]² over one copy of the texture, u to the right and
//! v **up**: v = 0 is the image's bottom row (OpenGL convention). A texture's `scale` and
//! `offset` map a surface's coordinates before any lookup: `uv' = uv * scale + offset`.
//!
//! # Tangent space
//! Tangent-space normals have +z along the shading normal, +x along ∂p/∂u and +y along
//! ∂p/∂v (OpenGL, "green up"); DirectX-style maps need `flip_y`.
//!
//! Runtime types ([`AlbedoTexture`], [`NormalMap`]) take the already-mapped uv'; [`Texture`]
//! bundles both with the mapping and takes surface uv.

pub mod image_tex;
pub mod procedural;

use crate::simd::{Float, Mask, V3};
use glam::{Vec2, Vec3};
use std::sync::Arc;

pub use image_tex::{ColorSpace, TEXTURE_EXTENSIONS, TexImage, TextureCache, TextureError, Wrap};
pub use procedural::{Bricks, Checker, Wood};

/// A colour channel of an image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
pub enum Channel {
    /// Red.
    #[default]
    R,
    /// Green.
    G,
    /// Blue.
    B,
}

/// A scalar surface parameter (a roughness) as a function of uv, linear, clamped to [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub enum ScalarTexture {
    /// One channel of an image, sampled bilinearly.
    Image {
        /// The image's texels, read linearly.
        image: Arc<TexImage>,
        /// The channel read.
        channel: Channel,
        /// How uv outside [0, 1]² is folded back.
        wrap: Wrap,
    },
    /// A checkerboard of two values (equal in the three channels).
    Checker(Checker),
}

impl ScalarTexture {
    /// The value at `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> f32 {
        let v = match self {
            Self::Image {
                image,
                channel,
                wrap,
            } => image.bilinear(uv, *wrap)[*channel as usize],
            Self::Checker(c) => c.eval(uv).x,
        };
        // An HDR image may hold any value; NaN becomes 0 too.
        v.clamp(0.0, 1.0).max(0.0)
    }
}

/// Reflectance as a function of uv, linear RGB.
#[derive(Clone, Debug, PartialEq)]
pub enum AlbedoTexture {
    /// An image, sampled bilinearly.
    Image {
        /// The image's texels, linear RGB.
        image: Arc<TexImage>,
        /// How uv outside [0, 1]² is folded back.
        wrap: Wrap,
    },
    /// A checkerboard of two colours.
    Checker(Checker),
    /// Bricks in running bond with mortar joints.
    Bricks(Bricks),
    /// Wood rings with noise.
    Wood(Wood),
}

impl AlbedoTexture {
    /// Linear RGB at `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        match self {
            Self::Image { image, wrap } => image.bilinear(uv, *wrap),
            Self::Checker(c) => c.eval(uv),
            Self::Bricks(b) => b.eval(uv),
            Self::Wood(w) => w.eval(uv),
        }
    }

    /// Whether [`eval_lanes`](Self::eval_lanes) shares its work between lanes (images and
    /// checkerboards); bricks and wood are cheaper looked up one lane at a time as they are
    /// met.
    #[inline]
    pub fn has_lane_form(&self) -> bool {
        matches!(self, Self::Image { .. } | Self::Checker(_))
    }

    /// [`eval`](Self::eval) for the lanes in `active` at once, bit for bit: images gather
    /// their texels and checkerboards compare in lanes; bricks and wood are looked up one
    /// active lane at a time (inactive lanes are zero for those, unspecified for the rest).
    #[inline(always)]
    pub fn eval_lanes<F: Float>(&self, u: F, v: F, active: F::Mask) -> V3<F> {
        match self {
            Self::Image { image, wrap } => image.bilinear_lanes(u, v, *wrap),
            Self::Checker(c) => c.eval_lanes(u, v),
            Self::Bricks(_) | Self::Wood(_) => V3::from_fn(|i| {
                if active.lane(i) {
                    self.eval(Vec2::new(u.lane(i), v.lane(i)))
                } else {
                    Vec3::ZERO
                }
            }),
        }
    }

    /// Relief height in uv units (see [`procedural`]): mortar below bricks, latewood ridges
    /// above earlywood, a checkerboard flat. For images it is the luminance with a step from
    /// black to white one texel high, the usual "bump from albedo" stand-in.
    #[inline]
    pub fn height(&self, uv: Vec2) -> f32 {
        match self {
            Self::Image { image, wrap } => {
                let texel = 1.0 / image.width().max(image.height()) as f32;
                image.luminance(uv, *wrap) * texel
            }
            Self::Checker(c) => c.height(uv),
            Self::Bricks(b) => b.height(uv),
            Self::Wood(w) => w.height(uv),
        }
    }

    /// A finite-difference step suited to the pattern's finest feature (one texel for
    /// images), for callers without a pixel footprint.
    pub fn height_step(&self) -> f32 {
        match self {
            Self::Image { image, .. } => 1.0 / image.width().max(image.height()) as f32,
            Self::Checker(c) => c.height_step(),
            Self::Bricks(b) => b.height_step(),
            Self::Wood(w) => w.height_step(),
        }
    }
}

/// Where a shading normal's perturbation comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum NormalMap {
    /// A tangent-space normal map, stored linearly with components encoded as `2c − 1`.
    Image {
        /// The map's texels.
        image: Arc<TexImage>,
        /// Negate y, for maps authored with +y along −v (DirectX convention).
        flip_y: bool,
        /// How uv outside [0, 1]² is folded back.
        wrap: Wrap,
    },
    /// Bumps from the albedo's [`AlbedoTexture::height`], scaled by `strength` (negative
    /// inverts the relief).
    FromHeight {
        /// Relief scale; negative inverts it.
        strength: f32,
    },
}

impl NormalMap {
    /// Unit tangent-space normal at `uv` (+z = unperturbed). `FromHeight` takes central
    /// differences of `albedo`'s height with step `duv`; a non-positive or non-finite `duv`
    /// falls back to [`AlbedoTexture::height_step`].
    #[inline]
    pub fn tangent_normal(&self, uv: Vec2, albedo: &AlbedoTexture, duv: f32) -> Vec3 {
        match self {
            Self::Image {
                image,
                flip_y,
                wrap,
            } => {
                let c = image.bilinear(uv, *wrap);
                let mut n = c * 2.0 - Vec3::ONE;
                if *flip_y {
                    n.y = -n.y;
                }
                n.normalize_or(Vec3::Z)
            }
            Self::FromHeight { strength } => {
                let d = if duv.is_finite() && duv > 0.0 {
                    duv
                } else {
                    albedo.height_step()
                };
                let du = Vec2::new(d, 0.0);
                let dv = Vec2::new(0.0, d);
                // h(−) − h(+): the minus sign of the gradient folded in.
                let k = strength / (2.0 * d);
                let gx = (albedo.height(uv - du) - albedo.height(uv + du)) * k;
                let gy = (albedo.height(uv - dv) - albedo.height(uv + dv)) * k;
                // Bounded so an absurd strength still gives a grazing normal, not NaN.
                const LIMIT: f32 = 1e6;
                // Adding +0 turns −0 (from a negative strength) into +0: flat stays exactly +z.
                let g =
                    Vec2::new(gx, gy).clamp(Vec2::splat(-LIMIT), Vec2::splat(LIMIT)) + Vec2::ZERO;
                Vec3::new(g.x, g.y, 1.0).normalize_or(Vec3::Z)
            }
        }
    }
}

/// An entity's texture: optional albedo and normal source plus the uv mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Reflectance, if the texture sets it.
    pub albedo: Option<AlbedoTexture>,
    /// Shading-normal perturbation, if any.
    pub normal_map: Option<NormalMap>,
    /// A rough material's perceptual roughness (α = r²), if the texture sets it.
    pub roughness: Option<ScalarTexture>,
    /// uv multiplier: `uv' = uv * scale + offset`.
    pub scale: Vec2,
    /// uv offset, added after `scale`.
    pub offset: Vec2,
}

/// A colour in the scene format's syntax.
fn rgb(c: Vec3) -> String {
    format!("Rgb({:?}, {:?}, {:?})", c.x, c.y, c.z)
}

/// An image's file as `path: "..."` (as resolved from the scene file), or a note for an
/// in-memory image, which has none.
fn image_path(image: &TexImage) -> String {
    match image.source() {
        Some(p) => format!("path: {:?}", p.display().to_string()),
        None => "path: \"(in memory)\"".to_owned(),
    }
}

/// The texture as a scene file writes it: `(albedo: Checker(..), scale: (2.0, 2.0))`, with
/// fields at their defaults left out and an image's path as it was resolved.
impl std::fmt::Display for Texture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut parts = Vec::new();
        if let Some(a) = &self.albedo {
            parts.push(format!(
                "albedo: {}",
                match a {
                    AlbedoTexture::Image { image, wrap } =>
                        format!("Image({}, wrap: {wrap:?})", image_path(image)),
                    AlbedoTexture::Checker(c) => format!(
                        "Checker(a: {}, b: {}, size: {:?})",
                        rgb(c.a),
                        rgb(c.b),
                        c.size
                    ),
                    AlbedoTexture::Bricks(b) => format!(
                        "Bricks(brick: {}, mortar: {}, size: ({:?}, {:?}), joint: {:?})",
                        rgb(b.brick),
                        rgb(b.mortar),
                        b.size.x,
                        b.size.y,
                        // The file gives the joint as a fraction of the shorter side.
                        b.joint / b.size.min_element()
                    ),
                    AlbedoTexture::Wood(w) => format!(
                        "Wood(light: {}, dark: {}, rings: {:?}, noise: {:?})",
                        rgb(w.light),
                        rgb(w.dark),
                        w.rings,
                        w.noise
                    ),
                }
            ));
        }
        if let Some(n) = &self.normal_map {
            parts.push(format!(
                "normal_map: {}",
                match n {
                    NormalMap::Image {
                        image,
                        flip_y,
                        wrap,
                    } => format!(
                        "Image({}, flip_y: {flip_y}, wrap: {wrap:?})",
                        image_path(image)
                    ),
                    NormalMap::FromHeight { strength } =>
                        format!("FromHeight(strength: {strength:?})"),
                }
            ));
        }
        if let Some(r) = &self.roughness {
            parts.push(format!(
                "roughness: {}",
                match r {
                    ScalarTexture::Image {
                        image,
                        channel,
                        wrap,
                    } => format!(
                        "Image({}, channel: {channel:?}, wrap: {wrap:?})",
                        image_path(image)
                    ),
                    ScalarTexture::Checker(c) => format!(
                        "Checker(a: {:?}, b: {:?}, size: {:?})",
                        c.a.x, c.b.x, c.size
                    ),
                }
            ));
        }
        if self.scale != Vec2::ONE {
            parts.push(format!("scale: ({:?}, {:?})", self.scale.x, self.scale.y));
        }
        if self.offset != Vec2::ZERO {
            parts.push(format!(
                "offset: ({:?}, {:?})",
                self.offset.x, self.offset.y
            ));
        }
        write!(f, "({})", parts.join(", "))
    }
}

impl Texture {
    /// `uv * scale + offset`.
    #[inline]
    pub fn map_uv(&self, uv: Vec2) -> Vec2 {
        uv * self.scale + self.offset
    }

    /// The perceptual roughness at surface coordinates `uv`, if this texture sets one.
    #[inline]
    pub fn roughness(&self, uv: Vec2) -> Option<f32> {
        self.roughness.as_ref().map(|r| r.eval(self.map_uv(uv)))
    }

    /// The albedo at surface coordinates `uv`, if this texture has one.
    #[inline]
    pub fn albedo(&self, uv: Vec2) -> Option<Vec3> {
        self.albedo.as_ref().map(|a| a.eval(self.map_uv(uv)))
    }

    /// [`albedo`](Self::albedo) in lanes, for a texture known to have one (`None` otherwise):
    /// surface coordinates `(u, v)`, lanes outside `active` unspecified.
    #[inline(always)]
    pub fn albedo_lanes<F: Float>(&self, u: F, v: F, active: F::Mask) -> Option<V3<F>> {
        let a = self.albedo.as_ref()?;
        // `uv * scale + offset` as glam computes it: multiply, then add (unfused).
        let u = u * F::splat(self.scale.x) + F::splat(self.offset.x);
        let v = v * F::splat(self.scale.y) + F::splat(self.offset.y);
        Some(a.eval_lanes(u, v, active))
    }

    /// Unit tangent-space normal at surface coordinates `uv`; +z without a normal map (or
    /// for `FromHeight` without an albedo to take heights from).
    #[inline]
    pub fn tangent_normal(&self, uv: Vec2) -> Vec3 {
        let uv = self.map_uv(uv);
        match (&self.normal_map, &self.albedo) {
            (Some(n @ NormalMap::Image { .. }), _) => {
                // The albedo is unused by image maps; any value will do.
                n.tangent_normal(uv, &FLAT, 0.0)
            }
            (Some(n), Some(a)) => n.tangent_normal(uv, a, a.height_step()),
            _ => Vec3::Z,
        }
    }

    /// The perturbed shading normal at surface coordinates `uv`, `ns` unchanged when there is
    /// no normal map.
    #[inline]
    pub fn shading_normal(&self, uv: Vec2, ns: Vec3, dpdu: Vec3, dpdv: Vec3) -> Vec3 {
        if self.normal_map.is_none() {
            return ns;
        }
        perturb(ns, dpdu, dpdv, self.tangent_normal(uv))
    }
}

/// A flat albedo for calls whose albedo argument is ignored.
const FLAT: AlbedoTexture = AlbedoTexture::Checker(Checker {
    a: Vec3::ZERO,
    b: Vec3::ZERO,
    size: 1.0,
});

/// Orthonormal tangent frame `(t, b)` around the shading normal: `t` is `dpdu` made
/// perpendicular to `ns` (Gram–Schmidt), `b` is ±`ns × t`, signed to point along `dpdv` so
/// mirrored uv layouts keep +y along +v.
///
/// When `dpdu` is zero, non-finite or parallel to `ns`, `dpdv` supplies the frame instead;
/// when both are unusable, an arbitrary frame around `ns` is used. `ns` need not be exactly
/// unit; a zero or non-finite `ns` is taken as +z.
pub fn tangent_frame(ns: Vec3, dpdu: Vec3, dpdv: Vec3) -> (Vec3, Vec3) {
    frame_around(ns.try_normalize().unwrap_or(Vec3::Z), dpdu, dpdv)
}

/// [`tangent_frame`] for a unit `n`.
#[inline]
fn frame_around(n: Vec3, dpdu: Vec3, dpdv: Vec3) -> (Vec3, Vec3) {
    // Unit perpendicular part of `d`, or None when `d` is (nearly) along `n` or unusable.
    let perp = |d: Vec3| -> Option<Vec3> {
        // Rescale first: squaring 1e30 overflows and 1e-30 underflows, either of which
        // would misjudge a perfectly good direction.
        let m = d.abs().max_element();
        if !(m.is_finite() && m > 0.0) {
            return None;
        }
        let d = d / m;
        let p = d - n * n.dot(d);
        // Relative test: reject directions within ~1e-4 rad of the normal.
        if p.length_squared() > 1e-8 * d.length_squared() {
            p.try_normalize()
        } else {
            None
        }
    };
    match (perp(dpdu), perp(dpdv)) {
        (Some(t), pv) => {
            let b = n.cross(t);
            // Mirrored uvs: dpdv points against n × t, so +y must too.
            let flip = pv.is_some_and(|v| v.dot(b) < 0.0);
            (t, if flip { -b } else { b })
        }
        (None, Some(b)) => (b.cross(n), b),
        (None, None) => crate::sampling::coordinate_system(n),
    }
}

/// Maps a unit tangent-space normal (OpenGL +y) to world space around `ns` and returns the
/// unit result. A flat tangent normal (+z) returns `ns` normalised.
#[inline]
pub fn perturb(ns: Vec3, dpdu: Vec3, dpdv: Vec3, tangent_normal: Vec3) -> Vec3 {
    let n = ns.try_normalize().unwrap_or(Vec3::Z);
    let (t, b) = frame_around(n, dpdu, dpdv);
    (t * tangent_normal.x + b * tangent_normal.y + n * tangent_normal.z).normalize_or(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_follows_dpdu_and_dpdv() {
        let (t, b) = tangent_frame(Vec3::Z, Vec3::new(2.0, 0.0, 0.5), Vec3::Y);
        assert!((t - Vec3::X).length() < 1e-6 && (b - Vec3::Y).length() < 1e-6);
        // Mirrored v: +y follows dpdv.
        let (_, b) = tangent_frame(Vec3::Z, Vec3::X, -Vec3::Y);
        assert!((b + Vec3::Y).length() < 1e-6);
        // dpdu along the normal: dpdv supplies the frame.
        let (t, b) = tangent_frame(Vec3::Z, Vec3::Z, Vec3::Y);
        assert!((t - Vec3::X).length() < 1e-6 && (b - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn perturb_tilts_towards_tangent() {
        let tn = Vec3::new(0.6, 0.0, 0.8);
        let n = perturb(Vec3::Z, Vec3::X, Vec3::Y, tn);
        assert!((n - tn).length() < 1e-6);
        let tn = Vec3::new(0.0, 0.6, 0.8);
        let n = perturb(Vec3::Z, Vec3::X, Vec3::Y, tn);
        assert!((n - tn).length() < 1e-6);
    }

    #[test]
    fn texture_without_normal_map_keeps_ns() {
        let t = Texture {
            albedo: None,
            normal_map: None,
            roughness: None,
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        };
        let ns = Vec3::new(0.0, 0.6, 0.8);
        assert_eq!(t.shading_normal(Vec2::ZERO, ns, Vec3::X, Vec3::Y), ns);
        assert_eq!(t.albedo(Vec2::ZERO), None);
    }
}
