//! Physically defined emission spectra: Planck's law and named illuminants.

use super::cie::{CMF_ROWS, cmf_row};
use super::{CIE_Y_INTEGRAL, Spectrum, d65};

/// Speed of light in vacuum, m/s (exact, SI 2019).
const C: f64 = 299_792_458.0;
/// Planck constant, J·s (exact, SI 2019).
const H: f64 = 6.626_070_15e-34;
/// Boltzmann constant, J/K (exact, SI 2019).
const KB: f64 = 1.380_649e-23;

/// Planck's law: spectral radiance of a black body at `kelvin`, in
/// W·sr⁻¹·m⁻²·m⁻¹, at `lambda_nm`. Zero for non-positive temperatures.
pub fn planck(lambda_nm: f32, kelvin: f32) -> f32 {
    planck_f64(f64::from(lambda_nm), f64::from(kelvin)) as f32
}

fn planck_f64(lambda_nm: f64, kelvin: f64) -> f64 {
    if !(kelvin > 0.0 && lambda_nm > 0.0) {
        return 0.0;
    }
    let l = lambda_nm * 1e-9;
    // exp_m1 keeps the long-wavelength (Rayleigh–Jeans) end accurate; an
    // overflowing exponent correctly gives zero radiance.
    2.0 * H * C * C / (l.powi(5) * (H * C / (l * KB * kelvin)).exp_m1())
}

/// Σ f·ȳ over the 1 nm colour-matching rows, f64.
fn y_sum(f: impl Fn(f64) -> f64) -> f64 {
    (0..CMF_ROWS)
        .map(|row| f((360 + row) as f64) * cmf_row(row)[1])
        .sum()
}

/// Factor that scales a spectrum with ȳ-sum `sum` to luminance `scale`;
/// zero when the spectrum has no visible power, so it stays black, not NaN.
fn normaliser(sum: f64, scale: f32) -> f64 {
    if sum > 0.0 && sum.is_finite() {
        f64::from(scale) * f64::from(CIE_Y_INTEGRAL) / sum
    } else {
        0.0
    }
}

/// A black-body emitter, scaled so its luminance Y
/// (∫ L ȳ / [`CIE_Y_INTEGRAL`]) equals `scale`: the temperature sets the
/// colour, `scale` the brightness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blackbody {
    kelvin: f64,
    norm: f64,
}

impl Blackbody {
    /// Black body at `kelvin` with luminance `scale`. A temperature too low
    /// to emit any visible power (or non-positive) gives a black spectrum.
    pub fn new(kelvin: f32, scale: f32) -> Self {
        let kelvin = f64::from(kelvin);
        let sum = y_sum(|l| planck_f64(l, kelvin));
        Self {
            kelvin,
            norm: normaliser(sum, scale),
        }
    }

    /// Temperature, K.
    pub fn kelvin(&self) -> f32 {
        self.kelvin as f32
    }

    /// Scaled spectral radiance at `lambda` nm.
    #[inline(always)]
    pub fn eval(&self, lambda: f32) -> f32 {
        (self.norm * planck_f64(f64::from(lambda), self.kelvin)) as f32
    }
}

impl Spectrum for Blackbody {
    fn eval(&self, lambda: f32) -> f32 {
        Blackbody::eval(self, lambda)
    }
}

/// Standard light sources available by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NamedIlluminant {
    /// CIE standard illuminant D65 (average daylight, the sRGB white).
    D65,
    /// The Sun seen from space, approximated by a 5778 K black body (its
    /// effective temperature); atmospheric absorption is not modelled.
    Sun,
}

/// Temperature used for [`NamedIlluminant::Sun`], K.
pub const SUN_KELVIN: f32 = 5778.0;

/// A named illuminant scaled so its luminance Y equals `scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Illuminant {
    which: NamedIlluminant,
    d65_norm: f32,
    sun: Blackbody,
}

impl Illuminant {
    /// `which` with luminance `scale`.
    pub fn new(which: NamedIlluminant, scale: f32) -> Self {
        let (d65_norm, sun) = match which {
            NamedIlluminant::D65 => {
                let sum = y_sum(|l| f64::from(d65(l as f32)));
                (normaliser(sum, scale) as f32, Blackbody::new(0.0, 0.0))
            }
            NamedIlluminant::Sun => (0.0, Blackbody::new(SUN_KELVIN, scale)),
        };
        Self {
            which,
            d65_norm,
            sun,
        }
    }

    /// Which illuminant this is.
    pub fn which(&self) -> NamedIlluminant {
        self.which
    }

    /// Scaled spectral power at `lambda` nm.
    #[inline(always)]
    pub fn eval(&self, lambda: f32) -> f32 {
        match self.which {
            NamedIlluminant::D65 => self.d65_norm * d65(lambda),
            NamedIlluminant::Sun => self.sun.eval(lambda),
        }
    }
}

impl Spectrum for Illuminant {
    fn eval(&self, lambda: f32) -> f32 {
        Illuminant::eval(self, lambda)
    }
}

/// What an emitter's spectrum is. Every emitter also has an RGB value (the
/// linear sRGB colour of this spectrum), which RGB transport and light
/// selection by power use; spectral transport evaluates this instead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EmitterSpectrum {
    /// The emitter's RGB value, upsampled as an [`RgbIlluminant`](super::RgbIlluminant)
    /// when transport is spectral.
    Rgb,
    /// A black body at a temperature (see [`Blackbody`]).
    Blackbody(Blackbody),
    /// A named standard illuminant (see [`Illuminant`]).
    Illuminant(Illuminant),
}

impl EmitterSpectrum {
    /// True for physically defined spectra, which turn spectral transport on.
    pub fn is_spectral(&self) -> bool {
        !matches!(self, Self::Rgb)
    }

    /// The linear sRGB colour of a spectral emitter (negative channels of
    /// colours outside the sRGB gamut clipped to 0); `None` for `Rgb`.
    pub fn rgb(&self) -> Option<glam::Vec3> {
        let xyz = match self {
            Self::Rgb => return None,
            Self::Blackbody(b) => super::spectrum_to_xyz(|l| b.eval(l)),
            Self::Illuminant(i) => super::spectrum_to_xyz(|l| i.eval(l)),
        };
        Some(super::xyz_to_linear_srgb(xyz).max(glam::Vec3::ZERO))
    }

    /// A short description for the effect manifest.
    pub fn describe(&self) -> String {
        match self {
            Self::Rgb => "Rgb".into(),
            Self::Blackbody(b) => format!("Blackbody {} K", b.kelvin()),
            Self::Illuminant(i) => format!("Illuminant {:?}", i.which()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planck_peak_follows_wien() {
        // Wien's displacement: λ_max = 2.897771955e-3 m·K / T.
        let t = 5000.0;
        let peak = (300..1200)
            .map(|nm| (nm, planck(nm as f32, t)))
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a })
            .0;
        assert!((peak as f32 - 2.897_772e6 / t).abs() <= 1.0, "{peak}");
    }

    #[test]
    fn cold_or_invalid_bodies_are_black() {
        for t in [0.0, -5.0, 1.0, f32::NAN] {
            let b = Blackbody::new(t, 1.0);
            assert_eq!(b.eval(550.0), 0.0, "{t}");
        }
    }
}
