//! RGB or spectral transport: what a path carries and how scene colours enter it.
//!
//! The integrator is generic over [`Transport`]. [`Rgb`] multiplies linear sRGB triples, as
//! the renderer does for every scene without a spectral cause. [`Spectral`] carries four
//! wavelengths per path (hero wavelength sampling, Wilkie et al. 2014): reflectances and
//! emitters are evaluated at those wavelengths (RGB inputs upsampled by Jakob & Hanika 2019),
//! a dispersive interface keeps only the hero, and the film receives the CIE XYZ estimate
//! converted to linear sRGB (the conversion is linear, so converting each sample equals
//! converting the accumulated XYZ).

use super::bsdf::Chan;
use super::ctx::Ctx;
use super::state::{MAX_W, mask_from_bits};
use crate::components::ConductorIor;
use crate::medium::{HomogeneousMedium, lanes};
use crate::scene::lights::{LightSample, LightSource};
use crate::scene::sky::Sky;
use crate::scene::{LightKind, RenderScene};
use crate::simd::{Float, Mask, UInt, V3};
use crate::spectrum::N_LAMBDA;
use crate::spectrum::lanes::{self as spectrum_lanes, LaneWavelengths};
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
    /// Scattering coefficient σs per channel (1/scene unit).
    fn sigma_s(&self) -> S;
    /// Extinction σt = σa + σs.
    fn sigma_t(&self) -> S;
    /// Henyey–Greenstein asymmetry.
    fn g(&self) -> f32;
    /// Transmittance over distance `d` per channel, `exp(−σt·d)`.
    fn transmittance(&self, d: f32) -> S;
    /// Density per unit length of free-flight sampling drawing `t`, channels chosen in proportion
    /// to the throughput `probs` ([`lanes::channel_probabilities`]).
    fn distance_pdf(&self, t: f32, probs: S) -> f32;
    /// Henyey–Greenstein phase function for directions `wo` and `wi`, both pointing away from the
    /// scattering point.
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
    /// Emits nothing.
    Zero,
    /// An RGB colour upsampled to a smooth illuminant spectrum.
    Rgb(RgbIlluminant),
    /// A physically defined spectrum (black body or named illuminant).
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
    /// Per material: a conductor's complex IOR η and k as smooth unbounded spectra (zero
    /// for other materials).
    conductor: Vec<(RgbUnbounded, RgbUnbounded)>,
}

impl SpectralData {
    /// No spectral data: what RGB transport carries.
    pub const EMPTY: SpectralData = SpectralData {
        refl: Vec::new(),
        emit: Vec::new(),
        point: Vec::new(),
        environment: None,
        media: Vec::new(),
        conductor: Vec::new(),
    };

