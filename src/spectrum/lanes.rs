//! The per-path spectral functions over lanes: wavelength sampling, the RGB spectra and the
//! illuminant table, one lane per path. (The film's XYZ → sRGB step runs per ended path,
//! through the scalar functions: plain loads beat a packet's gathers there.) Each computes what its scalar counterpart computes, operation for operation (no
//! fused multiply-add where the scalar code has none), so a path's numbers do not depend on
//! the width it runs at; `tests` checks them against the scalar functions bit for bit.

use super::rgb2spec::{ILLUMINANT_1NM, INV_T_HALF, T_CENTRE};
use super::sampled::{VIS_A, VIS_MU, VIS_NORM, VIS_T0, VIS_T1};
use super::{LAMBDA_MAX, LAMBDA_MIN, N_LAMBDA, Wavelengths};
use crate::simd::{Float, Mask, UInt};

/// Each lane's [`Wavelengths`]: `lambda[k]` and `pdf[k]` hold wavelength `k` of every lane.
#[derive(Clone, Copy, Debug)]
pub struct LaneWavelengths<F> {
    /// Wavelengths, nm; `lambda[0]` is the hero.
    pub lambda: [F; N_LAMBDA],
    /// Density of each wavelength, 1/nm.
    pub pdf: [F; N_LAMBDA],
    /// The unit-luminance D65 ([`illuminant`]) at each wavelength. RGB emitters multiply by
    /// it at every evaluation, and a path's wavelengths never change: looked up once when
    /// they are drawn, not by two gathers per wavelength at every emitter.
    pub illum: [F; N_LAMBDA],
}

impl<F: Float> LaneWavelengths<F> {
    /// Every wavelength and pdf 0 (a placeholder to be overwritten).
    #[inline(always)]
    pub fn zero() -> Self {
        LaneWavelengths {
            lambda: [F::zero(); N_LAMBDA],
            pdf: [F::zero(); N_LAMBDA],
            illum: [F::zero(); N_LAMBDA],
        }
    }

    /// Wavelengths `lambda` with densities `pdf`, and the illuminant at each.
    #[inline(always)]
    pub fn new(lambda: [F; N_LAMBDA], pdf: [F; N_LAMBDA]) -> Self {
        let mut illum = [F::zero(); N_LAMBDA];
        for (i, &l) in illum.iter_mut().zip(&lambda) {
            *i = illuminant(l);
        }
        LaneWavelengths { lambda, pdf, illum }
    }

    /// [`Wavelengths::sample_visible`] in every lane.
    #[inline(always)]
    pub fn sample_visible(u: F) -> Self {
        let u = F::select(u.is_finite(), u.clamp(F::zero(), F::one()), F::zero());
        let (lo, hi) = (F::splat(LAMBDA_MIN), F::splat(LAMBDA_MAX));
        let (mut lambda, mut pdf) = ([F::zero(); N_LAMBDA], [F::zero(); N_LAMBDA]);
        for k in 0..N_LAMBDA {
            let uk = u + F::splat(k as f32 / N_LAMBDA as f32);
            let uk = F::select(uk.ge(F::one()), uk - F::one(), uk);
            let t = F::splat(VIS_T0) + uk * F::splat(VIS_T1 - VIS_T0);
            lambda[k] = (F::splat(VIS_MU) + atanh(t) / F::splat(VIS_A)).clamp(lo, hi);
            pdf[k] = F::splat(VIS_NORM) * (F::one() - t * t);
        }
        Self::new(lambda, pdf)
    }

    /// Every lane carries the one wavelength `lambda` with pdf 1 (a monochromatic render).
    #[inline(always)]
    pub fn monochromatic(lambda: f32) -> Self {
        Self::new(
            [F::splat(lambda); N_LAMBDA],
            [F::one(), F::zero(), F::zero(), F::zero()],
        )
    }

    /// `a` in lanes where `m` is set, else `b`.
    #[inline(always)]
    pub fn select(m: F::Mask, a: Self, b: Self) -> Self {
        let mut w = a;
        for k in 0..N_LAMBDA {
            w.lambda[k] = F::select(m, a.lambda[k], b.lambda[k]);
            w.pdf[k] = F::select(m, a.pdf[k], b.pdf[k]);
            w.illum[k] = F::select(m, a.illum[k], b.illum[k]);
        }
        w
    }

