//! Smooth spectra for RGB colours (Jakob & Hanika 2019, "A Low-Dimensional
//! Function Space for Efficient Spectral Upsampling").
//!
//! A reflectance is s(λ) = σ(c₀t² + c₁t + c₂) with σ(x) = ½ + x/(2√(1+x²)),
//! which is smooth and stays inside [0, 1] for any coefficients. The
//! coefficients for an sRGB colour are found by least squares on the CIELAB
//! difference between the colour the spectrum shows under D65 and the
//! target. Doing that per shading point would be far too slow, so a table
//! over the colour cube is fitted once, at first use, and interpolated.
//!
//! The table follows the paper's layout (largest channel, its value z, the
//! other two as ratios to it), fitted by our own Gauss–Newton solver
//! (`Fitter`), with three changes: z stops at [`Z_DARK`], below which
//! colours are scaled copies of brighter ones; the ratio axes get nodes
//! crowded at both ends; and the fit integrates through 5 nm nodes with
//! cubic weights instead of at every nm. Building it (3·32³ cells) takes
//! about 0.1–0.3 s in an optimised build, on all available cores.
//!
//! Unlike the paper, the polynomial variable is the normalised wavelength
//! t = (λ − 595 nm)/235 nm ∈ [−1, 1], not λ in nm: the three coefficients
//! then have similar magnitudes, which keeps the 3×3 normal equations well
//! conditioned and avoids cancelling large terms in f32.
//! [`RgbSigmoid::coeffs_nm`] converts to the nm form.

use std::sync::OnceLock;

use glam::{DVec3, Vec3};

use super::cie::{CMF_ROWS, D65_Y_SUM, cmf_row, d65_at_nm};
use super::{CIE_Y_INTEGRAL, LAMBDA_MAX, LAMBDA_MIN, SRGB_TO_XYZ, Spectrum, d65};

/// Centre of the normalised wavelength, nm.
pub(super) const T_CENTRE: f32 = 0.5 * (LAMBDA_MIN + LAMBDA_MAX);
/// Half-width of the normalised wavelength, nm.
pub(super) const T_HALF: f32 = 0.5 * (LAMBDA_MAX - LAMBDA_MIN);
/// Its reciprocal: evaluation multiplies (a division costs several multiplications' time).
pub(super) const INV_T_HALF: f32 = 1.0 / T_HALF;

/// σ(x) = ½ + x/(2√(1+x²)): maps ℝ onto (0, 1), with σ(±∞) = 0 or 1.
///
/// Evaluated as 1/(2√(1+x²)(√(1+x²)+|x|)) on the dark side, which is the
/// same value without the cancellation of ½ − (almost ½), so small
/// reflectances keep their relative precision.
pub fn sigmoid(x: f32) -> f32 {
    let tail = |a: f32| {
        let r = (1.0 + a * a).sqrt();
        1.0 / (2.0 * r * (r + a))
    };
    if x < 0.0 { tail(-x) } else { 1.0 - tail(x) }
}

/// A smooth reflectance spectrum reproducing an sRGB albedo:
/// `scale`·σ(c₀t² + c₁t + c₂).
///
/// `scale` is 1 except for colours darker than [`Z_DARK`], which are that
/// fraction of the spectrum of the same colour brightened to [`Z_DARK`]
/// (see [`RgbSigmoid::from_rgb`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbSigmoid {
    /// Coefficients of c₀t² + c₁t + c₂ in the normalised wavelength t.
    c: [f32; 3],
    scale: f32,
}

