//! serde types of the RON scene file: the public contract of DESIGN.md.
//!
//! Value ranges are checked here, during deserialisation (`#[serde(try_from)]` newtypes), so
//! that a bad value is reported with the line and column where it stands. Parts of the schema
//! that this build does not simulate yet are parsed and then refused with a message that says
//! so, never ignored.

use serde::de::{self, Deserializer, IgnoredAny, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::fmt;

/// A top-level scene.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    #[serde(default)]
    pub render: Render,
    pub camera: Camera,
    #[serde(default)]
    pub animation: Option<Animation>,
    #[serde(default)]
    pub environment: Option<Environment>,
    #[serde(default)]
    pub entities: Vec<Entity>,
}

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

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub position: V3,
    pub look_at: V3,
    #[serde(default = "default_up")]
    pub up: V3,
    #[serde(default = "default_fov")]
    pub fov_y: FovY,
    #[serde(default)]
    pub lens: Option<Lens>,
    #[serde(default)]
    pub shutter: Option<Shutter>,
}

fn default_up() -> V3 {
    V3([0.0, 1.0, 0.0])
}
fn default_fov() -> FovY {
    FovY(40.0)
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lens {
    pub aperture_radius: NonNegative,
    pub focus_distance: Positive,
    #[serde(default)]
    pub blades: Blades,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "ShutterSpec")]
pub struct Shutter {
    pub open: f32,
    pub close: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ShutterSpec {
    open: f32,
    close: f32,
}

impl TryFrom<ShutterSpec> for Shutter {
    type Error = String;
    fn try_from(s: ShutterSpec) -> Result<Self, String> {
        if !(s.open.is_finite()
            && s.close.is_finite()
            && 0.0 <= s.open
            && s.open <= s.close
            && s.close <= 1.0)
        {
            return Err(format!(
                "shutter must satisfy 0 <= open <= close <= 1 (a fraction of a frame), got open {} close {}",
                s.open, s.close
            ));
        }
        Ok(Shutter {
            open: s.open,
            close: s.close,
        })
    }
}

/// Rigid motion of an entity: scene units per frame, and degrees per frame about the object
/// origin (the transform's translation), applied as R = Rz·Ry·Rx of the angles times time.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motion {
    #[serde(default)]
    pub velocity: Option<V3>,
    #[serde(default)]
    pub angular_velocity: Option<V3>,
}

