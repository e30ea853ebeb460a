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
//! let m: Material = ron::from_str("Conductor(metal: Some(Au), alpha: Some(0.2))").unwrap();
//! # let _ = m;
//! let m: Material = ron::from_str("Plastic(albedo: Rgb(0.8, 0.1, 0.1), roughness: Some(0.3))").unwrap();
//! # let _ = m;
//! let m: Material = ron::from_str("Light(emission: Rgb(17.0, 12.0, 4.0), two_sided: false)").unwrap();
//! # let _ = m;
//! ```
//! A `Light` emits from the side its normal faces (spheres and boxes: outward) unless
//! `two_sided`; it does not scatter.

use crate::spectrum::{EmitterSpectrum, IorModel, Metal};
use glam::Vec3;

/// How a surface scatters or emits light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflection.
    Diffuse {
        /// Reflectance per linear sRGB channel, in [0, 1].
        albedo: Vec3,
    },
    /// Perfect specular reflection.
    Mirror {
        /// Reflectance per linear sRGB channel, in [0, 1].
        tint: Vec3,
    },
    /// Glass: Fresnel-weighted reflection and refraction, smooth or (α at least
    /// [`crate::integrator::microfacet::SMOOTH_ALPHA`]) through GGX microfacets. A
    /// wavelength-dependent IOR disperses light (spectral transport only).
    Dielectric {
        /// Refractive index of the glass as a function of wavelength.
        ior: IorModel,
        /// GGX roughness α, each axis in [0, 1]; 0 is smooth.
        alpha: Alpha,
        /// Restore the energy of light scattered among microfacets (Kulla & Conty 2017).
        multiscatter: bool,
    },
    /// A metal: GGX microfacet reflection with a conductor's Fresnel term; a mirror weighted
    /// by that term when `alpha` is below [`crate::integrator::microfacet::SMOOTH_ALPHA`].
    Conductor {
        /// What the Fresnel term is made of.
        ior: ConductorIor,
        /// GGX roughness α, each axis in [0, 1].
        alpha: Alpha,
        /// Restore the energy of light scattered among microfacets (Kulla & Conty 2017).
        multiscatter: bool,
    },
    /// Plastic: a dielectric coat of IOR `ior`, smooth or GGX-rough, over a Lambertian base
    /// of reflectance `albedo`, the coat's internal reflections accounted for
    /// ([`crate::integrator::coat`]).
    Plastic {
        /// The base's reflectance per linear sRGB channel, in [0, 1].
        albedo: Vec3,
        /// The coat's refractive index, in [1, 3].
        ior: f32,
        /// The coat's GGX roughness α, each axis in [0, 1]; 0 is smooth.
        alpha: Alpha,
    },
    /// An area emitter of constant radiance: `emission` is its linear sRGB colour, `spectrum`
    /// what spectral transport evaluates.
    Light {
        /// Emitted radiance, linear sRGB.
        emission: Vec3,
        /// Emits from both sides, not only the side the normal faces.
        two_sided: bool,
        /// The emission spectrum spectral transport evaluates instead of `emission`.
        spectrum: EmitterSpectrum,
    },
    /// No surface at all: the boundary of a medium, crossed without scattering.
    Boundary,
}

/// A GGX roughness: α along the surface's tangent ∂p/∂u (`x`) and along its bitangent (`y`),
/// equal for an isotropic surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alpha {
    /// α along the tangent.
    pub x: f32,
    /// α along the bitangent.
    pub y: f32,
}

impl Alpha {
    /// Smooth: α = 0.
    pub const ZERO: Alpha = Alpha { x: 0.0, y: 0.0 };

    /// The same α along both axes.
    pub const fn iso(a: f32) -> Self {
        Alpha { x: a, y: a }
    }

    /// Whether the two axes differ: the BSDF then needs the surface's tangent.
    pub fn is_anisotropic(&self) -> bool {
        self.x != self.y
    }

    /// Whether either axis is rough.
    pub fn is_rough(&self) -> bool {
        self.x.max(self.y) > 0.0
    }

    /// The same anisotropy with √(αx·αy) = `mean`: how a roughness texture's value applies
    /// to an anisotropic material.
    pub fn with_mean(&self, mean: f32) -> Self {
        let m = (self.x * self.y).sqrt();
        if m > 0.0 && self.is_anisotropic() {
            Alpha {
                x: self.x * mean / m,
                y: self.y * mean / m,
            }
        } else {
            Alpha::iso(mean)
        }
    }
}