impl RgbSigmoid {
    /// The spectrum for a linear sRGB reflectance; channels are clamped to
    /// [0, 1] (NaN counts as 0).
    ///
    /// Greys are solved in closed form (flat spectra, exact); everything
    /// else is interpolated from the fitted table.
    ///
    /// A colour whose largest channel is below [`Z_DARK`] gets the spectrum
    /// of the same colour brightened to [`Z_DARK`], scaled down: XYZ is
    /// linear in the spectrum, so the colour is exact, and the sigmoid is
    /// spared very dark chromatic targets, which it can only meet with huge
    /// coefficients and narrow spikes up to 1 where the eye is insensitive.
    pub fn from_rgb(rgb: Vec3) -> Self {
        let c = |v: f32| if v > 0.0 { v.min(1.0) } else { 0.0 };
        let rgb = [c(rgb.x), c(rgb.y), c(rgb.z)];
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return Self::grey(rgb[0]);
        }
        let (rgb, scale) = brighten(rgb);
        Self {
            c: table().lookup(rgb),
            scale,
        }
    }

    /// The flat spectrum of value `v` ∈ [0, 1]: σ(x) = v at
    /// x = (v − ½)/√(v(1 − v)), infinite (and still exact) at 0 and 1.
    pub fn grey(v: f32) -> Self {
        let x = (v - 0.5) / (v * (1.0 - v)).sqrt();
        Self {
            c: [0.0, 0.0, x],
            scale: 1.0,
        }
    }

    /// σ(c₀t² + c₁t + c₂) for coefficients of the normalised wavelength t
    /// (see [`RgbSigmoid::coeffs`]).
    pub const fn from_coeffs(c: [f32; 3]) -> Self {
        Self { c, scale: 1.0 }
    }

    /// Coefficients (c₀, c₁, c₂) of σ(c₀t² + c₁t + c₂) with
    /// t = (λ − 595 nm)/235 nm.
    pub fn coeffs(&self) -> [f32; 3] {
        self.c
    }

    /// Factor applied to the sigmoid (1 unless the colour is darker than
    /// [`Z_DARK`]).
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// The same polynomial in λ (nm): σ(a λ² + b λ + c), returned as
    /// (a, b, c) in f64 because the nm form cancels large terms.
    pub fn coeffs_nm(&self) -> [f64; 3] {
        let [c0, c1, c2] = self.c.map(f64::from);
        let (m, h) = (f64::from(T_CENTRE), f64::from(T_HALF));
        [
            c0 / (h * h),
            -2.0 * c0 * m / (h * h) + c1 / h,
            c0 * m * m / (h * h) - c1 * m / h + c2,
        ]
    }

    /// Reflectance at `lambda` nm.
    #[inline(always)]
    pub fn eval(&self, lambda: f32) -> f32 {
        let t = (lambda - T_CENTRE) * INV_T_HALF;
        self.scale * sigmoid((self.c[0] * t + self.c[1]) * t + self.c[2])
    }

    /// Reflectance at four wavelengths at once (the path's), as [`RgbSigmoid::eval`] in
    /// 4-wide arithmetic: one polynomial, one square root and one division per call.
    #[inline(always)]
    pub fn eval4(&self, lambda: [f32; 4]) -> [f32; 4] {
        use glam::Vec4;
        let t = (Vec4::from_array(lambda) - Vec4::splat(T_CENTRE)) * INV_T_HALF;
        let x = (Vec4::splat(self.c[0]) * t + Vec4::splat(self.c[1])) * t + Vec4::splat(self.c[2]);
        // The same cancellation-free form as `sigmoid`: the tail 1/(2r(r + |x|)) on the
        // dark side, one minus it on the bright side.
        let a = x.abs();
        let r = (Vec4::ONE + a * a).sqrt();
        let tail = Vec4::ONE / (2.0 * r * (r + a));
        let s = Vec4::select(x.cmplt(Vec4::ZERO), tail, Vec4::ONE - tail);
        (s * self.scale).to_array()
    }

    /// Largest reflectance over [`LAMBDA_MIN`]..=[`LAMBDA_MAX`] (σ is
    /// monotonic, so the polynomial's maximum decides: an end or the vertex).
    pub fn max_value(&self) -> f32 {
        let mut m = self.eval(LAMBDA_MIN).max(self.eval(LAMBDA_MAX));
        if self.c[0] != 0.0 {
            let t = -self.c[1] / (2.0 * self.c[0]);
            if (-1.0..=1.0).contains(&t) {
                m = m.max(self.eval(T_CENTRE + t * T_HALF));
            }
        }
        m
    }

    /// Fits the spectrum for `rgb` directly (no table), starting from the
    /// table's interpolated coefficients. Returns the spectrum and its
    /// CIELAB error ΔE*ab under D65 (below 1e-3 for any sRGB colour short
    /// of the white corner). Takes microseconds: for scene loading, not for
    /// per-hit texture lookups.
    pub fn fit(rgb: Vec3) -> (Self, f32) {
        Self::fit_from(rgb, Self::from_rgb(rgb))
    }

    /// [`RgbSigmoid::fit`] from a given starting spectrum.
    pub fn fit_from(rgb: Vec3, start: Self) -> (Self, f32) {
        let rgb = rgb.clamp(Vec3::ZERO, Vec3::ONE);
        if rgb.x == rgb.y && rgb.y == rgb.z {
            return (Self::grey(rgb.x), 0.0);
        }
        let (bright, scale) = brighten(rgb.to_array());
        let target = Vec3::from(bright).as_dvec3();
        let (c, err) = fitter().fit(target, start.c.map(f64::from), FIT_MAX_ITERS_EXACT);
        let s = Self {
            c: c.map(|v| v as f32),
            scale,
        };
        // The error was measured on the brightened colour; CIELAB is not
        // linear, so report it for the colour actually asked for.
        let err = if scale < 1.0 {
            delta_e(s, rgb)
        } else {
            err as f32
        };
        (s, err)
    }
}

impl Spectrum for RgbSigmoid {
    fn eval(&self, lambda: f32) -> f32 {
        RgbSigmoid::eval(self, lambda)
    }
}

