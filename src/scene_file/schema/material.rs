//! Materials: their reflectance colours, indices of refraction and emission spectra.

use serde::{Deserialize, Serialize};

/// How a surface scatters or emits light. Surfaces scatter on both sides.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Material {
    /// A Lambertian reflector.
    Diffuse {
        /// Reflectance, every channel in [0, 1].
        albedo: Albedo,
    },
    /// A perfect specular reflector.
    Mirror {
        /// Reflectance, every channel in [0, 1].
        tint: Albedo,
    },
    /// Glass: Fresnel-weighted reflection and refraction, smooth or rough (GGX microfacets,
    /// Walter et al. 2007). At most one of `alpha` and `roughness` (neither: smooth).
    Dielectric {
        /// Index of refraction inside the surface; outside it is 1.
        ior: Ior,
        /// GGX α in [0, 1] (as Mitsuba's `alpha`): frosted glass. A pair `(αx, αy)` is
        /// anisotropic, αx along the surface's ∂p/∂u.
        #[serde(default)]
        alpha: Option<Rough>,
        /// Perceptual roughness r in [0, 1] (glTF, Blender): α = r²; a pair is anisotropic.
        #[serde(default)]
        roughness: Option<Rough>,
        /// Restore the energy single scattering among the microfacets loses (Kulla & Conty
        /// 2017); default `true`. `false` matches renderers without it (Mitsuba's
        /// `roughdielectric`, pbrt-v4's `dielectric`).
        #[serde(default)]
        multiscatter: Option<bool>,
    },
    /// A metal: GGX microfacet reflection (smooth below α = 0.001) with a conductor's Fresnel
    /// term. Exactly one of `metal`, `eta` with `k`, or `reflectance`; at most one of `alpha`
    /// and `roughness` (neither: a polished, smooth surface).
    Conductor {
        /// A measured metal: `Au`, `Ag`, `Cu`, `Al`, `Cr`, `Ti`, `Ni` or `Pt`.
        #[serde(default)]
        metal: Option<crate::spectrum::Metal>,
        /// The real part of the complex IOR per channel, each in (0, 100].
        #[serde(default)]
        eta: Option<Color>,
        /// The extinction coefficient per channel, each in [0, 100].
        #[serde(default)]
        k: Option<Color>,
        /// An artist's normal-incidence reflectance (Schlick's form), every channel in [0, 1].
        #[serde(default)]
        reflectance: Option<Albedo>,
        /// GGX α in [0, 1] (as Mitsuba's `alpha`). A pair `(αx, αy)` is anisotropic, αx
        /// along the surface's ∂p/∂u (brushed metal).
        #[serde(default)]
        alpha: Option<Rough>,
        /// Perceptual roughness r in [0, 1] (glTF, Blender): α = r²; a pair is anisotropic.
        #[serde(default)]
        roughness: Option<Rough>,
        /// Restore the energy single scattering among the microfacets loses (Kulla & Conty
        /// 2017); default `true`. `false` matches renderers without it (Mitsuba's
        /// `roughconductor`, pbrt-v4's `conductor`).
        #[serde(default)]
        multiscatter: Option<bool>,
    },
    /// Plastic: a dielectric coat over a Lambertian base (energy conserving, the coat's
    /// internal reflections accounted for). At most one of `alpha` and `roughness` (neither:
    /// a smooth, glossy coat).
    Plastic {
        /// The base's reflectance, every channel in [0, 1].
        albedo: Albedo,
        /// The coat's refractive index in [1, 3]; default 1.5.
        #[serde(default)]
        ior: Option<f32>,
        /// The coat's GGX α in [0, 1]; a pair `(αx, αy)` is anisotropic.
        #[serde(default)]
        alpha: Option<Rough>,
        /// The coat's perceptual roughness r in [0, 1]: α = r²; a pair is anisotropic.
        #[serde(default)]
        roughness: Option<Rough>,
    },
    /// An area light on a Sphere, Rect or Disk; it emits and does not scatter.
    Light {
        /// Emitted radiance.
        emission: Emission,
        /// Emit from both sides instead of only the side the normal faces (outward on a
        /// sphere); default `false`.
        #[serde(default)]
        two_sided: bool,
    },
}

/// Index of refraction: `Constant(n)`, `Cauchy(a:, b:)` (λ in µm), `Sellmeier(b:, c:)` (c in
/// µm²) or `Preset(name)`. Checked to be finite and ≥ 1 over the simulated 360–830 nm, with no
/// Sellmeier resonance inside that range.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(try_from = "IorSpec")]
pub struct Ior(pub crate::spectrum::IorModel);

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
enum IorSpec {
    Constant(f32),
    Cauchy {
        a: f32,
        b: f32,
    },
    Sellmeier {
        b: (f32, f32, f32),
        c: (f32, f32, f32),
    },
    Preset(IorPresetName),
}

