//! Native lanes on x86-64: 8 lanes in AVX2 + FMA registers, 16 in AVX-512 registers (F for
//! the arithmetic, BW for the byte shuffle of `reverse_bits`).
//!
//! Every `unsafe` block here calls intrinsics of the instruction set its type belongs to. The
//! types are private to `simd`, so a value of one exists only inside a kernel that
//! [`super::dispatch`] runs after detecting that instruction set: that is the invariant each
//! `// SAFETY:` comment refers to ("the type's invariant").

use super::{Float, LaneKernel, Mask, TypedKernel, UInt};
use std::arch::x86_64::*;
use std::ops::{
    Add, AddAssign, BitAnd, BitAndAssign, BitOr, BitOrAssign, BitXor, Div, DivAssign, Mul,
    MulAssign, Neg, Not, Sub, SubAssign,
};

/// Runs `k` (of kernel type `K`) through entry point `$entry` of `K`'s home: the match on the
/// constant itself is what leaves one arm per instantiation (see [`LaneKernel::SHARD`]). A
/// home past the last is refused when the kernel is compiled. Expands to unsafe calls: the
/// caller guarantees the entry point's CPU features.
macro_rules! in_home {
    ($K:ident, $k:ident, $entry:ident; $($i:literal => $home:ident),*) => {{
        const { assert!($K::SHARD < super::SHARDS) };
        match $K::SHARD {
            $($i => unsafe { $home::$entry($k) },)*
            _ => unreachable!(),
        }
    }};
}

