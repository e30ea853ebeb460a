//! The per-path wavelength sample and the spectral values carried with it.

use std::ops::{
    Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign,
};

use super::{LAMBDA_MAX, LAMBDA_MIN, N_LAMBDA};

/// Width of the sech² lobe of the visible-wavelength pdf, 1/nm.
///
/// The pdf ∝ cosh⁻²(A(λ − MU)) follows pbrt-v4's `SampleVisibleWavelengths`
/// (Pharr, Jakob & Humphreys, 4th ed., 2023): it roughly follows the
/// luminous efficiency so noise is spent where the eye sees it, yet never
/// reaches zero, so the deep-red and violet ends stay unbiased.
pub(super) const VIS_A: f32 = 0.0072;
/// Centre of the visible-wavelength pdf, nm.
pub(super) const VIS_MU: f32 = 538.0;
/// tanh(A·(LAMBDA_MIN − MU)) and tanh(A·(LAMBDA_MAX − MU)): the CDF of the
/// sech² pdf is an affine map of tanh, so these bound its range.
pub(super) const VIS_T0: f32 = -0.856_910_6;
pub(super) const VIS_T1: f32 = 0.970_591_4;
/// A / (T1 − T0): normalises the pdf to integrate to 1 over the range.
pub(super) const VIS_NORM: f32 = VIS_A / (VIS_T1 - VIS_T0);

/// The wavelengths one path carries and the density each was drawn with.
///
/// `pdf[i] == 0` marks a terminated wavelength (see
/// [`Wavelengths::terminate_secondary`]); estimators must skip it.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Wavelengths {
    /// Wavelengths, nm. `lambda[0]` is the hero.
    pub lambda: [f32; N_LAMBDA],
    /// Density of each wavelength, 1/nm.
    pub pdf: [f32; N_LAMBDA],
}

impl Wavelengths {
    /// Hero wavelength from `u` ∈ [0, 1) with [`Wavelengths::visible_pdf`],
    /// the other three from `u + i/4` (wrapped) through the same inverse CDF.
    ///
    /// Rotating in the primary-sample domain rather than in λ keeps every
    /// wavelength distributed by the same importance pdf, so each `pdf[i]`
    /// is simply `visible_pdf(lambda[i])`, and the four are stratified in
    /// CDF space as hero sampling intends.
    #[inline(always)]
    pub fn sample_visible(u: f32) -> Self {
        let u = if u.is_finite() {
            u.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let t: [f32; N_LAMBDA] = std::array::from_fn(|i| {
            let mut ui = u + i as f32 / N_LAMBDA as f32;
            if ui >= 1.0 {
                ui -= 1.0;
            }
            VIS_T0 + ui * (VIS_T1 - VIS_T0)
        });
        // All four inverse CDFs in one pass of a branch-free atanh (libm's, one lane at a
        // time, was a tenth of what spectral transport adds to a Cornell box path).
        let at = atanh4(t);
        // With t the CDF's tanh value, cosh²(A(λ − μ)) = 1/(1 − t²): the pdf needs no
        // transcendental beyond the inverse CDF's one.
        Self {
            lambda: std::array::from_fn(|i| (VIS_MU + at[i] / VIS_A).clamp(LAMBDA_MIN, LAMBDA_MAX)),
            pdf: t.map(|t| VIS_NORM * (1.0 - t * t)),
        }
    }

    /// Density of [`sample_visible_wavelength`] at `lambda` nm; zero outside
    /// [`LAMBDA_MIN`]..=[`LAMBDA_MAX`].
    pub fn visible_pdf(lambda: f32) -> f32 {
        if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
            return 0.0;
        }
        let c = (VIS_A * (lambda - VIS_MU)).cosh();
        VIS_NORM / (c * c)
    }