/// `0.2`, or `(0.05, 0.4)` when anisotropic: the scene format's syntax.
impl std::fmt::Display for Alpha {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.is_anisotropic() {
            write!(f, "({:?}, {:?})", self.x, self.y)
        } else {
            write!(f, "{:?}", self.x)
        }
    }
}

/// A conductor's Fresnel term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConductorIor {
    /// A measured metal: its n + ik at each wavelength in spectral transport; in RGB
    /// transport Schlick's form with its D65 normal-incidence reflectance `r0`
    /// ([`ConductorIor::metal`] computes it).
    Metal {
        /// The metal.
        metal: Metal,
        /// Its normal-incidence reflectance under D65, linear sRGB.
        r0: Vec3,
    },
    /// A complex IOR per linear sRGB channel, upsampled to smooth spectra in spectral
    /// transport.
    Complex {
        /// Real part, > 0.
        eta: Vec3,
        /// Extinction coefficient, ≥ 0.
        k: Vec3,
    },
    /// Schlick's form with this normal-incidence reflectance (linear sRGB, in [0, 1]).
    Reflectance(Vec3),
}

impl ConductorIor {
    /// A measured metal, with the RGB colour RGB transport uses for it.
    pub fn metal(metal: Metal) -> Self {
        ConductorIor::Metal {
            metal,
            r0: metal.reflectance_rgb(),
        }
    }
}

impl Material {
    /// The material with its colour multiplied by a texture's albedo: Diffuse albedo, Mirror
    /// tint, Light emission, a Conductor's reflectance colour; a Dielectric and a Conductor
    /// of measured or complex IOR have no colour to modulate.
    #[inline]
    pub fn modulated(self, a: Vec3) -> Material {
        match self {
            Material::Diffuse { albedo } => Material::Diffuse { albedo: albedo * a },
            Material::Mirror { tint } => Material::Mirror { tint: tint * a },
            Material::Plastic { albedo, ior, alpha } => Material::Plastic {
                albedo: albedo * a,
                ior,
                alpha,
            },
            Material::Light {
                emission,
                two_sided,
                spectrum,
            } => Material::Light {
                emission: emission * a,
                two_sided,
                spectrum,
            },
            Material::Conductor {
                ior: ConductorIor::Reflectance(r),
                alpha,
                multiscatter,
            } => Material::Conductor {
                ior: ConductorIor::Reflectance(r * a),
                alpha,
                multiscatter,
            },
            m @ (Material::Dielectric { .. } | Material::Boundary | Material::Conductor { .. }) => {
                m
            }
        }
    }

    /// The material with a roughness texture's value `r` applied (α = r², or for an
    /// anisotropic material √(αx·αy) = r²); materials without a roughness are unchanged.
    #[inline]
    pub fn roughened(mut self, r: f32) -> Material {
        if let Material::Conductor { alpha, .. }
        | Material::Dielectric { alpha, .. }
        | Material::Plastic { alpha, .. } = &mut self
        {
            *alpha = alpha.with_mean(r * r);
        }
        self
    }

    /// The GGX roughness of a Conductor, Dielectric or Plastic.
    pub fn alpha(&self) -> Option<Alpha> {
        match self {
            Material::Conductor { alpha, .. }
            | Material::Dielectric { alpha, .. }
            | Material::Plastic { alpha, .. } => Some(*alpha),
            _ => None,
        }
    }

    /// Whether this is a `Light` with some non-zero emission.
    pub fn is_emissive(&self) -> bool {
        matches!(self, Material::Light { emission, .. } if emission.max_element() > 0.0)
    }
}

/// `x` to five significant digits: a scale recovered by integrating the spectrum carries
/// rounding in the last digits of an f32.
fn significant(x: f32) -> f64 {
    let x = f64::from(x);
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let p = 10f64.powi(4 - x.abs().log10().floor() as i32);
    (x * p).round() / p
}

/// RGB in the scene format's syntax.
struct Rgb(Vec3);

impl std::fmt::Display for Rgb {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Rgb({:?}, {:?}, {:?})", self.0.x, self.0.y, self.0.z)
    }
}

