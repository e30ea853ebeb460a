//! `render:` settings: image size, samples, depth, seed, filter and the integrator's options.

use super::{ImageDim, Positive, Spp, Wavelengths};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Render {
    #[serde(default = "default_width")]
    pub width: ImageDim,
    #[serde(default = "default_height")]
    pub height: ImageDim,
    #[serde(default = "default_spp")]
    pub spp: Spp,
    #[serde(default = "default_max_depth")]
    pub max_depth: u32,
    #[serde(default = "default_seed")]
    pub seed: u64,
    #[serde(default)]
    pub integrator: IntegratorSettings,
    /// The pixel filter camera samples are drawn from.
    #[serde(default)]
    pub filter: Filter,
    /// The lane width of the kernel: `"auto"`, 16, 8 or 1 (`--simd` overrides it).
    #[serde(default)]
    pub simd: crate::simd::SimdChoice,
    /// Overrides every surface of revolution's Newton tolerance (for accuracy studies).
    #[serde(default)]
    pub newton_tolerance: Option<Positive>,
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
fn default_max_depth() -> u32 {
    12
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
        }
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSettings {
    #[serde(default)]
    pub light_sampling: LightSampling,
    #[serde(default = "default_rr_depth")]
    pub rr_depth: u32,
    #[serde(default)]
    pub fresnel: Fresnel,
    #[serde(default = "default_wavelengths")]
    pub wavelengths: Wavelengths,
    #[serde(default)]
    pub sampler: SamplerChoice,
    /// In media, also sample scattering distances towards point, spot and area lights
    /// (equiangular sampling, combined with free-flight sampling by MIS).
    #[serde(default = "default_true")]
    pub equiangular: bool,
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
        }
    }
}

/// Next-event estimation with multiple importance sampling, or pure path tracing (emitters
/// found only by chance).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum LightSampling {
    #[default]
    Nee,
    Path,
}

/// The pixel filter, importance-sampled (each camera sample has weight one, nothing is
/// splatted): a tent of radius one pixel, or a box of one pixel (what renderers that filter
/// with a box use, for equal-error comparisons).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum Filter {
    #[default]
    Tent,
    Box,
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum Fresnel {
    #[default]
    Exact,
    Schlick,
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
pub enum SamplerChoice {
    #[default]
    Sobol,
    Independent,
}