    /// Uniform wavelengths (stratified like [`Wavelengths::sample_visible`]);
    /// a reference for tests and for spectra whose importance is unknown.
    pub fn sample_uniform(u: f32) -> Self {
        let u = if u.is_finite() {
            u.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let range = LAMBDA_MAX - LAMBDA_MIN;
        let mut lambda = [0.0; N_LAMBDA];
        for (i, l) in lambda.iter_mut().enumerate() {
            let mut ui = u + i as f32 / N_LAMBDA as f32;
            if ui >= 1.0 {
                ui -= 1.0;
            }
            *l = (LAMBDA_MIN + ui * range).min(LAMBDA_MAX);
        }
        Self {
            lambda,
            pdf: [1.0 / range; N_LAMBDA],
        }
    }

    /// Keeps only the hero wavelength, for a wavelength-dependent event such
    /// as refraction through a dispersive interface, after which the four
    /// wavelengths no longer share one path.
    ///
    /// The secondaries' pdfs become 0 (so [`to_xyz`](super::to_xyz) skips
    /// them) and the hero's pdf is divided by [`N_LAMBDA`]. The estimator
    /// averages over N wavelengths, so this makes the hero's term count N
    /// times: the result is the unbiased single-wavelength estimate
    /// L(λ₀)·cmf(λ₀)/p(λ₀) instead of a quarter of it (pbrt-v4's
    /// `TerminateSecondary`). Calling it again does nothing.
    #[inline(always)]
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for p in &mut self.pdf[1..] {
            *p = 0.0;
        }
        self.pdf[0] /= N_LAMBDA as f32;
    }

    /// True once [`Wavelengths::terminate_secondary`] has run.
    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

/// atanh of four values in (−1, 1), as ½·ln((1 + t)/(1 − t)) with the logarithm split into
/// exponent and mantissa m ∈ [√½, √2): ln m = 2·artanh(s), s = (m − 1)/(m + 1), |s| ≤ 0.172,
/// whose odd series to s⁹ leaves a relative error below 4·10⁻¹⁰, far under f32's ulp. Lanes
/// are independent and branch-free, so the loop vectorises.
#[inline(always)]
fn atanh4(t: [f32; N_LAMBDA]) -> [f32; N_LAMBDA] {
    let mut out = [0.0; N_LAMBDA];
    for i in 0..N_LAMBDA {
        let x = (1.0 + t[i]) / (1.0 - t[i]);
        let bits = x.to_bits();
        // Exponent relative to the mantissa range [√½, √2): shift by √½'s bit pattern.
        let k = ((bits.wrapping_sub(0x3f35_04f3)) as i32) >> 23;
        let m = f32::from_bits(bits.wrapping_sub((k as u32) << 23));
        let s = (m - 1.0) / (m + 1.0);
        let s2 = s * s;
        let series = 1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 / 9.0)));
        let ln = k as f32 * std::f32::consts::LN_2 + 2.0 * s * series;
        out[i] = 0.5 * ln;
    }
    out
}

/// Inverse CDF of the visible-wavelength pdf: `u` ∈ [0, 1] → λ in nm.
#[inline(always)]
pub fn sample_visible_wavelength(u: f32) -> f32 {
    let t = VIS_T0 + u * (VIS_T1 - VIS_T0);
    (VIS_MU + t.atanh() / VIS_A).clamp(LAMBDA_MIN, LAMBDA_MAX)
}

/// Values of a spectral quantity at the N wavelengths of a [`Wavelengths`].
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SampledSpectrum(pub [f32; N_LAMBDA]);

impl SampledSpectrum {
    /// All zeros.
    pub const ZERO: Self = Self([0.0; N_LAMBDA]);
    /// All ones.
    pub const ONE: Self = Self([1.0; N_LAMBDA]);

    /// The same value at every wavelength.
    pub const fn splat(v: f32) -> Self {
        Self([v; N_LAMBDA])
    }

    /// `f` evaluated at each wavelength of `w`.
    pub fn from_fn(w: &Wavelengths, f: impl Fn(f32) -> f32) -> Self {
        Self(w.lambda.map(f))
    }

    /// Largest value.
    pub fn max_value(&self) -> f32 {
        self.0.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }

