//! Lane types: f32, u32 and mask values of width 1, 8 or 16, and the one place that picks the
//! width at run time.
//!
//! Per-path arithmetic is written once, generic over [`Float`], as Mitsuba 3 writes its plugins
//! over `Float`. Width 1 is plain `f32` / `u32` / `bool`: the readable reference. Widths 8 and
//! 16 exist in two forms with the same results bit for bit:
//! - a portable form over plain arrays, which runs on any CPU (so every kernel is tested
//!   everywhere);
//! - a native form over AVX2 + FMA (8 lanes) or AVX-512F/BW (16 lanes) registers on x86-64.
//!
//! Every operation is exactly rounded or defined bit for bit (fused multiply-add is fused in
//! every form, `min`/`max` follow the SSE rule), so a kernel gives the same bits in the portable
//! and native forms of a width, and widths differ only where a kernel's own control flow does.
//!
//! # Why intrinsics, and why this is sound
//! The native lane types wrap `core::arch` registers, and their operations call intrinsics in
//! `#[inline(always)]` wrappers. A kernel instantiated with them runs only inside
//! [`dispatch`], whose entry point for that width carries `#[target_feature]`: everything the
//! kernel inlines is compiled for that instruction set, in one function, with no out-of-line
//! intrinsic calls. Relying on auto-vectorisation of array loops instead gave scalar or
//! gather-ridden code at width 16 (LLVM vectorised the loop around the kernel, not its lanes).
//!
//! The native types are private to this module: kernel code cannot name them, so the only way
//! to obtain a value of one is through [`dispatch`], which instantiates it only after CPU
//! feature detection has found the instructions it uses. This is what makes the `unsafe`
//! intrinsic calls sound; it is the only module of the crate with `unsafe` code.
//!
//! # Kernels must inline
//! `LaneKernel::run` and everything it calls with lane values should be `#[inline(always)]`
//! (or small enough to inline): a function that is not inlined into the entry point is compiled
//! without the target features and calls the intrinsics out of line, correct but slow.

#![allow(unsafe_code)]

pub mod math;
mod portable;
mod vec3;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use portable::{PortableF32, PortableMask, PortableU32};
pub use vec3::V3;

use std::fmt::Debug;
use std::ops::{
    Add, AddAssign, BitAnd, BitAndAssign, BitOr, BitOrAssign, BitXor, Div, DivAssign, Mul,
    MulAssign, Neg, Not, Sub, SubAssign,
};

/// A lane mask: one boolean per lane.
pub trait Mask:
    Copy
    + Debug
    + Send
    + Sync
    + 'static
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
    + Not<Output = Self>
    + BitAndAssign
    + BitOrAssign
{
    /// Number of lanes.
    const WIDTH: usize;
    /// Every lane set to `b`.
    fn splat(b: bool) -> Self;
    /// Lane `i` set to `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> bool) -> Self;
    /// Lane `i`.
    fn lane(self, i: usize) -> bool;
    /// Lane `i` in bit `i`.
    fn bits(self) -> u32;
    /// Whether any lane is set.
    fn any(self) -> bool;
    /// Whether every lane is set.
    fn all(self) -> bool;
    /// Whether no lane is set.
    #[inline(always)]
    fn none(self) -> bool {
        !self.any()
    }
    /// `self & !other`.
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        self & !other
    }
    /// Number of true lanes.
    #[inline(always)]
    fn count(self) -> u32 {
        self.bits().count_ones()
    }
}

