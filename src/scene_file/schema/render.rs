//! `render:` settings: image size, samples, depth, seed, filter and the integrator's options.

use super::{ImageDim, MaxDepth, Positive, Spp, TargetError, Wavelengths};
use serde::{Deserialize, Serialize};

/// The `render:` settings; every field is optional.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Render {
    /// Image width in pixels, 1..=65536; default 640.
    #[serde(default = "default_width")]
    pub width: ImageDim,
    /// Image height in pixels, 1..=65536; default 480.
    #[serde(default = "default_height")]
    pub height: ImageDim,
    /// Samples per pixel, >= 1; default 64.
    #[serde(default = "default_spp")]
    pub spp: Spp,
    /// Scattering events after which a path ends, counted as pbrt counts them, 0..=1024;
    /// default 12.
    #[serde(default = "default_max_depth")]
    pub max_depth: MaxDepth,
    /// Sampler seed: different seeds give independent images; default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// The integrator's options; each has a default.
    #[serde(default)]
    pub integrator: IntegratorSettings,
    /// The pixel filter camera samples are drawn from; default `Tent`.
    #[serde(default)]
    pub filter: Filter,
    /// The lane width of the kernel: `"auto"` (default), 16, 8 or 1 (`--simd` overrides it).
    #[serde(default)]
    pub simd: crate::simd::SimdChoice,
    /// Overrides every surface of revolution's Newton tolerance (for accuracy studies); > 0,
    /// absent by default.
    #[serde(default)]
    pub newton_tolerance: Option<Positive>,
    /// Render until the image's estimated relMSE is at most this, in (0, 1]; `spp` is then
    /// ignored unless given on the command line, where it caps every pixel. Absent by
    /// default (`--target-error` overrides it).
    #[serde(default)]
    pub target_error: Option<TargetError>,
}

/// The most pixels a film may have: 2²⁸ (16384 × 16384), the bound on decoded images too.
/// The film keeps about 24 bytes per pixel, so this is 6 GiB; each side is at most 65536.
pub const MAX_PIXELS: u64 = 1 << 28;

/// Refuses a film above [`MAX_PIXELS`], before anything is allocated.
pub fn check_film_size(width: u32, height: u32) -> Result<(), String> {
    let n = u64::from(width) * u64::from(height);
    if n <= MAX_PIXELS {
        Ok(())
    } else {
        Err(format!(
            "width × height = {width} × {height} = {n} pixels, above the limit of {MAX_PIXELS} \
             (16384 × 16384)"
        ))
    }
}

/// `render:` read and its film size checked, so a file's error carries its position.
pub(super) fn checked_render<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Render, D::Error> {
    let r = Render::deserialize(d)?;
    check_film_size(r.width.0, r.height.0).map_err(serde::de::Error::custom)?;
    Ok(r)
}

fn default_width() -> ImageDim {
    ImageDim(640)
}
fn default_height() -> ImageDim {
    ImageDim(480)
}
fn default_spp() -> Spp {
    Spp(64)
}
fn default_max_depth() -> MaxDepth {
    MaxDepth(12)
}
fn default_seed() -> u64 {
    1
}

impl Default for Render {
    fn default() -> Self {
        Self {
            width: default_width(),
            height: default_height(),
            spp: default_spp(),
            max_depth: default_max_depth(),
            seed: default_seed(),
            integrator: IntegratorSettings::default(),
            filter: Filter::default(),
            simd: Default::default(),
            newton_tolerance: None,
            target_error: None,
        }
    }
}

/// `render: (integrator: (..))`: how paths are sampled; every field is optional.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSettings {
    /// How emitters are found; default `Nee`.
    #[serde(default)]
    pub light_sampling: LightSampling,
    /// Scattering events before Russian roulette may end a path; default 5.
    #[serde(default = "default_rr_depth")]
    pub rr_depth: u32,
    /// The Fresnel term at dielectrics; default `Exact`.
    #[serde(default)]
    pub fresnel: Fresnel,
    /// Wavelengths per path in spectral transport: 4 (the default, hero wavelength sampling)
    /// or 1.
    #[serde(default = "default_wavelengths")]
    pub wavelengths: Wavelengths,
    /// Where sample values come from; default `Sobol`.
    #[serde(default)]
    pub sampler: SamplerChoice,
    /// In media, also sample scattering distances towards point, spot and area lights
    /// (equiangular sampling, combined with free-flight sampling by MIS); default `true`.
    #[serde(default = "default_true")]
    pub equiangular: bool,
    /// The estimator: paths from the camera (`Path`, the default), from the lights
    /// (`LightTracing`), from both (`Bdpt`), or chosen by the scene (`Auto`).
    #[serde(default)]
    pub kind: Estimator,
}

fn default_true() -> bool {
    true
}

fn default_rr_depth() -> u32 {
    5
}
fn default_wavelengths() -> Wavelengths {
    Wavelengths(4)
}

impl Default for IntegratorSettings {
    fn default() -> Self {
        Self {
            light_sampling: LightSampling::default(),
            rr_depth: default_rr_depth(),
            fresnel: Fresnel::default(),
            wavelengths: default_wavelengths(),
            sampler: SamplerChoice::default(),
            equiangular: true,
            kind: Estimator::default(),
        }
    }
}

/// Next-event estimation with multiple importance sampling, or pure path tracing (emitters
/// found only by chance).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum LightSampling {
    /// Next-event estimation: a light sample at every scattering event, weighted by MIS
    /// against the BSDF sample.
    #[default]
    Nee,
    /// Pure path tracing: emitters contribute only when a path hits them.
    Path,
}

/// Which paths carry the light to the film.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum Estimator {
    /// Unidirectional path tracing from the camera, with the scene's `light_sampling`.
    Path,
    /// Light tracing: paths start on the emitters, and every vertex whose BSDF has a density
    /// connects to the camera and splats its contribution through the pixel filter. It
    /// cannot see a specular surface from the camera.
    LightTracing,
    /// Bidirectional path tracing: a camera and a light subpath per sample, joined in every
    /// way, weighted by multiple importance sampling.
    Bdpt,
    /// `Bdpt` where a light reaches a specular or dispersive surface and the caustics carry
    /// a measured share of what the camera sees, else `Path` (`prism info` says which, and
    /// why). The default.
    #[default]
    Auto,
}

/// The pixel filter, importance-sampled (each camera sample has weight one, nothing is
/// splatted): a tent of radius one pixel, or a box of one pixel (what renderers that filter
/// with a box use, for equal-error comparisons).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum Filter {
    /// A tent of radius one pixel.
    #[default]
    Tent,
    /// A box one pixel wide.
    Box,
}

/// The Fresnel reflectance at dielectric interfaces.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum Fresnel {
    /// The unpolarised Fresnel equations.
    #[default]
    Exact,
    /// Schlick's approximation, for comparison with renderers that use it.
    Schlick,
}

/// The sample sequence camera, light and BSDF samples are drawn from.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum SamplerChoice {
    /// Owen-scrambled Sobol points: lower error at the same sample count.
    #[default]
    Sobol,
    /// Independent uniform random numbers, as a baseline.
    Independent,
}
