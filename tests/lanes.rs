//! Lane types and lane math: every width and form against scalar code and against f64.
//!
//! Each form (width 1, the portable widths 8 and 16, and the native widths this CPU has) runs
//! the same kernels; the operations are exactly rounded, so every form must give width 1's bits.
//! The transcendentals are measured against f64 over more than 10⁶ arguments each, and their
//! maximum errors are asserted at the bounds stated in `prism::simd::math`.

use prism::simd::{self, Float, LaneKernel, Lanes, Mask, SimdChoice, UInt, math};

/// Forms under test; the widths this CPU lacks natively are named once.
fn forms() -> Vec<Lanes> {
    if Lanes::native8().is_none() {
        println!("lanes: native width 8 (AVX2 + FMA) not on this CPU: skipped");
    }
    if Lanes::native16().is_none() {
        println!("lanes: native width 16 (AVX-512F and BW) not on this CPU: skipped");
    }
    Lanes::all_available()
}

#[path = "common/splitmix.rs"]
mod splitmix;
use splitmix::SplitMix;

/// Test arguments from SplitMix64.
trait Args {
    fn uniform(&mut self, lo: f64, hi: f64) -> f32;
    /// Any f32 bit pattern: every exponent equally likely, NaNs and infinities included.
    fn bits(&mut self) -> f32;
}

impl Args for SplitMix {
    fn uniform(&mut self, lo: f64, hi: f64) -> f32 {
        self.range(lo, hi) as f32
    }
    fn bits(&mut self) -> f32 {
        f32::from_bits(self.next() as u32)
    }
}

const SPECIALS: [f32; 16] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.5,
    -0.5,
    f32::MIN_POSITIVE,
    -f32::MIN_POSITIVE,
    1e-45,
    -1e-45,
    f32::MAX,
    f32::MIN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
    1e-30,
];

#[derive(Clone, Copy, Debug, PartialEq)]
enum Fun {
    Sin,
    Cos,
    Exp,
    Ln,
    Ln1p,
    Atan,
    Asin,
    Acos,
    Atan2,
    Powf,
}

/// Evaluates one function over `a` (and `b`) at the kernel's width.
struct Eval<'a> {
    fun: Fun,
    a: &'a [f32],
    b: &'a [f32],
    out: &'a mut Vec<f32>,
}

impl LaneKernel for Eval<'_> {
    type Output = ();
    #[inline(always)]
    fn run<F: Float>(self) {
        let w = F::WIDTH;
        assert_eq!(self.a.len() % w, 0);
        self.out.resize(self.a.len(), 0.0);
        for i in (0..self.a.len()).step_by(w) {
            let x = F::load(&self.a[i..]);
            let y = F::load(&self.b[i..]);
            let r = match self.fun {
                Fun::Sin => math::sin(x),
                Fun::Cos => math::cos(x),
                Fun::Exp => math::exp(x),
                Fun::Ln => math::ln(x),
                Fun::Ln1p => math::ln_1p(x),
                Fun::Atan => math::atan(x),
                Fun::Asin => math::asin(x),
                Fun::Acos => math::acos(x),
                Fun::Atan2 => math::atan2(x, y),
                Fun::Powf => math::powf(x, y),
            };
            r.store(&mut self.out[i..]);
        }
    }
}

fn eval(lanes: Lanes, fun: Fun, a: &[f32], b: &[f32]) -> Vec<f32> {
    let mut out = Vec::new();
    simd::dispatch(
        lanes,
        Eval {
            fun,
            a,
            b,
            out: &mut out,
        },
    );
    out
}

fn reference(fun: Fun, x: f32, y: f32) -> f64 {
    let (x, y) = (x as f64, y as f64);
    match fun {
        Fun::Sin => x.sin(),
        Fun::Cos => x.cos(),
        Fun::Exp => x.exp(),
        Fun::Ln => x.ln(),
        Fun::Ln1p => x.ln_1p(),
        Fun::Atan => x.atan(),
        Fun::Asin => x.asin(),
        Fun::Acos => x.acos(),
        Fun::Atan2 => x.atan2(y),
        Fun::Powf => x.powf(y),
    }
}