/// An f32 lane of width `WIDTH`, with its mask and u32 companions.
///
/// Semantics that are not plain IEEE operations:
/// - `min(a, b)` is `if a < b { a } else { b }` and `max(a, b)` is `if a > b { a } else { b }`:
///   the SSE rule, so a NaN in `b` propagates and a NaN in `a` is replaced by `b`;
/// - `mul_add` is fused (one rounding) in every form;
/// - `recip` is an exact division, not a hardware estimate;
/// - compares are ordered: a NaN lane compares false, except `ne`, which is true.
pub trait Float:
    Copy
    + Debug
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
{
    /// One boolean per lane, as compares return.
    type Mask: Mask;
    /// The u32 lane of the same width, for bit patterns and indices.
    type U32: UInt<Mask = Self::Mask, Float = Self>;
    /// Number of lanes.
    const WIDTH: usize;

    /// Every lane set to `x`.
    fn splat(x: f32) -> Self;
    /// Lane `i` set to `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self;
    /// Lane `i`.
    fn lane(self, i: usize) -> f32;
    /// The first `WIDTH` values of `s`.
    ///
    /// # Panics
    /// If `s` is shorter than `WIDTH`.
    fn load(s: &[f32]) -> Self;
    /// Writes the lanes to the first `WIDTH` values of `out`.
    ///
    /// # Panics
    /// If `out` is shorter than `WIDTH`.
    fn store(self, out: &mut [f32]);
    /// `s[idx[i]]` in lane `i`.
    ///
    /// # Panics
    /// If an index is out of bounds.
    #[inline(always)]
    fn gather(s: &[f32], idx: Self::U32) -> Self {
        Self::from_fn(|i| s[idx.lane(i) as usize])
    }

    /// Lanes where `self == o`.
    fn eq(self, o: Self) -> Self::Mask;
    /// Lanes where `self != o` (true where either is NaN).
    fn ne(self, o: Self) -> Self::Mask;
    /// Lanes where `self < o`.
    fn lt(self, o: Self) -> Self::Mask;
    /// Lanes where `self <= o`.
    fn le(self, o: Self) -> Self::Mask;
    /// Lanes where `self > o`.
    #[inline(always)]
    fn gt(self, o: Self) -> Self::Mask {
        o.lt(self)
    }
    /// Lanes where `self >= o`.
    #[inline(always)]
    fn ge(self, o: Self) -> Self::Mask {
        o.le(self)
    }
    /// `a` where `m` is set, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Lane-wise minimum under the SSE rule (see the trait docs).
    fn min(self, o: Self) -> Self;
    /// Lane-wise maximum under the SSE rule (see the trait docs).
    fn max(self, o: Self) -> Self;
    /// `self * b + c` with one rounding.
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// `1 / self`, by an exact division.
    #[inline(always)]
    fn recip(self) -> Self {
        Self::splat(1.0) / self
    }
    /// `self` with the sign bit cleared.
    fn abs(self) -> Self;
    /// The magnitude of `self` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// Round toward negative infinity.
    fn floor(self) -> Self;
    /// Round to nearest, ties to even.
    fn round(self) -> Self;
    /// The IEEE bit pattern of each lane.
    fn to_bits(self) -> Self::U32;
    /// Lanes whose IEEE bit patterns are `u`.
    fn from_bits(u: Self::U32) -> Self;
    /// Truncating conversion to i32, as `U32` bits. Out of range and NaN give `i32::MIN`
    /// (the x86 rule; the portable forms match it).
    fn to_i32_bits(self) -> Self::U32;

    /// Every lane 0.
    #[inline(always)]
    fn zero() -> Self {
        Self::splat(0.0)
    }
    /// Every lane 1.
    #[inline(always)]
    fn one() -> Self {
        Self::splat(1.0)
    }
    /// Lanes that are NaN.
    #[inline(always)]
    fn is_nan(self) -> Self::Mask {
        self.ne(self)
    }
    /// Neither infinite nor NaN.
    #[inline(always)]
    fn is_finite(self) -> Self::Mask {
        self.abs().lt(Self::splat(f32::INFINITY))
    }
    /// `self` limited to [lo, hi]; a NaN lane stays NaN.
    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        // Under the SSE rule the second operand wins a comparison with NaN.
        hi.min(lo.max(self))
    }
    /// Runs `k` at this lane type inside the entry point of its instruction set: for work a
    /// kernel hands to a function it does not inline (a mesh's own walk), so that the lane
    /// operations there are compiled for the instructions too.
    fn enter<K: LaneKernel>(k: K) -> K::Output;

    /// Runs `k`, whose inputs are already lanes of this type, inside the entry point of its
    /// instruction set: for a function a kernel keeps out of line (to bound the kernel's
    /// size). Out of an entry point every intrinsic of the function would be a call.
    fn enter_typed<K: TypedKernel<Self>>(k: K) -> K::Output;

    /// Sum of the lanes, in lane order (for reports and tests, not hot loops).
    #[inline(always)]
    fn reduce_sum(self) -> f32 {
        (0..Self::WIDTH).map(|i| self.lane(i)).sum()
    }
    /// Lane `i` for lanes set in `m`, else `self`.
    #[inline(always)]
    fn blend(self, m: Self::Mask, v: Self) -> Self {
        Self::select(m, v, self)
    }
}

