//! The medium's estimators over lanes: the one implementation every width runs (per lane or
//! over lanes), so a lane's medium events are those of width 1.
//!
//! The f64 functions of the parent module ([`super::sample_free_flight`] and its kin) stay as
//! the accurate statement of the same estimators, against which these are tested. Here
//! everything is f32, so the ratios of exponentials in the free-flight weights are taken
//! relative to the largest factor (`e_k = exp(−(τ_k − τ_ref))`, τ = σt·t) instead of as raw
//! transmittances: the raw factors span hundreds of orders of magnitude between a dense and a
//! clear channel, the relative ones stay in [e⁻¹⁰⁴, 1] wherever the estimator can land.

use crate::simd::{Float, Mask, V3, math};

/// Transmittance `exp(−σt·d)` per channel with `0·∞ = 0`: an empty channel transmits
/// everything over any distance and no distance (`d ≤ 0`) transmits everything; NaN
/// propagates.
#[inline(always)]
pub fn transmittance<F: Float, const N: usize>(sigma_t: &[F; N], d: F) -> [F; N] {
    let none = d.le(F::zero());
    // Loops here, not `array::from_fn`: its closures are not inlined into the lane kernels.
    let mut tr = [F::one(); N];
    for k in 0..N {
        let s = sigma_t[k];
        tr[k] = F::select(none | s.eq(F::zero()), F::one(), math::exp(-(s * d)));
    }
    tr
}

/// Channel-selection probabilities proportional to `beta`, its negative or non-finite
/// entries counted as 0; uniform when that leaves nothing (see
/// [`super::channel_probabilities`]).
#[inline(always)]
pub fn channel_probabilities<F: Float, const N: usize>(beta: &[F; N]) -> [F; N] {
    let mut clean = [F::zero(); N];
    for k in 0..N {
        let b = beta[k];
        clean[k] = F::select(b.is_finite() & b.gt(F::zero()), b, F::zero());
    }
    let mut sum = clean[0];
    for &c in &clean[1..] {
        sum += c;
    }
    let ok = sum.gt(F::zero()) & sum.is_finite();
    let uniform = F::splat(1.0 / N as f32);
    let mut p = [F::zero(); N];
    for k in 0..N {
        p[k] = F::select(ok, clean[k] / sum, uniform);
    }
    p
}

/// A free-flight sample per lane.
#[derive(Clone, Copy, Debug)]
pub struct FreeFlight<F: Float, const N: usize> {
    /// Lanes that scatter at `t` (the others pass their segment's end).
    pub scatter: F::Mask,
    /// Distance to the scattering event along the ray (meaningful where `scatter` is set).
    pub t: F,
    /// σs·Tr(t) / pdf(t) where scattering, Tr(t_max) / P(pass) where passing.
    pub weight: [F; N],
}

/// Ratio `num / den` clamped to f32's range, 0 where `num` is 0 or `den` is not positive:
/// as [`super::distance`]'s `to_f32`, a weight of f32::MAX can only come from an event of
/// (numerically) zero probability, and must give 0, not NaN, against a zero throughput.
#[inline(always)]
fn ratio<F: Float>(num: F, den: F) -> F {
    let r = (num / den).min(F::splat(f32::MAX));
    F::select(num.eq(F::zero()) | !den.gt(F::zero()), F::zero(), r)
}

/// [`super::sample_free_flight`] over lanes: channel `c` chosen with `u_channel` among the
/// [`channel_probabilities`] of `beta`, `t = −ln(1 − u) / σt_c` (∞ for an empty channel),
/// and the one-sample MIS weights over channels.
#[inline(always)]
pub fn sample_free_flight<F: Float, const N: usize>(
    sigma_s: &[F; N],
    sigma_t: &[F; N],
    t_max: F,
    u_channel: F,
    u: F,
    beta: &[F; N],
) -> FreeFlight<F, N> {
    let p = channel_probabilities(beta);
    // The first eligible channel whose running sum passes u; rounding that leaves u at or
    // above the total gives the top end to the last eligible channel.
    let (mut acc, mut st_c, mut st_last) = (F::zero(), F::zero(), F::zero());
    let mut found = F::Mask::splat(false);
    for k in 0..N {
        let elig = p[k].gt(F::zero());
        acc += F::select(elig, p[k], F::zero());
        let pick = elig & u_channel.lt(acc) & !found;
        st_c = F::select(pick, sigma_t[k], st_c);
        st_last = F::select(elig, sigma_t[k], st_last);
        found |= pick;
    }
    let st_c = F::select(found, st_c, st_last);
    let t = F::select(
        st_c.gt(F::zero()),
        -math::ln_1p(-u) / st_c,
        F::splat(f32::INFINITY),
    );
    let scatter = t.lt(t_max);
    // Scattering: every τ_k is finite (t < t_max), and e_k = exp(−(τ_k − τ_min)) ≤ 1. The
    // sampled channel's own term keeps the denominator ≥ p_c σt_c e^(−τ_c), and
    // τ_c = −ln(1 − u) ≤ 17 for f32's u.
    let ts = F::select(scatter, t, F::zero());
    let mut tau = [F::zero(); N];
    for k in 0..N {
        tau[k] = sigma_t[k] * ts;
    }
    let mut tau_min = tau[0];
    for &x in &tau[1..] {
        tau_min = tau_min.min(x);
    }
    let mut e = [F::zero(); N];
    let mut pdf = F::zero();
    for k in 0..N {
        e[k] = math::exp(tau_min - tau[k]);
        pdf += p[k] * sigma_t[k] * e[k];
    }
    // Passing: τ_k = σt_k·t_max with 0·∞ = 0, relative to the smallest τ of an eligible
    // channel (finite: the sampled channel passed, so τ_c ≤ −ln(1 − u)). Channels of zero
    // probability may exceed 1 there, which the clamp in `ratio` bounds.
    let tm = F::select(scatter, F::zero(), t_max);
    let mut tau_p = [F::zero(); N];
    let mut tau_ref = F::splat(f32::INFINITY);
    for k in 0..N {
        let s = sigma_t[k];
        tau_p[k] = F::select(s.eq(F::zero()) | tm.le(F::zero()), F::zero(), s * tm);
        tau_ref = F::select(p[k].gt(F::zero()), tau_ref.min(tau_p[k]), tau_ref);
    }
    // exp(finite − ∞) = 0: that channel transmits nothing.
    let mut e_p = [F::zero(); N];
    let mut pass = F::zero();
    for k in 0..N {
        e_p[k] = math::exp(tau_ref - tau_p[k]);
        pass += p[k] * e_p[k];
    }
    let mut weight = [F::zero(); N];
    for k in 0..N {
        weight[k] = F::select(scatter, ratio(sigma_s[k] * e[k], pdf), ratio(e_p[k], pass));
    }
    FreeFlight { scatter, t, weight }
}