/// The entry points, once in each codegen home (see [`LaneKernel::SHARD`]). Each is
/// `#[target_feature]`, so a kernel it inlines is compiled for that instruction set.
macro_rules! homes {
    ($($i:literal => $home:ident),* $(,)?) => {
        $(
            pub(super) mod $home {
                use super::{F16, F8};
                use crate::simd::{LaneKernel, TypedKernel};

                /// Width 1 compiled with hardware FMA: the same bits as plain scalar code.
                #[target_feature(enable = "fma")]
                pub(in crate::simd) fn entry_fma<K: LaneKernel>(k: K) -> K::Output {
                    k.run::<f32>()
                }

                #[target_feature(enable = "avx2,fma")]
                pub(in crate::simd) fn entry_avx2<K: LaneKernel>(k: K) -> K::Output {
                    k.run::<F8>()
                }

                #[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
                pub(in crate::simd) fn entry_avx512<K: LaneKernel>(k: K) -> K::Output {
                    k.run::<F16>()
                }

                #[target_feature(enable = "fma")]
                pub(super) fn entry_fma_typed<K: TypedKernel<f32>>(k: K) -> K::Output {
                    k.run()
                }

                /// Width 1 without FMA, out of line so that it too compiles in this home.
                #[inline(never)]
                pub(super) fn plain_typed<K: TypedKernel<f32>>(k: K) -> K::Output {
                    k.run()
                }

                #[target_feature(enable = "avx2,fma")]
                pub(super) fn entry_avx2_typed<K: TypedKernel<F8>>(k: K) -> K::Output {
                    k.run()
                }

                #[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
                pub(super) fn entry_avx512_typed<K: TypedKernel<F16>>(k: K) -> K::Output {
                    k.run()
                }
            }
        )*

        /// [`Float::enter`] at width 8, in the kernel's home.
        ///
        /// # Safety
        /// The CPU has AVX2 and FMA.
        #[inline(always)]
        unsafe fn entry_avx2<K: LaneKernel>(k: K) -> K::Output {
            // SAFETY: the caller's.
            in_home!(K, k, entry_avx2; $($i => $home),*)
        }

        /// [`Float::enter`] at width 16, in the kernel's home.
        ///
        /// # Safety
        /// The CPU has AVX-512F/BW, AVX2 and FMA.
        #[inline(always)]
        unsafe fn entry_avx512<K: LaneKernel>(k: K) -> K::Output {
            // SAFETY: the caller's.
            in_home!(K, k, entry_avx512; $($i => $home),*)
        }

        /// [`Float::enter_typed`] at width 8, in the kernel's home.
        ///
        /// # Safety
        /// The CPU has AVX2 and FMA.
        #[inline(always)]
        unsafe fn entry_avx2_typed<K: TypedKernel<F8>>(k: K) -> K::Output {
            // SAFETY: the caller's.
            in_home!(K, k, entry_avx2_typed; $($i => $home),*)
        }

        /// [`Float::enter_typed`] at width 16, in the kernel's home.
        ///
        /// # Safety
        /// The CPU has AVX-512F/BW, AVX2 and FMA.
        #[inline(always)]
        unsafe fn entry_avx512_typed<K: TypedKernel<F16>>(k: K) -> K::Output {
            // SAFETY: the caller's.
            in_home!(K, k, entry_avx512_typed; $($i => $home),*)
        }

        /// Width 1's [`Float::enter_typed`]: the FMA entry where the CPU has FMA (its `mul_add`
        /// is then one instruction, not a call into libm; both round once, so the bits are the
        /// same), in the kernel's home.
        #[inline(always)]
        pub(super) fn enter_scalar_typed<K: TypedKernel<f32>>(k: K) -> K::Output {
            let fma = is_x86_feature_detected!("fma");
            // A home past the last is refused when the kernel is compiled.
            const { assert!(K::SHARD < super::SHARDS) };
            match K::SHARD {
                $($i => if fma {
                    // SAFETY: FMA, all the entry enables, was just detected.
                    unsafe { $home::entry_fma_typed(k) }
                } else {
                    $home::plain_typed(k)
                },)*
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

/// Binary operator traits from one intrinsic each.
macro_rules! binops {
    ($ty:ident, $( $tr:ident $m:ident $tra:ident $ma:ident = $f:ident ),* $(,)?) => {$(
        impl $tr for $ty {
            type Output = Self;
            #[inline(always)]
            fn $m(self, o: Self) -> Self {
                // SAFETY: the type's invariant.
                $ty(unsafe { $f(self.0, o.0) })
            }
        }
        impl $tra for $ty {
            #[inline(always)]
            fn $ma(&mut self, o: Self) {
                *self = $tr::$m(*self, o);
            }
        }
    )*};
}

/// Binary operators without an assigning form.
macro_rules! binops_plain {
    ($ty:ident, $( $tr:ident $m:ident = $f:ident ),* $(,)?) => {$(
        impl $tr for $ty {
            type Output = Self;
            #[inline(always)]
            fn $m(self, o: Self) -> Self {
                // SAFETY: the type's invariant.
                $ty(unsafe { $f(self.0, o.0) })
            }
        }
    )*};
}

/// Panics unless every lane's index addresses `len` values: the hardware gathers below read
/// `s[idx]` unchecked.
#[inline(always)]
fn check_gather<U: UInt>(len: usize, idx: U) {
    let len = u32::try_from(len).unwrap_or(u32::MAX).min(i32::MAX as u32);
    assert!(
        idx.lt(U::splat(len)).all(),
        "gather index out of bounds (len {len})"
    );
}

// ---------------------------------------------------------------- AVX2 + FMA, 8 lanes

#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub(super) struct F8(__m256);

#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub(super) struct U8(__m256i);

/// All ones or all zeros per lane.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub(super) struct M8(__m256i);

binops!(F8,
    Add add AddAssign add_assign = _mm256_add_ps,
    Sub sub SubAssign sub_assign = _mm256_sub_ps,
    Mul mul MulAssign mul_assign = _mm256_mul_ps,
    Div div DivAssign div_assign = _mm256_div_ps,
);
binops_plain!(U8,
    BitAnd bitand = _mm256_and_si256,
    BitOr bitor = _mm256_or_si256,
    BitXor bitxor = _mm256_xor_si256,
);
binops!(M8,
    BitAnd bitand BitAndAssign bitand_assign = _mm256_and_si256,
    BitOr bitor BitOrAssign bitor_assign = _mm256_or_si256,
);
binops_plain!(M8, BitXor bitxor = _mm256_xor_si256);

impl Neg for F8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
    }
}

impl Not for U8 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_xor_si256(self.0, _mm256_set1_epi32(-1)) })
    }
}