/// A u32 lane with wrapping arithmetic, the companion of a [`Float`].
pub trait UInt:
    Copy
    + Debug
    + Send
    + Sync
    + 'static
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
    + Not<Output = Self>
{
    /// One boolean per lane, as compares return.
    type Mask: Mask;
    /// The f32 lane of the same width.
    type Float: Float<Mask = Self::Mask, U32 = Self>;
    /// Number of lanes.
    const WIDTH: usize;

    /// Every lane set to `x`.
    fn splat(x: u32) -> Self;
    /// Lane `i` set to `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> u32) -> Self;
    /// Lane `i`.
    fn lane(self, i: usize) -> u32;
    /// `s[idx[i]]` in lane `i`.
    ///
    /// # Panics
    /// If an index is out of bounds.
    #[inline(always)]
    fn gather(s: &[u32], idx: Self) -> Self {
        Self::from_fn(|i| s[idx.lane(i) as usize])
    }
    /// Lane-wise sum, modulo 2^32.
    fn wrapping_add(self, o: Self) -> Self;
    /// Lane-wise difference, modulo 2^32.
    fn wrapping_sub(self, o: Self) -> Self;
    /// Low 32 bits of the lane-wise product.
    fn wrapping_mul(self, o: Self) -> Self;
    /// Logical shift left by `n` bits (`n < 32`).
    fn shli<const N: u32>(self) -> Self;
    /// Logical shift right by `n` bits (`n < 32`).
    fn shri<const N: u32>(self) -> Self;
    /// Arithmetic shift right (the sign bit is copied in), as on i32.
    fn srai<const N: u32>(self) -> Self;
    /// Per-lane logical shift left; counts of 32 or more give 0.
    fn shl_var(self, n: Self) -> Self;
    /// Per-lane logical shift right; counts of 32 or more give 0.
    fn shr_var(self, n: Self) -> Self;
    /// Lanes where `self == o`.
    fn eq(self, o: Self) -> Self::Mask;
    /// Unsigned less-than.
    fn lt(self, o: Self) -> Self::Mask;
    /// Signed (i32) less-than.
    fn lt_i32(self, o: Self) -> Self::Mask;
    /// `a` where `m` is set, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// The lanes read as i32 and converted to f32 (round to nearest even).
    fn i32_to_f32(self) -> Self::Float;

    /// Each lane with its 32 bits in reverse order (as `u32::reverse_bits`).
    #[inline(always)]
    fn reverse_bits(self) -> Self {
        // Swap halves, bytes, nibbles, pairs and bits: five shift-and-mask steps, in every form.
        let mut x = self.shri::<16>() | self.shli::<16>();
        let m = Self::splat(0x00ff_00ff);
        x = (x.shri::<8>() & m) | (x & m).shli::<8>();
        let m = Self::splat(0x0f0f_0f0f);
        x = (x.shri::<4>() & m) | (x & m).shli::<4>();
        let m = Self::splat(0x3333_3333);
        x = (x.shri::<2>() & m) | (x & m).shli::<2>();
        let m = Self::splat(0x5555_5555);
        (x.shri::<1>() & m) | (x & m).shli::<1>()
    }
}

