//! Daylight: the Hosek–Wilkie (2012) spectral sky model and the sun's disc.
//!
//! The sky's radiance in eleven bands (320, 360, …, 720 nm) comes from the model's fitted
//! coefficients, blended for the sun's elevation (a quintic Bézier over six control points in
//! (elevation / 90°)^⅓), the turbidity (linear between integer turbidities 1–10) and the ground
//! albedo (linear between 0 and 1, per band):
//!
//! ```text
//! L(θ, γ) = [1 + A·e^(B / (cos θ + 0.01))] · [C + D·e^(E·γ) + F·cos²γ + G·χ(H, γ) + I·√cos θ] · L_M
//! χ(H, γ) = (1 + cos²γ) / (1 + H² − 2H·cos γ)^{3/2}
//! ```
//!
//! θ is the view direction's angle from the zenith, γ its angle to the sun. Between bands the
//! radiance is linear in wavelength; above 720 nm it holds the 720 nm value (the model stops
//! there; prism's wavelengths reach 830 nm). Below the horizon the sky is black: the ground is
//! the scene's to model. Units: W m⁻² sr⁻¹ nm⁻¹, as the model's and Mitsuba 3's `sunsky`.
//!
//! The sun is a disc of uniform radiance, 0.5358° across (6.87·10⁻⁵ sr), whose radiance is the
//! model's solar irradiance for the elevation and turbidity (tabulated every 3° from 2° to 89°;
//! held at 2° below that) over the disc's solid angle.
//!
//! The data are the Hosek–Wilkie datasets as Mitsuba 3 ships them, converted by
//! `scripts/sky_tables.py` (BSD-3-Clause, Lukas Hosek and Alexander Wilkie: see
//! `src/scene/sky/LICENSE-hosek-wilkie.txt`).

use super::envmap::{EnvMap, EnvMapError, local_of_uv};
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::PI;
use std::sync::LazyLock;

/// Number of spectral bands of the model.
pub const BANDS: usize = 11;
/// Wavelength of the first band, nm.
pub const BAND_FIRST_NM: f32 = 320.0;
/// Spacing of the bands, nm.
pub const BAND_STEP_NM: f32 = 40.0;
/// The sun's apparent diameter, degrees (as Mitsuba 3's `sunsky`).
pub const SUN_APERTURE_DEG: f64 = 0.5358;

const TURBIDITIES: usize = 10;
const CONTROL: usize = 6;
const COEFFS: usize = 9;
const SUN_ELEVATIONS: usize = 30;
const PARAMS_LEN: usize = TURBIDITIES * 2 * CONTROL * BANDS * COEFFS;
const RADIANCE_LEN: usize = TURBIDITIES * 2 * CONTROL * BANDS;
const SUN_LEN: usize = TURBIDITIES * SUN_ELEVATIONS * BANDS;

static BYTES: &[u8] = include_bytes!("sky/hosek_wilkie.bin");

/// The committed tables: coefficients, radiance, sun irradiance.
type Tables = (Box<[f32]>, Box<[f32]>, Box<[f32]>);

/// The committed tables, decoded once per process.
static TABLES: LazyLock<Tables> = LazyLock::new(|| {
    let body = BYTES
        .strip_prefix(b"PRISMSKY\x01\x00\x00\x00")
        .expect("hosek_wilkie.bin: header");
    assert_eq!(
        body.len(),
        4 * (PARAMS_LEN + RADIANCE_LEN + SUN_LEN),
        "hosek_wilkie.bin: size"
    );
    let floats: Vec<f32> = body
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let (p, rest) = floats.split_at(PARAMS_LEN);
    let (r, s) = rest.split_at(RADIANCE_LEN);
    (p.into(), r.into(), s.into())
});

