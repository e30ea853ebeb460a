//! Wavelength-dependent indices of refraction.
//!
//! Wavelengths are nm at the API, as everywhere in the renderer; the
//! dispersion formulas take µm because that is how their coefficients are
//! published.

/// How a material's refractive index depends on wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IorModel {
    /// The same index at every wavelength (no dispersion).
    Constant(f32),
    /// Cauchy's two-term formula n = a + b/λ², `b` in µm².
    Cauchy {
        /// Index approached at long wavelengths.
        a: f32,
        /// Dispersion coefficient, µm².
        b: f32,
    },
    /// Three-term Sellmeier formula n² = 1 + Σ bᵢλ²/(λ² − cᵢ), `c` in µm².
    Sellmeier {
        /// Oscillator strengths bᵢ (dimensionless).
        b: [f32; 3],
        /// Resonance wavelengths squared cᵢ, µm².
        c: [f32; 3],
    },
    /// Four-term Sellmeier formula, the form in which some fits (water,
    /// Daimon & Masumura 2007) are published.
    Sellmeier4 {
        /// Oscillator strengths bᵢ (dimensionless).
        b: [f32; 4],
        /// Resonance wavelengths squared cᵢ, µm².
        c: [f32; 4],
    },
}

impl IorModel {
    /// Refractive index at `lambda_nm`. Where a Sellmeier formula has no
    /// real index (n² ≤ 0, inside an absorption resonance, far outside any
    /// published range) it returns 1, so a bad model cannot divide by zero
    /// downstream.
    #[inline(always)]
    pub fn eta(&self, lambda_nm: f32) -> f32 {
        let um = f64::from(lambda_nm) * 1e-3;
        let l2 = um * um;
        let sellmeier = |b: &[f32], c: &[f32]| {
            let n2: f64 = 1.0
                + b.iter()
                    .zip(c)
                    .map(|(&b, &c)| f64::from(b) * l2 / (l2 - f64::from(c)))
                    .sum::<f64>();
            if n2 > 0.0 && n2.is_finite() {
                n2.sqrt() as f32
            } else {
                1.0
            }
        };
        match self {
            Self::Constant(n) => *n,
            Self::Cauchy { a, b } => (f64::from(*a) + f64::from(*b) / l2) as f32,
            Self::Sellmeier { b, c } => sellmeier(b, c),
            Self::Sellmeier4 { b, c } => sellmeier(b, c),
        }
    }

    /// True if the index varies with wavelength, so refraction must
    /// terminate the secondary wavelengths of a path.
    pub fn is_dispersive(&self) -> bool {
        match self {
            Self::Constant(_) => false,
            Self::Cauchy { b, .. } => *b != 0.0,
            Self::Sellmeier { b, .. } => b.iter().any(|&v| v != 0.0),
            Self::Sellmeier4 { b, .. } => b.iter().any(|&v| v != 0.0),
        }
    }
}

/// Square of a resonance wavelength: several sources publish Sellmeier
/// terms as wavelengths rather than their squares.
const fn sq(x: f32) -> f32 {
    x * x
}

/// Common optical materials with published dispersion formulas.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IorPreset {
    /// Schott N-BK7 borosilicate crown glass, n_d = 1.5168.
    Bk7,
    /// Fused silica (SiO₂ glass), n_d = 1.4585.
    FusedSilica,
    /// Distilled water at 20 °C, n_d ≈ 1.333.
    Water,
    /// Diamond, n_D ≈ 2.417.
    Diamond,
    /// Sapphire (Al₂O₃), ordinary ray, n_d ≈ 1.768.
    Sapphire,
}

impl IorPreset {
    /// Every preset, for listing in scene documentation and errors.
    pub const ALL: [IorPreset; 5] = [
        Self::Bk7,
        Self::FusedSilica,
        Self::Water,
        Self::Diamond,
        Self::Sapphire,
    ];

    /// The preset's name as written in scenes (its variant name).
    pub fn name(self) -> &'static str {
        match self {
            Self::Bk7 => "Bk7",
            Self::FusedSilica => "FusedSilica",
            Self::Water => "Water",
            Self::Diamond => "Diamond",
            Self::Sapphire => "Sapphire",
        }
    }

    /// The preset called `name` (case-insensitive).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
    }

    /// The dispersion formula for this material (λ in µm, c in µm²).
    pub fn model(self) -> IorModel {
        match self {
            // Schott optical glass datasheet, N-BK7 (valid 0.3–2.5 µm).
            Self::Bk7 => IorModel::Sellmeier {
                b: [1.039_612, 0.231_792_34, 1.010_469_4],
                c: [0.006_000_699, 0.020_017_914, 103.560_65],
            },
            // I. H. Malitson, "Interspecimen comparison of the refractive
            // index of fused silica", JOSA 55, 1205 (1965); published as
            // resonance wavelengths (µm), squared here.
            Self::FusedSilica => IorModel::Sellmeier {
                b: [0.696_166_3, 0.407_942_6, 0.897_479_4],
                c: [sq(0.068_404_3), sq(0.116_241_4), sq(9.896_161)],
            },
            // M. Daimon & A. Masumura, "Measurement of the refractive index
            // of distilled water from the near-infrared region to the
            // ultraviolet region", Appl. Opt. 46, 3811 (2007), 20 °C fit.
            Self::Water => IorModel::Sellmeier4 {
                b: [0.568_402_76, 0.172_617_74, 0.020_861_896, 0.113_074_87],
                c: [0.005_101_83, 0.018_211_54, 0.026_207_223, 10.697_927],
            },
            // F. Peter, "Über Brechungsindizes und Absorptionskonstanten
            // des Diamanten zwischen 644 und 226 mµ", Z. Phys. 15, 358
            // (1923): two terms, resonances at 0.1750 and 0.1060 µm.
            Self::Diamond => IorModel::Sellmeier {
                b: [0.3306, 4.3356, 0.0],
                c: [sq(0.1750), sq(0.1060), 0.0],
            },
            // I. H. Malitson & M. J. Dodge, "Refractive index and
            // birefringence of synthetic sapphire", JOSA 62, 1405 (1972),
            // ordinary ray; published as resonance wavelengths (µm).
            Self::Sapphire => IorModel::Sellmeier {
                b: [1.431_349_3, 0.650_547_13, 5.341_402],
                c: [sq(0.072_663_1), sq(0.119_324_2), sq(18.028_251)],
            },
        }
    }
}
