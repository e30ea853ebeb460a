//! RGB or spectral transport: what a path carries and how scene colours enter it.
//!
//! The integrator is generic over [`Transport`]. [`Rgb`] multiplies linear sRGB triples, as
//! the renderer does for every scene without a spectral cause. [`Spectral`] carries four
//! wavelengths per path (hero wavelength sampling, Wilkie et al. 2014): reflectances and
//! emitters are evaluated at those wavelengths (RGB inputs upsampled by Jakob & Hanika 2019),
//! a dispersive interface keeps only the hero, and the film receives the CIE XYZ estimate
//! converted to linear sRGB (the conversion is linear, so converting each sample equals
//! converting the accumulated XYZ).

use super::ctx::Ctx;
use crate::medium::{HomogeneousMedium, lanes};
use crate::scene::lights::{LightSample, LightSource};
use crate::scene::{LightKind, RenderScene};
use crate::spectrum::{
    Channels, EmitterSpectrum, IorModel, RgbIlluminant, RgbSigmoid, RgbUnbounded, SampledSpectrum,
    Wavelengths,
};
use glam::Vec3;

/// A homogeneous medium with coefficients in the transport's channels.
///
/// The estimators are [`crate::medium::lanes`]' at width 1, the functions the kernel runs
/// over lanes, so the per-lane steps take the same decisions from the same numbers. Their
/// methods are always inlined: out of the lane kernels' `target_feature` entry points the
/// lane math would call `fmaf` and `rintf` for every fused multiply-add and rounding.
pub trait MediumOps<S>: Copy {
    fn sigma_s(&self) -> S;
    /// Extinction σt = σa + σs.
    fn sigma_t(&self) -> S;
    /// Henyey–Greenstein asymmetry.
    fn g(&self) -> f32;
    fn transmittance(&self, d: f32) -> S;
    fn distance_pdf(&self, t: f32, probs: S) -> f32;
    fn phase(&self, wo: Vec3, wi: Vec3) -> f32;
}

impl MediumOps<Vec3> for HomogeneousMedium {
    #[inline(always)]
    fn sigma_s(&self) -> Vec3 {
        self.sigma_s
    }
    #[inline(always)]
    fn sigma_t(&self) -> Vec3 {
        HomogeneousMedium::sigma_t(self)
    }
    #[inline(always)]
    fn g(&self) -> f32 {
        self.g
    }
    #[inline(always)]
    fn transmittance(&self, d: f32) -> Vec3 {
        Vec3::from_array(lanes::transmittance::<f32, 3>(
            &self.sigma_t().to_array(),
            d,
        ))
    }
    #[inline(always)]
    fn distance_pdf(&self, t: f32, probs: Vec3) -> f32 {
        lanes::free_flight_pdf::<f32, 3>(&self.sigma_t().to_array(), t, &probs.to_array())
    }
    #[inline(always)]
    fn phase(&self, wo: Vec3, wi: Vec3) -> f32 {
        lanes::hg_phase_dirs::<f32>(wo.into(), wi.into(), self.g)
    }
}

/// A medium evaluated at one path's four wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct SpectralMedium {
    sigma_s: SampledSpectrum,
    sigma_t: SampledSpectrum,
    g: f32,
}

impl MediumOps<SampledSpectrum> for SpectralMedium {
    #[inline(always)]
    fn sigma_s(&self) -> SampledSpectrum {
        self.sigma_s
    }
    #[inline(always)]
    fn sigma_t(&self) -> SampledSpectrum {
        self.sigma_t
    }
    #[inline(always)]
    fn g(&self) -> f32 {
        self.g
    }
    #[inline(always)]
    fn transmittance(&self, d: f32) -> SampledSpectrum {
        SampledSpectrum(lanes::transmittance::<f32, 4>(&self.sigma_t.0, d))
    }
    #[inline(always)]
    fn distance_pdf(&self, t: f32, probs: SampledSpectrum) -> f32 {
        lanes::free_flight_pdf::<f32, 4>(&self.sigma_t.0, t, &probs.0)
    }
    #[inline(always)]
    fn phase(&self, wo: Vec3, wi: Vec3) -> f32 {
        lanes::hg_phase_dirs::<f32>(wo.into(), wi.into(), self.g)
    }
}

/// How one emitter's spectrum is evaluated in spectral transport.
#[derive(Clone, Copy, Debug)]
pub enum EmitSpec {
    Zero,
    Rgb(RgbIlluminant),
    Physical(EmitterSpectrum),
}