#[derive(Deserialize)]
enum IorPresetName {
    Bk7,
    FusedSilica,
    Water,
    Diamond,
    Sapphire,
}

impl TryFrom<IorSpec> for Ior {
    type Error = String;
    fn try_from(s: IorSpec) -> Result<Self, String> {
        use crate::spectrum::{IorModel, IorPreset, LAMBDA_MAX, LAMBDA_MIN};
        let (model, what) = match s {
            IorSpec::Constant(n) => (IorModel::Constant(n), format!("Constant({n})")),
            IorSpec::Cauchy { a, b } => {
                (IorModel::Cauchy { a, b }, format!("Cauchy(a: {a}, b: {b})"))
            }
            IorSpec::Sellmeier { b, c } => {
                let (b, c) = ([b.0, b.1, b.2], [c.0, c.1, c.2]);
                if b.iter().chain(&c).any(|v| !v.is_finite() || *v < 0.0) {
                    return Err(format!(
                        "Sellmeier coefficients must be finite and >= 0, got b: {b:?}, c: {c:?}"
                    ));
                }
                // A resonance (λ² = c) inside the simulated range would make n infinite there.
                let (lo, hi) = ((LAMBDA_MIN * 1e-3).powi(2), (LAMBDA_MAX * 1e-3).powi(2));
                if let Some(ci) = c.iter().find(|&&ci| ci >= lo && ci <= hi) {
                    return Err(format!(
                        "Sellmeier c = {ci} µm² puts a resonance at {:.0} nm, inside the \
                         simulated {LAMBDA_MIN}–{LAMBDA_MAX} nm; c must be < {lo:.4} or > {hi:.4} µm²",
                        ci.sqrt() * 1e3
                    ));
                }
                (
                    IorModel::Sellmeier { b, c },
                    format!("Sellmeier(b: {b:?}, c: {c:?})"),
                )
            }
            IorSpec::Preset(p) => {
                let p = match p {
                    IorPresetName::Bk7 => IorPreset::Bk7,
                    IorPresetName::FusedSilica => IorPreset::FusedSilica,
                    IorPresetName::Water => IorPreset::Water,
                    IorPresetName::Diamond => IorPreset::Diamond,
                    IorPresetName::Sapphire => IorPreset::Sapphire,
                };
                return Ok(Ior(p.model()));
            }
        };
        // Every model is smooth in λ on the range once resonances are excluded: checking a
        // 1 nm grid finds any n < 1 or non-finite value.
        let mut lambda = LAMBDA_MIN;
        while lambda <= LAMBDA_MAX {
            let n = match model {
                IorModel::Sellmeier { b, c } => {
                    let l2 = (lambda * 1e-3).powi(2);
                    let n2: f32 = 1.0 + (0..3).map(|i| b[i] * l2 / (l2 - c[i])).sum::<f32>();
                    n2.sqrt()
                }
                m => m.eta(lambda),
            };
            if !(n.is_finite() && n >= 1.0) {
                return Err(format!(
                    "ior {what} gives n = {n} at {lambda} nm; it must be a finite number >= 1 \
                     over {LAMBDA_MIN}–{LAMBDA_MAX} nm"
                ));
            }
            lambda += 1.0;
        }
        Ok(Ior(model))
    }
}

/// Linear sRGB colour.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
pub enum Color {
    /// Red, green and blue components.
    Rgb(f32, f32, f32),
}

impl Color {
    /// The components as a vector (r, g, b).
    pub fn vec(&self) -> glam::Vec3 {
        let Color::Rgb(r, g, b) = *self;
        glam::Vec3::new(r, g, b)
    }
}

/// A reflectance: every channel in [0, 1], so no surface creates energy.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(try_from = "Color")]
pub struct Albedo(pub Color);

impl TryFrom<Color> for Albedo {
    type Error = String;
    fn try_from(c: Color) -> Result<Self, String> {
        let v = c.vec();
        if v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0 {
            Ok(Albedo(c))
        } else {
            Err(format!(
                "a reflectance must have every channel in [0, 1], got Rgb({}, {}, {})",
                v.x, v.y, v.z
            ))
        }
    }
}

/// Emitted radiance (or a point light's intensity): `Rgb(r, g, b)`, `Blackbody(kelvin:, scale:)`
/// or `Illuminant(spectrum: D65 | Sun, scale:)`; the spectral ones are normalised to luminance
/// Y = `scale`. `rgb` is the linear sRGB colour of the emission either way. Checked: `Rgb`
/// channels finite and >= 0, `kelvin` in 500..=100000, `scale` finite and >= 0.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(try_from = "EmissionSpec")]
pub struct Emission {
    /// The emission as linear sRGB, what RGB transport and power-based light selection use;
    /// every channel >= 0.
    pub rgb: glam::Vec3,
    /// What spectral transport evaluates instead: `rgb` upsampled, a black body or an
    /// illuminant.
    pub spectrum: crate::spectrum::EmitterSpectrum,
}

