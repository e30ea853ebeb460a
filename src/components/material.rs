//! `Material`: how a surface scatters or emits.
//!
//! ```
//! # use prism::scene_file::schema::Material;
//! let m: Material = ron::from_str("Diffuse(albedo: Rgb(0.8, 0.8, 0.8))").unwrap();
//! # let _ = m;
//! let m: Material = ron::from_str("Mirror(tint: Rgb(0.9, 0.9, 0.9))").unwrap();
//! # let _ = m;
//! let m: Material = ron::from_str("Dielectric(ior: Constant(1.5))").unwrap();
//! # let _ = m;
//! let m: Material = ron::from_str("Light(emission: Rgb(17.0, 12.0, 4.0), two_sided: false)").unwrap();
//! # let _ = m;
//! ```
//! A `Light` emits from the side its normal faces (spheres and boxes: outward) unless
//! `two_sided`; it does not scatter.

use crate::spectrum::{EmitterSpectrum, IorModel};
use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflection.
    Diffuse { albedo: Vec3 },
    /// Perfect specular reflection.
    Mirror { tint: Vec3 },
    /// Smooth glass: Fresnel-weighted reflection and refraction. A wavelength-dependent IOR
    /// disperses light (spectral transport only).
    Dielectric { ior: IorModel },
    /// An area emitter of constant radiance: `emission` is its linear sRGB colour, `spectrum`
    /// what spectral transport evaluates.
    Light {
        emission: Vec3,
        two_sided: bool,
        spectrum: EmitterSpectrum,
    },
    /// No surface at all: the boundary of a medium, crossed without scattering.
    Boundary,
}

impl Material {
    /// The material with its colour multiplied by a texture's albedo: Diffuse albedo, Mirror
    /// tint, Light emission; a Dielectric has no colour to modulate.
    #[inline]
    pub fn modulated(self, a: Vec3) -> Material {
        match self {
            Material::Diffuse { albedo } => Material::Diffuse { albedo: albedo * a },
            Material::Mirror { tint } => Material::Mirror { tint: tint * a },
            Material::Light {
                emission,
                two_sided,
                spectrum,
            } => Material::Light {
                emission: emission * a,
                two_sided,
                spectrum,
            },
            m @ (Material::Dielectric { .. } | Material::Boundary) => m,
        }
    }

    pub fn is_emissive(&self) -> bool {
        matches!(self, Material::Light { emission, .. } if emission.max_element() > 0.0)
    }
}
