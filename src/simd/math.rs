//! Transcendental functions over any [`Float`], branch-free (both sides of a range split are
//! computed and selected), so one definition serves every width.
//!
//! The polynomials are the single-precision minimax fits of the Cephes library (S. L. Moshier,
//! "Methods and Programs for Mathematical Functions", 1989; `sinf.c`, `cosf.c`, `expf.c`,
//! `logf.c`, `atanf.c`, `asinf.c`), evaluated with fused multiply-adds. The range reductions
//! are prism's own: sin and cos reduce by π/2 with a three-part Cody–Waite split, exact under
//! FMA for the stated range.
//!
//! Maximum errors, measured against f64 over at least 10⁶ arguments per function (including
//! 0, ±0, subnormals, huge values, ±∞ and NaN) by `tests/lanes.rs`, which asserts them. An
//! "ulp" is the spacing of f32 at the exact result (2⁻¹⁴⁹ for subnormal results):
//!
//! | function | domain | max error |
//! |---|---|---|
//! | `sin`, `cos`, `sin_cos` | \|x\| ≤ 2²⁰ | 2 ulp, or 2⁻²⁴ absolute near zeros |
//! | `sin`, `cos`, `sin_cos` | \|x\| > 2²⁰ | no accuracy bound; the result lies in [−1, 1]; ±∞ gives NaN |
//! | `exp` | all | 2 ulp; ≥ 88.7228… gives +∞, below −103.98 gives 0 |
//! | `ln` | all | 2 ulp; 0 gives −∞, negative gives NaN, +∞ gives +∞ |
//! | `ln_1p` | all | 4 ulp; −1 gives −∞, below −1 gives NaN, +∞ gives +∞ |
//! | `atan` | all | 2.5 ulp |
//! | `atan2` | all | 3 ulp; C99 special cases (±0, ±∞) |
//! | `asin`, `acos` | [−1, 1] | 3 ulp; outside gives NaN |
//! | `powf` | x > 0 | relative (1 + \|y ln x\|)·2⁻²²; x = ±0 (as +0), +∞ and y = 0 as C99; x < 0 gives NaN |
//!
//! NaN arguments give NaN everywhere (C99 has `powf(1, NaN) = 1` and `powf(NaN, 0) = 1`, and so
//! does this `powf`).

use super::{Float, UInt};

const FRAC_PI_2: f32 = std::f32::consts::FRAC_PI_2;
const FRAC_PI_4: f32 = std::f32::consts::FRAC_PI_4;
const PI: f32 = std::f32::consts::PI;

/// Horner's rule with fused steps; `c` from the highest degree down.
#[inline(always)]
fn horner<F: Float>(x: F, c: &[f32]) -> F {
    let mut acc = F::splat(c[0]);
    for &k in &c[1..] {
        acc = acc.mul_add(x, F::splat(k));
    }
    acc
}

/// sin and cos of r ∈ [−π/4, π/4].
#[inline(always)]
fn sin_cos_poly<F: Float>(r: F) -> (F, F) {
    let z = r * r;
    let s = horner(z, &[-1.951_529_6e-4, 8.332_161e-3, -1.666_665_5e-1]);
    let s = (s * z).mul_add(r, r);
    let c = horner(z, &[2.443_315_7e-5, -1.388_731_6e-3, 4.166_664_6e-2]);
    let c = (c * z).mul_add(z, F::splat(-0.5).mul_add(z, F::one()));
    (s, c)
}

/// x = q·π/2 + r with |r| ≤ π/4 (slightly more at rounding boundaries) and the quadrant q mod 4.
#[inline(always)]
fn reduce_half_pi<F: Float>(x: F) -> (F, F::U32) {
    // π/2 = P1 + P2 + P3 to about 2⁻⁷⁶; with FMA the first two steps are exact while q < 2²⁰.
    const P1: f32 = 1.570_796_4;
    const P2: f32 = -4.371_139e-8;
    const P3: f32 = -1.715_124_5e-15;
    let q = (x * F::splat(std::f32::consts::FRAC_2_PI)).round();
    let r = q.mul_add(F::splat(-P1), x);
    let r = q.mul_add(F::splat(-P2), r);
    let r = q.mul_add(F::splat(-P3), r);
    (r, q.to_i32_bits() & F::U32::splat(3))
}

/// sin and cos of x together (one range reduction).
#[inline(always)]
pub fn sin_cos<F: Float>(x: F) -> (F, F) {
    let (r, k) = reduce_half_pi(x);
    // |r| < 0.9 wherever the reduction is accurate; the bound keeps huge arguments finite.
    let r = r.clamp(F::splat(-1.0), F::one());
    let (s, c) = sin_cos_poly(r);
    // Quadrant k: (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s).
    let odd = (k & F::U32::splat(1)).eq(F::U32::splat(1));
    let (sin, cos) = (F::select(odd, c, s), F::select(odd, s, c));
    let sin_neg = (k & F::U32::splat(2)).eq(F::U32::splat(2));
    let cos_neg = (k.wrapping_add(F::U32::splat(1)) & F::U32::splat(2)).eq(F::U32::splat(2));
    let sin =
        F::from_bits(sin.to_bits() ^ (F::U32::select(sin_neg, sign_bit::<F>(), zero_u::<F>())));
    let cos =
        F::from_bits(cos.to_bits() ^ (F::U32::select(cos_neg, sign_bit::<F>(), zero_u::<F>())));
    // Past 2²⁰ the reduction is inexact and r may leave [−π/4, π/4]: keep the range promise
    // (`clamp` lets NaN through).
    let one = F::one();
    (sin.clamp(-one, one), cos.clamp(-one, one))
}