/// The spacing of f32 at `r` (2⁻¹⁴⁹ in the subnormal range).
fn ulp_at(r: f64) -> f64 {
    let a = r.abs();
    if a < f32::MIN_POSITIVE as f64 {
        return 2f64.powi(-149);
    }
    let e = a.log2().floor() as i32;
    2f64.powi(e.min(127) - 23)
}

/// Error of `got` against the exact `r`, in ulp, with infinities and NaN matched exactly.
fn ulp_error(got: f32, r: f64) -> f64 {
    if r.is_nan() {
        return if got.is_nan() { 0.0 } else { f64::INFINITY };
    }
    let rf = r as f32;
    if rf.is_infinite() || got.is_infinite() {
        // The exact value overflows f32 (or nearly): the result must be that infinity or the
        // largest finite value beside it.
        return if got == rf || (got.is_infinite() && (r.abs() >= f32::MAX as f64)) {
            0.0
        } else {
            f64::INFINITY
        };
    }
    (got as f64 - r).abs() / ulp_at(r)
}

/// Arguments: a quarter uniform over `typical`, a half any bit pattern accepted by `keep`, the
/// rest uniform over the wider `wide` range, then the specials; padded to a multiple of 16.
fn arguments(
    seed: u64,
    typical: (f64, f64),
    wide: (f64, f64),
    keep: impl Fn(f32) -> bool,
) -> Vec<f32> {
    let mut g = SplitMix(seed);
    let n = 1 << 20;
    let mut v: Vec<f32> = Vec::with_capacity(n + 32);
    while v.len() < n / 4 {
        v.push(g.uniform(typical.0, typical.1));
    }
    while v.len() < 3 * n / 4 {
        let x = g.bits();
        if keep(x) {
            v.push(x);
        }
    }
    while v.len() < n {
        v.push(g.uniform(wide.0, wide.1));
    }
    v.extend(SPECIALS);
    // Subnormals of both signs.
    for k in 0..16 {
        v.push(f32::from_bits(1 << k));
        v.push(-f32::from_bits(1 << (k + 7)));
    }
    while !v.len().is_multiple_of(16) {
        v.push(0.25);
    }
    v
}

/// Runs `fun` in every form, checks each form gives width 1's bits, and returns the largest
/// ulp error (with the worst argument) over the arguments `accurate` accepts.
fn check(fun: Fun, a: &[f32], b: &[f32], accurate: impl Fn(f32, f32) -> bool) -> (f64, f32, f32) {
    let scalar = eval(Lanes::scalar(), fun, a, b);
    for lanes in forms() {
        let got = eval(lanes, fun, a, b);
        for i in 0..a.len() {
            let (s, g) = (scalar[i], got[i]);
            assert!(
                s.to_bits() == g.to_bits() || (s.is_nan() && g.is_nan()),
                "{fun:?} at width {}: lane result {g:e} differs from width 1's {s:e} for ({:e}, {:e})",
                lanes.describe(),
                a[i],
                b[i]
            );
        }
    }
    let mut worst = (0.0, 0.0, 0.0);
    for i in 0..a.len() {
        if !accurate(a[i], b[i]) {
            continue;
        }
        let e = ulp_error(scalar[i], reference(fun, a[i], b[i]));
        if e > worst.0 {
            worst = (e, a[i], b[i]);
        }
    }
    let measured = a.iter().zip(b).filter(|(x, y)| accurate(**x, **y)).count();
    println!(
        "{fun:?}: max {:.2} ulp at ({:e}, {:e}) over {measured} arguments",
        worst.0, worst.1, worst.2,
    );
    worst
}

fn assert_within(fun: Fun, worst: (f64, f32, f32), bound: f64) {
    assert!(
        worst.0 <= bound,
        "{fun:?}: {:.2} ulp at ({:e}, {:e}), over the stated {bound} ulp",
        worst.0,
        worst.1,
        worst.2
    );
}