    /// Lane `i` as one path's wavelengths.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Wavelengths {
        let (l, p) = (&self.lambda, &self.pdf);
        Wavelengths {
            lambda: [l[0].lane(i), l[1].lane(i), l[2].lane(i), l[3].lane(i)],
            pdf: [p[0].lane(i), p[1].lane(i), p[2].lane(i), p[3].lane(i)],
        }
    }

    /// The lanes whose secondary wavelengths are terminated.
    #[inline(always)]
    pub fn secondary_terminated(&self) -> F::Mask {
        let mut m = self.pdf[1].eq(F::zero());
        for p in &self.pdf[2..] {
            m &= p.eq(F::zero());
        }
        m
    }

    /// [`Wavelengths::terminate_secondary`] in the lanes of `m`; returns the lanes it changed
    /// (those not terminated before), whose secondary throughput the caller zeroes.
    #[inline(always)]
    pub fn terminate_secondary(&mut self, m: F::Mask) -> F::Mask {
        let m = m.and_not(self.secondary_terminated());
        if m.none() {
            return m;
        }
        self.pdf[0] = F::select(m, self.pdf[0] / F::splat(N_LAMBDA as f32), self.pdf[0]);
        for p in &mut self.pdf[1..] {
            *p = F::select(m, F::zero(), *p);
        }
        m
    }
}

/// The branch-free atanh of the scalar wavelength sampler (½·ln((1 + t)/(1 − t)), the
/// logarithm split into exponent and a mantissa in [√½, √2) and a series to s⁹), over lanes.
#[inline(always)]
fn atanh<F: Float>(t: F) -> F {
    let x = (F::one() + t) / (F::one() - t);
    let bits = x.to_bits();
    let k = bits.wrapping_sub(F::U32::splat(0x3f35_04f3)).srai::<23>();
    let m = F::from_bits(bits.wrapping_sub(k.shli::<23>()));
    let s = (m - F::one()) / (m + F::one());
    let s2 = s * s;
    let c = |v: f32| F::splat(v);
    let series =
        F::one() + s2 * (c(1.0 / 3.0) + s2 * (c(1.0 / 5.0) + s2 * (c(1.0 / 7.0) + s2 / c(9.0))));
    let ln = k.i32_to_f32() * c(std::f32::consts::LN_2) + c(2.0) * s * series;
    c(0.5) * ln
}

/// [`super::RgbSigmoid::eval4`] at wavelength `lambda` of every lane, each lane with its own
/// coefficients `c` and scale: scale·σ(c₀t² + c₁t + c₂), t the normalised wavelength.
#[inline(always)]
pub fn sigmoid<F: Float>(c: &[F; 3], scale: F, lambda: F) -> F {
    let t = (lambda - F::splat(T_CENTRE)) * F::splat(INV_T_HALF);
    let x = (c[0] * t + c[1]) * t + c[2];
    // The cancellation-free form: the tail 1/(2r(r + |x|)) on the dark side.
    let a = x.abs();
    let r = (F::one() + a * a).sqrt();
    let tail = F::one() / (F::splat(2.0) * r * (r + a));
    let s = F::select(x.lt(F::zero()), tail, F::one() - tail);
    s * scale
}