#[inline(always)]
fn sign_bit<F: Float>() -> F::U32 {
    F::U32::splat(0x8000_0000)
}

#[inline(always)]
fn zero_u<F: Float>() -> F::U32 {
    F::U32::splat(0)
}

/// sin x, x in radians (accuracy in the module table).
#[inline(always)]
pub fn sin<F: Float>(x: F) -> F {
    sin_cos(x).0
}

/// cos x, x in radians (accuracy in the module table).
#[inline(always)]
pub fn cos<F: Float>(x: F) -> F {
    sin_cos(x).1
}

/// 2ⁿ for integer n ∈ [−126, 127] given as i32 lanes.
#[inline(always)]
fn pow2i<F: Float>(n: F::U32) -> F {
    F::from_bits(n.wrapping_add(F::U32::splat(127)).shli::<23>())
}

/// eˣ.
#[inline(always)]
pub fn exp<F: Float>(x: F) -> F {
    const LN_MAX: f32 = 88.722_84;
    let xc = x.clamp(F::splat(-104.0), F::splat(89.0));
    let n = (xc * F::splat(std::f32::consts::LOG2_E)).round();
    // ln 2 = C1 + C2, C1 with few bits so n·C1 is exact.
    let r = n.mul_add(F::splat(-0.693_359_4), xc);
    let r = n.mul_add(F::splat(2.121_944_4e-4), r);
    let p = horner(
        r,
        &[
            1.987_569_1e-4,
            1.398_199_9e-3,
            8.333_452e-3,
            4.166_579_6e-2,
            1.666_666_5e-1,
            0.5,
        ],
    );
    let y = p.mul_add(r * r, r) + F::one();
    // 2ⁿ in two factors so n down to −150 scales without leaving the normal range early;
    // the one rounding into the subnormals happens in the last product.
    let ni = n.to_i32_bits();
    let n1 = ni.srai::<1>();
    let n2 = ni.wrapping_sub(n1);
    let y = y * pow2i::<F>(n1) * pow2i::<F>(n2);
    let y = F::select(x.gt(F::splat(LN_MAX)), F::splat(f32::INFINITY), y);
    F::select(x.is_nan(), x, y)
}

/// Natural logarithm.
#[inline(always)]
pub fn ln<F: Float>(x: F) -> F {
    // Subnormals are scaled into the normal range first.
    let sub = x.lt(F::splat(f32::MIN_POSITIVE));
    let xs = F::select(sub, x * F::splat(8_388_608.0), x);
    let bits = xs.to_bits();
    // x = m·2ᵉ with m ∈ [0.5, 1).
    let e = (bits.shri::<23>() & F::U32::splat(0xff)).wrapping_sub(F::U32::splat(126));
    let m = F::from_bits((bits & F::U32::splat(0x007f_ffff)) | F::U32::splat(0x3f00_0000));
    let mut e = e.i32_to_f32() - F::select(sub, F::splat(23.0), F::zero());
    // m < √½: use 2m − 1 and e − 1, so the argument of the series is in [√½ − 1, √2 − 1).
    let small = m.lt(F::splat(std::f32::consts::FRAC_1_SQRT_2));
    let t = F::select(small, m + m, m) - F::one();
    e -= F::select(small, F::one(), F::zero());
    let z = t * t;
    let p = horner(
        t,
        &[
            7.037_683_6e-2,
            -1.151_461e-1,
            1.167_699_84e-1,
            -1.242_014_1e-1,
            1.424_932_3e-1,
            -1.666_805_8e-1,
            2.000_071_4e-1,
            -2.499_999_4e-1,
            0.333_333_3,
        ],
    );
    let y = (p * t) * z;
    let y = e.mul_add(F::splat(-2.121_944_4e-4), y);
    let y = F::splat(-0.5).mul_add(z, y);
    let y = e.mul_add(F::splat(0.693_359_4), t + y);
    let y = F::select(x.eq(F::zero()), F::splat(f32::NEG_INFINITY), y);
    let y = F::select(x.eq(F::splat(f32::INFINITY)), x, y);
    // Negative arguments and NaN.
    F::select(x.lt(F::zero()) | x.is_nan(), F::splat(f32::NAN), y)
}

/// ln(1 + x), accurate for small |x| where `ln(1 + x)` loses its digits to the rounding of
/// 1 + x: with w = 1 + x rounded, ln(w) · x / (w − 1) cancels that rounding (Goldberg 1991,
/// theorem 4).
#[inline(always)]
pub fn ln_1p<F: Float>(x: F) -> F {
    let w = F::one() + x;
    let y = ln(w) * (x / (w - F::one()));
    // w = 1: x is below half an ulp of 1 and ln(1 + x) = x to f32 precision (keeps ±0);
    // x = +∞ would give ∞/∞.
    let y = F::select(w.eq(F::one()), x, y);
    F::select(x.eq(F::splat(f32::INFINITY)), x, y)
}