impl Not for M8 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        // SAFETY: the type's invariant.
        M8(unsafe { _mm256_xor_si256(self.0, _mm256_set1_epi32(-1)) })
    }
}

impl Mask for M8 {
    const WIDTH: usize = 8;
    #[inline(always)]
    fn splat(b: bool) -> Self {
        // SAFETY: the type's invariant.
        M8(unsafe { _mm256_set1_epi32(-(b as i32)) })
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        let a: [i32; 8] = std::array::from_fn(|i| -(f(i) as i32));
        // SAFETY: the type's invariant; `a` holds 8 i32.
        M8(unsafe { _mm256_loadu_si256(a.as_ptr().cast()) })
    }
    #[inline(always)]
    fn lane(self, i: usize) -> bool {
        self.bits() >> i & 1 != 0
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        // SAFETY: the type's invariant.
        unsafe { _mm256_movemask_ps(_mm256_castsi256_ps(self.0)) as u32 }
    }
    #[inline(always)]
    fn any(self) -> bool {
        // SAFETY: the type's invariant.
        unsafe { _mm256_testz_si256(self.0, self.0) == 0 }
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.bits() == 0xff
    }
}

impl F8 {
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        let mut a = [0.0f32; 8];
        // SAFETY: the type's invariant; `a` has room for 8 f32.
        unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) };
        a
    }
}

impl Float for F8 {
    type Mask = M8;
    type U32 = U8;
    const WIDTH: usize = 8;

    #[inline(always)]
    fn enter<K: LaneKernel>(k: K) -> K::Output {
        // SAFETY: the type's invariant: code that names this type runs inside a kernel that
        // `dispatch` started after detecting the instructions `entry_avx2` enables.
        unsafe { entry_avx2(k) }
    }

    #[inline(always)]
    fn enter_typed<K: TypedKernel<Self>>(k: K) -> K::Output {
        // SAFETY: the type's invariant, as for `enter`.
        unsafe { entry_avx2_typed(k) }
    }