impl EmitSpec {
    fn new(rgb: Vec3, spectrum: EmitterSpectrum) -> Self {
        match spectrum {
            EmitterSpectrum::Rgb if rgb.max_element() > 0.0 => {
                EmitSpec::Rgb(RgbIlluminant::from_rgb(rgb))
            }
            EmitterSpectrum::Rgb => EmitSpec::Zero,
            s => EmitSpec::Physical(s),
        }
    }

    #[inline(always)]
    fn eval(&self, lam: &Wavelengths) -> SampledSpectrum {
        match self {
            EmitSpec::Zero => SampledSpectrum::ZERO,
            EmitSpec::Rgb(s) => SampledSpectrum(s.eval4(lam.lambda)),
            EmitSpec::Physical(EmitterSpectrum::Blackbody(b)) => {
                SampledSpectrum(lam.lambda.map(|l| b.eval(l)))
            }
            EmitSpec::Physical(EmitterSpectrum::Illuminant(i)) => {
                SampledSpectrum(lam.lambda.map(|l| i.eval(l)))
            }
            EmitSpec::Physical(EmitterSpectrum::Rgb) => SampledSpectrum::ZERO,
        }
    }
}

/// Per-render spectral forms of the scene's colours, computed once (a table lookup per
/// material) so the per-hit cost is evaluating a sigmoid at four wavelengths.
#[derive(Debug, Default)]
pub struct SpectralData {
    /// Per material: the albedo (Diffuse) or tint (Mirror) as a smooth reflectance.
    refl: Vec<RgbSigmoid>,
    /// Per material: emission.
    emit: Vec<EmitSpec>,
    /// Per light index: point and spot light intensity (`Zero` for other lights).
    point: Vec<EmitSpec>,
    environment: Option<EmitSpec>,
    /// Per medium: σa, σs as smooth unbounded spectra, and g.
    media: Vec<(RgbUnbounded, RgbUnbounded, f32)>,
}

impl SpectralData {
    pub const EMPTY: SpectralData = SpectralData {
        refl: Vec::new(),
        emit: Vec::new(),
        point: Vec::new(),
        environment: None,
        media: Vec::new(),
    };

    pub fn new(scene: &RenderScene) -> Self {
        use crate::components::Material;
        let prims = &scene.prims;
        let refl = prims
            .materials
            .iter()
            .map(|m| match *m {
                Material::Diffuse { albedo } => RgbSigmoid::from_rgb(albedo),
                Material::Mirror { tint } => RgbSigmoid::from_rgb(tint),
                _ => RgbSigmoid::grey(0.0),
            })
            .collect();
        let emit = prims
            .materials
            .iter()
            .map(|m| match *m {
                Material::Light {
                    emission, spectrum, ..
                } => EmitSpec::new(emission, spectrum),
                _ => EmitSpec::Zero,
            })
            .collect();
        let point = scene
            .lights
            .lights
            .iter()
            .map(|l| match l {
                LightKind::Point(p) => EmitSpec::new(p.intensity, p.spectrum),
                _ => EmitSpec::Zero,
            })
            .collect();
        let media = prims
            .media
            .iter()
            .map(|m| {
                (
                    RgbUnbounded::from_rgb(m.sigma_a),
                    RgbUnbounded::from_rgb(m.sigma_s),
                    m.g,
                )
            })
            .collect();
        SpectralData {
            refl,
            emit,
            point,
            environment: Some(EmitSpec::new(scene.environment, scene.environment_spectrum)),
            media,
        }
    }
}

/// A transport's channels as a plain array, to move them in and out of lanes.
pub trait ChannelArray<const N: usize>: Channels {
    fn to_array(self) -> [f32; N];
    fn from_array(a: [f32; N]) -> Self;
}

impl ChannelArray<3> for Vec3 {
    #[inline(always)]
    fn to_array(self) -> [f32; 3] {
        self.into()
    }
    #[inline(always)]
    fn from_array(a: [f32; 3]) -> Self {
        a.into()
    }
}

impl ChannelArray<4> for SampledSpectrum {
    #[inline(always)]
    fn to_array(self) -> [f32; 4] {
        self.0
    }
    #[inline(always)]
    fn from_array(a: [f32; 4]) -> Self {
        SampledSpectrum(a)
    }
}