    /// Smallest value.
    pub fn min_value(&self) -> f32 {
        self.0.iter().copied().fold(f32::INFINITY, f32::min)
    }

    /// Mean of the values.
    pub fn average(&self) -> f32 {
        self.0.iter().sum::<f32>() / N_LAMBDA as f32
    }

    /// True if every value is exactly zero.
    pub fn is_zero(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }

    /// True if any value is NaN.
    pub fn has_nan(&self) -> bool {
        self.0.iter().any(|v| v.is_nan())
    }

    /// Elementwise maximum.
    pub fn max(self, o: Self) -> Self {
        self.zip(o, f32::max)
    }

    /// Elementwise minimum.
    pub fn min(self, o: Self) -> Self {
        self.zip(o, f32::min)
    }

    /// Elementwise division with x/0 = 0, for ratios of throughput and pdf
    /// where a zero pdf means "no contribution", not infinity.
    pub fn safe_div(self, o: Self) -> Self {
        self.zip(o, |a, b| if b != 0.0 { a / b } else { 0.0 })
    }

    /// `f` applied to each value.
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Self(self.0.map(f))
    }

    /// Elementwise exponential (Beer–Lambert transmittance).
    pub fn exp(self) -> Self {
        self.map(f32::exp)
    }

    /// Elementwise square root.
    pub fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }

    /// Values clamped to [lo, hi].
    pub fn clamp(self, lo: f32, hi: f32) -> Self {
        self.map(|v| v.clamp(lo, hi))
    }

    fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        let mut r = self.0;
        for (a, b) in r.iter_mut().zip(o.0) {
            *a = f(*a, b);
        }
        Self(r)
    }
}

impl From<f32> for SampledSpectrum {
    fn from(v: f32) -> Self {
        Self::splat(v)
    }
}

impl Index<usize> for SampledSpectrum {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}

impl IndexMut<usize> for SampledSpectrum {
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i]
    }
}

impl Neg for SampledSpectrum {
    type Output = Self;
    fn neg(self) -> Self {
        self.map(|v| -v)
    }
}