    #[inline(always)]
    fn splat(x: f32) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_set1_ps(x) })
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        let a: [f32; 8] = std::array::from_fn(f);
        Self::load(&a)
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn gather(s: &[f32], idx: U8) -> Self {
        check_gather(s.len(), idx);
        // SAFETY: the type's invariant; every index is below `s.len()` and `i32::MAX`
        // (checked above), so each lane reads inside `s`.
        F8(unsafe { _mm256_i32gather_ps::<4>(s.as_ptr(), idx.0) })
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        assert!(s.len() >= 8, "F8::load needs 8 values, got {}", s.len());
        // SAFETY: the type's invariant; the slice holds at least 8 f32 (checked above).
        F8(unsafe { _mm256_loadu_ps(s.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        assert!(
            out.len() >= 8,
            "F8::store needs room for 8, got {}",
            out.len()
        );
        // SAFETY: the type's invariant; the slice has room for 8 f32 (checked above).
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M8 {
        // SAFETY: the type's invariant.
        M8(unsafe { _mm256_castps_si256(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0)) })
    }
    #[inline(always)]
    fn ne(self, o: Self) -> M8 {
        // SAFETY: the type's invariant.
        M8(unsafe { _mm256_castps_si256(_mm256_cmp_ps::<_CMP_NEQ_UQ>(self.0, o.0)) })
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M8 {
        // SAFETY: the type's invariant.
        M8(unsafe { _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0)) })
    }
    #[inline(always)]
    fn le(self, o: Self) -> M8 {
        // SAFETY: the type's invariant.
        M8(unsafe { _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0)) })
    }
    #[inline(always)]
    fn select(m: M8, a: Self, b: Self) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_blendv_ps(b.0, a.0, _mm256_castsi256_ps(m.0)) })
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_min_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_max_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_fmadd_ps(self.0, b.0, c.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // No closure here: one that is not inlined is compiled without the entry point's
        // target features, and its intrinsics become calls.
        // SAFETY: the type's invariant.
        F8(unsafe {
            _mm256_castsi256_ps(_mm256_and_si256(
                _mm256_castps_si256(self.0),
                _mm256_set1_epi32(0x7fff_ffff),
            ))
        })
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        // SAFETY: the type's invariant.
        unsafe {
            let mag = _mm256_and_si256(_mm256_castps_si256(self.0), _mm256_set1_epi32(0x7fff_ffff));
            let sgn = _mm256_and_si256(_mm256_castps_si256(sign.0), _mm256_set1_epi32(i32::MIN));
            F8(_mm256_castsi256_ps(_mm256_or_si256(mag, sgn)))
        }
    }
    #[inline(always)]
    fn floor(self) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_round_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(self.0) })
    }
    #[inline(always)]
    fn round(self) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_round_ps::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(self.0) })
    }
    #[inline(always)]
    fn to_bits(self) -> U8 {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_castps_si256(self.0) })
    }
    #[inline(always)]
    fn from_bits(u: U8) -> Self {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_castsi256_ps(u.0) })
    }
    #[inline(always)]
    fn to_i32_bits(self) -> U8 {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_cvttps_epi32(self.0) })
    }
}

impl U8 {
    #[inline(always)]
    fn to_array(self) -> [u32; 8] {
        let mut a = [0u32; 8];
        // SAFETY: the type's invariant; `a` has room for 8 u32.
        unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), self.0) };
        a
    }
}

impl UInt for U8 {
    type Mask = M8;
    type Float = F8;
    const WIDTH: usize = 8;