/// What a path carries, and how the scene's colours become that.
pub trait Transport: Copy + Send + Sync + 'static {
    /// Colours depend on the path's wavelengths (so the kernel evaluates them per lane;
    /// RGB colours are the same for every lane).
    const SPECTRAL: bool;
    type S: Channels;
    /// The path's wavelengths (nothing in RGB).
    type Lambda: Copy + std::fmt::Debug + Default + Send + Sync;
    type Med: MediumOps<Self::S>;

    fn wavelengths(ctx: &Ctx, pixel: u32, index: u32) -> Self::Lambda;
    /// Throughput of a new path: one on every live wavelength.
    fn initial_beta(lam: &Self::Lambda) -> Self::S;
    /// Material `mat`'s reflectance, `rgb` its (possibly texture-modulated) colour.
    fn reflectance(ctx: &Ctx, mat: u32, rgb: Vec3, textured: bool, lam: &Self::Lambda) -> Self::S;
    /// Radiance `le` (RGB, already texture-modulated by `tex`) of emitter material `mat`.
    fn emission(ctx: &Ctx, mat: u32, le: Vec3, tex: Option<Vec3>, lam: &Self::Lambda) -> Self::S;
    #[inline(always)]
    fn light_radiance(ctx: &Ctx, ls: &LightSample, lam: &Self::Lambda) -> Self::S {
        Self::source_radiance(ctx, &ls.source, ls.radiance, lam)
    }
    /// The radiance `rgb` of a light sample from `source`.
    fn source_radiance(ctx: &Ctx, source: &LightSource, rgb: Vec3, lam: &Self::Lambda) -> Self::S;
    /// A point light's intensity times `scale` (falloff / d²).
    fn point_radiance(ctx: &Ctx, light: u32, rgb: Vec3, scale: f32, lam: &Self::Lambda) -> Self::S;
    fn environment(ctx: &Ctx, lam: &Self::Lambda) -> Self::S;
    /// The relative IOR to use at this interface; a dispersive one ends the secondary
    /// wavelengths (and their throughput).
    fn eta(ior: &IorModel, lam: &mut Self::Lambda, beta: &mut Self::S) -> f32;
    fn medium(ctx: &Ctx, m: u32, lam: &Self::Lambda) -> Self::Med;
    /// The path's radiance as linear sRGB for the film.
    fn to_rgb(l: Self::S, lam: &Self::Lambda) -> Vec3;
}

/// Three-channel linear sRGB transport.
#[derive(Clone, Copy, Debug)]
pub struct Rgb;

impl Transport for Rgb {
    const SPECTRAL: bool = false;
    type S = Vec3;
    type Lambda = ();
    type Med = HomogeneousMedium;

    #[inline(always)]
    fn wavelengths(_: &Ctx, _: u32, _: u32) {}
    #[inline(always)]
    fn initial_beta(_: &()) -> Vec3 {
        Vec3::ONE
    }
    #[inline(always)]
    fn reflectance(_: &Ctx, _: u32, rgb: Vec3, _: bool, _: &()) -> Vec3 {
        rgb
    }
    #[inline(always)]
    fn emission(_: &Ctx, _: u32, le: Vec3, _: Option<Vec3>, _: &()) -> Vec3 {
        le
    }
    #[inline(always)]
    fn source_radiance(_: &Ctx, _: &LightSource, rgb: Vec3, _: &()) -> Vec3 {
        rgb
    }
    #[inline(always)]
    fn point_radiance(_: &Ctx, _: u32, rgb: Vec3, scale: f32, _: &()) -> Vec3 {
        rgb * scale
    }
    #[inline(always)]
    fn environment(ctx: &Ctx, _: &()) -> Vec3 {
        ctx.scene.environment
    }
    #[inline(always)]
    fn eta(ior: &IorModel, _: &mut (), _: &mut Vec3) -> f32 {
        match *ior {
            IorModel::Constant(n) => n,
            ref m => m.eta(crate::spectrum::LAMBDA_D),
        }
    }
    #[inline(always)]
    fn medium(ctx: &Ctx, m: u32, _: &()) -> HomogeneousMedium {
        ctx.scene.prims.media[m as usize]
    }
    #[inline(always)]
    fn to_rgb(l: Vec3, _: &()) -> Vec3 {
        l
    }
}

/// Four wavelengths per path, film in CIE XYZ converted to linear sRGB.
#[derive(Clone, Copy, Debug)]
pub struct Spectral;

#[inline(always)]
fn sigmoid4(s: &RgbSigmoid, lam: &Wavelengths) -> SampledSpectrum {
    SampledSpectrum(s.eval4(lam.lambda))
}