#[test]
fn sin_and_cos_within_two_ulp_up_to_2_pow_20() {
    let lim = (1u32 << 20) as f32;
    let a = arguments(1, (-10.0, 10.0), (-1e6, 1e6), |_| true);
    let b = vec![0.0; a.len()];
    for fun in [Fun::Sin, Fun::Cos] {
        let scalar = eval(Lanes::scalar(), fun, &a, &b);
        // Near a zero of the function an ulp is tiny: there the bound is 2⁻²⁴ absolute.
        let mut worst = (0.0, 0.0, 0.0);
        for (i, &x) in a.iter().enumerate() {
            let r = reference(fun, x, 0.0);
            if x.abs() <= lim {
                let e = ulp_error(scalar[i], r);
                let abs = (scalar[i] as f64 - r).abs();
                if e > worst.0 && abs > 2f64.powi(-24) {
                    worst = (e, x, 0.0);
                }
            } else {
                let s = scalar[i];
                assert!(
                    s.is_nan() == x.is_nan() || (x.is_infinite() && s.is_nan()),
                    "{fun:?}({x:e}) = {s}"
                );
                assert!(
                    s.is_nan() || s.abs() <= 1.0,
                    "{fun:?}({x:e}) = {s} outside [-1, 1]"
                );
            }
        }
        println!(
            "{fun:?}: max {:.2} ulp (beyond 2^-24 absolute) at {:e}",
            worst.0, worst.1
        );
        assert_within(fun, worst, 2.0);
        check(fun, &a, &b, |x, _| x.abs() <= lim);
    }
}

#[test]
fn exp_within_two_ulp() {
    let a = arguments(2, (-10.0, 10.0), (-110.0, 95.0), |x| {
        x.abs() < 200.0 || !x.is_finite()
    });
    let b = vec![0.0; a.len()];
    assert_within(Fun::Exp, check(Fun::Exp, &a, &b, |_, _| true), 2.0);
}

#[test]
fn ln_within_two_ulp() {
    let a = arguments(3, (1e-3, 10.0), (0.0, 1e30), |_| true);
    let b = vec![0.0; a.len()];
    assert_within(Fun::Ln, check(Fun::Ln, &a, &b, |_, _| true), 2.0);
}

#[test]
fn ln_1p_within_four_ulp() {
    // Free-flight distances take ln(1 − u) for u ∈ [0, 1): small |x| is where it matters.
    let a = arguments(9, (-1.0, 1e-2), (-1.0, 1e30), |x| x >= -1.0 || x.is_nan());
    let b = vec![0.0; a.len()];
    assert_within(Fun::Ln1p, check(Fun::Ln1p, &a, &b, |_, _| true), 4.0);
}

#[test]
fn atan_within_two_and_a_half_ulp() {
    let a = arguments(4, (-5.0, 5.0), (-1e8, 1e8), |_| true);
    let b = vec![0.0; a.len()];
    assert_within(Fun::Atan, check(Fun::Atan, &a, &b, |_, _| true), 2.5);
}

#[test]
fn asin_and_acos_within_three_ulp() {
    let a = arguments(5, (-1.0, 1.0), (-1.5, 1.5), |x| {
        x.abs() <= 1.0 || !x.is_finite()
    });
    let b = vec![0.0; a.len()];
    assert_within(Fun::Asin, check(Fun::Asin, &a, &b, |_, _| true), 3.0);
    assert_within(Fun::Acos, check(Fun::Acos, &a, &b, |_, _| true), 3.0);
}

#[test]
fn atan2_within_three_ulp_with_c99_special_cases() {
    let mut g = SplitMix(6);
    let mut a = arguments(6, (-5.0, 5.0), (-1e4, 1e4), |_| true);
    let mut b: Vec<f32> = (0..a.len())
        .map(|i| match i % 3 {
            0 => g.uniform(-5.0, 5.0),
            1 => g.bits(),
            _ => g.uniform(-1e4, 1e4),
        })
        .collect();
    // Every pair of specials.
    for &y in &SPECIALS {
        for &x in &SPECIALS {
            a.push(y);
            b.push(x);
        }
    }
    while !a.len().is_multiple_of(16) {
        a.push(1.0);
        b.push(1.0);
    }
    assert_within(Fun::Atan2, check(Fun::Atan2, &a, &b, |_, _| true), 3.0);
}