    #[inline(always)]
    fn splat(x: u32) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_set1_epi32(x as i32) })
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> u32) -> Self {
        let a: [u32; 8] = std::array::from_fn(f);
        // SAFETY: the type's invariant; `a` holds 8 u32.
        U8(unsafe { _mm256_loadu_si256(a.as_ptr().cast()) })
    }
    #[inline(always)]
    fn lane(self, i: usize) -> u32 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_add_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn wrapping_sub(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_sub_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn wrapping_mul(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_mullo_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn shli<const N: u32>(self) -> Self {
        // A count register built from a constant folds to the immediate form.
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_sll_epi32(self.0, _mm_cvtsi32_si128(N as i32)) })
    }
    #[inline(always)]
    fn shri<const N: u32>(self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_srl_epi32(self.0, _mm_cvtsi32_si128(N as i32)) })
    }
    #[inline(always)]
    fn srai<const N: u32>(self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_sra_epi32(self.0, _mm_cvtsi32_si128(N as i32)) })
    }
    #[inline(always)]
    fn shl_var(self, n: Self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_sllv_epi32(self.0, n.0) })
    }
    #[inline(always)]
    fn shr_var(self, n: Self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_srlv_epi32(self.0, n.0) })
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M8 {
        // SAFETY: the type's invariant.
        M8(unsafe { _mm256_cmpeq_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M8 {
        // AVX2 compares signed only: flipping the sign bits orders unsigned values as signed.
        // SAFETY: the type's invariant.
        unsafe {
            let s = _mm256_set1_epi32(i32::MIN);
            M8(_mm256_cmpgt_epi32(
                _mm256_xor_si256(o.0, s),
                _mm256_xor_si256(self.0, s),
            ))
        }
    }
    #[inline(always)]
    fn lt_i32(self, o: Self) -> M8 {
        // SAFETY: the type's invariant.
        M8(unsafe { _mm256_cmpgt_epi32(o.0, self.0) })
    }
    #[inline(always)]
    fn select(m: M8, a: Self, b: Self) -> Self {
        // SAFETY: the type's invariant.
        U8(unsafe { _mm256_blendv_epi8(b.0, a.0, m.0) })
    }
    #[inline(always)]
    fn i32_to_f32(self) -> F8 {
        // SAFETY: the type's invariant.
        F8(unsafe { _mm256_cvtepi32_ps(self.0) })
    }
    #[inline(always)]
    fn reverse_bits(self) -> Self {
        // Each byte's nibbles reversed by table, swapped, then the bytes reversed: eight
        // instructions instead of the generic fifteen shifts and masks.
        // SAFETY: the type's invariant.
        U8(unsafe {
            let lut = _mm256_setr_epi8(
                0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15, 0, 8, 4, 12, 2, 10, 6, 14, 1,
                9, 5, 13, 3, 11, 7, 15,
            );
            let nib = _mm256_set1_epi8(0x0f);
            let lo = _mm256_shuffle_epi8(lut, _mm256_and_si256(self.0, nib));
            let hi =
                _mm256_shuffle_epi8(lut, _mm256_and_si256(_mm256_srli_epi16::<4>(self.0), nib));
            let bytes = _mm256_or_si256(_mm256_slli_epi16::<4>(lo), hi);
            let order = _mm256_setr_epi8(
                3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4, 11,
                10, 9, 8, 15, 14, 13, 12,
            );
            _mm256_shuffle_epi8(bytes, order)
        })
    }
}

// ---------------------------------------------------------------- AVX-512F, 16 lanes

#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub(super) struct F16(__m512);

#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub(super) struct U16(__m512i);

/// One bit per lane, in a mask register.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub(super) struct M16(__mmask16);

binops!(F16,
    Add add AddAssign add_assign = _mm512_add_ps,
    Sub sub SubAssign sub_assign = _mm512_sub_ps,
    Mul mul MulAssign mul_assign = _mm512_mul_ps,
    Div div DivAssign div_assign = _mm512_div_ps,
);
binops_plain!(U16,
    BitAnd bitand = _mm512_and_si512,
    BitOr bitor = _mm512_or_si512,
    BitXor bitxor = _mm512_xor_si512,
);

impl BitAnd for M16 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        M16(self.0 & o.0)
    }
}
impl BitOr for M16 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        M16(self.0 | o.0)
    }
}
impl BitXor for M16 {
    type Output = Self;
    #[inline(always)]
    fn bitxor(self, o: Self) -> Self {
        M16(self.0 ^ o.0)
    }
}
impl BitAndAssign for M16 {
    #[inline(always)]
    fn bitand_assign(&mut self, o: Self) {
        self.0 &= o.0;
    }
}
impl BitOrAssign for M16 {
    #[inline(always)]
    fn bitor_assign(&mut self, o: Self) {
        self.0 |= o.0;
    }
}
impl Not for M16 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        M16(!self.0)
    }
}

impl Neg for F16 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // Bitwise float operations through the integer forms (`_mm512_xor_ps` needs
        // AVX-512DQ), written out: a closure that is not inlined loses the target features.
        // SAFETY: the type's invariant.
        F16(unsafe {
            _mm512_castsi512_ps(_mm512_xor_si512(
                _mm512_castps_si512(self.0),
                _mm512_set1_epi32(i32::MIN),
            ))
        })
    }
}

impl Not for U16 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_xor_si512(self.0, _mm512_set1_epi32(-1)) })
    }
}

impl Mask for M16 {
    const WIDTH: usize = 16;
    #[inline(always)]
    fn splat(b: bool) -> Self {
        M16(if b { 0xffff } else { 0 })
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        M16((0..16).fold(0, |acc, i| acc | (u16::from(f(i)) << i)))
    }
    #[inline(always)]
    fn lane(self, i: usize) -> bool {
        self.0 >> i & 1 != 0
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        u32::from(self.0)
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0 != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.0 == 0xffff
    }
}