impl Transport for Spectral {
    const SPECTRAL: bool = true;
    type S = SampledSpectrum;
    type Lambda = Wavelengths;
    type Med = SpectralMedium;

    #[inline(always)]
    fn wavelengths(ctx: &Ctx, pixel: u32, index: u32) -> Wavelengths {
        if let Some(lambda) = ctx.monochromatic {
            return Wavelengths {
                lambda: [lambda; 4],
                pdf: [1.0, 0.0, 0.0, 0.0],
            };
        }
        let u = ctx.sampler.get_1d(pixel, index, super::ctx::DIM_WAVELENGTH);
        let mut lam = Wavelengths::sample_visible(u);
        if ctx.single_wavelength {
            lam.terminate_secondary();
        }
        lam
    }
    #[inline(always)]
    fn initial_beta(lam: &Wavelengths) -> SampledSpectrum {
        SampledSpectrum(lam.pdf.map(|p| if p > 0.0 { 1.0 } else { 0.0 }))
    }
    #[inline(always)]
    fn reflectance(
        ctx: &Ctx,
        mat: u32,
        rgb: Vec3,
        textured: bool,
        lam: &Wavelengths,
    ) -> SampledSpectrum {
        if textured {
            sigmoid4(&RgbSigmoid::from_rgb(rgb), lam)
        } else {
            sigmoid4(&ctx.spectral.refl[mat as usize], lam)
        }
    }
    #[inline(always)]
    fn emission(
        ctx: &Ctx,
        mat: u32,
        le: Vec3,
        tex: Option<Vec3>,
        lam: &Wavelengths,
    ) -> SampledSpectrum {
        let spec = &ctx.spectral.emit[mat as usize];
        match (tex, spec) {
            (None, s) => s.eval(lam),
            // A textured RGB emitter: the modulated colour is the emitter's colour.
            (Some(_), EmitSpec::Rgb(_)) => {
                SampledSpectrum(RgbIlluminant::from_rgb(le).eval4(lam.lambda))
            }
            (Some(t), s) => s.eval(lam) * sigmoid4(&RgbSigmoid::from_rgb(t), lam),
        }
    }
    #[inline(always)]
    fn source_radiance(
        ctx: &Ctx,
        source: &LightSource,
        rgb: Vec3,
        lam: &Wavelengths,
    ) -> SampledSpectrum {
        match *source {
            LightSource::Area { material, tex, .. } => Self::emission(ctx, material, rgb, tex, lam),
            LightSource::Point { light, scale } => {
                Self::point_radiance(ctx, light, rgb, scale, lam)
            }
            LightSource::Environment => Self::environment(ctx, lam),
        }
    }
    #[inline(always)]
    fn point_radiance(
        ctx: &Ctx,
        light: u32,
        _: Vec3,
        scale: f32,
        lam: &Wavelengths,
    ) -> SampledSpectrum {
        ctx.spectral.point[light as usize].eval(lam) * scale
    }
    #[inline(always)]
    fn environment(ctx: &Ctx, lam: &Wavelengths) -> SampledSpectrum {
        ctx.spectral
            .environment
            .map_or(SampledSpectrum::ZERO, |e| e.eval(lam))
    }
    #[inline(always)]
    fn eta(ior: &IorModel, lam: &mut Wavelengths, beta: &mut SampledSpectrum) -> f32 {
        match *ior {
            IorModel::Constant(n) => n,
            ref m => {
                // Each wavelength would refract its own way: only the hero goes on.
                if !lam.secondary_terminated() {
                    lam.terminate_secondary();
                    for b in &mut beta.0[1..] {
                        *b = 0.0;
                    }
                }
                m.eta(lam.lambda[0])
            }
        }
    }
    #[inline(always)]
    fn medium(ctx: &Ctx, m: u32, lam: &Wavelengths) -> SpectralMedium {
        let (a, s, g) = &ctx.spectral.media[m as usize];
        let sigma_a = SampledSpectrum(a.eval4(lam.lambda));
        let sigma_s = SampledSpectrum(s.eval4(lam.lambda));
        SpectralMedium {
            sigma_s,
            sigma_t: sigma_a + sigma_s,
            g: *g,
        }
    }
    #[inline(always)]
    fn to_rgb(l: SampledSpectrum, lam: &Wavelengths) -> Vec3 {
        crate::spectrum::xyz_to_linear_srgb(crate::spectrum::to_xyz(&l, lam))
    }
}