#[test]
fn powf_within_its_stated_relative_error() {
    let mut g = SplitMix(7);
    let mut a = arguments(7, (0.0, 1.0), (0.0, 1e6), |x| x >= 0.0 || x.is_nan());
    let mut b: Vec<f32> = (0..a.len())
        .map(|i| match i % 2 {
            0 => g.uniform(0.2, 3.0),
            _ => g.uniform(-3.0, 3.0),
        })
        .collect();
    for &y in &SPECIALS {
        for &x in &SPECIALS {
            if x >= 0.0 || x.is_nan() {
                a.push(x);
                b.push(y);
            }
        }
    }
    while !a.len().is_multiple_of(16) {
        a.push(1.0);
        b.push(1.0);
    }
    let got = eval(Lanes::scalar(), Fun::Powf, &a, &b);
    check(Fun::Powf, &a, &b, |_, _| false);
    for i in 0..a.len() {
        let (x, y) = (a[i], b[i]);
        // −0 is +0 here (no odd-integer cases: bases are never negative).
        let r = reference(Fun::Powf, if x == 0.0 { 0.0 } else { x }, y);
        let rf = r as f32;
        let g = got[i];
        if x < 0.0 && y != 0.0 {
            assert!(
                g.is_nan(),
                "powf({x:e}, {y:e}) = {g:e}: negative bases give NaN"
            );
            continue;
        }
        if y == 0.0 || x == 1.0 {
            assert_eq!(g, 1.0, "powf({x:e}, {y:e})");
            continue;
        }
        if r.is_nan() || rf.is_infinite() || rf == 0.0 || !r.is_finite() {
            // Exact cases: NaN, overflow, underflow, and C99's 0ʸ, ∞ʸ, x⁰, 1ʸ.
            let same = (g.is_nan() && r.is_nan()) || g == rf || (rf == 0.0 && g.abs() < 1e-37);
            assert!(same, "powf({x:e}, {y:e}) = {g:e}, expected {r:e}");
            continue;
        }
        if r.abs() < f32::MIN_POSITIVE as f64 {
            continue; // subnormal results: absolute error below 2⁻¹²⁶, not relative
        }
        let bound = (1.0 + (y as f64 * (x as f64).ln()).abs()) * 2f64.powi(-22);
        if g.is_infinite() && r.abs() * (1.0 + bound) >= f32::MAX as f64 {
            continue; // within the bound of overflowing
        }
        let rel = ((g as f64 - r) / r).abs();
        assert!(
            rel <= bound,
            "powf({x:e}, {y:e}) = {g:e}: relative error {rel:e} over {bound:e}"
        );
    }
}

/// Elementary operations at every width, against the scalar rule they stand for.
struct Ops<'a> {
    a: &'a [f32],
    b: &'a [f32],
    out: &'a mut Vec<u32>,
}