/// Largest channel below which colours are scaled copies of brighter ones
/// (see [`RgbSigmoid::from_rgb`]); the table covers [`Z_DARK`]..=1.
pub const Z_DARK: f32 = 0.05;

/// A non-grey colour with its largest channel raised to at least
/// [`Z_DARK`], and the factor that undoes it.
fn brighten(rgb: [f32; 3]) -> ([f32; 3], f32) {
    let z = rgb[0].max(rgb[1]).max(rgb[2]);
    if z >= Z_DARK {
        return (rgb, 1.0);
    }
    let k = Z_DARK / z;
    // The largest channel is set exactly so rounding cannot leave it below.
    (rgb.map(|v| if v == z { Z_DARK } else { v * k }), z / Z_DARK)
}

/// CIELAB ΔE*ab between the colour of reflectance `s` under D65 and `rgb`.
fn delta_e(s: RgbSigmoid, rgb: Vec3) -> f32 {
    let f = fitter();
    let xyz = super::reflectance_to_xyz(|l| s.eval(l))
        .as_dvec3()
        .to_array();
    let want = (SRGB_TO_XYZ.as_dmat3() * rgb.as_dvec3()).to_array();
    let (a, b) = (f.lab(xyz).0, f.lab(want).0);
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt() as f32
}

/// Luminance Y of the D65 table relative to the ȳ integral: dividing D65 by
/// it gives the D65 emitter of luminance 1.
const D65_LUMINANCE: f32 = (D65_Y_SUM / CIE_Y_INTEGRAL as f64) as f32;

/// D65 of luminance 1 at every nm of the visible range, for [`RgbIlluminant::illuminant4`].
pub(super) static ILLUMINANT_1NM: [f32; 471] = {
    let mut t = [0.0f32; 471];
    let mut i = 0;
    while i < t.len() {
        t[i] = (d65_at_nm(360 + i) / (D65_Y_SUM / CIE_Y_INTEGRAL as f64)) as f32;
        i += 1;
    }
    t
};

/// An emission spectrum for an unbounded linear sRGB colour (pbrt-v4's
/// `RGBIlluminantSpectrum`): `scale`·σ-spectrum of rgb/`scale`·D65, with
/// `scale` = 2·max(rgb).
///
/// Halving the normalised colour keeps its largest channel at ½, where the
/// sigmoid fit is smooth and exact, instead of at 1, where spectra turn
/// into boxes; multiplying by D65 (scaled to luminance 1) makes a colour
/// mean "this RGB seen on an sRGB display", so (1, 1, 1) renders as
/// (1, 1, 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbIlluminant(RgbUnbounded);

impl RgbIlluminant {
    /// Emission for a linear sRGB colour; negative or NaN channels count
    /// as 0.
    pub fn from_rgb(rgb: Vec3) -> Self {
        Self(RgbUnbounded::from_rgb(rgb))
    }

    /// The sigmoid spectrum whose multiple this is (see [`RgbIlluminant::scale`]).
    pub fn shape(&self) -> RgbSigmoid {
        self.0.shape
    }

    /// The factor on [`RgbIlluminant::shape`] (before the illuminant): 2·max(rgb).
    pub fn scale(&self) -> f32 {
        self.0.scale
    }

    /// Spectral radiance at `lambda` nm.
    #[inline(always)]
    pub fn eval(&self, lambda: f32) -> f32 {
        self.0.eval(lambda) * d65(lambda) / D65_LUMINANCE
    }

    /// [`RgbIlluminant::eval`] at four wavelengths.
    #[inline(always)]
    pub fn eval4(&self, lambda: [f32; 4]) -> [f32; 4] {
        let s = self.0.eval4(lambda);
        let illuminant = Self::illuminant4(lambda);
        std::array::from_fn(|i| s[i] * illuminant[i])
    }

    /// The illuminant every RGB emitter is a multiple of (D65 of luminance 1) at four
    /// wavelengths, from a 1 nm table over the visible range (D65 is linear between its 5 nm
    /// entries, so the finer table interpolates to the same function).
    #[inline(always)]
    pub fn illuminant4(lambda: [f32; 4]) -> [f32; 4] {
        lambda.map(|l| {
            let x = l - LAMBDA_MIN;
            if !(x >= 0.0 && x <= (ILLUMINANT_1NM.len() - 1) as f32) {
                return 0.0;
            }
            let i = (x as usize).min(ILLUMINANT_1NM.len() - 2);
            let f = x - i as f32;
            ILLUMINANT_1NM[i] + (ILLUMINANT_1NM[i + 1] - ILLUMINANT_1NM[i]) * f
        })
    }
}

impl Spectrum for RgbIlluminant {
    fn eval(&self, lambda: f32) -> f32 {
        RgbIlluminant::eval(self, lambda)
    }
}