/// What a sky is made of, as the scene file gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyParams {
    /// The sun's angle above the horizon, degrees, in [0, 90].
    pub sun_elevation: f32,
    /// The sun's compass direction, degrees: 0 towards `-z`, 90 towards `+x` (as an
    /// environment map's columns).
    pub sun_azimuth: f32,
    /// Atmospheric turbidity, in [1, 10] (2 is a clear day, 10 hazy).
    pub turbidity: f32,
    /// Albedo of the ground under the sky, linear RGB in [0, 1].
    pub ground_albedo: Vec3,
    /// Whether the sun's disc shines.
    pub sun: bool,
    /// Multiplies sky and sun.
    pub scale: f32,
}

impl SkyParams {
    /// Unit direction towards the sun's centre.
    pub fn sun_direction(&self) -> Vec3 {
        let (e, a) = (
            f64::from(self.sun_elevation).to_radians(),
            f64::from(self.sun_azimuth).to_radians(),
        );
        DVec3::new(e.cos() * a.sin(), e.sin(), -e.cos() * a.cos()).as_vec3()
    }
}

impl std::fmt::Display for SkyParams {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.ground_albedo;
        write!(
            f,
            "Sky(sun_elevation: {}, sun_azimuth: {}, turbidity: {}, ground_albedo: Rgb({}, {}, {}), \
             sun: {}, scale: {})",
            self.sun_elevation,
            self.sun_azimuth,
            self.turbidity,
            a.x,
            a.y,
            a.z,
            self.sun,
            self.scale
        )
    }
}

/// A sky ready to evaluate: per band, the model's nine coefficients and its radiance scale
/// for this sun and atmosphere; the sun's direction, disc and spectral radiance.
#[derive(Clone, Debug)]
pub struct Sky {
    params: SkyParams,
    /// Per band: A B C D E F G I H (the datasets' order), then the radiance scale L_M
    /// (times `scale`).
    bands: [[f32; COEFFS + 1]; BANDS],
    sun_dir: Vec3,
    /// sin² of the sun's angular radius: a direction d is on the disc when
    /// |d × sun|² ≤ this and d · sun > 0 (robust where 1 − cos would lose digits in f32).
    sun_sin2: f32,
    /// Solid angle of the disc, sr.
    sun_omega: f32,
    /// The disc's radiance per band (times `scale`; zero without a sun).
    sun_bands: [f32; BANDS],
    /// Linear sRGB of unit radiance in one band (the band's share of the piecewise-linear
    /// spectrum, through the CIE 1931 observer).
    band_rgb: [Vec3; BANDS],
    sun_rgb: Vec3,
}

/// The quintic Bézier over six control values at `x`.
fn bezier(c: [f64; CONTROL], x: f64) -> f64 {
    const BINOMIAL: [f64; CONTROL] = [1.0, 5.0, 10.0, 10.0, 5.0, 1.0];
    (0..CONTROL)
        .map(|i| BINOMIAL[i] * x.powi(i as i32) * (1.0 - x).powi((CONTROL - 1 - i) as i32) * c[i])
        .sum()
}

/// Where the band interpolation reads wavelength `lambda`: the lower band and the weight of
/// the next (flat beyond both ends).
#[inline(always)]
fn band_at(lambda: f32) -> (usize, f32) {
    let x = ((lambda - BAND_FIRST_NM) / BAND_STEP_NM).clamp(0.0, (BANDS - 1) as f32);
    let i = (x as usize).min(BANDS - 2);
    (i, x - i as f32)
}