impl LaneKernel for Ops<'_> {
    type Output = ();
    #[inline(always)]
    fn run<F: Float>(self) {
        let w = F::WIDTH;
        for i in (0..self.a.len()).step_by(w) {
            let (x, y) = (F::load(&self.a[i..]), F::load(&self.b[i..]));
            let (ux, uy) = (x.to_bits(), y.to_bits());
            let m = x.lt(y);
            let results: [F::U32; 24] = [
                (x + y).to_bits(),
                (x - y).to_bits(),
                (x * y).to_bits(),
                (x / y).to_bits(),
                (-x).to_bits(),
                x.min(y).to_bits(),
                x.max(y).to_bits(),
                x.mul_add(y, F::splat(0.3)).to_bits(),
                x.sqrt().to_bits(),
                x.abs().copysign(y).to_bits(),
                x.floor().to_bits(),
                x.round().to_bits(),
                x.to_i32_bits(),
                F::select(m, x, y).to_bits(),
                F::U32::select(x.le(y) | x.eq(y) | x.ne(y), ux, uy),
                ux.wrapping_add(uy).wrapping_mul(uy) ^ ux.wrapping_sub(uy),
                ux.shli::<7>() | uy.shri::<3>(),
                ux.srai::<5>(),
                ux.shl_var(uy & F::U32::splat(63)),
                ux.shr_var(uy & F::U32::splat(63)),
                F::U32::select(ux.lt(uy), ux, !uy),
                F::U32::select(ux.lt_i32(uy), uy, ux),
                ux.reverse_bits(),
                x.clamp(F::splat(-1.0), F::splat(2.0)).to_bits(),
            ];
            for (k, r) in results.iter().enumerate() {
                for lane in 0..w {
                    self.out[(i + lane) * 24 + k] = r.lane(lane);
                }
            }
            // Masks: bits, any, all and counts agree with their lanes.
            let bits = m.bits();
            for lane in 0..w {
                assert_eq!(m.lane(lane), bits >> lane & 1 == 1);
            }
            assert_eq!(m.any(), bits != 0);
            assert_eq!(m.all(), bits == (1u64 << w) as u32 - 1);
            assert_eq!(m.none(), bits == 0);
            assert_eq!(m.and_not(x.le(y)).bits(), bits & !x.le(y).bits());
            assert_eq!(m.count(), bits.count_ones());
            assert_eq!(F::Mask::from_fn(|l| m.lane(l)).bits(), bits);
            // blend takes `v` where the mask is set; reduce_sum adds the lanes in order.
            let blended = x.blend(m, y);
            let sum = F::from_fn(|l| l as f32).reduce_sum();
            assert_eq!(sum, (0..w).map(|l| l as f32).sum::<f32>());
            // Gathers and u32 → f32 conversion.
            let words: Vec<u32> = (0..64u32).map(|k| k.wrapping_mul(0x9e37_79b9)).collect();
            let uidx = F::U32::from_fn(|l| (l * 5 % 64) as u32);
            let ug = F::U32::gather(&words, uidx);
            let idx = F::U32::from_fn(|l| (l * 7 % self.a.len()) as u32);
            let gathered = F::gather(self.a, idx);
            for lane in 0..w {
                assert_eq!(
                    gathered.lane(lane).to_bits(),
                    self.a[lane * 7 % self.a.len()].to_bits()
                );
                assert_eq!(ug.lane(lane), words[lane * 5 % 64]);
                let want = if m.lane(lane) {
                    y.lane(lane)
                } else {
                    x.lane(lane)
                };
                assert_eq!(blended.lane(lane).to_bits(), want.to_bits());
                assert_eq!(
                    (ux & F::U32::splat(0x00ff_ffff)).i32_to_f32().lane(lane),
                    (ux.lane(lane) & 0x00ff_ffff) as f32
                );
            }
        }
    }
}

