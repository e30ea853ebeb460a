//! What every stage reads and never changes during a render: the scene, the sampler, the
//! settings hoisted out of the per-ray loop, and the fixed layout of sample dimensions.

use super::transport::SpectralData;
use crate::sampling::{self, Sampler};
use crate::scene::RenderScene;
use crate::scene_file::schema::{Fresnel, LightSampling};

// Sample dimensions. The layout is fixed whatever the effect set, so an absent effect never
// shifts the dimensions of the others: a scene renders the same image with or without code
// for effects it does not use.
/// Position within the pixel (2 dimensions).
pub const DIM_FILM: u32 = 0;
/// Point on the lens (2 dimensions).
pub const DIM_LENS: u32 = 2;
/// Time within the shutter (1 dimension).
pub const DIM_TIME: u32 = 4;
/// Hero wavelength (1 dimension).
pub const DIM_WAVELENGTH: u32 = 5;
/// First dimension of the first scattering event; event k starts `k * DIMS_PER_BOUNCE` later.
pub const DIM_BOUNCE: u32 = 8;
/// Dimensions each scattering event may use: light choice (1), light point (2), lobe (1),
/// direction (2), Russian roulette (1), and one reserved.
pub const DIMS_PER_BOUNCE: u32 = 8;
/// Medium segments take their dimensions from a separate range, 12 per segment: channel,
/// distance, light choice, light point (2), phase direction (2), Russian roulette, and the
/// equiangular technique's light choice, distance and light point (2). A path may cross
/// boundaries without scattering, so segments are counted apart from bounces.
pub const DIM_MEDIA: u32 = 1 << 20;
/// Dimensions each medium segment may use (see [`DIM_MEDIA`]).
pub const DIMS_PER_SEGMENT: u32 = 12;

/// Per-render constants of the kernel, hoisted out of the per-ray loop.
#[derive(Clone, Copy)]
pub struct Ctx<'a> {
    /// The scene being rendered.
    pub scene: &'a RenderScene,
    /// The sample generator, seeded from the render settings.
    pub sampler: Sampler,
    /// Image width in pixels: pixels are numbered `y * width + x`.
    pub width: u32,
    /// Scattering events after which a path ends.
    pub max_depth: u32,
    /// Scattering events before Russian roulette starts.
    pub rr_depth: u32,
    /// Next-event estimation is on and the scene has lights to sample.
    pub nee: bool,
    /// Dielectrics use Schlick's Fresnel approximation instead of the exact formula.
    pub schlick: bool,
    /// LENS: camera rays start on a thin lens instead of a pinhole.
    pub lens: bool,
    /// TEXTURES and NORMAL_MAPS: read once per render, never per ray from the world.
    pub textures: bool,
    /// NORMAL_MAPS: some surface has a normal map.
    pub normal_maps: bool,
    /// In media, also sample distances towards lights (equiangular sampling, MIS).
    pub equiangular: bool,
    /// Whether the scene has a pure medium boundary material (an entity with a medium and no
    /// material): the only surface a shadow ray may pass through (MEDIA).
    pub boundaries: bool,
    /// A box pixel filter instead of the tent.
    pub box_filter: bool,
    /// Spectral forms of the scene's colours (empty in RGB transport).
    pub spectral: &'a SpectralData,
    /// One wavelength per path instead of four (`render.integrator.wavelengths: 1`).
    pub single_wavelength: bool,
    /// Every path carries this one wavelength (nm) with pdf 1: a monochromatic render of the
    /// hero channel, for studies of dispersion ([`super::RenderOptions::monochromatic`]).
    pub monochromatic: Option<f32>,
}

static NO_SPECTRAL_DATA: SpectralData = SpectralData::EMPTY;

impl<'a> Ctx<'a> {
    /// The constants of a render of `scene`, with a thin lens if `lens`.
    pub fn new(scene: &'a RenderScene, lens: bool) -> Self {
        let s = &scene.settings;
        Ctx {
            scene,
            sampler: Sampler::new(
                match s.sampler {
                    crate::scene_file::schema::SamplerChoice::Sobol => sampling::SamplerKind::Sobol,
                    crate::scene_file::schema::SamplerChoice::Independent => {
                        sampling::SamplerKind::Independent
                    }
                },
                s.seed,
            ),
            width: s.width,
            max_depth: s.max_depth,
            rr_depth: s.rr_depth,
            nee: s.light_sampling == LightSampling::Nee && !scene.lights.is_empty(),
            schlick: s.fresnel == Fresnel::Schlick,
            lens,
            textures: scene.effects.has(crate::scene::Effect::Textures),
            normal_maps: scene.effects.has(crate::scene::Effect::NormalMaps),
            equiangular: s.equiangular,
            boundaries: scene
                .prims
                .materials
                .iter()
                .any(|m| matches!(m, crate::components::Material::Boundary)),
            box_filter: s.filter == crate::scene_file::schema::Filter::Box,
            spectral: &NO_SPECTRAL_DATA,
            single_wavelength: s.wavelengths == 1,
            monochromatic: None,
        }
    }

    /// The same constants with the spectral data spectral transport reads.
    pub fn with_spectral(self, spectral: &'a SpectralData) -> Self {
        Ctx { spectral, ..self }
    }
}