/// xʸ for x ≥ 0, as e^(y ln x).
#[inline(always)]
pub fn powf<F: Float>(x: F, y: F) -> F {
    let r = exp(y * ln(x));
    // C99: x⁰ = 1 for every x (NaN included), 1ʸ = 1 for every y (NaN included).
    let one_case = y.eq(F::zero()) | x.eq(F::one());
    F::select(one_case, F::one(), r)
}

/// atan of t ∈ [0, ∞], reduced by tan(π/8) and tan(3π/8).
#[inline(always)]
fn atan_pos<F: Float>(a: F) -> F {
    let big = a.gt(F::splat(2.414_213_7));
    let mid = a.gt(F::splat(0.414_213_57)) & !big;
    let t = F::select(
        big,
        -a.recip(),
        F::select(mid, (a - F::one()) / (a + F::one()), a),
    );
    // The offsets π/2 and π/4 as f32 plus the low part they round off, added to the small
    // terms first (π/4 alone in f32 is off by 0.7 ulp of a result near 0.4).
    let pick = |b: f32, m: f32| F::select(big, F::splat(b), F::select(mid, F::splat(m), F::zero()));
    let y0 = pick(FRAC_PI_2, FRAC_PI_4);
    let y0_lo = pick(-4.371_139e-8, -2.185_569_5e-8);
    let z = t * t;
    let p = horner(
        z,
        &[
            8.053_744_5e-2,
            -1.387_768_6e-1,
            1.997_771_1e-1,
            -3.333_295e-1,
        ],
    );
    ((p * z).mul_add(t, y0_lo) + t) + y0
}

/// arctan x in (−π/2, π/2).
#[inline(always)]
pub fn atan<F: Float>(x: F) -> F {
    atan_pos(x.abs()).copysign(x)
}

/// The angle of (x, y) in (−π, π], with C99's special cases.
#[inline(always)]
pub fn atan2<F: Float>(y: F, x: F) -> F {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    let inf = F::splat(f32::INFINITY);
    // 0/0 → 0 and ∞/∞ → 1 give C99's values for (±0, ±0) and (±∞, ±∞).
    let t = F::select(
        hi.eq(F::zero()),
        F::zero(),
        F::select(lo.eq(inf), F::one(), lo / hi),
    );
    let r = atan_pos(t);
    let r = F::select(ay.gt(ax), F::splat(FRAC_PI_2) - r, r);
    // The sign bit of x, not x < 0, so that atan2(±0, −0) = ±π.
    let x_neg = (x.to_bits() & sign_bit::<F>()).eq(sign_bit::<F>());
    let r = F::select(x_neg, F::splat(PI) - r, r);
    let r = r.copysign(y);
    F::select(x.is_nan() | y.is_nan(), F::splat(f32::NAN), r)
}

/// The series of asin on [0, 0.5]: asin(a) = a + a·z·P(z), z = a².
#[inline(always)]
fn asin_series<F: Float>(a: F, z: F) -> F {
    let p = horner(
        z,
        &[
            4.216_32e-2,
            2.418_131_2e-2,
            4.547_002_6e-2,
            7.495_300_3e-2,
            1.666_675_2e-1,
        ],
    );
    (a * z).mul_add(p, a)
}

/// arcsin x in [−π/2, π/2]; NaN outside [−1, 1].
#[inline(always)]
pub fn asin<F: Float>(x: F) -> F {
    let a = x.abs();
    let big = a.gt(F::splat(0.5));
    // Past 0.5: asin(a) = π/2 − 2·asin(√((1 − a)/2)).
    let z_big = F::splat(0.5) * (F::one() - a);
    let s = z_big.sqrt();
    let z = F::select(big, z_big, a * a);
    let b = F::select(big, s, a);
    let r = asin_series(b, z);
    let r = F::select(big, F::splat(-2.0).mul_add(r, F::splat(FRAC_PI_2)), r);
    F::select(a.gt(F::one()), F::splat(f32::NAN), r.copysign(x))
}

/// arccos x in [0, π]; NaN outside [−1, 1].
#[inline(always)]
pub fn acos<F: Float>(x: F) -> F {
    let a = x.abs();
    let big = a.gt(F::splat(0.5));
    // Past 0.5: acos(a) = 2·asin(√((1 − a)/2)); acos(−a) = π − acos(a).
    let z_big = F::splat(0.5) * (F::one() - a);
    let s = z_big.sqrt();
    let z = F::select(big, z_big, x * x);
    let b = F::select(big, s, x);
    let r = asin_series(b, z);
    let pos = r + r;
    let big_r = F::select(x.lt(F::zero()), F::splat(PI) - pos, pos);
    let r = F::select(big, big_r, F::splat(FRAC_PI_2) - r);
    F::select(a.gt(F::one()), F::splat(f32::NAN), r)
}
