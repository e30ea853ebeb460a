//! Per-pixel sample generators that are pure functions of
//! (seed, pixel, sample index, dimension).
//!
//! Having no state means any thread, or any later render pass, recomputes the
//! same value, so sample ranges rendered separately can be merged.

use glam::Vec2;
use rand::Rng;
use rand_pcg::Pcg32;

use super::sobol;
use crate::simd::{Float, UInt};

/// Which sample generator a [`Sampler`] uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    /// Owen-scrambled Sobol points, padded per dimension and shuffled per
    /// pixel (Burley 2020): every power-of-two prefix of a pixel's samples is
    /// stratified in each 1-D and 2-D dimension.
    Sobol,
    /// Independent uniform samples from PCG32.
    Independent,
}

/// A stateless sample generator; see [`Sampler::get_1d`].
#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    kind: SamplerKind,
    seed: u64,
    // Pre-mixed seed so nearby user seeds give unrelated sequences.
    key: u64,
    // The same for the 32-bit lane hashes of the Sobol sampler.
    key32: u32,
}

/// PCG stream selector for the independent sampler. Streams differing only
/// in their increment are known to be correlated, so all sequences share one
/// stream and differ by (hashed) starting state instead.
const PCG_STREAM: u64 = 0x2b99_2ddf_a232_49d6;