/// A non-negative, unbounded RGB quantity (a medium's σa or σs, and the
/// shape of an [`RgbIlluminant`]) as a smooth spectrum: `scale`·σ(…) with
/// `scale` = 2·max(rgb) (pbrt-v4's `RGBUnboundedSpectrum`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbUnbounded {
    scale: f32,
    shape: RgbSigmoid,
}

impl RgbUnbounded {
    /// Negative or NaN channels count as 0.
    pub fn from_rgb(rgb: Vec3) -> Self {
        let c = |v: f32| if v > 0.0 { v } else { 0.0 };
        let rgb = Vec3::new(c(rgb.x), c(rgb.y), c(rgb.z));
        let scale = 2.0 * rgb.max_element();
        if !(scale > 0.0 && scale.is_finite()) {
            return Self {
                scale: 0.0,
                shape: RgbSigmoid::grey(0.0),
            };
        }
        Self {
            scale,
            shape: RgbSigmoid::from_rgb(rgb / scale),
        }
    }

    /// Value at `lambda` nm.
    #[inline(always)]
    pub fn eval(&self, lambda: f32) -> f32 {
        self.scale * self.shape.eval(lambda)
    }

    /// The bounded spectrum this one is a multiple of.
    pub fn shape(&self) -> RgbSigmoid {
        self.shape
    }

    /// The factor on [`RgbUnbounded::shape`]: 2·max(rgb).
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// [`RgbUnbounded::eval`] at four wavelengths.
    #[inline(always)]
    pub fn eval4(&self, lambda: [f32; 4]) -> [f32; 4] {
        self.shape.eval4(lambda).map(|v| v * self.scale)
    }
}

// ---------------------------------------------------------------------------
// The optimiser.

/// Spacing of the fitter's quadrature nodes, nm. The sigmoid spectra are
/// smooth on this scale; the colour matching functions and D65 still enter
/// at their full 1 nm resolution through the node weights.
const FIT_STEP_NM: usize = 5;
/// The nodes start one step below [`LAMBDA_MIN`]: the cubic interpolation
/// between nodes needs a neighbour on each side.
const FIT_FIRST_NM: usize = 360 - FIT_STEP_NM;
/// Accumulator lanes of the fitter's inner loop.
const LANES: usize = 8;
/// Quadrature nodes from 355 nm to 835 nm, padded with zero-weight nodes
/// to a multiple of [`LANES`].
const FIT_NODES: usize = ((CMF_ROWS - 1) / FIT_STEP_NM + 3).div_ceil(LANES) * LANES;
/// Stop once ΔE*ab falls below this: far below what anyone can see, and
/// reached in a step or two once Gauss–Newton converges quadratically.
const FIT_TOL: f64 = 1e-3;
/// Iteration cap per table cell. Almost all cells converge in two or three
/// steps; the white corner (whose exact coefficients are infinite) and the
/// darkest nodes creep, and the cap bounds the time they take.
const FIT_MAX_ITERS_TABLE: usize = 40;
/// Iteration cap for [`RgbSigmoid::fit`].
const FIT_MAX_ITERS_EXACT: usize = 400;

/// CIELAB's cube-root nonlinearity and its derivative.
fn lab_f(u: f64) -> (f64, f64) {
    const D: f64 = 6.0 / 29.0;
    if u > D * D * D {
        let c = u.cbrt();
        (c, 1.0 / (3.0 * c * c))
    } else {
        (u / (3.0 * D * D) + 4.0 / 29.0, 1.0 / (3.0 * D * D))
    }
}

/// Least-squares fitter of sigmoid coefficients to a CIELAB target.
struct Fitter {
    /// Normalised wavelength of each node.
    t: [f32; FIT_NODES],
    /// Node weights of the 12 sums the fit needs: X, Y, Z, then
    /// ∂X/∂c₀, ∂X/∂c₁, ∂X/∂c₂, ∂Y/∂c₀, … ∂Z/∂c₂. The XYZ weights are
    /// ∫ φₖ(λ)·cmf(λ)·D65(λ) / ∫ D65 ȳ with φₖ node k's cubic interpolation
    /// basis function, so Σ s(tₖ)·wₖ is the XYZ of reflectance s under D65
    /// with white at Y = 1; the derivative weights carry the extra t², t, 1
    /// of ∂p/∂c.
    w: [[f32; FIT_NODES]; 12],
    /// CIELAB reference white: the XYZ of sRGB (1, 1, 1).
    white: [f64; 3],
}

fn fitter() -> &'static Fitter {
    static F: OnceLock<Fitter> = OnceLock::new();
    F.get_or_init(Fitter::new)
}

