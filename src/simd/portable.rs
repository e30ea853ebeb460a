//! Width 1 (`f32`, `u32`, `bool`) and the portable widths (plain arrays of N lanes).
//!
//! Each operation is written to give exactly the bits of the native x86 instruction it stands
//! for (see [`Float`]'s semantics), so a portable kernel is a bit-exact oracle of the native one.

use super::{Float, LaneKernel, Mask, TypedKernel, UInt};
use std::ops::{
    Add, AddAssign, BitAnd, BitAndAssign, BitOr, BitOrAssign, BitXor, Div, DivAssign, Mul,
    MulAssign, Neg, Not, Sub, SubAssign,
};

#[inline(always)]
fn min1(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

#[inline(always)]
fn max1(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// `cvttps2dq`: truncation, with NaN and out-of-range values giving `i32::MIN`.
#[inline(always)]
fn cvtt1(x: f32) -> u32 {
    if (-2_147_483_648.0..2_147_483_648.0).contains(&x) {
        x as i32 as u32
    } else {
        i32::MIN as u32
    }
}

#[inline(always)]
fn abs1(x: f32) -> f32 {
    f32::from_bits(x.to_bits() & 0x7fff_ffff)
}

#[inline(always)]
fn copysign1(x: f32, s: f32) -> f32 {
    f32::from_bits((x.to_bits() & 0x7fff_ffff) | (s.to_bits() & 0x8000_0000))
}

#[inline(always)]
fn shl_var1(x: u32, n: u32) -> u32 {
    if n < 32 { x << n } else { 0 }
}

#[inline(always)]
fn shr_var1(x: u32, n: u32) -> u32 {
    if n < 32 { x >> n } else { 0 }
}

impl Mask for bool {
    const WIDTH: usize = 1;
    #[inline(always)]
    fn splat(b: bool) -> Self {
        b
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> bool {
        self
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        self as u32
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
}

impl Float for f32 {
    type Mask = bool;
    type U32 = u32;
    const WIDTH: usize = 1;

    #[inline(always)]
    fn enter<K: LaneKernel>(k: K) -> K::Output {
        k.run::<f32>()
    }

    #[inline(always)]
    fn enter_typed<K: TypedKernel<Self>>(k: K) -> K::Output {
        #[cfg(target_arch = "x86_64")]
        return super::x86::enter_scalar_typed(k);
        #[cfg(not(target_arch = "x86_64"))]
        k.run()
    }

    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> f32 {
        self
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        s[0]
    }
    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        out[0] = self;
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self == o
    }
    #[inline(always)]
    fn ne(self, o: Self) -> bool {
        self != o
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        // By masks, not a branch: the choice is data-dependent (which slab is nearer, which
        // root is valid), and a mispredicted branch per select made intersection 40 % slower.
        let mask = 0u32.wrapping_sub(u32::from(m));
        f32::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        min1(self, o)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        max1(self, o)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        f32::mul_add(self, b, c)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        abs1(self)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        copysign1(self, sign)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        f32::floor(self)
    }
    #[inline(always)]
    fn round(self) -> Self {
        f32::round_ties_even(self)
    }
    #[inline(always)]
    fn to_bits(self) -> u32 {
        f32::to_bits(self)
    }
    #[inline(always)]
    fn from_bits(u: u32) -> Self {
        f32::from_bits(u)
    }
    #[inline(always)]
    fn to_i32_bits(self) -> u32 {
        cvtt1(self)
    }
}

impl UInt for u32 {
    type Mask = bool;
    type Float = f32;
    const WIDTH: usize = 1;

    #[inline(always)]
    fn splat(x: u32) -> Self {
        x
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> u32) -> Self {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> u32 {
        self
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        u32::wrapping_add(self, o)
    }
    #[inline(always)]
    fn wrapping_sub(self, o: Self) -> Self {
        u32::wrapping_sub(self, o)
    }
    #[inline(always)]
    fn wrapping_mul(self, o: Self) -> Self {
        u32::wrapping_mul(self, o)
    }
    #[inline(always)]
    fn shli<const N: u32>(self) -> Self {
        self << N
    }
    #[inline(always)]
    fn shri<const N: u32>(self) -> Self {
        self >> N
    }
    #[inline(always)]
    fn srai<const N: u32>(self) -> Self {
        ((self as i32) >> N) as u32
    }
    #[inline(always)]
    fn shl_var(self, n: Self) -> Self {
        shl_var1(self, n)
    }
    #[inline(always)]
    fn shr_var(self, n: Self) -> Self {
        shr_var1(self, n)
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self == o
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn lt_i32(self, o: Self) -> bool {
        (self as i32) < (o as i32)
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        let mask = 0u32.wrapping_sub(u32::from(m));
        (a & mask) | (b & !mask)
    }
    #[inline(always)]
    fn i32_to_f32(self) -> f32 {
        self as i32 as f32
    }
}

// The portable forms are bit-exact oracles for tests (no CPU runs them by default: `auto` and
// forced widths take the native forms), so their operations stay out of line. Inlined, every
// operation's loop over the lanes was unrolled and re-vectorised inside each whole kernel:
// the 16 portable packet kernels took 10 of the crate's 15 minutes of build.

/// N boolean lanes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PortableMask<const N: usize>(pub [bool; N]);

/// N f32 lanes in a plain array.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct PortableF32<const N: usize>(pub [f32; N]);

/// N u32 lanes in a plain array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(64))]
pub struct PortableU32<const N: usize>(pub [u32; N]);

#[inline(always)]
fn map<T: Copy, U, const N: usize>(a: [T; N], f: impl Fn(T) -> U) -> [U; N] {
    a.map(f)
}

#[inline(always)]
fn zip<T: Copy, U, const N: usize>(a: [T; N], b: [T; N], f: impl Fn(T, T) -> U) -> [U; N] {
    std::array::from_fn(|i| f(a[i], b[i]))
}

macro_rules! portable_binop {
    ($ty:ident, $tr:ident, $m:ident, $tra:ident, $ma:ident, $f:expr) => {
        impl<const N: usize> $tr for $ty<N> {
            type Output = Self;
            #[inline(never)]
            fn $m(self, o: Self) -> Self {
                $ty(zip(self.0, o.0, $f))
            }
        }
        impl<const N: usize> $tra for $ty<N> {
            #[inline(never)]
            fn $ma(&mut self, o: Self) {
                *self = $tr::$m(*self, o);
            }
        }
    };
    ($ty:ident, $tr:ident, $m:ident, $f:expr) => {
        impl<const N: usize> $tr for $ty<N> {
            type Output = Self;
            #[inline(never)]
            fn $m(self, o: Self) -> Self {
                $ty(zip(self.0, o.0, $f))
            }
        }
    };
}

portable_binop!(PortableF32, Add, add, AddAssign, add_assign, |a, b| a + b);
portable_binop!(PortableF32, Sub, sub, SubAssign, sub_assign, |a, b| a - b);
portable_binop!(PortableF32, Mul, mul, MulAssign, mul_assign, |a, b| a * b);
portable_binop!(PortableF32, Div, div, DivAssign, div_assign, |a, b| a / b);
portable_binop!(PortableU32, BitAnd, bitand, |a, b| a & b);
portable_binop!(PortableU32, BitOr, bitor, |a, b| a | b);
portable_binop!(PortableU32, BitXor, bitxor, |a, b| a ^ b);
portable_binop!(
    PortableMask,
    BitAnd,
    bitand,
    BitAndAssign,
    bitand_assign,
    |a, b| a & b
);
portable_binop!(
    PortableMask,
    BitOr,
    bitor,
    BitOrAssign,
    bitor_assign,
    |a, b| a | b
);
portable_binop!(PortableMask, BitXor, bitxor, |a, b| a ^ b);

impl<const N: usize> Neg for PortableF32<N> {
    type Output = Self;
    #[inline(never)]
    fn neg(self) -> Self {
        // Flips the sign bit, as `xorps` with -0.0 does (so -NaN keeps its payload).
        PortableF32(map(self.0, |a| f32::from_bits(a.to_bits() ^ 0x8000_0000)))
    }
}

impl<const N: usize> Not for PortableU32<N> {
    type Output = Self;
    #[inline(never)]
    fn not(self) -> Self {
        PortableU32(map(self.0, |a| !a))
    }
}

impl<const N: usize> Not for PortableMask<N> {
    type Output = Self;
    #[inline(never)]
    fn not(self) -> Self {
        PortableMask(map(self.0, |a| !a))
    }
}

impl<const N: usize> Mask for PortableMask<N> {
    const WIDTH: usize = N;
    #[inline(never)]
    fn splat(b: bool) -> Self {
        PortableMask([b; N])
    }
    #[inline]
    fn from_fn(f: impl FnMut(usize) -> bool) -> Self {
        PortableMask(std::array::from_fn(f))
    }
    #[inline]
    fn lane(self, i: usize) -> bool {
        self.0[i]
    }
    #[inline(never)]
    fn bits(self) -> u32 {
        self.0
            .iter()
            .enumerate()
            .fold(0, |acc, (i, &b)| acc | ((b as u32) << i))
    }
    #[inline(never)]
    fn any(self) -> bool {
        self.0.iter().any(|&b| b)
    }
    #[inline(never)]
    fn all(self) -> bool {
        self.0.iter().all(|&b| b)
    }
}

impl<const N: usize> Float for PortableF32<N> {
    type Mask = PortableMask<N>;
    type U32 = PortableU32<N>;
    const WIDTH: usize = N;

    #[inline(always)]
    fn enter<K: LaneKernel>(k: K) -> K::Output {
        k.run::<Self>()
    }

    #[inline(always)]
    fn enter_typed<K: TypedKernel<Self>>(k: K) -> K::Output {
        k.run()
    }

    #[inline(never)]
    fn splat(x: f32) -> Self {
        PortableF32([x; N])
    }
    #[inline]
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        PortableF32(std::array::from_fn(f))
    }
    #[inline]
    fn lane(self, i: usize) -> f32 {
        self.0[i]
    }
    #[inline(never)]
    fn load(s: &[f32]) -> Self {
        PortableF32(s[..N].try_into().expect("slice of N values"))
    }
    #[inline(never)]
    fn store(self, out: &mut [f32]) {
        out[..N].copy_from_slice(&self.0);
    }
    #[inline(never)]
    fn eq(self, o: Self) -> Self::Mask {
        PortableMask(zip(self.0, o.0, |a, b| a == b))
    }
    #[inline(never)]
    fn ne(self, o: Self) -> Self::Mask {
        PortableMask(zip(self.0, o.0, |a, b| a != b))
    }
    #[inline(never)]
    fn lt(self, o: Self) -> Self::Mask {
        PortableMask(zip(self.0, o.0, |a, b| a < b))
    }
    #[inline(never)]
    fn le(self, o: Self) -> Self::Mask {
        PortableMask(zip(self.0, o.0, |a, b| a <= b))
    }
    #[inline(never)]
    fn select(m: Self::Mask, a: Self, b: Self) -> Self {
        PortableF32(std::array::from_fn(
            |i| if m.0[i] { a.0[i] } else { b.0[i] },
        ))
    }
    #[inline(never)]
    fn min(self, o: Self) -> Self {
        PortableF32(zip(self.0, o.0, min1))
    }
    #[inline(never)]
    fn max(self, o: Self) -> Self {
        PortableF32(zip(self.0, o.0, max1))
    }
    #[inline(never)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        PortableF32(std::array::from_fn(|i| self.0[i].mul_add(b.0[i], c.0[i])))
    }
    #[inline(never)]
    fn sqrt(self) -> Self {
        PortableF32(map(self.0, f32::sqrt))
    }
    #[inline(never)]
    fn abs(self) -> Self {
        PortableF32(map(self.0, abs1))
    }
    #[inline(never)]
    fn copysign(self, sign: Self) -> Self {
        PortableF32(zip(self.0, sign.0, copysign1))
    }
    #[inline(never)]
    fn floor(self) -> Self {
        PortableF32(map(self.0, f32::floor))
    }
    #[inline(never)]
    fn round(self) -> Self {
        PortableF32(map(self.0, f32::round_ties_even))
    }
    #[inline(never)]
    fn to_bits(self) -> Self::U32 {
        PortableU32(map(self.0, f32::to_bits))
    }
    #[inline(never)]
    fn from_bits(u: Self::U32) -> Self {
        PortableF32(map(u.0, f32::from_bits))
    }
    #[inline(never)]
    fn to_i32_bits(self) -> Self::U32 {
        PortableU32(map(self.0, cvtt1))
    }
}

impl<const N: usize> UInt for PortableU32<N> {
    type Mask = PortableMask<N>;
    type Float = PortableF32<N>;
    const WIDTH: usize = N;

    #[inline(never)]
    fn splat(x: u32) -> Self {
        PortableU32([x; N])
    }
    #[inline]
    fn from_fn(f: impl FnMut(usize) -> u32) -> Self {
        PortableU32(std::array::from_fn(f))
    }
    #[inline]
    fn lane(self, i: usize) -> u32 {
        self.0[i]
    }
    #[inline(never)]
    fn wrapping_add(self, o: Self) -> Self {
        PortableU32(zip(self.0, o.0, u32::wrapping_add))
    }
    #[inline(never)]
    fn wrapping_sub(self, o: Self) -> Self {
        PortableU32(zip(self.0, o.0, u32::wrapping_sub))
    }
    #[inline(never)]
    fn wrapping_mul(self, o: Self) -> Self {
        PortableU32(zip(self.0, o.0, u32::wrapping_mul))
    }
    #[inline(never)]
    fn shli<const S: u32>(self) -> Self {
        PortableU32(map(self.0, |a| a << S))
    }
    #[inline(never)]
    fn shri<const S: u32>(self) -> Self {
        PortableU32(map(self.0, |a| a >> S))
    }
    #[inline(never)]
    fn srai<const S: u32>(self) -> Self {
        PortableU32(map(self.0, |a| ((a as i32) >> S) as u32))
    }
    #[inline(never)]
    fn shl_var(self, n: Self) -> Self {
        PortableU32(zip(self.0, n.0, shl_var1))
    }
    #[inline(never)]
    fn shr_var(self, n: Self) -> Self {
        PortableU32(zip(self.0, n.0, shr_var1))
    }
    #[inline(never)]
    fn eq(self, o: Self) -> Self::Mask {
        PortableMask(zip(self.0, o.0, |a, b| a == b))
    }
    #[inline(never)]
    fn lt(self, o: Self) -> Self::Mask {
        PortableMask(zip(self.0, o.0, |a, b| a < b))
    }
    #[inline(never)]
    fn lt_i32(self, o: Self) -> Self::Mask {
        PortableMask(zip(self.0, o.0, |a, b| (a as i32) < (b as i32)))
    }
    #[inline(never)]
    fn select(m: Self::Mask, a: Self, b: Self) -> Self {
        PortableU32(std::array::from_fn(
            |i| if m.0[i] { a.0[i] } else { b.0[i] },
        ))
    }
    #[inline(never)]
    fn i32_to_f32(self) -> Self::Float {
        PortableF32(map(self.0, |a| a as i32 as f32))
    }
}