    /// The spectral forms of every material, point light, medium and the environment of `scene`.
    pub fn new(scene: &RenderScene) -> Self {
        use crate::components::Material;
        let prims = &scene.prims;
        let refl = prims
            .materials
            .iter()
            .map(|m| match *m {
                Material::Diffuse { albedo } => RgbSigmoid::from_rgb(albedo),
                Material::Mirror { tint } => RgbSigmoid::from_rgb(tint),
                Material::Plastic { albedo, .. } => RgbSigmoid::from_rgb(albedo),
                Material::Conductor {
                    ior: ConductorIor::Reflectance(r),
                    ..
                } => RgbSigmoid::from_rgb(r),
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
        let conductor = prims
            .materials
            .iter()
            .map(|m| match *m {
                Material::Conductor {
                    ior: ConductorIor::Complex { eta, k },
                    ..
                } => (RgbUnbounded::from_rgb(eta), RgbUnbounded::from_rgb(k)),
                _ => (
                    RgbUnbounded::from_rgb(Vec3::ZERO),
                    RgbUnbounded::from_rgb(Vec3::ZERO),
                ),
            })
            .collect();
        SpectralData {
            refl,
            emit,
            point,
            conductor,
            environment: Some(EmitSpec::new(scene.environment, scene.environment_spectrum)),
            media,
        }
    }
}

/// A transport's channels as a plain array, to move them in and out of lanes.
pub trait ChannelArray<const N: usize>: Channels {
    /// The channels as an array.
    fn to_array(self) -> [f32; N];
    /// Channels from an array.
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
///
/// The kernel keeps every lane's wavelengths in lanes ([`Transport::Lanes`]) and evaluates
/// the scene's colours over lanes: a stage records each lane's colour (an RGB triple, or a
/// spectrum's few coefficients) one lane at a time in [`Transport::Colours`], then
/// [`Transport::eval`] computes all lanes at their wavelengths at once. The one-path forms
/// (`Lambda`, `source_radiance`, `medium`) serve the per-lane medium estimators.
pub trait Transport: Copy + Send + Sync + 'static {
    /// Colours depend on the path's wavelengths.
    const SPECTRAL: bool;
    /// One path's colour channels: `Vec3` for RGB, four wavelengths' values for spectral.
    type S: Channels;
    /// One path's wavelengths (nothing in RGB).
    type Lambda: Copy + std::fmt::Debug + Default + Send + Sync;
    /// Every lane's wavelengths (nothing in RGB).
    type Lanes<F: Float>: Copy;
    /// Colours recorded one lane at a time, evaluated over lanes.
    type Colours;
    /// A medium evaluated in this transport's channels.
    type Med: MediumOps<Self::S>;

    /// Placeholder wavelengths for lanes without a path.
    fn no_lanes<F: Float>() -> Self::Lanes<F>;
    /// The wavelengths of sample `sample` of pixel `pixel`, in every lane.
    fn wavelengths<F: Float>(ctx: &Ctx, pixel: F::U32, sample: F::U32) -> Self::Lanes<F>;
    /// `a`'s wavelengths in lanes where `m` is set, else `b`'s.
    fn select_lanes<F: Float>(m: F::Mask, a: Self::Lanes<F>, b: Self::Lanes<F>) -> Self::Lanes<F>;
    /// Lane `i`'s wavelengths.
    fn lane<F: Float>(lam: &Self::Lanes<F>, i: usize) -> Self::Lambda;
    /// Throughput of a new path: one on every live wavelength.
    fn initial_beta<F: Float, const N: usize>(lam: &Self::Lanes<F>) -> Chan<F, N>;
    /// The IOR of a dielectric at lane `i`'s hero wavelength, and whether it disperses (so
    /// the lane must end its secondary wavelengths: [`Transport::terminate_secondary`]).
    fn ior<F: Float>(model: &IorModel, lam: &Self::Lanes<F>, i: usize) -> (f32, bool);
    /// Ends the secondary wavelengths (and their throughput) of the lanes in `m`.
    fn terminate_secondary<F: Float, const N: usize>(
        lam: &mut Self::Lanes<F>,
        beta: &mut Chan<F, N>,
        m: F::Mask,
    );
    /// The lanes whose secondary wavelengths have ended (none in RGB).
    fn terminated<F: Float>(lam: &Self::Lanes<F>) -> F::Mask;

    /// An empty record of lane colours, in which each lane is set at most once.
    fn colours() -> Self::Colours;
    /// Lane `i`: material `mat`'s reflectance, `rgb` its (possibly texture-modulated) colour.
    fn set_reflectance(
        c: &mut Self::Colours,
        i: usize,
        ctx: &Ctx,
        mat: u32,
        rgb: Vec3,
        textured: bool,
    );
    /// Lane `i`: the Fresnel inputs of conductor `mat` described by `ior` (texture-modulated
    /// when `textured`): η, or Schlick's normal-incidence reflectance, into `eta`, and k into
    /// `k`. Returns whether the lane takes Schlick's form.
    #[allow(clippy::too_many_arguments)]
    fn set_conductor<F: Float>(
        eta: &mut Self::Colours,
        k: &mut Self::Colours,
        i: usize,
        ctx: &Ctx,
        mat: u32,
        ior: &ConductorIor,
        textured: bool,
        lam: &Self::Lanes<F>,
    ) -> bool;
    /// Lane `i`: radiance `le` (RGB, already texture-modulated by `tex`) of emitter `mat`.
    #[allow(clippy::too_many_arguments)]
    fn set_emission<F: Float>(
        c: &mut Self::Colours,
        i: usize,
        ctx: &Ctx,
        mat: u32,
        le: Vec3,
        tex: Option<Vec3>,
        lam: &Self::Lanes<F>,
    );
    /// Lane `i`: the radiance `rgb` of a light sample from `source`.
    fn set_source<F: Float>(
        c: &mut Self::Colours,
        i: usize,
        ctx: &Ctx,
        source: &LightSource,
        rgb: Vec3,
        lam: &Self::Lanes<F>,
    );
    /// Lane `i`: the environment's radiance.
    fn set_environment<F: Float>(c: &mut Self::Colours, i: usize, ctx: &Ctx, lam: &Self::Lanes<F>);
    /// Lane `i`: the linear RGB radiance `rgb` of an environment map, upsampled as an
    /// illuminant by spectral transport.
    fn set_map_radiance<F: Float>(c: &mut Self::Colours, i: usize, rgb: Vec3, lam: &Self::Lanes<F>);
    /// Lane `i`: `w_sky` times the sky's radiance along `-d` plus `w_sun` times the sun's
    /// (spectral transport evaluates the model's spectra, RGB their linear sRGB).
    #[allow(clippy::too_many_arguments)]
    fn set_sky<F: Float>(
        c: &mut Self::Colours,
        i: usize,
        sky: &Sky,
        d: Vec3,
        w_sky: f32,
        w_sun: f32,
        lam: &Self::Lanes<F>,
    );
    /// The recorded colours at every lane's wavelengths (lanes never set are unspecified).
    fn eval<F: Float, const N: usize>(c: &Self::Colours, lam: &Self::Lanes<F>) -> Chan<F, N>;
    /// The radiance `l` of each lane in `ended` (bit i: lane i) as linear sRGB for the film,
    /// into `rgb[i]`.
    fn ended_rgb<F: Float, const N: usize>(
        l: &Chan<F, N>,
        lam: &Self::Lanes<F>,
        ended: u32,
        rgb: &mut [Vec3; MAX_W],
    );

    /// One path's radiance of light sample `ls`.
    #[inline(always)]
    fn light_radiance(ctx: &Ctx, ls: &LightSample, lam: &Self::Lambda) -> Self::S {
        Self::source_radiance(ctx, &ls.source, ls.radiance, lam)
    }
    /// One path's radiance `rgb` of a light sample from `source`.
    fn source_radiance(ctx: &Ctx, source: &LightSource, rgb: Vec3, lam: &Self::Lambda) -> Self::S;
    /// A point light's intensity times `scale` (falloff / d²) for one path.
    fn point_radiance(ctx: &Ctx, light: u32, rgb: Vec3, scale: f32, lam: &Self::Lambda) -> Self::S;
    /// Medium `m` in this transport's channels, at one path's wavelengths.
    fn medium(ctx: &Ctx, m: u32, lam: &Self::Lambda) -> Self::Med;
}

/// Three-channel linear sRGB transport.
#[derive(Clone, Copy, Debug)]
pub struct Rgb;

/// RGB colours, one triple per lane.
pub struct RgbColours([[f32; MAX_W]; 3]);

impl RgbColours {
    #[inline(always)]
    fn set(&mut self, i: usize, v: Vec3) {
        (self.0[0][i], self.0[1][i], self.0[2][i]) = (v.x, v.y, v.z);
    }
}

/// Channels `[F; M]` as `Chan<F, N>`: the transports' channel counts are fixed (3 and 4), the
/// kernels' `N` is theirs.
#[inline(always)]
fn chan<F: Float, const N: usize, const M: usize>(a: [F; M]) -> Chan<F, N> {
    const { assert!(N == M) };
    // A loop rather than `std::array::from_fn`, which is not always inlined.
    let mut c = [F::zero(); N];
    for (c, a) in c.iter_mut().zip(a) {
        *c = a;
    }
    Chan(c)
}

impl Transport for Rgb {
    const SPECTRAL: bool = false;
    type S = Vec3;
    type Lambda = ();
    type Lanes<F: Float> = ();
    type Colours = RgbColours;
    type Med = HomogeneousMedium;

    #[inline(always)]
    fn no_lanes<F: Float>() {}
    #[inline(always)]
    fn wavelengths<F: Float>(_: &Ctx, _: F::U32, _: F::U32) {}
    #[inline(always)]
    fn select_lanes<F: Float>(_: F::Mask, _: (), _: ()) {}
    #[inline(always)]
    fn lane<F: Float>(_: &(), _: usize) {}
    #[inline(always)]
    fn initial_beta<F: Float, const N: usize>(_: &()) -> Chan<F, N> {
        Chan([F::one(); N])
    }
    #[inline(always)]
    fn ior<F: Float>(model: &IorModel, _: &(), _: usize) -> (f32, bool) {
        match *model {
            IorModel::Constant(n) => (n, false),
            ref m => (m.eta(crate::spectrum::LAMBDA_D), false),
        }
    }
    #[inline(always)]
    fn terminate_secondary<F: Float, const N: usize>(_: &mut (), _: &mut Chan<F, N>, _: F::Mask) {}
    #[inline(always)]
    fn terminated<F: Float>(_: &()) -> F::Mask {
        F::Mask::splat(false)
    }
    #[inline(always)]
    fn colours() -> RgbColours {
        RgbColours([[0.0; MAX_W]; 3])
    }
    #[inline(always)]
    fn set_reflectance(c: &mut RgbColours, i: usize, _: &Ctx, _: u32, rgb: Vec3, _: bool) {
        c.set(i, rgb);
    }
    #[inline(always)]
    fn set_conductor<F: Float>(
        eta: &mut RgbColours,
        k: &mut RgbColours,
        i: usize,
        _: &Ctx,
        _: u32,
        ior: &ConductorIor,
        _: bool,
        _: &(),
    ) -> bool {
        match *ior {
            ConductorIor::Metal { r0, .. } => {
                eta.set(i, r0);
                true
            }
            ConductorIor::Complex { eta: e, k: kk } => {
                eta.set(i, e);
                k.set(i, kk);
                false
            }
            ConductorIor::Reflectance(r) => {
                eta.set(i, r);
                true
            }
        }
    }
    #[inline(always)]
    fn set_emission<F: Float>(
        c: &mut RgbColours,
        i: usize,
        _: &Ctx,
        _: u32,
        le: Vec3,
        _: Option<Vec3>,
        _: &(),
    ) {
        c.set(i, le);
    }
    #[inline(always)]
    fn set_source<F: Float>(
        c: &mut RgbColours,
        i: usize,
        _: &Ctx,
        _: &LightSource,
        rgb: Vec3,
        _: &(),
    ) {
        c.set(i, rgb);
    }
    #[inline(always)]
    fn set_environment<F: Float>(c: &mut RgbColours, i: usize, ctx: &Ctx, _: &()) {
        c.set(i, ctx.scene.environment);
    }
    #[inline(always)]
    fn set_map_radiance<F: Float>(c: &mut RgbColours, i: usize, rgb: Vec3, _: &()) {
        c.set(i, rgb);
    }
    #[inline(always)]
    fn set_sky<F: Float>(
        c: &mut RgbColours,
        i: usize,
        sky: &Sky,
        d: Vec3,
        w_sky: f32,
        w_sun: f32,
        _: &(),
    ) {
        let sky_rgb = if w_sky != 0.0 {
            sky.rgb(d) * w_sky
        } else {
            Vec3::ZERO
        };
        c.set(i, sky_rgb + sky.sun_rgb() * w_sun);
    }
    #[inline(always)]
    fn eval<F: Float, const N: usize>(c: &RgbColours, _: &()) -> Chan<F, N> {
        chan([F::load(&c.0[0]), F::load(&c.0[1]), F::load(&c.0[2])])
    }
    #[inline(always)]
    fn ended_rgb<F: Float, const N: usize>(
        l: &Chan<F, N>,
        _: &(),
        ended: u32,
        rgb: &mut [Vec3; MAX_W],
    ) {
        let v = V3::new(l.0[0], l.0[1], l.0[2]);
        for (i, rgb) in rgb.iter_mut().enumerate().take(F::WIDTH) {
            if ended >> i & 1 != 0 {
                *rgb = v.lane(i);
            }
        }
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
    fn medium(ctx: &Ctx, m: u32, _: &()) -> HomogeneousMedium {
        ctx.scene.prims.media[m as usize]
    }
}

/// Four wavelengths per path, film in CIE XYZ converted to linear sRGB.
#[derive(Clone, Copy, Debug)]
pub struct Spectral;

/// Each lane's spectrum as the few numbers that define it, evaluated over lanes at the lanes'
/// wavelengths: k · P(λ) · D(λ) · s₂ · s₁ · σ(c₀t² + c₁t + c₂), multiplied in the order the
/// one-path spectra multiply, so both give the same bits. A reflectance sets c and s₁; an RGB
/// emitter also s₂ and D, the unit-luminance D65; a physically defined emitter (Planck, a
/// named illuminant) is evaluated for its lane when it is set (P, rare); a point light's
/// falloff is k.
pub struct SpectralColours {
    c: [[f32; MAX_W]; 3],
    s1: [f32; MAX_W],
    s2: [f32; MAX_W],
    k: [f32; MAX_W],
    /// Lanes with D65 (bit i: lane i) and with a physically defined spectrum P.
    d65: u32,
    phys: u32,
    p: [[f32; MAX_W]; N_LAMBDA],
}

impl SpectralColours {
    /// Lane `i` is the reflectance `s`. A record is fresh from [`Transport::colours`] and each
    /// lane is set at most once, so s₂, k and the flags still hold their neutral values.
    #[inline(always)]
    fn sigmoid(&mut self, i: usize, s: &RgbSigmoid) {
        debug_assert!((self.d65 | self.phys) >> i & 1 == 0 && self.s2[i] == 1.0);
        let c = s.coeffs();
        (self.c[0][i], self.c[1][i], self.c[2][i]) = (c[0], c[1], c[2]);
        self.s1[i] = s.scale();
    }

    /// Lane `i` is the unbounded spectrum `u` (a conductor's η or k).
    #[inline(always)]
    fn unbounded(&mut self, i: usize, u: &RgbUnbounded) {
        self.sigmoid(i, &u.shape());
        self.s2[i] = u.scale();
    }

    /// Lane `i` takes the values `v` at its wavelengths (a measured metal's n or k, looked up
    /// for the lane when it is set, as a physically defined emitter is).
    #[inline(always)]
    fn tabulated(&mut self, i: usize, v: [f32; N_LAMBDA]) {
        self.sigmoid(i, &RgbSigmoid::grey(1.0));
        for (p, v) in self.p.iter_mut().zip(v) {
            p[i] = v;
        }
        self.phys |= 1 << i;
    }

    /// Lane `i` emits `spec` (times the reflectance `tint`, a texture's, if any) times `k`.
    #[inline(always)]
    fn emitter<F: Float>(
        &mut self,
        i: usize,
        spec: &EmitSpec,
        tint: Option<Vec3>,
        k: f32,
        lam: &LaneWavelengths<F>,
    ) {
        match (spec, tint) {
            (EmitSpec::Zero | EmitSpec::Physical(EmitterSpectrum::Rgb), _) => {
                self.sigmoid(i, &RgbSigmoid::grey(0.0))
            }
            (EmitSpec::Rgb(s), _) => {
                self.sigmoid(i, &s.shape());
                self.s2[i] = s.scale();
                self.d65 |= 1 << i;
            }
            (EmitSpec::Physical(_), t) => {
                let shape = t.map_or(RgbSigmoid::grey(1.0), RgbSigmoid::from_rgb);
                self.sigmoid(i, &shape);
                let v = spec.eval(&lam.lane(i));
                for (p, v) in self.p.iter_mut().zip(v.0) {
                    p[i] = v;
                }
                self.phys |= 1 << i;
            }
        }
        self.k[i] = k;
    }
}

impl Transport for Spectral {
    const SPECTRAL: bool = true;
    type S = SampledSpectrum;
    type Lambda = Wavelengths;
    type Lanes<F: Float> = LaneWavelengths<F>;
    type Colours = SpectralColours;
    type Med = SpectralMedium;

    #[inline(always)]
    fn no_lanes<F: Float>() -> LaneWavelengths<F> {
        LaneWavelengths::zero()
    }
    #[inline(always)]
    fn wavelengths<F: Float>(ctx: &Ctx, pixel: F::U32, sample: F::U32) -> LaneWavelengths<F> {
        if let Some(lambda) = ctx.monochromatic {
            return LaneWavelengths::monochromatic(lambda);
        }
        let dim = F::U32::splat(super::ctx::DIM_WAVELENGTH);
        let u = ctx.sampler.get_1d_lanes::<F>(pixel, sample, dim);
        let mut lam = LaneWavelengths::sample_visible(u);
        if ctx.single_wavelength {
            lam.terminate_secondary(F::Mask::splat(true));
        }
        lam
    }
    #[inline(always)]
    fn select_lanes<F: Float>(
        m: F::Mask,
        a: LaneWavelengths<F>,
        b: LaneWavelengths<F>,
    ) -> LaneWavelengths<F> {
        LaneWavelengths::select(m, a, b)
    }
    #[inline(always)]
    fn lane<F: Float>(lam: &LaneWavelengths<F>, i: usize) -> Wavelengths {
        lam.lane(i)
    }
    #[inline(always)]
    fn initial_beta<F: Float, const N: usize>(lam: &LaneWavelengths<F>) -> Chan<F, N> {
        let mut b = [F::zero(); N_LAMBDA];
        for (b, p) in b.iter_mut().zip(lam.pdf) {
            *b = F::select(p.gt(F::zero()), F::one(), F::zero());
        }
        chan(b)
    }
    #[inline(always)]
    fn ior<F: Float>(model: &IorModel, lam: &LaneWavelengths<F>, i: usize) -> (f32, bool) {
        match *model {
            IorModel::Constant(n) => (n, false),
            // Each wavelength would refract its own way: only the hero goes on.
            ref m => (m.eta(lam.lambda[0].lane(i)), true),
        }
    }
    #[inline(always)]
    fn terminate_secondary<F: Float, const N: usize>(
        lam: &mut LaneWavelengths<F>,
        beta: &mut Chan<F, N>,
        m: F::Mask,
    ) {
        let changed = lam.terminate_secondary(m);
        for b in &mut beta.0[1..] {
            *b = F::select(changed, F::zero(), *b);
        }
    }
    #[inline(always)]
    fn terminated<F: Float>(lam: &LaneWavelengths<F>) -> F::Mask {
        lam.secondary_terminated()
    }
    #[inline(always)]
    fn colours() -> SpectralColours {
        SpectralColours {
            c: [[0.0; MAX_W]; 3],
            s1: [0.0; MAX_W],
            s2: [1.0; MAX_W],
            k: [1.0; MAX_W],
            d65: 0,
            phys: 0,
            p: [[1.0; MAX_W]; N_LAMBDA],
        }
    }
    #[inline(always)]
    fn set_reflectance(
        c: &mut SpectralColours,
        i: usize,
        ctx: &Ctx,
        mat: u32,
        rgb: Vec3,
        textured: bool,
    ) {
        if textured {
            c.sigmoid(i, &RgbSigmoid::from_rgb(rgb));
        } else {
            c.sigmoid(i, &ctx.spectral.refl[mat as usize]);
        }
    }
    #[inline(always)]
    fn set_conductor<F: Float>(
        eta: &mut SpectralColours,
        k: &mut SpectralColours,
        i: usize,
        ctx: &Ctx,
        mat: u32,
        ior: &ConductorIor,
        textured: bool,
        lam: &LaneWavelengths<F>,
    ) -> bool {
        match *ior {
            ConductorIor::Metal { metal, .. } => {
                let l = lam.lane(i).lambda;
                let nk = l.map(|l| metal.nk(l));
                eta.tabulated(i, nk.map(|v| v.0));
                k.tabulated(i, nk.map(|v| v.1));
                false
            }
            ConductorIor::Complex { .. } => {
                let (e, kk) = &ctx.spectral.conductor[mat as usize];
                eta.unbounded(i, e);
                k.unbounded(i, kk);
                false
            }
            ConductorIor::Reflectance(r) => {
                if textured {
                    eta.sigmoid(i, &RgbSigmoid::from_rgb(r));
                } else {
                    eta.sigmoid(i, &ctx.spectral.refl[mat as usize]);
                }
                true
            }
        }
    }
    #[inline(always)]
    fn set_emission<F: Float>(
        c: &mut SpectralColours,
        i: usize,
        ctx: &Ctx,
        mat: u32,
        le: Vec3,
        tex: Option<Vec3>,
        lam: &LaneWavelengths<F>,
    ) {
        let spec = &ctx.spectral.emit[mat as usize];
        match (tex, spec) {
            // A textured RGB emitter: the modulated colour is the emitter's colour.
            (Some(_), EmitSpec::Rgb(_)) => c.emitter(
                i,
                &EmitSpec::Rgb(RgbIlluminant::from_rgb(le)),
                None,
                1.0,
                lam,
            ),
            (t, s) => c.emitter(i, s, t, 1.0, lam),
        }
    }
    #[inline(always)]
    fn set_source<F: Float>(
        c: &mut SpectralColours,
        i: usize,
        ctx: &Ctx,
        source: &LightSource,
        rgb: Vec3,
        lam: &LaneWavelengths<F>,
    ) {
        match *source {
            LightSource::Area { material, tex, .. } => {
                Self::set_emission(c, i, ctx, material, rgb, tex, lam)
            }
            LightSource::Point { light, scale } => {
                c.emitter(i, &ctx.spectral.point[light as usize], None, scale, lam)
            }
            LightSource::Environment => Self::set_environment(c, i, ctx, lam),
            LightSource::EnvMap { wi } => match ctx.scene.lights.sky.as_deref() {
                Some(sky) => Self::set_sky(c, i, sky, wi, 1.0, 0.0, lam),
                None => Self::set_map_radiance(c, i, rgb, lam),
            },
            LightSource::Sun => match ctx.scene.lights.sky.as_deref() {
                Some(sky) => Self::set_sky(c, i, sky, Vec3::ZERO, 0.0, 1.0, lam),
                None => c.sigmoid(i, &RgbSigmoid::grey(0.0)),
            },
        }
    }
    #[inline(always)]
    fn set_map_radiance<F: Float>(
        c: &mut SpectralColours,
        i: usize,
        rgb: Vec3,
        lam: &LaneWavelengths<F>,
    ) {
        c.emitter(
            i,
            &EmitSpec::Rgb(RgbIlluminant::from_rgb(rgb)),
            None,
            1.0,
            lam,
        );
    }
    #[inline(always)]
    fn set_sky<F: Float>(
        c: &mut SpectralColours,
        i: usize,
        sky: &Sky,
        d: Vec3,
        w_sky: f32,
        w_sun: f32,
        lam: &LaneWavelengths<F>,
    ) {
        let lambda = lam.lane(i).lambda;
        let a = if w_sky != 0.0 {
            sky.radiance(d, lambda)
        } else {
            [0.0; N_LAMBDA]
        };
        let b = sky.sun_radiance(lambda);
        c.tabulated(i, std::array::from_fn(|k| a[k] * w_sky + b[k] * w_sun));
    }
    #[inline(always)]
    fn set_environment<F: Float>(
        c: &mut SpectralColours,
        i: usize,
        ctx: &Ctx,
        lam: &LaneWavelengths<F>,
    ) {
        let env = ctx.spectral.environment.unwrap_or(EmitSpec::Zero);
        c.emitter(i, &env, None, 1.0, lam);
    }
    #[inline(always)]
    fn eval<F: Float, const N: usize>(c: &SpectralColours, lam: &LaneWavelengths<F>) -> Chan<F, N> {
        let coeffs = [F::load(&c.c[0]), F::load(&c.c[1]), F::load(&c.c[2])];
        let (s1, s2, k) = (F::load(&c.s1), F::load(&c.s2), F::load(&c.k));
        let d65 = mask_from_bits::<F>(c.d65);
        let phys = mask_from_bits::<F>(c.phys);
        // A loop, not a closure: closures this size are not always inlined.
        let mut out = [F::zero(); N_LAMBDA];
        for (w, out) in out.iter_mut().enumerate() {
            let l = lam.lambda[w];
            let mut v = spectrum_lanes::sigmoid(&coeffs, s1, l) * s2;
            if c.d65 != 0 {
                v = F::select(d65, v * lam.illum[w], v);
            }
            if c.phys != 0 {
                v = F::select(phys, v * F::load(&c.p[w]), v);
            }
            *out = v * k;
        }
        chan(out)
    }
    #[inline(always)]
    fn ended_rgb<F: Float, const N: usize>(
        l: &Chan<F, N>,
        lam: &LaneWavelengths<F>,
        ended: u32,
        rgb: &mut [Vec3; MAX_W],
    ) {
        // Eight table rows per lane: only the lanes that ended pay for them, one at a time
        // (plain loads where the packet would gather for every lane).
        let mut v = [[0.0f32; MAX_W]; 3 * N_LAMBDA];
        for k in 0..N_LAMBDA {
            l.0[k].store(&mut v[k]);
            lam.lambda[k].store(&mut v[N_LAMBDA + k]);
            lam.pdf[k].store(&mut v[2 * N_LAMBDA + k]);
        }
        let mut bits = ended;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let at = |o: usize| std::array::from_fn(|k| v[o + k][i]);
            rgb[i] = crate::spectrum::to_linear_srgb(at(0), at(N_LAMBDA), at(2 * N_LAMBDA));
        }
    }
    #[inline(always)]
    fn source_radiance(
        ctx: &Ctx,
        source: &LightSource,
        rgb: Vec3,
        lam: &Wavelengths,
    ) -> SampledSpectrum {
        // The lane code at width 1: one description of every emitter's spectrum.
        let lanes = LaneWavelengths::<f32>::new(lam.lambda, lam.pdf);
        let mut c = Self::colours();
        Self::set_source::<f32>(&mut c, 0, ctx, source, rgb, &lanes);
        SampledSpectrum(Self::eval::<f32, N_LAMBDA>(&c, &lanes).0)
    }
    #[inline(always)]
    fn point_radiance(
        ctx: &Ctx,
        light: u32,
        rgb: Vec3,
        scale: f32,
        lam: &Wavelengths,
    ) -> SampledSpectrum {
        Self::source_radiance(ctx, &LightSource::Point { light, scale }, rgb, lam)
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
}