macro_rules! elementwise_op {
    ($tr:ident, $f:ident, $tra:ident, $fa:ident, $op:tt) => {
        impl $tr for SampledSpectrum {
            type Output = Self;
            fn $f(self, o: Self) -> Self {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl $tr<f32> for SampledSpectrum {
            type Output = Self;
            fn $f(self, o: f32) -> Self {
                self.map(|a| a $op o)
            }
        }
        impl $tr<SampledSpectrum> for f32 {
            type Output = SampledSpectrum;
            fn $f(self, o: SampledSpectrum) -> SampledSpectrum {
                o.map(|b| self $op b)
            }
        }
        impl $tra for SampledSpectrum {
            fn $fa(&mut self, o: Self) {
                *self = *self $op o;
            }
        }
        impl $tra<f32> for SampledSpectrum {
            fn $fa(&mut self, o: f32) {
                *self = *self $op o;
            }
        }
    };
}

elementwise_op!(Add, add, AddAssign, add_assign, +);
elementwise_op!(Sub, sub, SubAssign, sub_assign, -);
elementwise_op!(Mul, mul, MulAssign, mul_assign, *);
elementwise_op!(Div, div, DivAssign, div_assign, /);

/// What light transport multiplies along a path: RGB triples ([`glam::Vec3`]) or spectral
/// samples ([`SampledSpectrum`]). The integrator is generic over it, so RGB scenes run
/// exactly the arithmetic they always did.
pub trait Channels:
    Copy
    + std::fmt::Debug
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + AddAssign
    + Mul<Output = Self>
    + MulAssign
    + Mul<f32, Output = Self>
    + MulAssign<f32>
    + Div<f32, Output = Self>
    + DivAssign<f32>
{
    /// Zero in every channel.
    const ZERO: Self;
    /// One in every channel.
    const ONE: Self;
    /// Largest channel value.
    fn max_element(self) -> f32;
    /// Whether every channel is finite.
    fn is_finite(self) -> bool;
}

impl Channels for glam::Vec3 {
    const ZERO: Self = glam::Vec3::ZERO;
    const ONE: Self = glam::Vec3::ONE;
    #[inline]
    fn max_element(self) -> f32 {
        glam::Vec3::max_element(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        glam::Vec3::is_finite(self)
    }
}

impl Channels for SampledSpectrum {
    const ZERO: Self = SampledSpectrum::ZERO;
    const ONE: Self = SampledSpectrum::ONE;
    #[inline]
    fn max_element(self) -> f32 {
        self.max_value()
    }
    #[inline]
    fn is_finite(self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdf_constants_match_their_definition() {
        let t0 = (f64::from(VIS_A) * (f64::from(LAMBDA_MIN) - f64::from(VIS_MU))).tanh();
        let t1 = (f64::from(VIS_A) * (f64::from(LAMBDA_MAX) - f64::from(VIS_MU))).tanh();
        assert!((t0 - f64::from(VIS_T0)).abs() < 1e-7);
        assert!((t1 - f64::from(VIS_T1)).abs() < 1e-7);
    }

    #[test]
    fn fast_atanh_matches_f64_over_the_cdf_range() {
        // Over the whole range the sampler uses: absolute error below 2e-7, i.e. below
        // 3e-5 nm once divided by A, and relative error below 1e-6 away from 0.
        let n = 20_000;
        for k in 0..=n {
            let t0 = VIS_T0 + (VIS_T1 - VIS_T0) * k as f32 / n as f32;
            let t = [t0, -t0 * 0.5, t0 * 0.25, 0.999 * t0];
            let got = atanh4(t);
            for i in 0..N_LAMBDA {
                let want = f64::from(t[i]).atanh();
                let err = (f64::from(got[i]) - want).abs();
                assert!(
                    err < 2e-7 || err < 1e-6 * want.abs(),
                    "atanh({}) = {} vs {want}",
                    t[i],
                    got[i]
                );
            }
        }
    }

    #[test]
    fn sampling_inverts_the_cdf() {
        // CDF(λ) = (tanh(A(λ−μ)) − T0)/(T1 − T0); sampling must invert it.
        for k in 0..=100 {
            let u = k as f32 / 100.0;
            let l = sample_visible_wavelength(u);
            let cdf = ((VIS_A * (l - VIS_MU)).tanh() - VIS_T0) / (VIS_T1 - VIS_T0);
            assert!((cdf - u).abs() < 2e-4, "u {u} λ {l} cdf {cdf}");
        }
    }

    #[test]
    fn terminate_is_idempotent() {
        let mut w = Wavelengths::sample_visible(0.3);
        let hero = w.pdf[0];
        assert!(!w.secondary_terminated());
        w.terminate_secondary();
        w.terminate_secondary();
        assert!(w.secondary_terminated());
        assert_eq!(w.pdf[0], hero / N_LAMBDA as f32);
    }

    #[test]
    fn arithmetic() {
        let a = SampledSpectrum([1.0, 2.0, 3.0, 4.0]);
        let b = SampledSpectrum::splat(2.0);
        assert_eq!(a + b, SampledSpectrum([3.0, 4.0, 5.0, 6.0]));
        assert_eq!(a * 2.0, a * b);
        assert_eq!((a / b).0, [0.5, 1.0, 1.5, 2.0]);
        assert_eq!(2.0 - a, SampledSpectrum([1.0, 0.0, -1.0, -2.0]));
        assert_eq!(a.max_value(), 4.0);
        assert_eq!(a.average(), 2.5);
        assert_eq!(a.safe_div(SampledSpectrum::ZERO), SampledSpectrum::ZERO);
        let mut c = a;
        c *= b;
        c -= a;
        assert_eq!(c, a);
        assert!(SampledSpectrum::ZERO.is_zero() && !a.is_zero());
    }
}