impl Fitter {
    fn new() -> Self {
        let mut t = [0.0f64; FIT_NODES];
        let mut w = [[0.0f64; 3]; FIT_NODES];
        for (k, tk) in t.iter_mut().enumerate() {
            let nm = (FIT_FIRST_NM + k * FIT_STEP_NM) as f64;
            *tk = (nm - f64::from(T_CENTRE)) / f64::from(T_HALF);
        }
        // Spread each 1 nm row over its four nearest nodes with the weights
        // of Catmull–Rom (Keys) cubic interpolation: the fit then sees the
        // 1 nm integral of the cubic through the node values, whose error
        // on steep sigmoids is several times smaller than linear's.
        for row in 0..CMF_ROWS {
            let cmf = cmf_row(row);
            let e = d65_at_nm(360 + row) / D65_Y_SUM;
            let off = 360 + row - FIT_FIRST_NM;
            let k = off / FIT_STEP_NM;
            let f = (off % FIT_STEP_NM) as f64 / FIT_STEP_NM as f64;
            let (f2, f3) = (f * f, f * f * f);
            let kernel = [
                0.5 * (-f3 + 2.0 * f2 - f),
                0.5 * (3.0 * f3 - 5.0 * f2 + 2.0),
                0.5 * (-3.0 * f3 + 4.0 * f2 + f),
                0.5 * (f3 - f2),
            ];
            for (n, kw) in kernel.iter().enumerate() {
                for ch in 0..3 {
                    w[k + n - 1][ch] += kw * cmf[ch] * e;
                }
            }
        }
        let mut wq = [[0.0f32; FIT_NODES]; 12];
        for k in 0..FIT_NODES {
            let basis = [t[k] * t[k], t[k], 1.0];
            for ch in 0..3 {
                wq[ch][k] = w[k][ch] as f32;
                for (j, b) in basis.iter().enumerate() {
                    wq[3 + 3 * ch + j][k] = (w[k][ch] * b) as f32;
                }
            }
        }
        let white = SRGB_TO_XYZ.as_dmat3() * DVec3::ONE;
        Self {
            t: t.map(|v| v as f32),
            w: wq,
            white: white.to_array(),
        }
    }

    /// CIELAB of an XYZ colour and ∂Lab/∂XYZ (rows L, a, b).
    fn lab(&self, xyz: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        let (fx, dx) = lab_f(xyz[0] / self.white[0]);
        let (fy, dy) = lab_f(xyz[1] / self.white[1]);
        let (fz, dz) = lab_f(xyz[2] / self.white[2]);
        let (dx, dy, dz) = (dx / self.white[0], dy / self.white[1], dz / self.white[2]);
        (
            [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)],
            [
                [0.0, 116.0 * dy, 0.0],
                [500.0 * dx, -500.0 * dy, 0.0],
                [0.0, 200.0 * dy, -200.0 * dz],
            ],
        )
    }

    /// CIELAB of the spectrum with coefficients `c`, and its Jacobian
    /// ∂Lab/∂c (rows L, a, b; columns c₀, c₁, c₂).
    ///
    /// This loop is the whole cost of building the table, so it is written
    /// to vectorise: f32 (its rounding, ~1e-6 of XYZ, is far below the fit
    /// tolerance), [`LANES`] independent partial sums (float sums are not
    /// reassociated otherwise), one square root and one division per node,
    /// and σ in its branch-free form.
    fn eval(&self, c: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        let [c0, c1, c2] = c.map(|v| v as f32);
        let mut sv = [0.0f32; FIT_NODES];
        let mut dv = [0.0f32; FIT_NODES];
        for k in 0..FIT_NODES {
            let t = self.t[k];
            let p = (c0 * t + c1) * t + c2;
            let inv_r = 1.0 / (1.0 + p * p).sqrt();
            sv[k] = 0.5 + 0.5 * p * inv_r;
            dv[k] = 0.5 * inv_r * inv_r * inv_r;
        }
        let sum = |q: usize| {
            let v = if q < 3 { &sv } else { &dv };
            let mut acc = [0.0f32; LANES];
            for (w, v) in self.w[q].chunks_exact(LANES).zip(v.chunks_exact(LANES)) {
                for lane in 0..LANES {
                    acc[lane] += w[lane] * v[lane];
                }
            }
            acc.iter().map(|&a| f64::from(a)).sum::<f64>()
        };
        let xyz = [sum(0), sum(1), sum(2)];
        let jx: [[f64; 3]; 3] =
            std::array::from_fn(|ch| std::array::from_fn(|j| sum(3 + 3 * ch + j)));
        let (lab, dl) = self.lab(xyz);
        let mut j = [[0.0; 3]; 3];
        for r in 0..3 {
            for col in 0..3 {
                j[r][col] = (0..3).map(|m| dl[r][m] * jx[m][col]).sum();
            }
        }
        (lab, j)
    }

    /// Levenberg–Marquardt on the CIELAB residual, from `c`. Returns the
    /// coefficients and the final ΔE*ab.
    ///
    /// With three unknowns and three residuals this is Gauss–Newton (as in
    /// the paper) whenever a step reduces the error; the damping only steps
    /// in when the Jacobian is near singular, as at the white corner.
    fn fit(&self, rgb: DVec3, mut c: [f64; 3], max_iters: usize) -> ([f64; 3], f64) {
        let target = self.lab((SRGB_TO_XYZ.as_dmat3() * rgb).to_array()).0;
        let residual = |c: [f64; 3]| {
            let (lab, j) = self.eval(c);
            let r = [lab[0] - target[0], lab[1] - target[1], lab[2] - target[2]];
            (r, j, r.iter().map(|v| v * v).sum::<f64>())
        };
        let (mut r, mut j, mut err) = residual(c);
        let mut mu = 1e-4;
        for _ in 0..max_iters {
            if err < FIT_TOL * FIT_TOL {
                break;
            }
            // Normal equations JᵀJ δ = −Jᵀr.
            let mut a = [[0.0; 3]; 3];
            let mut g = [0.0; 3];
            for p in 0..3 {
                for q in 0..3 {
                    a[p][q] = (0..3).map(|m| j[m][p] * j[m][q]).sum();
                }
                g[p] = -(0..3).map(|m| j[m][p] * r[m]).sum::<f64>();
            }
            let mut improved = false;
            for _ in 0..12 {
                let mut d = a;
                for (p, row) in d.iter_mut().enumerate() {
                    row[p] += mu * a[p][p].max(1e-12);
                }
                let Some(step) = solve3(d, g) else {
                    mu *= 8.0;
                    continue;
                };
                let cn = [c[0] + step[0], c[1] + step[1], c[2] + step[2]];
                let (rn, jn, en) = residual(cn);
                if en < err && cn.iter().all(|v| v.is_finite()) {
                    (c, r, j, err) = (cn, rn, jn, en);
                    mu = (mu / 8.0).max(1e-12);
                    improved = true;
                    break;
                }
                mu *= 8.0;
            }
            if !improved {
                break;
            }
        }
        (c, err.sqrt())
    }
}