impl Emission {
    /// The linear sRGB colour, [`Emission::rgb`].
    pub fn vec(&self) -> glam::Vec3 {
        self.rgb
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
enum EmissionSpec {
    Rgb(f32, f32, f32),
    Blackbody {
        kelvin: f32,
        scale: f32,
    },
    Illuminant {
        spectrum: IlluminantName,
        scale: f32,
    },
}

#[derive(Deserialize)]
enum IlluminantName {
    D65,
    Sun,
}

impl TryFrom<EmissionSpec> for Emission {
    type Error = String;
    fn try_from(s: EmissionSpec) -> Result<Self, String> {
        use crate::spectrum::{Blackbody, EmitterSpectrum, Illuminant, NamedIlluminant};
        let check_scale = |scale: f32| {
            if scale.is_finite() && scale >= 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "field `scale`: must be a finite number >= 0, got {scale}"
                ))
            }
        };
        let spectrum = match s {
            EmissionSpec::Rgb(r, g, b) => {
                return if [r, g, b].iter().all(|c| c.is_finite() && *c >= 0.0) {
                    Ok(Emission {
                        rgb: glam::Vec3::new(r, g, b),
                        spectrum: EmitterSpectrum::Rgb,
                    })
                } else {
                    Err(format!(
                        "emission must be finite and >= 0 in every channel, got Rgb({r}, {g}, {b})"
                    ))
                };
            }
            EmissionSpec::Blackbody { kelvin, scale } => {
                if !(kelvin.is_finite() && (500.0..=1.0e5).contains(&kelvin)) {
                    return Err(format!(
                        "field `kelvin`: must be in 500..=100000 (a body colder than 500 K emits almost \
                         nothing visible), got {kelvin}"
                    ));
                }
                check_scale(scale)?;
                EmitterSpectrum::Blackbody(Blackbody::new(kelvin, scale))
            }
            EmissionSpec::Illuminant { spectrum, scale } => {
                check_scale(scale)?;
                let which = match spectrum {
                    IlluminantName::D65 => NamedIlluminant::D65,
                    IlluminantName::Sun => NamedIlluminant::Sun,
                };
                EmitterSpectrum::Illuminant(Illuminant::new(which, scale))
            }
        };
        Ok(Emission {
            rgb: spectrum.rgb().unwrap_or_default(),
            spectrum,
        })
    }
}

/// A roughness as a scene writes it: one number (isotropic) or a pair `(x, y)`, x along the
/// surface's tangent ∂p/∂u. The loader checks the range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rough(pub f32, pub f32);

impl<'de> Deserialize<'de> for Rough {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Rough;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number, or a pair (along u, along v) for an anisotropic surface")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Rough, E> {
                Ok(Rough(v as f32, v as f32))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Rough, E> {
                self.visit_f64(v as f64)
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Rough, E> {
                self.visit_f64(v as f64)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Rough, A::Error> {
                use serde::de::Error;
                let x: f32 = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(0, &self))?;
                let y: f32 = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(1, &self))?;
                if seq.next_element::<f32>()?.is_some() {
                    return Err(A::Error::invalid_length(3, &self));
                }
                Ok(Rough(x, y))
            }
        }
        d.deserialize_any(V)
    }
}

#[cfg(test)]
mod rough_tests {
    use super::*;

    fn parse(text: &str) -> Result<Material, ron::error::SpannedError> {
        crate::scene_file::load::ron_options().from_str::<Material>(text)
    }

    /// One number is isotropic, a pair anisotropic, with or without `Some`; a triple or a
    /// string is refused.
    #[test]
    fn roughness_is_a_number_or_a_pair() {
        for (text, want) in [
            ("Conductor(metal: Au, alpha: 0.2)", Rough(0.2, 0.2)),
            ("Conductor(metal: Au, alpha: 1)", Rough(1.0, 1.0)),
            ("Conductor(metal: Au, alpha: Some(0.3))", Rough(0.3, 0.3)),
            ("Conductor(metal: Au, alpha: (0.05, 0.4))", Rough(0.05, 0.4)),
            (
                "Conductor(metal: Au, alpha: Some((0.05, 0.4)))",
                Rough(0.05, 0.4),
            ),
        ] {
            let Ok(Material::Conductor { alpha, .. }) = parse(text) else {
                panic!("{text}");
            };
            assert_eq!(alpha, Some(want), "{text}");
        }
        for text in [
            "Conductor(metal: Au, alpha: (0.1, 0.2, 0.3))",
            "Conductor(metal: Au, alpha: (0.1))",
            "Conductor(metal: Au, alpha: \"rough\")",
        ] {
            assert!(parse(text).is_err(), "{text}");
        }
        let Ok(Material::Plastic { roughness, .. }) =
            parse("Plastic(albedo: Rgb(1, 1, 1), roughness: (0.2, 0.5))")
        else {
            panic!("plastic");
        };
        assert_eq!(roughness, Some(Rough(0.2, 0.5)));
    }
}