#[test]
fn elementary_operations_give_width_1_bits_in_every_form() {
    let mut g = SplitMix(8);
    let mut a: Vec<f32> = Vec::new();
    let mut b: Vec<f32> = Vec::new();
    for &x in &SPECIALS {
        for &y in &SPECIALS {
            a.push(x);
            b.push(y);
        }
    }
    for _ in 0..20_000 {
        a.push(if g.next().is_multiple_of(2) {
            g.bits()
        } else {
            g.uniform(-4.0, 4.0)
        });
        b.push(if g.next().is_multiple_of(2) {
            g.bits()
        } else {
            g.uniform(-4.0, 4.0)
        });
    }
    // Values on rounding boundaries and at the edges of the i32 range.
    for x in [
        0.5f32,
        1.5,
        2.5,
        -0.5,
        -2.5,
        2.147_483_6e9,
        -2.147_483_6e9,
        3e9,
        -3e9,
    ] {
        a.push(x);
        b.push(1.0);
    }
    while !a.len().is_multiple_of(16) {
        a.push(1.0);
        b.push(2.0);
    }
    let run = |lanes| {
        let mut out = vec![0u32; a.len() * 24];
        simd::dispatch(
            lanes,
            Ops {
                a: &a,
                b: &b,
                out: &mut out,
            },
        );
        out
    };
    let scalar = run(Lanes::scalar());
    // Width 1 follows the stated rules.
    for (i, (&x, &y)) in a.iter().zip(&b).enumerate() {
        let r = &scalar[i * 24..i * 24 + 24];
        let min = if x < y { x } else { y };
        let max = if x > y { x } else { y };
        assert_eq!(r[5], min.to_bits(), "min({x}, {y})");
        assert_eq!(r[6], max.to_bits(), "max({x}, {y})");
        let t = if x.is_nan() || x.abs() >= 2_147_483_648.0 {
            i32::MIN as u32
        } else {
            x as i32 as u32
        };
        assert_eq!(r[12], t, "to_i32_bits({x})");
        if x.is_nan() {
            assert!(f32::from_bits(r[11]).is_nan(), "round(NaN)");
        } else {
            assert_eq!(r[11], x.round_ties_even().to_bits(), "round({x})");
        }
        assert_eq!(r[22], x.to_bits().reverse_bits());
        let c = f32::from_bits(r[23]);
        assert!(if x.is_nan() {
            c.is_nan()
        } else {
            (-1.0..=2.0).contains(&c)
        });
    }
    for lanes in forms() {
        let got = run(lanes);
        for (i, (s, g)) in scalar.iter().zip(&got).enumerate() {
            let (p, k) = (i / 24, i % 24);
            let nan = |u: u32| f32::from_bits(u).is_nan();
            // NaN payloads may differ between instruction sets (x86 makes them quiet and
            // negative); every other bit must match.
            let float_op = !matches!(k, 12 | 14..=22);
            assert!(
                s == g || (float_op && nan(*s) && nan(*g)),
                "op {k} at width {} on ({:e}, {:e}): {g:#x} against width 1's {s:#x}",
                lanes.describe(),
                a[p],
                b[p]
            );
        }
    }
}

#[test]
fn lane_vectors_match_glam() {
    use glam::Vec3;
    struct Vecs<'a>(&'a [Vec3], &'a mut Vec<Vec3>);
    impl LaneKernel for Vecs<'_> {
        type Output = ();
        #[inline(always)]
        fn run<F: Float>(self) {
            let w = F::WIDTH;
            for i in (0..self.0.len() - 1).step_by(w) {
                let a = simd::V3::<F>::from_fn(|l| self.0[i + l]);
                let b = simd::V3::<F>::from_fn(|l| self.0[i + l + 1]);
                let r = a.cross(b).normalize() * a.dot(b) + a.mul_elem(b) - b;
                for l in 0..w {
                    self.1.push(r.lane(l));
                }
            }
        }
    }
    let mut g = SplitMix(9);
    let v: Vec<Vec3> = (0..16 * 64 + 1)
        .map(|_| {
            Vec3::new(
                g.uniform(-2.0, 2.0),
                g.uniform(-2.0, 2.0),
                g.uniform(-2.0, 2.0),
            )
        })
        .collect();
    for lanes in forms() {
        let mut out = Vec::new();
        simd::dispatch(lanes, Vecs(&v, &mut out));
        for (i, r) in out.iter().enumerate() {
            let (a, b) = (v[i], v[i + 1]);
            let e = a.cross(b).normalize() * a.dot(b) + a * b - b;
            assert!((*r - e).abs().max_element() <= 1e-5 * (1.0 + e.abs().max_element()));
        }
    }
}