/// A 64-bit bijective finalizer (xor-shift / multiply rounds with good
/// avalanche); being a bijection, distinct inputs never collide.
#[inline]
pub const fn mix64(mut z: u64) -> u64 {
    z ^= z >> 30;
    z = z.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z ^= z >> 27;
    z = z.wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A 32-bit bijective finalizer over lanes: two xor-shift / multiply rounds, with the
/// constants of Wellons' "lowbias32" (hash-prospector, public domain), whose bias (mean
/// deviation from ideal avalanche) is among the lowest found for this shape. 32-bit
/// multiplies exist in every lane width; 64-bit ones do not (AVX2 lacks them).
#[inline(always)]
pub fn mix32<U: UInt>(mut x: U) -> U {
    x = x ^ x.shri::<16>();
    x = x.wrapping_mul(U::splat(0x7feb_352d));
    x = x ^ x.shri::<15>();
    x = x.wrapping_mul(U::splat(0x846c_a68b));
    x ^ x.shri::<16>()
}

/// Top 24 bits of `x` as an f32 in [0, 1): exact, and never 1.0 (rounding
/// all 32 bits could produce exactly 1.0).
#[inline]
pub fn u32_to_unit_f32(x: u32) -> f32 {
    unit::<f32>(x)
}

/// [`u32_to_unit_f32`] over lanes.
#[inline(always)]
pub fn unit<F: Float>(x: F::U32) -> F {
    x.shri::<8>().i32_to_f32() * F::splat(1.0 / (1u32 << 24) as f32)
}

/// Odd constants that separate the six 32-bit scramble seeds drawn from one key hash.
const SEED_SALT: [u32; 6] = [
    0x9e37_79b9,
    0x3c6e_f372,
    0xdaa6_6d2b,
    0x78dd_e6e5,
    0x1715_609d,
    0xb54c_da57,
];

impl Sampler {
    /// A sampler of the given kind; different seeds give unrelated samples.
    pub fn new(kind: SamplerKind, seed: u64) -> Self {
        let key = mix64(seed ^ 0x5a6d_e1f3_0c47_b28e);
        Self {
            kind,
            seed,
            key,
            key32: (key >> 32) as u32 ^ key as u32,
        }
    }

    /// The generator this sampler uses.
    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// The seed it was built with.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Hash identifying one (pixel, index) pair for PCG; a bijection of the
    /// pair for a fixed seed.
    #[inline]
    fn hash(&self, pixel: u32, x: u32) -> u64 {
        mix64(self.key ^ ((u64::from(pixel) << 32) | u64::from(x)))
    }

    /// Scramble seed `k` (of [`SEED_SALT`]) of one (pixel, dimension) hash.
    #[inline(always)]
    fn seed32<U: UInt>(h: U, k: usize) -> sobol::Scramble<U> {
        sobol::Scramble {
            add: mix32(h ^ U::splat(SEED_SALT[k])),
            mul: mix32(h ^ U::splat(SEED_SALT[k + 1])) | U::splat(1),
        }
    }

    /// 32-bit hash of (seed, pixel, dimension): a bijection of the dimension for a fixed
    /// pixel, so a pixel's dimensions never share scrambles.
    #[inline(always)]
    fn key_hash<U: UInt>(&self, pixel: U, dim: U) -> U {
        mix32(mix32(pixel ^ U::splat(self.key32)).wrapping_add(dim))
    }

    #[inline]
    fn pcg(&self, pixel: u32, index: u32, dim: u32) -> Pcg32 {
        let mut rng = Pcg32::new(self.hash(pixel, index), PCG_STREAM);
        rng.advance(u64::from(dim));
        rng
    }

    /// Sample `index` of pixel `pixel` in dimension `dim`, in [0, 1) (never
    /// 1.0). A pure function of (seed, pixel, index, dim): no state, so any
    /// thread computes the same value.
    ///
    /// For [`SamplerKind::Sobol`], `get_1d(p, i, d)` equals
    /// `get_2d(p, i, d).x`: each call site owns its dimension numbers, and
    /// the 2-D sample at `dim` is not related to the 1-D one at `dim + 1`.
    #[inline]
    pub fn get_1d(&self, pixel: u32, index: u32, dim: u32) -> f32 {
        self.get_1d_lanes::<f32>(pixel, index, dim)
    }

    /// A 2-D sample occupying dimensions `dim` and `dim + 1` (callers advance
    /// `dim` by 2). For Sobol, the first `2^k` indices of any pixel (indeed
    /// any aligned block of `2^k` indices) form a (0, k, 2)-net. For the
    /// independent sampler it is `(get_1d(dim), get_1d(dim + 1))`.
    #[inline]
    pub fn get_2d(&self, pixel: u32, index: u32, dim: u32) -> Vec2 {
        let (x, y) = self.get_2d_lanes::<f32>(pixel, index, dim);
        Vec2::new(x, y)
    }

    /// [`Sampler::get_1d`] for a lane of (pixel, index, dimension) triples: lane `i` holds
    /// exactly the scalar sample of lane `i`'s triple, at every width.
    #[inline(always)]
    pub fn get_1d_lanes<F: Float>(&self, pixel: F::U32, index: F::U32, dim: F::U32) -> F {
        match self.kind {
            SamplerKind::Sobol => {
                let h = self.key_hash(pixel, dim);
                let i = sobol::shuffle_index(index, Self::seed32(h, 0));
                unit::<F>(sobol::owen_sobol_x(i, Self::seed32(h, 2)))
            }
            // PCG's 64-bit state has no lane form: one lane at a time.
            SamplerKind::Independent => {
                let (p, ix, d) = lane_keys::<F>(pixel, index, dim);
                F::from_fn(|k| u32_to_unit_f32(self.pcg(p[k], ix[k], d[k]).next_u32()))
            }
        }
    }

    /// [`Sampler::get_2d`] for a lane of triples.
    #[inline(always)]
    pub fn get_2d_lanes<F: Float>(&self, pixel: F::U32, index: F::U32, dim: F::U32) -> (F, F) {
        match self.kind {
            SamplerKind::Sobol => {
                let h = self.key_hash(pixel, dim);
                let seeds = [Self::seed32(h, 0), Self::seed32(h, 2), Self::seed32(h, 4)];
                let (x, y) = sobol::owen_sobol_2d(index, seeds);
                (unit::<F>(x), unit::<F>(y))
            }
            SamplerKind::Independent => {
                let (p, ix, d) = lane_keys::<F>(pixel, index, dim);
                let mut ys = [0.0f32; 16];
                let x = F::from_fn(|k| {
                    let mut rng = self.pcg(p[k], ix[k], d[k]);
                    let x = u32_to_unit_f32(rng.next_u32());
                    ys[k] = u32_to_unit_f32(rng.next_u32());
                    x
                });
                (x, F::load(&ys))
            }
        }
    }
}

/// The lanes of three keys as arrays, extracted here rather than inside a `from_fn` closure:
/// a closure that is not inlined loses the kernel's target features, and each lane
/// extraction in it becomes a call.
#[inline(always)]
fn lane_keys<F: Float>(
    pixel: F::U32,
    index: F::U32,
    dim: F::U32,
) -> ([u32; 16], [u32; 16], [u32; 16]) {
    let (mut p, mut ix, mut d) = ([0u32; 16], [0u32; 16], [0u32; 16]);
    for k in 0..F::WIDTH {
        (p[k], ix[k], d[k]) = (pixel.lane(k), index.lane(k), dim.lane(k));
    }
    (p, ix, d)
}