/// [`super::free_flight_pdf`] over lanes: `Σ_c p_c σt_c Tr_c(t)`, 0 for t < 0.
#[inline(always)]
pub fn free_flight_pdf<F: Float, const N: usize>(sigma_t: &[F; N], t: F, beta: &[F; N]) -> F {
    let p = channel_probabilities(beta);
    let tr = transmittance(sigma_t, t);
    let mut pdf = F::zero();
    for k in 0..N {
        pdf += p[k] * sigma_t[k] * tr[k];
    }
    F::select(t.lt(F::zero()), F::zero(), pdf)
}

/// Henyey–Greenstein from `1 − cos θ` and `1 + cos θ` (see [`super::hg_phase`]); `g` must
/// already be clamped to ±[`super::HG_G_MAX`].
#[inline(always)]
fn hg_from_parts<F: Float>(one_minus_cos: F, one_plus_cos: F, g: F) -> F {
    let one = F::one();
    let two_g = F::splat(2.0) * g;
    // 1 + g² − 2g cos θ as a sum of non-negative terms picked by the sign of g.
    let pos = g.ge(F::zero());
    let denom = F::select(
        pos,
        (one - g) * (one - g) + two_g * one_minus_cos,
        (one + g) * (one + g) - two_g * one_plus_cos,
    );
    (one - g) * (one + g) * F::splat(0.25 * std::f32::consts::FRAC_1_PI) / (denom * denom.sqrt())
}

#[inline(always)]
fn clamp_g<F: Float>(g: F) -> F {
    g.clamp(F::splat(-super::HG_G_MAX), F::splat(super::HG_G_MAX))
}

/// [`super::hg_phase_dirs`] over lanes.
#[inline(always)]
pub fn hg_phase_dirs<F: Float>(wo: V3<F>, wi: V3<F>, g: F) -> F {
    let half = F::splat(0.5);
    let (s, d) = (wo + wi, wo - wi);
    hg_from_parts(half * s.dot(s), half * d.dot(d), clamp_g(g))
}

/// [`super::sample_hg`] over lanes: `(wi, pdf)` with the pdf per steradian.
#[inline(always)]
pub fn sample_hg<F: Float>(wo: V3<F>, g: F, ux: F, uy: F) -> (V3<F>, F) {
    let g = clamp_g(g);
    let (one, two) = (F::one(), F::splat(2.0));
    let xi = ux;
    let om = one - xi;
    let pos = g.ge(F::zero());
    let a = F::select(pos, (one - g) + two * g * xi, (one + g) - two * g * om);
    let b_minus = F::select(pos, one + g * xi, om + xi * (one + g));
    let b_plus = F::select(pos, (one - g) + g * xi, one - g * om);
    let inv_a2 = (a * a).recip();
    let one_minus_cos = (two * (one - g) * (one - g) * om * b_minus * inv_a2).clamp(F::zero(), two);
    let one_plus_cos = (two * (one + g) * (one + g) * xi * b_plus * inv_a2).clamp(F::zero(), two);
    let cos_theta = F::select(
        one_minus_cos.le(one_plus_cos),
        one - one_minus_cos,
        one_plus_cos - one,
    );
    let sin_theta = (one_minus_cos * one_plus_cos).sqrt();
    let forward = -wo;
    let (t, b) = crate::sampling::warp::lanes::coordinate_system(forward);
    let (s, c) = math::sin_cos(F::splat(std::f32::consts::TAU) * uy);
    let wi = ((t * c + b * s) * sin_theta + forward * cos_theta).normalize();
    (wi, hg_from_parts(one_minus_cos, one_plus_cos, g))
}