impl Sky {
    /// The sky and sun of `params` (assumed validated: elevation in [0, 90], turbidity in
    /// [1, 10], albedo in [0, 1]).
    pub fn new(params: SkyParams) -> Sky {
        let (p_tab, r_tab, s_tab) = &*TABLES;
        let elevation = f64::from(params.sun_elevation.clamp(0.0, 90.0)).to_radians();
        // The model's elevation parameter; 1 itself would weight the last control point alone,
        // which the fit does not reach.
        let x = (elevation / (PI / 2.0)).cbrt().min(1.0 - 1e-7);
        let t = f64::from(params.turbidity.clamp(1.0, 10.0)) - 1.0;
        let ti = (t as usize).min(TURBIDITIES - 2);
        let tf = t - ti as f64;
        let albedo = crate::spectrum::RgbSigmoid::from_rgb(
            params.ground_albedo.clamp(Vec3::ZERO, Vec3::ONE),
        );
        let scale = f64::from(params.scale);
        let mut bands = [[0.0f32; COEFFS + 1]; BANDS];
        for (b, out) in bands.iter_mut().enumerate() {
            let a = f64::from(albedo.eval(BAND_FIRST_NM + BAND_STEP_NM * b as f32)).clamp(0.0, 1.0);
            // Control value k of coefficient `c` (c = COEFFS: the radiance), blended over
            // turbidity and albedo.
            let control = |k: usize, c: usize| {
                let at = |turb: usize, alb: usize| {
                    let base = ((turb * 2 + alb) * CONTROL + k) * BANDS + b;
                    f64::from(if c < COEFFS {
                        p_tab[base * COEFFS + c]
                    } else {
                        r_tab[base]
                    })
                };
                let low = (1.0 - tf) * at(ti, 0) + tf * at(ti + 1, 0);
                let high = (1.0 - tf) * at(ti, 1) + tf * at(ti + 1, 1);
                (1.0 - a) * low + a * high
            };
            for (c, v) in out.iter_mut().enumerate() {
                let value = bezier(std::array::from_fn(|k| control(k, c)), x);
                *v = if c == COEFFS { value * scale } else { value } as f32;
            }
        }
        // The sun: irradiance every 3° from 2° to 89°, linear in elevation and turbidity.
        let half = (SUN_APERTURE_DEG / 2.0).to_radians();
        let omega = 2.0 * PI * (1.0 - half.cos());
        let e = (f64::from(params.sun_elevation).max(2.0) - 2.0) / 3.0;
        let e = e.min((SUN_ELEVATIONS - 1) as f64);
        let ei = (e as usize).min(SUN_ELEVATIONS - 2);
        let ef = e - ei as f64;
        let sun_bands = std::array::from_fn(|b| {
            if !params.sun {
                return 0.0;
            }
            let at =
                |turb: usize, el: usize| f64::from(s_tab[(turb * SUN_ELEVATIONS + el) * BANDS + b]);
            let lo = (1.0 - ef) * at(ti, ei) + ef * at(ti, ei + 1);
            let hi = (1.0 - ef) * at(ti + 1, ei) + ef * at(ti + 1, ei + 1);
            (((1.0 - tf) * lo + tf * hi) / omega * scale) as f32
        });
        let band_rgb = std::array::from_fn(|b| {
            let hat = |l: f32| {
                let (i, f) = band_at(l);
                if i == b {
                    1.0 - f
                } else if i + 1 == b {
                    f
                } else {
                    0.0
                }
            };
            crate::spectrum::xyz_to_linear_srgb(crate::spectrum::spectrum_to_xyz(hat))
        });
        let sun_rgb = rgb_of(&band_rgb, &sun_bands);
        Sky {
            params,
            bands,
            sun_dir: params.sun_direction(),
            sun_sin2: half.sin().powi(2) as f32,
            sun_omega: omega as f32,
            sun_bands,
            band_rgb,
            sun_rgb,
        }
    }

    /// The parameters the sky was made from.
    pub fn params(&self) -> &SkyParams {
        &self.params
    }

    /// The sky's radiance in every band along `-d` (unit `d` pointing away from the scene);
    /// zero at and below the horizon.
    #[inline]
    pub fn bands(&self, d: Vec3) -> [f32; BANDS] {
        let cos_theta = d.y;
        if cos_theta <= 0.0 {
            return [0.0; BANDS];
        }
        let cos_gamma = d.dot(self.sun_dir).clamp(-1.0, 1.0);
        let gamma = cos_gamma.acos();
        let sqrt_cos = cos_theta.sqrt();
        let inv = 1.0 / (cos_theta + 0.01);
        std::array::from_fn(|b| {
            let [a, bb, c, dd, e, f, g, i, h, lm] = self.bands[b];
            let chi = (1.0 + cos_gamma * cos_gamma) / (1.0 + h * h - 2.0 * h * cos_gamma).powf(1.5);
            let zenith = 1.0 + a * (bb * inv).exp();
            let sun =
                c + dd * (e * gamma).exp() + f * cos_gamma * cos_gamma + g * chi + i * sqrt_cos;
            (zenith * sun * lm).max(0.0)
        })
    }

