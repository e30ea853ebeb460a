//! Per-pixel sample generators that are pure functions of
//! (seed, pixel, sample index, dimension).
//!
//! Having no state means any thread, or any later render pass, recomputes the
//! same value, so sample ranges rendered separately can be merged.

use glam::Vec2;
use rand::Rng;
use rand_pcg::Pcg32;

use super::sobol;

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
}

/// PCG stream selector for the independent sampler. Streams differing only
/// in their increment are known to be correlated, so all sequences share one
/// stream and differ by (hashed) starting state instead.
const PCG_STREAM: u64 = 0x2b99_2ddf_a232_49d6;
/// Weyl increment used to derive several independent hashes from one.
const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

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

/// Top 24 bits of `x` as an f32 in [0, 1): exact, and never 1.0 (rounding
/// all 32 bits could produce exactly 1.0).
#[inline]
pub fn u32_to_unit_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

impl Sampler {
    /// A sampler of the given kind; different seeds give unrelated samples.
    pub fn new(kind: SamplerKind, seed: u64) -> Self {
        Self {
            kind,
            seed,
            key: mix64(seed ^ 0x5a6d_e1f3_0c47_b28e),
        }
    }

    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Hash identifying one (pixel, dimension) or (pixel, index) pair; a
    /// bijection of the pair for a fixed seed.
    #[inline]
    fn hash(&self, pixel: u32, x: u32) -> u64 {
        mix64(self.key ^ ((u64::from(pixel) << 32) | u64::from(x)))
    }

    #[inline]
    fn sobol_seeds(&self, pixel: u32, dim: u32) -> [u64; 3] {
        let h = self.hash(pixel, dim);
        [
            mix64(h.wrapping_add(GOLDEN)),
            mix64(h.wrapping_add(GOLDEN.wrapping_mul(2))),
            mix64(h.wrapping_add(GOLDEN.wrapping_mul(3))),
        ]
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
        let bits = match self.kind {
            SamplerKind::Sobol => {
                let [shuffle, sx, _] = self.sobol_seeds(pixel, dim);
                let i = sobol::nested_uniform_scramble(index, shuffle);
                sobol::owen_sobol_x(i, sx)
            }
            SamplerKind::Independent => self.pcg(pixel, index, dim).next_u32(),
        };
        u32_to_unit_f32(bits)
    }

    /// A 2-D sample occupying dimensions `dim` and `dim + 1` (callers advance
    /// `dim` by 2). For Sobol, the first `2^k` indices of any pixel (indeed
    /// any aligned block of `2^k` indices) form a (0, k, 2)-net. For the
    /// independent sampler it is `(get_1d(dim), get_1d(dim + 1))`.
    #[inline]
    pub fn get_2d(&self, pixel: u32, index: u32, dim: u32) -> Vec2 {
        match self.kind {
            SamplerKind::Sobol => {
                let (x, y) = sobol::owen_sobol_2d(index, self.sobol_seeds(pixel, dim));
                Vec2::new(u32_to_unit_f32(x), u32_to_unit_f32(y))
            }
            SamplerKind::Independent => {
                let mut rng = self.pcg(pixel, index, dim);
                let x = rng.next_u32();
                Vec2::new(u32_to_unit_f32(x), u32_to_unit_f32(rng.next_u32()))
            }
        }
    }
}