/// [`super::RgbIlluminant::illuminant4`] (D65 of luminance 1) at wavelength `lambda` of every
/// lane: linear interpolation in its 1 nm table from [`LAMBDA_MIN`], zero outside the table, as
/// the scalar lookup does.
#[inline(always)]
pub fn illuminant<F: Float>(lambda: F) -> F {
    let rows = ILLUMINANT_1NM.len();
    let x = lambda - F::splat(LAMBDA_MIN);
    let inside = x.ge(F::zero()) & x.le(F::splat((rows - 1) as f32));
    let x = F::select(inside, x, F::zero());
    let fi = x.floor().min(F::splat((rows - 2) as f32));
    let f = x - fi;
    let i = fi.to_i32_bits();
    let a = F::gather(&ILLUMINANT_1NM, i);
    let b = F::gather(&ILLUMINANT_1NM, i.wrapping_add(F::U32::splat(1)));
    F::select(inside, a + (b - a) * f, F::zero())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::PortableF32;
    use crate::spectrum::{RgbIlluminant, RgbSigmoid};
    use glam::Vec3;

    type P8 = PortableF32<8>;

    /// Arguments covering the sampler's range densely, its ends, and hostile values.
    fn us() -> Vec<f32> {
        let mut v: Vec<f32> = (0..20_000).map(|i| i as f32 / 20_000.0).collect();
        v.extend([
            0.0,
            -0.0,
            1.0,
            f32::from_bits(0x3f7f_ffff),
            f32::MIN_POSITIVE,
            1e-40,
            -1.0,
            2.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ]);
        v
    }

    fn bits(w: &Wavelengths) -> [u32; 8] {
        std::array::from_fn(|i| {
            if i < 4 {
                w.lambda[i].to_bits()
            } else {
                w.pdf[i - 4].to_bits()
            }
        })
    }

    #[test]
    fn wavelength_sampling_matches_the_scalar_sampler_bit_for_bit() {
        for chunk in us().chunks(8) {
            let u = P8::from_fn(|i| chunk[i % chunk.len()]);
            let lanes = LaneWavelengths::sample_visible(u);
            for i in 0..8 {
                let want = Wavelengths::sample_visible(chunk[i % chunk.len()]);
                assert_eq!(bits(&lanes.lane(i)), bits(&want), "u = {}", u.lane(i));
                let one = LaneWavelengths::<f32>::sample_visible(u.lane(i)).lane(0);
                assert_eq!(bits(&one), bits(&want));
                // The stored illuminant is the path's D65, as an emitter would look it up.
                let d65 = RgbIlluminant::illuminant4(want.lambda);
                for (k, d) in d65.iter().enumerate() {
                    assert_eq!(lanes.illum[k].lane(i).to_bits(), d.to_bits());
                }
            }
        }
    }

    #[test]
    fn termination_matches_the_scalar_rule_and_is_idempotent() {
        let u = P8::from_fn(|i| i as f32 / 8.0);
        let mut lanes = LaneWavelengths::sample_visible(u);
        let m = crate::simd::PortableMask::<8>::from_fn(|i| i % 2 == 0);
        let changed = lanes.terminate_secondary(m);
        assert_eq!(changed.bits(), m.bits());
        assert_eq!(
            lanes.terminate_secondary(m).bits(),
            0,
            "a second call changes nothing"
        );
        for i in 0..8 {
            let mut want = Wavelengths::sample_visible(u.lane(i));
            if i % 2 == 0 {
                want.terminate_secondary();
            }
            assert_eq!(bits(&lanes.lane(i)), bits(&want));
        }
    }

    fn lambdas() -> Vec<f32> {
        let mut v: Vec<f32> = (0..=47_000).map(|i| 360.0 + i as f32 * 0.01).collect();
        v.extend([
            359.999,
            830.0,
            830.001,
            0.0,
            -1.0,
            1e9,
            f32::INFINITY,
            f32::NAN,
        ]);
        v
    }

    #[test]
    fn the_illuminant_table_matches_the_scalar_lookup_bit_for_bit() {
        let ls = lambdas();
        for chunk in ls.chunks(8) {
            let l = P8::from_fn(|i| chunk[i % chunk.len()]);
            let ill = illuminant(l);
            for i in 0..8 {
                let x = l.lane(i);
                let want = RgbIlluminant::illuminant4([x; 4])[0];
                assert_eq!(ill.lane(i).to_bits(), want.to_bits(), "illuminant at {x}");
            }
        }
    }

    #[test]
    fn sigmoids_match_the_scalar_spectra_bit_for_bit() {
        let colours = [
            Vec3::new(0.8, 0.1, 0.1),
            Vec3::new(0.02, 0.3, 0.01),
            Vec3::new(0.5, 0.5, 0.5),
            Vec3::ZERO,
            Vec3::ONE,
            Vec3::new(0.2, 0.9, 0.99),
        ];
        let ls = lambdas();
        for rgb in colours {
            let s = RgbSigmoid::from_rgb(rgb);
            let c = s.coeffs().map(P8::splat);
            for chunk in ls.chunks(4) {
                let lam: [f32; 4] = std::array::from_fn(|i| chunk[i % chunk.len()]);
                let want = s.eval4(lam);
                for (k, &x) in lam.iter().enumerate() {
                    let got = sigmoid(&c, P8::splat(s.scale()), P8::splat(x)).lane(3);
                    assert_eq!(got.to_bits(), want[k].to_bits(), "{rgb} at {x}");
                }
            }
        }
    }
}