#[test]
fn widths_parse_and_resolve() {
    assert_eq!("auto".parse::<SimdChoice>(), Ok(SimdChoice::Auto));
    assert_eq!("16".parse::<SimdChoice>(), Ok(SimdChoice::W16));
    assert_eq!("8".parse::<SimdChoice>(), Ok(SimdChoice::W8));
    assert_eq!("1".parse::<SimdChoice>(), Ok(SimdChoice::W1));
    let e = "4".parse::<SimdChoice>().unwrap_err();
    assert!(e.contains("auto, 16, 8 or 1"), "{e}");
    assert_eq!(Lanes::resolve(SimdChoice::W1).unwrap().width(), 1);
    assert_eq!(Lanes::resolve(SimdChoice::W8).ok(), Lanes::native8());
    assert_eq!(Lanes::resolve(SimdChoice::W16).ok(), Lanes::native16());
    match Lanes::resolve(SimdChoice::W16) {
        Ok(l) => assert_eq!(l.width(), 16),
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.contains("--simd 16 needs AVX-512F"), "{msg}");
        }
    }
    let auto = Lanes::auto();
    assert!(auto.is_native());
    assert_eq!(
        auto.width(),
        if Lanes::native16().is_some() {
            16
        } else if Lanes::native8().is_some() {
            8
        } else {
            1
        }
    );
    assert!(!Lanes::portable(8).is_native());
    assert_eq!(Lanes::portable(16).width(), 16);
}

/// `unsafe` is allowed in `src/simd/` alone (the crate root denies it elsewhere; this also
/// catches an `#[allow(unsafe_code)]` added to another module).
#[test]
fn no_unsafe_outside_the_lane_module() {
    fn walk(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for d in ["src", "tests", "benches"] {
        walk(&root.join(d), &mut files);
    }
    let simd_dir = root.join("src").join("simd");
    let pattern = [
        "unsafe {",
        "unsafe fn",
        "unsafe impl",
        "unsafe trait",
        "unsafe extern",
        "allow(unsafe_code)",
    ];
    let mut found = Vec::new();
    for f in files {
        if f.starts_with(&simd_dir) || f.ends_with("lanes.rs") {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            if pattern.iter().any(|p| line.contains(p)) {
                found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "unsafe code outside src/simd/:\n{}",
        found.join("\n")
    );
    let lib = std::fs::read_to_string(root.join("src/lib.rs")).unwrap();
    assert!(lib.contains("#![deny(unsafe_code)]"));
}

/// Gathers read `table[idx]` in every lane at every width (the native forms use the
/// hardware gather), and an index past the end panics rather than reading out of bounds.
struct Gather<'a> {
    table: &'a [f32],
    idx: &'a [u32],
}

impl LaneKernel for Gather<'_> {
    type Output = Vec<f32>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<f32> {
        let mut out = Vec::new();
        for chunk in self.idx.chunks_exact(F::WIDTH) {
            let i = F::U32::from_fn(|l| chunk[l]);
            let g = F::gather(self.table, i);
            out.extend((0..F::WIDTH).map(|l| g.lane(l)));
        }
        out
    }
}

#[test]
fn gathers_read_the_table_and_refuse_indices_past_its_end() {
    let table: Vec<f32> = (0..1000).map(|i| (i as f32).sqrt() - 7.0).collect();
    let mut rng = SplitMix(99);
    let idx: Vec<u32> = (0..16 * 500)
        .map(|k| match k % 5 {
            0 => 0,
            1 => 999,
            _ => (rng.next() % 1000) as u32,
        })
        .collect();
    for lanes in forms() {
        let got = simd::dispatch(
            lanes,
            Gather {
                table: &table,
                idx: &idx,
            },
        );
        for (g, &i) in got.iter().zip(&idx) {
            assert_eq!(
                g.to_bits(),
                table[i as usize].to_bits(),
                "{}",
                lanes.describe()
            );
        }
        for bad in [1000u32, u32::MAX, 1 << 31] {
            let mut idx = vec![3u32; 16];
            idx[lanes.width() - 1] = bad;
            let r = std::panic::catch_unwind(|| {
                simd::dispatch(
                    lanes,
                    Gather {
                        table: &table,
                        idx: &idx,
                    },
                )
            });
            assert!(
                r.is_err(),
                "{}: index {bad} read past the table",
                lanes.describe()
            );
        }
    }
}