    /// The sky's spectral radiance along `-d` at four wavelengths.
    #[inline]
    pub fn radiance(&self, d: Vec3, lambda: [f32; 4]) -> [f32; 4] {
        let b = self.bands(d);
        lambda.map(|l| {
            let (i, f) = band_at(l);
            b[i] + (b[i + 1] - b[i]) * f
        })
    }

    /// The sky's radiance along `-d` as linear sRGB: the band-interpolated spectrum through
    /// the CIE observer, exactly as spectral transport sees it on average.
    #[inline]
    pub fn rgb(&self, d: Vec3) -> Vec3 {
        rgb_of(&self.band_rgb, &self.bands(d))
    }

    /// Unit direction towards the sun's centre.
    pub fn sun_direction(&self) -> Vec3 {
        self.sun_dir
    }

    /// Whether the sun shines (it is on, and `scale` is not zero).
    pub fn has_sun(&self) -> bool {
        self.sun_bands.iter().any(|&v| v > 0.0)
    }

    /// Solid angle of the sun's disc, sr.
    pub fn sun_solid_angle(&self) -> f32 {
        self.sun_omega
    }

    /// Whether the unit direction `d` falls on the sun's disc.
    #[inline]
    pub fn on_sun(&self, d: Vec3) -> bool {
        d.dot(self.sun_dir) > 0.0 && d.cross(self.sun_dir).length_squared() <= self.sun_sin2
    }

    /// A direction uniformly on the sun's disc from `u` ∈ [0, 1)²; its density is
    /// 1 / [`Self::sun_solid_angle`].
    #[inline]
    pub fn sample_sun(&self, u: Vec2) -> Vec3 {
        // sin²θ uniform in cos θ without forming 1 − cos θ of a tiny angle: with
        // s = sin²θ_max, 1 − cos θ_max = s / (1 + cos θ_max).
        let omc_max = self.sun_sin2 / (1.0 + (1.0 - self.sun_sin2).sqrt());
        let omc = u.x * omc_max;
        let sin_theta = (omc * (2.0 - omc)).max(0.0).sqrt();
        let cos_theta = 1.0 - omc;
        let phi = 2.0 * std::f32::consts::PI * u.y;
        let (t, b) = self.sun_dir.any_orthonormal_pair();
        (t * (sin_theta * phi.cos()) + b * (sin_theta * phi.sin()) + self.sun_dir * cos_theta)
            .normalize()
    }

    /// The sun's spectral radiance at four wavelengths (zero without a sun).
    #[inline]
    pub fn sun_radiance(&self, lambda: [f32; 4]) -> [f32; 4] {
        let s = &self.sun_bands;
        lambda.map(|l| {
            let (i, f) = band_at(l);
            s[i] + (s[i + 1] - s[i]) * f
        })
    }

    /// The sun's radiance as linear sRGB.
    pub fn sun_rgb(&self) -> Vec3 {
        self.sun_rgb
    }

    /// The sky (without the sun) tabulated as a `width × height` environment map of linear
    /// sRGB radiance at texel centres: what the sky's directions are importance-sampled by.
    pub fn tabulate(&self, width: u32, height: u32) -> Result<EnvMap, EnvMapError> {
        let mut texels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let uv = Vec2::new(
                    (x as f32 + 0.5) / width as f32,
                    (y as f32 + 0.5) / height as f32,
                );
                texels.push(self.rgb(local_of_uv(uv)).max(Vec3::ZERO).to_array());
            }
        }
        EnvMap::new(width, height, &texels, 1.0, Vec3::ZERO)
    }
}

/// Linear sRGB of per-band radiances.
#[inline]
fn rgb_of(band_rgb: &[Vec3; BANDS], bands: &[f32; BANDS]) -> Vec3 {
    band_rgb.iter().zip(bands).map(|(w, &v)| *w * v).sum()
}