/// Solves the 3×3 system `a x = b` by Gaussian elimination with partial
/// pivoting; `None` if it is singular.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3).max_by(|&p, &q| a[p][col].abs().total_cmp(&a[q][col].abs()))?;
        if a[piv][col].abs() <= 1e-300 || a[piv][col].is_nan() {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let pivot = a[col];
        for row in col + 1..3 {
            let f = a[row][col] / pivot[col];
            for (v, p) in a[row].iter_mut().zip(pivot).skip(col) {
                *v -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

// ---------------------------------------------------------------------------
// The coefficient table.

/// Table nodes per axis. Colours are addressed by their largest channel
/// (3 sub-tables), its value z, and the other two channels divided by it
/// (x, y). The fits themselves are exact to ΔE*ab 1e-3, so trilinear
/// interpolation is the only error left; at 32 nodes it measures, over
/// random colours, 5e-4 mean and 2.5e-3 worst in linear sRGB (ΔE*ab 0.05
/// and 0.25), where 24 nodes give about twice that.
pub const TABLE_RES: usize = 32;

/// Value of the largest channel at z-node `k`, from [`Z_DARK`] to 1,
/// spaced by a smoothstep so nodes crowd at both ends (the paper applies it
/// twice, to crowd them near 0, where its coefficients diverge; below
/// [`Z_DARK`] ours never need to).
pub fn z_node(k: usize) -> f32 {
    let u = k as f64 / (TABLE_RES - 1) as f64;
    let g = u * u * (3.0 - 2.0 * u);
    (f64::from(Z_DARK) + (1.0 - f64::from(Z_DARK)) * g) as f32
}

/// The sRGB colour whose coefficients table cell (`channel`, `k`, `j`, `i`)
/// holds: channel `channel` is [`z_node`]`(k)`; the next channel
/// (cyclically) is that times [`ratio_node`]`(i)`, the one after that times
/// [`ratio_node`]`(j)`.
pub fn table_cell_rgb(channel: usize, k: usize, j: usize, i: usize) -> Vec3 {
    let z = f64::from(z_node(k));
    let mut rgb = [0.0f64; 3];
    rgb[channel] = z;
    rgb[(channel + 1) % 3] = z * f64::from(ratio_node(i));
    rgb[(channel + 2) % 3] = z * f64::from(ratio_node(j));
    DVec3::from(rgb).as_vec3()
}

/// Ratio of a minor channel to the largest at x/y-node `i`: quadratic
/// from each end, so nodes crowd near 0 (saturated colours) and near 1
/// (near-greys and near-white), where the coefficients change fastest.
/// This halves the mean and cuts the worst interpolation error several
/// times compared with uniform nodes.
pub fn ratio_node(i: usize) -> f32 {
    let u = i as f64 / (TABLE_RES - 1) as f64;
    let r = if u < 0.5 {
        2.0 * u * u
    } else {
        1.0 - 2.0 * (1.0 - u) * (1.0 - u)
    };
    r as f32
}

/// Inverse of [`ratio_node`], in node units: `ratio_coord(ratio_node(i))`
/// is `i`.
fn ratio_coord(r: f32) -> f32 {
    let r = r.clamp(0.0, 1.0);
    let u = if r < 0.5 {
        (0.5 * r).sqrt()
    } else {
        1.0 - (0.5 * (1.0 - r)).sqrt()
    };
    u * (TABLE_RES - 1) as f32
}

/// The stored spectrum of a table cell (see [`table_cell_rgb`]).
pub fn table_cell(channel: usize, k: usize, j: usize, i: usize) -> RgbSigmoid {
    RgbSigmoid::from_coeffs(table().line(channel, j, i)[k])
}

/// Fits every cell of the table now rather than as colours need them (the table is otherwise
/// fitted lazily, one line of cells at a time), e.g. to time the whole fit.
pub fn init_table() {
    const R: usize = TABLE_RES;
    let t = table();
    for line in 0..3 * R * R {
        t.line(line / (R * R), (line / R) % R, line % R);
    }
}

/// The coefficient table, fitted lazily one z-line at a time.
///
/// Each (channel, x, y) line is walked along z from a mid-dark start outwards, each fit
/// starting from its neighbour's result: neighbouring colours have nearby optima, so
/// Gauss–Newton converges in a few steps and always to the same smooth family of solutions.
/// Lines do not depend on each other, so a line is fitted the first time a colour needs it
/// (a lookup reads at most four): a scene with a handful of colours fits a few dozen of the
/// 3,072 lines, about a millisecond, where the whole table took 80 ms at every spectral
/// render's start. The result is the same whichever thread or order fits a line.
struct Table {
    z: [f32; TABLE_RES],
    lines: Vec<OnceLock<[[f32; 3]; TABLE_RES]>>,
}

fn table() -> &'static Table {
    static T: OnceLock<Table> = OnceLock::new();
    T.get_or_init(|| Table {
        z: std::array::from_fn(z_node),
        lines: (0..3 * TABLE_RES * TABLE_RES)
            .map(|_| OnceLock::new())
            .collect(),
    })
}

/// Fits the z-line of cells for one (channel, y, x) line index.
fn fit_line(fitter: &Fitter, line: usize) -> [[f32; 3]; TABLE_RES] {
    const R: usize = TABLE_RES;
    let (channel, j, i) = (line / (R * R), (line / R) % R, line % R);
    let fit_at = |k: usize, c: [f64; 3]| {
        let rgb = table_cell_rgb(channel, k, j, i).as_dvec3();
        fitter.fit(rgb, c, FIT_MAX_ITERS_TABLE).0
    };
    let mut out = [[0.0f32; 3]; R];
    let start = R / 5;
    // Each fit starts from the secant extrapolation of the previous two
    // solutions along z, which saves about one Gauss–Newton step per cell.
    let mut walk = |ks: &mut dyn Iterator<Item = usize>, mut hist: Vec<(f64, [f64; 3])>| {
        for k in ks {
            let z = f64::from(z_node(k));
            let guess = match hist.as_slice() {
                [.., (z0, c0), (z1, c1)] => {
                    let f = (z - z1) / (z1 - z0);
                    std::array::from_fn(|n| c1[n] + (c1[n] - c0[n]) * f)
                }
                [.., (_, c1)] => *c1,
                [] => [0.0; 3],
            };
            let c = fit_at(k, guess);
            out[k] = c.map(|v| v as f32);
            hist.push((z, c));
        }
        hist
    };
    let up = walk(&mut (start..R), Vec::new());
    walk(&mut (0..start).rev(), vec![up[1], up[0]]);
    out
}

impl Table {
    /// The z-line of cells (channel, x = `i`, y = `j`), fitted on first use.
    fn line(&self, channel: usize, j: usize, i: usize) -> &[[f32; 3]; TABLE_RES] {
        let line = (channel * TABLE_RES + j) * TABLE_RES + i;
        self.lines[line].get_or_init(|| fit_line(fitter(), line))
    }

    /// Trilinear interpolation of the coefficients for a non-grey colour
    /// in [0, 1]³.
    fn lookup(&self, rgb: [f32; 3]) -> [f32; 3] {
        const R: usize = TABLE_RES;
        let mut channel = 0;
        for c in 1..3 {
            if rgb[c] > rgb[channel] {
                channel = c;
            }
        }
        let z = rgb[channel];
        let x = ratio_coord(rgb[(channel + 1) % 3] / z);
        let y = ratio_coord(rgb[(channel + 2) % 3] / z);
        let cell = |v: f32| {
            let i = (v.max(0.0) as usize).min(R - 2);
            (i, (v - i as f32).clamp(0.0, 1.0))
        };
        let (xi, dx) = cell(x);
        let (yi, dy) = cell(y);
        let zi = self.z.partition_point(|&n| n <= z).clamp(1, R - 1) - 1;
        let dz = ((z - self.z[zi]) / (self.z[zi + 1] - self.z[zi])).clamp(0.0, 1.0);
        let mut out = [0.0f32; 3];
        for (kz, wz) in [(zi, 1.0 - dz), (zi + 1, dz)] {
            for (ky, wy) in [(yi, 1.0 - dy), (yi + 1, dy)] {
                for (kx, wx) in [(xi, 1.0 - dx), (xi + 1, dx)] {
                    let w = wz * wy * wx;
                    if w != 0.0 {
                        let c = self.line(channel, ky, kx)[kz];
                        for (o, v) in out.iter_mut().zip(c) {
                            *o += w * v;
                        }
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tabulated_illuminant_is_d65_of_luminance_one() {
        // The 1 nm table against the 5 nm D65 interpolated directly, off and on the nodes.
        for k in 0..=4700 {
            let l = LAMBDA_MIN + k as f32 * 0.1;
            let got = RgbIlluminant::illuminant4([l; 4])[0];
            let want = d65(l) / D65_LUMINANCE;
            assert!(
                (got - want).abs() <= 2e-6 * want.max(1.0),
                "{l} nm: {got} vs {want}"
            );
        }
        assert_eq!(
            RgbIlluminant::illuminant4([359.0, 831.0, f32::NAN, 830.0])[..3],
            [0.0; 3]
        );
    }

    #[test]
    fn sigmoid_is_precise_and_saturates() {
        for x in [-1e3f32, -10.0, -0.3, 0.0, 0.7, 25.0] {
            let naive = 0.5 + f64::from(x) / (2.0 * (1.0 + f64::from(x).powi(2)).sqrt());
            let rel = (f64::from(sigmoid(x)) - naive).abs() / naive;
            assert!(rel < 1e-5, "{x}: {} vs {naive}", sigmoid(x));
        }
        assert_eq!(sigmoid(f32::INFINITY), 1.0);
        assert_eq!(sigmoid(f32::NEG_INFINITY), 0.0);
        assert_eq!(sigmoid(1e30), 1.0);
        assert_eq!(sigmoid(-1e30), 0.0);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let f = fitter();
        let c = [1.3, -2.1, 0.4];
        let (_, j) = f.eval(c);
        for col in 0..3 {
            // The sums run in f32, so the step must dwarf their rounding.
            let h = 1e-2;
            let (mut cp, mut cm) = (c, c);
            cp[col] += h;
            cm[col] -= h;
            let (lp, lm) = (f.eval(cp).0, f.eval(cm).0);
            for row in 0..3 {
                let fd = (lp[row] - lm[row]) / (2.0 * h);
                let tol = 2e-3 * (1.0 + fd.abs());
                assert!(
                    (fd - j[row][col]).abs() < tol,
                    "{row} {col}: {fd} vs {}",
                    j[row][col]
                );
            }
        }
    }

    #[test]
    fn grey_is_exact() {
        for v in [0.0f32, 0.01, 0.18, 0.5, 0.9, 1.0] {
            let s = RgbSigmoid::grey(v);
            for l in [360.0, 500.0, 830.0] {
                assert!((s.eval(l) - v).abs() < 1e-6, "{v}");
            }
        }
    }

    #[test]
    fn nm_coefficients_describe_the_same_curve() {
        let s = RgbSigmoid::from_coeffs([-3.0, 1.5, 0.25]);
        let [a, b, c] = s.coeffs_nm();
        for l in [360.0f32, 480.0, 595.0, 700.0, 830.0] {
            let l64 = f64::from(l);
            let x = (a * l64 + b) * l64 + c;
            let v = (0.5 + x / (2.0 * (1.0 + x * x).sqrt())) as f32;
            assert!((v - s.eval(l)).abs() < 1e-5);
        }
    }

    #[test]
    fn solve3_solves() {
        let a = [[2.0, 1.0, 0.0], [0.0, 0.0, 3.0], [1.0, 4.0, 1.0]];
        let x = solve3(a, [3.0, 6.0, 7.0]).unwrap();
        for (v, e) in x.iter().zip([1.0, 1.0, 2.0]) {
            assert!((v - e).abs() < 1e-12);
        }
        assert!(
            solve3(
                [[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]],
                [1.0; 3]
            )
            .is_none()
        );
    }
}