impl F16 {
    #[inline(always)]
    fn to_array(self) -> [f32; 16] {
        let mut a = [0.0f32; 16];
        // SAFETY: the type's invariant; `a` has room for 16 f32.
        unsafe { _mm512_storeu_ps(a.as_mut_ptr(), self.0) };
        a
    }
}

impl Float for F16 {
    type Mask = M16;
    type U32 = U16;
    const WIDTH: usize = 16;

    #[inline(always)]
    fn enter<K: LaneKernel>(k: K) -> K::Output {
        // SAFETY: the type's invariant: code that names this type runs inside a kernel that
        // `dispatch` started after detecting the instructions `entry_avx512` enables.
        unsafe { entry_avx512(k) }
    }

    #[inline(always)]
    fn enter_typed<K: TypedKernel<Self>>(k: K) -> K::Output {
        // SAFETY: the type's invariant, as for `enter`.
        unsafe { entry_avx512_typed(k) }
    }

    #[inline(always)]
    fn splat(x: f32) -> Self {
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_set1_ps(x) })
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        let a: [f32; 16] = std::array::from_fn(f);
        Self::load(&a)
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn gather(s: &[f32], idx: U16) -> Self {
        check_gather(s.len(), idx);
        // SAFETY: the type's invariant; every index is below `s.len()` and `i32::MAX`
        // (checked above), so each lane reads inside `s`.
        F16(unsafe { _mm512_i32gather_ps::<4>(idx.0, s.as_ptr()) })
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        assert!(s.len() >= 16, "F16::load needs 16 values, got {}", s.len());
        // SAFETY: the type's invariant; the slice holds at least 16 f32 (checked above).
        F16(unsafe { _mm512_loadu_ps(s.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        assert!(
            out.len() >= 16,
            "F16::store needs room for 16, got {}",
            out.len()
        );
        // SAFETY: the type's invariant; the slice has room for 16 f32 (checked above).
        unsafe { _mm512_storeu_ps(out.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M16 {
        // SAFETY: the type's invariant.
        M16(unsafe { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn ne(self, o: Self) -> M16 {
        // SAFETY: the type's invariant.
        M16(unsafe { _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M16 {
        // SAFETY: the type's invariant.
        M16(unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn le(self, o: Self) -> M16 {
        // SAFETY: the type's invariant.
        M16(unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn select(m: M16, a: Self, b: Self) -> Self {
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_mask_blend_ps(m.0, b.0, a.0) })
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_min_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_max_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_fmadd_ps(self.0, b.0, c.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // As in `neg`: integer forms (`_mm512_and_ps` needs AVX-512DQ), no closure.
        // SAFETY: the type's invariant.
        F16(unsafe {
            _mm512_castsi512_ps(_mm512_and_si512(
                _mm512_castps_si512(self.0),
                _mm512_set1_epi32(0x7fff_ffff),
            ))
        })
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        // SAFETY: the type's invariant.
        unsafe {
            let mag = _mm512_and_si512(_mm512_castps_si512(self.0), _mm512_set1_epi32(0x7fff_ffff));
            let sgn = _mm512_and_si512(_mm512_castps_si512(sign.0), _mm512_set1_epi32(i32::MIN));
            F16(_mm512_castsi512_ps(_mm512_or_si512(mag, sgn)))
        }
    }
    #[inline(always)]
    fn floor(self) -> Self {
        // Round toward −∞ (mode 1), exceptions suppressed (bit 3).
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_roundscale_ps::<0x09>(self.0) })
    }
    #[inline(always)]
    fn round(self) -> Self {
        // Round to nearest even (mode 0), exceptions suppressed (bit 3).
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_roundscale_ps::<0x08>(self.0) })
    }
    #[inline(always)]
    fn to_bits(self) -> U16 {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_castps_si512(self.0) })
    }
    #[inline(always)]
    fn from_bits(u: U16) -> Self {
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_castsi512_ps(u.0) })
    }
    #[inline(always)]
    fn to_i32_bits(self) -> U16 {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_cvttps_epi32(self.0) })
    }
}

impl U16 {
    #[inline(always)]
    fn to_array(self) -> [u32; 16] {
        let mut a = [0u32; 16];
        // SAFETY: the type's invariant; `a` has room for 16 u32.
        unsafe { _mm512_storeu_si512(a.as_mut_ptr().cast(), self.0) };
        a
    }
}

impl UInt for U16 {
    type Mask = M16;
    type Float = F16;
    const WIDTH: usize = 16;

    #[inline(always)]
    fn splat(x: u32) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_set1_epi32(x as i32) })
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> u32) -> Self {
        let a: [u32; 16] = std::array::from_fn(f);
        // SAFETY: the type's invariant; `a` holds 16 u32.
        U16(unsafe { _mm512_loadu_si512(a.as_ptr().cast()) })
    }
    #[inline(always)]
    fn lane(self, i: usize) -> u32 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_add_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn wrapping_sub(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_sub_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn wrapping_mul(self, o: Self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_mullo_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn shli<const N: u32>(self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_sll_epi32(self.0, _mm_cvtsi32_si128(N as i32)) })
    }
    #[inline(always)]
    fn shri<const N: u32>(self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_srl_epi32(self.0, _mm_cvtsi32_si128(N as i32)) })
    }
    #[inline(always)]
    fn srai<const N: u32>(self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_sra_epi32(self.0, _mm_cvtsi32_si128(N as i32)) })
    }
    #[inline(always)]
    fn shl_var(self, n: Self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_sllv_epi32(self.0, n.0) })
    }
    #[inline(always)]
    fn shr_var(self, n: Self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_srlv_epi32(self.0, n.0) })
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M16 {
        // SAFETY: the type's invariant.
        M16(unsafe { _mm512_cmpeq_epi32_mask(self.0, o.0) })
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M16 {
        // SAFETY: the type's invariant.
        M16(unsafe { _mm512_cmplt_epu32_mask(self.0, o.0) })
    }
    #[inline(always)]
    fn lt_i32(self, o: Self) -> M16 {
        // SAFETY: the type's invariant.
        M16(unsafe { _mm512_cmplt_epi32_mask(self.0, o.0) })
    }
    #[inline(always)]
    fn select(m: M16, a: Self, b: Self) -> Self {
        // SAFETY: the type's invariant.
        U16(unsafe { _mm512_mask_blend_epi32(m.0, b.0, a.0) })
    }
    #[inline(always)]
    fn i32_to_f32(self) -> F16 {
        // SAFETY: the type's invariant.
        F16(unsafe { _mm512_cvtepi32_ps(self.0) })
    }
    #[inline(always)]
    fn reverse_bits(self) -> Self {
        // As for `U8`, with AVX-512BW's byte shuffle.
        // SAFETY: the type's invariant (its entry point enables AVX-512BW).
        U16(unsafe {
            let lut = _mm512_set4_epi32(0x0f07_0b03, 0x0d05_0901, 0x0e06_0a02, 0x0c04_0800);
            let nib = _mm512_set1_epi8(0x0f);
            let lo = _mm512_shuffle_epi8(lut, _mm512_and_si512(self.0, nib));
            let hi =
                _mm512_shuffle_epi8(lut, _mm512_and_si512(_mm512_srli_epi16::<4>(self.0), nib));
            let bytes = _mm512_or_si512(_mm512_slli_epi16::<4>(lo), hi);
            let order = _mm512_set4_epi32(0x0c0d_0e0f, 0x0809_0a0b, 0x0405_0607, 0x0001_0203);
            _mm512_shuffle_epi8(bytes, order)
        })
    }
}
