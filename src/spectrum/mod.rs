//! Colour science for spectral light transport.
//!
//! Paths carry [`N_LAMBDA`] wavelengths over [`LAMBDA_MIN`]..[`LAMBDA_MAX`]
//! (hero wavelength sampling, Wilkie et al. 2014); radiance at those
//! wavelengths is a [`SampledSpectrum`], and [`to_xyz`] turns it into a
//! CIE 1931 XYZ estimate that [`xyz_to_linear_srgb`] maps to the film.
//!
//! - [`Wavelengths`], [`SampledSpectrum`]: the per-path spectral sample.
//! - [`cie_xyz`], [`to_xyz`], [`d65`], sRGB matrices: tabulated colorimetry.
//! - [`RgbSigmoid`], [`RgbIlluminant`]: smooth spectra for RGB inputs
//!   (Jakob & Hanika 2019).
//! - [`Blackbody`], [`Illuminant`]: physically defined emitters.
//! - [`IorModel`], [`IorPreset`]: wavelength-dependent refractive indices.

mod cie;
mod cie_data;
mod emitter;
mod ior;
pub mod lanes;
mod metals;
mod metals_data;
pub mod rgb2spec;
mod sampled;

pub use cie::{
    CIE_Y_INTEGRAL, SRGB_TO_XYZ, XYZ_TO_SRGB, cie_xyz, d65, linear_srgb_to_xyz, luminance,
    reflectance_to_xyz, spectrum_to_xyz, to_linear_srgb, to_xyz, xyz_to_chromaticity,
    xyz_to_linear_srgb,
};
pub use emitter::{Blackbody, EmitterSpectrum, Illuminant, NamedIlluminant, SUN_KELVIN, planck};
pub use ior::{IorModel, IorPreset};
pub use metals::Metal;
pub use rgb2spec::{RgbIlluminant, RgbSigmoid, RgbUnbounded};
pub use sampled::{Channels, SampledSpectrum, Wavelengths, sample_visible_wavelength};

/// Shortest wavelength carried by a path, nm.
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength carried by a path, nm.
pub const LAMBDA_MAX: f32 = 830.0;
/// Wavelengths per path.
pub const N_LAMBDA: usize = 4;
/// Wavelength at which RGB transport evaluates a dispersive IOR: the helium d line, where
/// glass catalogues quote n_d.
pub const LAMBDA_D: f32 = 587.56;

/// A spectral distribution that can be evaluated at any wavelength (nm).
pub trait Spectrum {
    /// Value at `lambda` nm.
    fn eval(&self, lambda: f32) -> f32;

    /// Values at a path's wavelengths.
    fn sample(&self, w: &Wavelengths) -> SampledSpectrum {
        SampledSpectrum(w.lambda.map(|l| self.eval(l)))
    }
}