/// The lane width a render asks for: `--simd auto|16|8|1`, `render: (simd: 8)` (or
/// `"auto"`) in a scene, `--set render.simd=8` (or `auto`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SimdChoice {
    /// The widest width this CPU runs natively (see [`Lanes::auto`]).
    #[default]
    Auto,
    /// 16 lanes (AVX-512F and BW).
    W16,
    /// 8 lanes (AVX2 + FMA).
    W8,
    /// 1 lane, scalar code; runs on any CPU.
    W1,
}

impl std::str::FromStr for SimdChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" | "Auto" => Ok(SimdChoice::Auto),
            "16" => Ok(SimdChoice::W16),
            "8" => Ok(SimdChoice::W8),
            "1" => Ok(SimdChoice::W1),
            _ => Err(format!(
                "unknown SIMD width '{s}': expected auto, 16, 8 or 1"
            )),
        }
    }
}

impl SimdChoice {
    fn from_width(w: u64) -> Option<Self> {
        match w {
            16 => Some(SimdChoice::W16),
            8 => Some(SimdChoice::W8),
            1 => Some(SimdChoice::W1),
            _ => None,
        }
    }
}

impl<'de> serde::Deserialize<'de> for SimdChoice {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = SimdChoice;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a lane width: Auto, 16, 8 or 1")
            }
            fn visit_u64<E: serde::de::Error>(self, w: u64) -> Result<SimdChoice, E> {
                SimdChoice::from_width(w).ok_or_else(|| {
                    E::custom(format!("lane width {w} is not one of Auto, 16, 8, 1"))
                })
            }
            fn visit_i64<E: serde::de::Error>(self, w: i64) -> Result<SimdChoice, E> {
                match u64::try_from(w) {
                    Ok(w) => self.visit_u64(w),
                    Err(_) => Err(E::custom(format!(
                        "lane width {w} is not one of Auto, 16, 8, 1"
                    ))),
                }
            }
            // RON hands a bare identifier over without its name, so `Auto` could not be told
            // from a typo: the file form is the string.
            fn visit_unit<E: serde::de::Error>(self) -> Result<SimdChoice, E> {
                Err(E::custom(
                    "write the lane width as 16, 8, 1 or \"auto\" (in quotes)",
                ))
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<SimdChoice, E> {
                match s {
                    "Auto" | "auto" => Ok(SimdChoice::Auto),
                    _ => Err(E::custom(format!("'{s}' is not one of Auto, 16, 8, 1"))),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// Which instruction set a width runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Form {
    Scalar,
    /// Scalar code compiled with FMA available (the same results, faster `mul_add`).
    #[cfg(target_arch = "x86_64")]
    ScalarFma,
    Portable8,
    Portable16,
    #[cfg(target_arch = "x86_64")]
    Avx2,
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

/// A lane width and the form it runs in, resolved against this CPU. A value naming a native
/// form exists only after feature detection found its instructions (the field is private).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Lanes(Form);

/// A forced width this CPU cannot run natively.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "--simd {width} needs {needs}, which this CPU does not have (it runs: {have}); use --simd auto"
)]
pub struct SimdUnavailable {
    /// The width that was asked for.
    pub width: usize,
    /// The instruction sets that width needs, e.g. `AVX2 and FMA`.
    pub needs: &'static str,
    /// What this CPU runs instead, as [`Lanes::describe`] gives it.
    pub have: String,
}

#[cfg(target_arch = "x86_64")]
fn has_avx2_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

#[cfg(target_arch = "x86_64")]
fn has_avx512() -> bool {
    has_avx2_fma()
        && std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512bw")
}

impl Lanes {
    /// Width 1, scalar code (with hardware FMA where the CPU has it).
    pub fn scalar() -> Self {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("fma") {
            return Lanes(Form::ScalarFma);
        }
        Lanes(Form::Scalar)
    }

    /// Width 8 or 16 over plain arrays: runs on any CPU, bit for bit as the native form.
    ///
    /// # Panics
    /// If `width` is not 8 or 16.
    pub fn portable(width: usize) -> Self {
        match width {
            8 => Lanes(Form::Portable8),
            16 => Lanes(Form::Portable16),
            _ => panic!("portable lanes come in widths 8 and 16, not {width}"),
        }
    }

    /// Native width 8 (AVX2 + FMA), if this CPU has it.
    pub fn native8() -> Option<Self> {
        #[cfg(target_arch = "x86_64")]
        if has_avx2_fma() {
            return Some(Lanes(Form::Avx2));
        }
        None
    }

    /// Native width 16 (AVX-512F and BW), if this CPU has it.
    pub fn native16() -> Option<Self> {
        #[cfg(target_arch = "x86_64")]
        if has_avx512() {
            return Some(Lanes(Form::Avx512));
        }
        None
    }

    /// The widest native width: 16 with AVX-512F and BW, 8 with AVX2 + FMA, else 1.
    pub fn auto() -> Self {
        Self::native16()
            .or_else(Self::native8)
            .unwrap_or_else(Self::scalar)
    }

    /// Resolves a requested width; a forced width without native support is refused.
    pub fn resolve(choice: SimdChoice) -> Result<Self, SimdUnavailable> {
        let refuse = |width, needs| SimdUnavailable {
            width,
            needs,
            have: Self::auto().describe(),
        };
        match choice {
            SimdChoice::Auto => Ok(Self::auto()),
            SimdChoice::W1 => Ok(Self::scalar()),
            SimdChoice::W8 => Self::native8().ok_or_else(|| refuse(8, "AVX2 and FMA")),
            SimdChoice::W16 => Self::native16().ok_or_else(|| refuse(16, "AVX-512F and AVX-512BW")),
        }
    }

    /// Every form this CPU can run: the native ones it has and the portable ones.
    pub fn all_available() -> Vec<Self> {
        let mut v = vec![Self::scalar(), Self::portable(8), Self::portable(16)];
        v.extend(Self::native8());
        v.extend(Self::native16());
        v
    }

    /// Number of lanes: 1, 8 or 16.
    pub fn width(self) -> usize {
        match self.0 {
            Form::Scalar => 1,
            #[cfg(target_arch = "x86_64")]
            Form::ScalarFma => 1,
            Form::Portable8 => 8,
            Form::Portable16 => 16,
            #[cfg(target_arch = "x86_64")]
            Form::Avx2 => 8,
            #[cfg(target_arch = "x86_64")]
            Form::Avx512 => 16,
        }
    }

    /// Whether this is a native or scalar form rather than a portable one over arrays.
    pub fn is_native(self) -> bool {
        !matches!(self.0, Form::Portable8 | Form::Portable16)
    }

    /// For messages and headers, e.g. `16 (AVX-512)`.
    pub fn describe(self) -> String {
        let isa = match self.0 {
            Form::Scalar => "scalar",
            #[cfg(target_arch = "x86_64")]
            Form::ScalarFma => "scalar, FMA",
            Form::Portable8 | Form::Portable16 => "portable",
            #[cfg(target_arch = "x86_64")]
            Form::Avx2 => "AVX2+FMA",
            #[cfg(target_arch = "x86_64")]
            Form::Avx512 => "AVX-512",
        };
        format!("{} ({isa})", self.width())
    }
}

/// How many codegen homes the entry points have: see [`LaneKernel::SHARD`].
pub const SHARDS: usize = 16;

/// A computation generic over the lane type, run by [`dispatch`] at one width.
pub trait LaneKernel {
    /// What the kernel returns.
    type Output;
    /// Which of the [`SHARDS`] copies of the entry points runs the kernel. The compiler
    /// places every instance of a generic function in the codegen unit of the module that
    /// defines it, so with one set of entry points every kernel variant (effects × lane
    /// forms) would be optimised in one unit, on one core, at the end of the build. Variants
    /// of similar size with different shards compile in parallel; the code is the same. Less
    /// than [`SHARDS`]: a `match` on the constant itself (no arithmetic) is what lets the
    /// compiler instantiate the one home's entry points rather than all of them.
    const SHARD: usize = 0;
    /// Mark `#[inline(always)]`: see the module docs.
    fn run<F: Float>(self) -> Self::Output;
}

/// Work over lanes of the one type `F` that a kernel keeps out of line, run by
/// [`Float::enter_typed`].
pub trait TypedKernel<F> {
    /// What the work returns.
    type Output;
    /// As [`LaneKernel::SHARD`].
    const SHARD: usize = 0;
    /// Mark `#[inline(always)]`, so the work is compiled inside the entry point.
    fn run(self) -> Self::Output;
}

/// The dispatch of each codegen home (see [`LaneKernel::SHARD`]), out of line so that the
/// kernels it inlines compile in that home.
macro_rules! homes {
    ($($i:literal => $home:ident),* $(,)?) => {
        $(
            mod $home {
                use super::{Form, LaneKernel, PortableF32};

                #[inline(never)]
                pub(super) fn run<K: LaneKernel>(form: Form, k: K) -> K::Output {
                    match form {
                        Form::Scalar => k.run::<f32>(),
                        Form::Portable8 => k.run::<PortableF32<8>>(),
                        Form::Portable16 => k.run::<PortableF32<16>>(),
                        // SAFETY: a `Lanes` naming a native form is built only by
                        // `Lanes::scalar`, `native8` and `native16` after
                        // `is_x86_feature_detected!` found every feature the entry point
                        // enables.
                        #[cfg(target_arch = "x86_64")]
                        Form::ScalarFma => unsafe { super::x86::$home::entry_fma(k) },
                        #[cfg(target_arch = "x86_64")]
                        // SAFETY: as above.
                        Form::Avx2 => unsafe { super::x86::$home::entry_avx2(k) },
                        #[cfg(target_arch = "x86_64")]
                        // SAFETY: as above.
                        Form::Avx512 => unsafe { super::x86::$home::entry_avx512(k) },
                    }
                }
            }
        )*

        /// Runs `k` instantiated at the lane type of `lanes`, inside an entry point compiled
        /// for that width's instruction set.
        pub fn dispatch<K: LaneKernel>(lanes: Lanes, k: K) -> K::Output {
            // A home past the last is refused when the kernel is compiled.
            const { assert!(K::SHARD < SHARDS) };
            match K::SHARD {
                $($i => $home::run(lanes.0, k),)*
                _ => unreachable!(),
            }
        }
    };
}

homes!(
    0 => home0, 1 => home1, 2 => home2, 3 => home3, 4 => home4, 5 => home5, 6 => home6,
    7 => home7, 8 => home8, 9 => home9, 10 => home10, 11 => home11, 12 => home12,
    13 => home13, 14 => home14, 15 => home15,
);

#[cfg(test)]
mod tests {
    use super::SimdChoice;

    #[test]
    fn simd_choice_reads_widths_and_auto_in_ron() {
        let read = |s: &str| ron::from_str::<SimdChoice>(s).map_err(|e| e.to_string());
        assert_eq!(read("16"), Ok(SimdChoice::W16));
        assert_eq!(read("8"), Ok(SimdChoice::W8));
        assert_eq!(read("1"), Ok(SimdChoice::W1));
        assert_eq!(read("\"auto\""), Ok(SimdChoice::Auto));
        assert!(read("Auto").unwrap_err().contains("in quotes"));
        assert!(read("Fast").unwrap_err().contains("in quotes"));
        let e = read("4").unwrap_err();
        assert!(e.contains("Auto, 16, 8, 1"), "{e}");
    }
}