/// A camera path: keyframes indexed by frame, interpolated smoothly between them.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "AnimationSpec")]
pub struct Animation {
    pub fps: u32,
    pub keyframes: Vec<Keyframe>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AnimationSpec {
    #[serde(default = "default_fps")]
    fps: u32,
    keyframes: Vec<Keyframe>,
}

fn default_fps() -> u32 {
    24
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    pub frame: u32,
    pub position: V3,
    pub look_at: V3,
    #[serde(default)]
    pub up: Option<V3>,
    #[serde(default)]
    pub fov_y: Option<FovY>,
    #[serde(default)]
    pub focus_distance: Option<Positive>,
}

impl TryFrom<AnimationSpec> for Animation {
    type Error = String;
    fn try_from(a: AnimationSpec) -> Result<Self, String> {
        if !(1..=1000).contains(&a.fps) {
            return Err(format!("fps must be in 1..=1000, got {}", a.fps));
        }
        if a.keyframes.is_empty() {
            return Err("an animation needs at least one keyframe".into());
        }
        for w in a.keyframes.windows(2) {
            if w[1].frame <= w[0].frame {
                return Err(format!(
                    "keyframes must have increasing frame numbers, got {} after {}",
                    w[1].frame, w[0].frame
                ));
            }
        }
        Ok(Animation {
            fps: a.fps,
            keyframes: a.keyframes,
        })
    }
}

/// A light without a shape: a point or a spot. `intensity` is radiant intensity (radiance
/// times area per solid angle); `cone` is the half-angle of the spot's cone in degrees and
/// `falloff` the width of the soft edge inside it.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "LightSpecRaw")]
pub enum LightSpec {
    Point {
        position: V3,
        intensity: Emission,
    },
    Spot {
        position: V3,
        direction: V3,
        cone: f32,
        falloff: f32,
        intensity: Emission,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
enum LightSpecRaw {
    Point {
        position: V3,
        intensity: Emission,
    },
    Spot {
        position: V3,
        direction: V3,
        cone: f32,
        #[serde(default)]
        falloff: f32,
        intensity: Emission,
    },
}

impl TryFrom<LightSpecRaw> for LightSpec {
    type Error = String;
    fn try_from(l: LightSpecRaw) -> Result<Self, String> {
        Ok(match l {
            LightSpecRaw::Point {
                position,
                intensity,
            } => LightSpec::Point {
                position,
                intensity,
            },
            LightSpecRaw::Spot {
                position,
                direction,
                cone,
                falloff,
                intensity,
            } => {
                if direction.vec().length_squared() == 0.0 {
                    return Err("Spot: direction must be a non-zero vector".into());
                }
                if !(cone > 0.0 && cone <= 90.0) {
                    return Err(format!(
                        "Spot: cone must be in (0, 90] degrees (a half-angle), got {cone}"
                    ));
                }
                if !(0.0..=cone).contains(&falloff) {
                    return Err(format!(
                        "Spot: falloff must be in [0, cone] = [0, {cone}] degrees, got {falloff}"
                    ));
                }
                LightSpec::Spot {
                    position,
                    direction,
                    cone,
                    falloff,
                    intensity,
                }
            }
        })
    }
}

/// A homogeneous participating medium filling a closed shape: absorption and scattering
/// coefficients per scene unit, and the Henyey–Greenstein asymmetry g.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "MediumRaw")]
pub struct MediumSpec {
    pub sigma_a: Color,
    pub sigma_s: Color,
    pub g: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MediumRaw {
    sigma_a: Color,
    sigma_s: Color,
    #[serde(default)]
    g: f32,
}

impl TryFrom<MediumRaw> for MediumSpec {
    type Error = String;
    fn try_from(m: MediumRaw) -> Result<Self, String> {
        for (name, c) in [("sigma_a", m.sigma_a), ("sigma_s", m.sigma_s)] {
            let v = c.vec();
            if !(v.is_finite() && v.min_element() >= 0.0) {
                return Err(format!(
                    "{name} must be finite and >= 0 in every channel, got Rgb({}, {}, {})",
                    v.x, v.y, v.z
                ));
            }
        }
        if !(m.g.is_finite() && m.g > -1.0 && m.g < 1.0) {
            return Err(format!("g must be in (-1, 1), got {}", m.g));
        }
        Ok(MediumSpec {
            sigma_a: m.sigma_a,
            sigma_s: m.sigma_s,
            g: m.g,
        })
    }
}

/// Background radiance seen by escaping rays.
#[derive(Clone, Debug, Deserialize)]
pub enum Environment {
    Constant(Emission),
}

/// One scene object.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entity {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub shape: Option<Shape>,
    #[serde(default)]
    pub transform: Option<Transform>,
    #[serde(default)]
    pub material: Option<Material>,
    #[serde(default)]
    pub texture: Option<crate::texture::TextureSpec>,
    #[serde(default)]
    pub motion: Option<Motion>,
    #[serde(default)]
    pub medium: Option<MediumSpec>,
    #[serde(default)]
    pub light: Option<LightSpec>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(try_from = "ShapeSpec")]
pub enum Shape {
    Sphere {
        center: V3,
        radius: Positive,
    },
    Rect {
        center: V3,
        u: V3,
        v: V3,
    },
    Disk {
        center: V3,
        normal: V3,
        radius: Positive,
    },
    Box {
        min: V3,
        max: V3,
    },
    /// A triangle mesh from an OBJ or PLY file, relative to the scene file.
    Mesh {
        path: String,
    },
    /// A cubic B-spline profile (radius, height) revolved about the local y axis.
    Revolution {
        profile: Vec<(f32, f32)>,
        tolerance: Option<f32>,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
enum ShapeSpec {
    Sphere {
        center: V3,
        radius: Positive,
    },
    Rect {
        center: V3,
        u: V3,
        v: V3,
    },
    Disk {
        center: V3,
        normal: V3,
        radius: Positive,
    },
    Box {
        min: V3,
        max: V3,
    },
    Mesh {
        path: String,
    },
    Revolution {
        profile: Vec<(f32, f32)>,
        #[serde(default)]
        tolerance: Option<f32>,
    },
}

impl TryFrom<ShapeSpec> for Shape {
    type Error = String;
    fn try_from(s: ShapeSpec) -> Result<Self, String> {
        Ok(match s {
            ShapeSpec::Sphere { center, radius } => Shape::Sphere { center, radius },
            ShapeSpec::Rect { center, u, v } => {
                let (a, b) = (u.vec(), v.vec());
                if a.cross(b).length_squared() <= 0.0 {
                    return Err(format!(
                        "Rect: u {:?} and v {:?} must be non-zero and not parallel (they span center ± u ± v)",
                        u.0, v.0
                    ));
                }
                Shape::Rect { center, u, v }
            }
            ShapeSpec::Disk {
                center,
                normal,
                radius,
            } => {
                if normal.vec().length_squared() <= 0.0 {
                    return Err("Disk: normal must be a non-zero vector".into());
                }
                Shape::Disk {
                    center,
                    normal,
                    radius,
                }
            }
            ShapeSpec::Box { min, max } => {
                let (a, b) = (min.vec(), max.vec());
                if !(a.x < b.x && a.y < b.y && a.z < b.z) {
                    return Err(format!(
                        "Box: min {:?} must be below max {:?} on every axis (a box needs a non-zero size)",
                        min.0, max.0
                    ));
                }
                Shape::Box { min, max }
            }
            ShapeSpec::Mesh { path } => {
                if path.trim().is_empty() {
                    return Err("Mesh: path must name an .obj or .ply file".into());
                }
                Shape::Mesh { path }
            }
            ShapeSpec::Revolution { profile, tolerance } => {
                if let Some(t) = tolerance
                    && !(t.is_finite() && t > 0.0 && t < 0.1)
                {
                    return Err(format!(
                        "Revolution: tolerance must be in (0, 0.1), got {t}"
                    ));
                }
                // Checked here so a bad profile keeps its line and column.
                crate::geometry::Revolution::new(
                    &profile,
                    tolerance.unwrap_or(crate::geometry::revolution::DEFAULT_TOLERANCE),
                )
                .map_err(|e| format!("Revolution: {e}"))?;
                Shape::Revolution { profile, tolerance }
            }
        })
    }
}

/// Object-to-world placement: scale, then rotation R = Rz·Ry·Rx (degrees), then translation.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    #[serde(default)]
    pub translate: Option<V3>,
    #[serde(default)]
    pub rotate: Option<V3>,
    #[serde(default)]
    pub scale: Option<Scale>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Material {
    Diffuse {
        albedo: Albedo,
    },
    Mirror {
        tint: Albedo,
    },
    Dielectric {
        ior: Ior,
    },
    Light {
        emission: Emission,
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
    Rgb(f32, f32, f32),
}

impl Color {
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
/// Y = `scale`. `rgb` is the linear sRGB colour of the emission either way.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(try_from = "EmissionSpec")]
pub struct Emission {
    pub rgb: glam::Vec3,
    pub spectrum: crate::spectrum::EmitterSpectrum,
}

impl Emission {
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
                Err(format!("scale must be a finite number >= 0, got {scale}"))
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
                        "kelvin must be in 500..=100000 (a body colder than 500 K emits almost \
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

/// A finite 3-vector written `(x, y, z)`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(try_from = "(f32, f32, f32)")]
pub struct V3(pub [f32; 3]);

impl V3 {
    pub fn vec(&self) -> glam::Vec3 {
        glam::Vec3::from_array(self.0)
    }
}

impl TryFrom<(f32, f32, f32)> for V3 {
    type Error = String;
    fn try_from((x, y, z): (f32, f32, f32)) -> Result<Self, String> {
        if x.is_finite() && y.is_finite() && z.is_finite() {
            Ok(V3([x, y, z]))
        } else {
            Err(format!("coordinates must be finite, got ({x}, {y}, {z})"))
        }
    }
}

macro_rules! checked_number {
    ($(#[$doc:meta])* $name:ident($t:ty, $tstr:literal), $ok:expr, $what:literal) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
        #[serde(try_from = $tstr)]
        pub struct $name(pub $t);

        impl TryFrom<$t> for $name {
            type Error = String;
            fn try_from(x: $t) -> Result<Self, String> {
                #[allow(clippy::redundant_closure_call)]
                if ($ok)(x) {
                    Ok($name(x))
                } else {
                    Err(format!(concat!("must be ", $what, ", got {}"), x))
                }
            }
        }
    };
}

checked_number!(
    /// A finite number > 0.
    Positive(f32, "f32"), |x: f32| x.is_finite() && x > 0.0, "a finite number > 0");
checked_number!(
    /// A finite number >= 0.
    NonNegative(f32, "f32"), |x: f32| x.is_finite() && x >= 0.0, "a finite number >= 0");
checked_number!(
    /// Vertical field of view in degrees.
    FovY(f32, "f32"), |x: f32| x.is_finite() && x > 0.0 && x < 180.0, "in (0, 180) degrees");
checked_number!(
    /// Image width or height in pixels.
    ImageDim(u32, "u32"), |x: u32| (1..=65536).contains(&x), "in 1..=65536 pixels");
checked_number!(
    /// Samples per pixel.
    Spp(u32, "u32"), |x: u32| x >= 1, "at least 1 sample per pixel");
checked_number!(
    /// Number of aperture blades: 0 for a round aperture, otherwise at least 3.
    #[derive(Default)]
    Blades(u32, "u32"), |x: u32| x == 0 || (3..=64).contains(&x), "0 (round) or 3..=64");
checked_number!(
    /// Wavelengths carried per path in spectral mode.
    Wavelengths(u32, "u32"), |x: u32| (1..=4).contains(&x), "1..=4");

/// `scale: 2.0` or `scale: (1.0, 2.0, 1.0)`; every component non-zero and finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale(pub [f32; 3]);

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Scale;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or a triple (x, y, z)")
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<Scale, E> {
                check_scale([x as f32; 3])
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<Scale, E> {
                check_scale([x as f32; 3])
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<Scale, E> {
                check_scale([x as f32; 3])
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Scale, A::Error> {
                let mut s = [0.0f32; 3];
                for (i, c) in s.iter_mut().enumerate() {
                    *c = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<IgnoredAny>()?.is_some() {
                    return Err(de::Error::invalid_length(4, &self));
                }
                check_scale(s)
            }
        }
        d.deserialize_any(V)
    }
}

fn check_scale<E: de::Error>(s: [f32; 3]) -> Result<Scale, E> {
    if s.iter().all(|c| c.is_finite() && *c != 0.0) {
        Ok(Scale(s))
    } else {
        Err(E::custom(format!(
            "scale must be finite and non-zero on every axis, got ({}, {}, {})",
            s[0], s[1], s[2]
        )))
    }
}