/// An emission (a `Light`'s, a point light's intensity, the environment's) as a scene file
/// writes it: `Rgb(..)`, or a spectral emitter with the luminance its `scale` gave it.
pub struct EmissionSyntax(pub Vec3, pub EmitterSpectrum);

impl std::fmt::Display for EmissionSyntax {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use crate::spectrum::{NamedIlluminant, spectrum_to_xyz};
        match &self.1 {
            EmitterSpectrum::Rgb => write!(f, "{}", Rgb(self.0)),
            EmitterSpectrum::Blackbody(b) => write!(
                f,
                "Blackbody(kelvin: {:?}, scale: {:?})",
                b.kelvin(),
                significant(spectrum_to_xyz(|l| b.eval(l)).y)
            ),
            EmitterSpectrum::Illuminant(i) => write!(
                f,
                "Illuminant(spectrum: {}, scale: {:?})",
                match i.which() {
                    NamedIlluminant::D65 => "D65",
                    NamedIlluminant::Sun => "Sun",
                },
                significant(spectrum_to_xyz(|l| i.eval(l)).y)
            ),
        }
    }
}

/// The material as a scene file writes it (`Diffuse(albedo: Rgb(0.7, 0.7, 0.7))`); a preset
/// IOR by its name, a spectral emitter with the luminance its `scale` gave it.
impl std::fmt::Display for Material {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use crate::spectrum::IorPreset;
        match self {
            Material::Diffuse { albedo } => write!(f, "Diffuse(albedo: {})", Rgb(*albedo)),
            Material::Mirror { tint } => write!(f, "Mirror(tint: {})", Rgb(*tint)),
            Material::Dielectric {
                ior,
                alpha,
                multiscatter,
            } => {
                let ior = match IorPreset::ALL.into_iter().find(|p| p.model() == *ior) {
                    Some(p) => format!("Preset({})", p.name()),
                    None => match ior {
                        IorModel::Constant(n) => format!("Constant({n:?})"),
                        IorModel::Cauchy { a, b } => format!("Cauchy(a: {a:?}, b: {b:?})"),
                        IorModel::Sellmeier { b, c } => format!(
                            "Sellmeier(b: ({:?}, {:?}, {:?}), c: ({:?}, {:?}, {:?}))",
                            b[0], b[1], b[2], c[0], c[1], c[2]
                        ),
                        IorModel::Sellmeier4 { b, c } => format!("Sellmeier4(b: {b:?}, c: {c:?})"),
                    },
                };
                write!(f, "Dielectric(ior: {ior}")?;
                if alpha.is_rough() {
                    write!(f, ", alpha: {alpha}")?;
                    if !multiscatter {
                        f.write_str(", multiscatter: false")?;
                    }
                }
                f.write_str(")")
            }
            Material::Conductor {
                ior,
                alpha,
                multiscatter,
            } => {
                match ior {
                    ConductorIor::Metal { metal, .. } => {
                        write!(f, "Conductor(metal: {}", metal.name())?
                    }
                    ConductorIor::Complex { eta, k } => {
                        write!(f, "Conductor(eta: {}, k: {}", Rgb(*eta), Rgb(*k))?
                    }
                    ConductorIor::Reflectance(r) => {
                        write!(f, "Conductor(reflectance: {}", Rgb(*r))?
                    }
                }
                write!(f, ", alpha: {alpha}")?;
                if !multiscatter {
                    f.write_str(", multiscatter: false")?;
                }
                f.write_str(")")
            }
            Material::Plastic { albedo, ior, alpha } => {
                write!(f, "Plastic(albedo: {}, ior: {ior:?}", Rgb(*albedo))?;
                if alpha.is_rough() {
                    write!(f, ", alpha: {alpha}")?;
                }
                f.write_str(")")
            }
            Material::Light {
                emission,
                two_sided,
                spectrum,
            } => {
                let emission = EmissionSyntax(*emission, *spectrum);
                if *two_sided {
                    write!(f, "Light(emission: {emission}, two_sided: true)")
                } else {
                    write!(f, "Light(emission: {emission})")
                }
            }
            Material::Boundary => f.write_str("none (a medium's boundary)"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::{Blackbody, Illuminant, IorPreset, NamedIlluminant};

    /// `prism info` prints materials as the scene format writes them: each printed form parses
    /// back as a scene material, and spectral emitters show the scale they were given.
    #[test]
    fn materials_print_in_scene_syntax() {
        let light = |spectrum, two_sided| Material::Light {
            emission: Vec3::new(1.0, 0.5, 0.25),
            two_sided,
            spectrum,
        };
        let cases = [
            (
                Material::Diffuse {
                    albedo: Vec3::new(0.7, 0.5, 0.25),
                },
                "Diffuse(albedo: Rgb(0.7, 0.5, 0.25))",
            ),
            (
                Material::Mirror { tint: Vec3::ONE },
                "Mirror(tint: Rgb(1.0, 1.0, 1.0))",
            ),
            (
                Material::Dielectric {
                    ior: IorModel::Constant(1.5),
                    alpha: Alpha::iso(0.0),
                    multiscatter: true,
                },
                "Dielectric(ior: Constant(1.5))",
            ),
            (
                Material::Dielectric {
                    ior: IorModel::Constant(1.5),
                    alpha: Alpha::iso(0.25),
                    multiscatter: true,
                },
                "Dielectric(ior: Constant(1.5), alpha: 0.25)",
            ),
            (
                Material::Plastic {
                    albedo: Vec3::new(0.8, 0.1, 0.1),
                    ior: 1.5,
                    alpha: Alpha::iso(0.0),
                },
                "Plastic(albedo: Rgb(0.8, 0.1, 0.1), ior: 1.5)",
            ),
            (
                Material::Plastic {
                    albedo: Vec3::ONE,
                    ior: 1.4,
                    alpha: Alpha::iso(0.09),
                },
                "Plastic(albedo: Rgb(1.0, 1.0, 1.0), ior: 1.4, alpha: 0.09)",
            ),
            (
                Material::Dielectric {
                    ior: IorModel::Cauchy { a: 1.5, b: 0.004 },
                    alpha: Alpha::iso(0.0),
                    multiscatter: true,
                },
                "Dielectric(ior: Cauchy(a: 1.5, b: 0.004))",
            ),
            (
                Material::Dielectric {
                    ior: IorPreset::Water.model(),
                    alpha: Alpha::iso(0.0),
                    multiscatter: true,
                },
                "Dielectric(ior: Preset(Water))",
            ),
            (
                light(EmitterSpectrum::Rgb, true),
                "Light(emission: Rgb(1.0, 0.5, 0.25), two_sided: true)",
            ),
            (
                light(
                    EmitterSpectrum::Blackbody(Blackbody::new(2700.0, 5.0)),
                    false,
                ),
                "Light(emission: Blackbody(kelvin: 2700.0, scale: 5.0))",
            ),
            (
                light(
                    EmitterSpectrum::Illuminant(Illuminant::new(NamedIlluminant::D65, 2.0)),
                    false,
                ),
                "Light(emission: Illuminant(spectrum: D65, scale: 2.0))",
            ),
            (
                Material::Conductor {
                    ior: ConductorIor::metal(Metal::Au),
                    alpha: Alpha::iso(0.2),
                    multiscatter: true,
                },
                "Conductor(metal: Au, alpha: 0.2)",
            ),
            (
                Material::Conductor {
                    ior: ConductorIor::Complex {
                        eta: Vec3::new(0.2, 0.9, 1.1),
                        k: Vec3::new(3.9, 2.4, 2.2),
                    },
                    alpha: Alpha::iso(0.0),
                    multiscatter: true,
                },
                "Conductor(eta: Rgb(0.2, 0.9, 1.1), k: Rgb(3.9, 2.4, 2.2), alpha: 0.0)",
            ),
            (
                Material::Conductor {
                    ior: ConductorIor::Reflectance(Vec3::new(0.9, 0.6, 0.3)),
                    alpha: Alpha::iso(0.5),
                    multiscatter: false,
                },
                "Conductor(reflectance: Rgb(0.9, 0.6, 0.3), alpha: 0.5, multiscatter: false)",
            ),
            (
                Material::Conductor {
                    ior: ConductorIor::metal(Metal::Ni),
                    alpha: Alpha { x: 0.05, y: 0.4 },
                    multiscatter: true,
                },
                "Conductor(metal: Ni, alpha: (0.05, 0.4))",
            ),
        ];
        for (m, want) in cases {
            let text = m.to_string();
            assert_eq!(text, want);
            let parsed = crate::scene_file::load::ron_options()
                .from_str::<crate::scene_file::schema::Material>(&text);
            assert!(parsed.is_ok(), "{text}: {parsed:?}");
        }
    }
}
