//! The state of a packet of paths, declared once: [`Paths`] holds `F::WIDTH` paths, one per
//! lane (width 1 is a single path: the reference every wider packet is tested against), and
//! the small lane helpers every stage uses.

use super::bsdf::Chan;
use super::transport::{ChannelArray, Transport};
use crate::simd::{Float, Mask, V3};
use glam::Vec3;

pub(super) type U<F> = <F as Float>::U32;
pub(super) type M<F> = <F as Float>::Mask;

/// The widest packet: scratch arrays for per-lane work are this long.
pub(super) const MAX_W: usize = 16;

/// Channels of lanes: N = 3 for RGB, 4 for spectral.
pub(super) type C<F, const N: usize> = Chan<F, N>;

/// The state of `F::WIDTH` paths, one per lane. Dead lanes hold stale values until refilled.
pub(super) struct Paths<F: Float, T: Transport, const N: usize> {
    pub(super) o: V3<F>,
    pub(super) d: V3<F>,
    pub(super) beta: C<F, N>,
    pub(super) l: C<F, N>,
    /// Each lane's wavelengths (nothing in RGB).
    pub(super) lam: T::Lanes<F>,
    pub(super) eta_scale: F,
    pub(super) depth: U<F>,
    pub(super) specular: M<F>,
    pub(super) prev_pdf: F,
    pub(super) prev_p: V3<F>,
    pub(super) time: F,
    pub(super) pixel: U<F>,
    pub(super) sample: U<F>,
    pub(super) alive: M<F>,
    /// MEDIA: each lane's medium and the medium segments its path has sampled so far.
    pub(super) medium: [u32; MAX_W],
    /// MEDIA: the lanes whose medium is not `NO_MEDIUM`.
    pub(super) in_medium: M<F>,
    pub(super) segments: [u32; MAX_W],
}

#[inline(always)]
pub(super) fn mask_from_bits<F: Float>(bits: u32) -> M<F> {
    M::<F>::from_fn(|i| bits >> i & 1 != 0)
}

#[inline(always)]
pub(super) fn select_c<F: Float, const N: usize>(m: M<F>, a: C<F, N>, b: C<F, N>) -> C<F, N> {
    Chan(std::array::from_fn(|c| F::select(m, a.0[c], b.0[c])))
}

/// Lane `i` of channels `c` as the scalar transport's channels.
#[inline(always)]
pub(super) fn chan_lane<F: Float, S: ChannelArray<N>, const N: usize>(c: &C<F, N>, i: usize) -> S {
    S::from_array(std::array::from_fn(|k| c.0[k].lane(i)))
}

/// Channels gathered one lane at a time, loaded into lanes afterwards.
pub(super) struct ScratchC<const N: usize>(pub(super) [[f32; MAX_W]; N]);

impl<const N: usize> ScratchC<N> {
    #[inline(always)]
    pub(super) fn new() -> Self {
        ScratchC([[0.0; MAX_W]; N])
    }
    #[inline(always)]
    pub(super) fn set<S: ChannelArray<N>>(&mut self, i: usize, v: S) {
        for (k, c) in v.to_array().into_iter().enumerate() {
            self.0[k][i] = c;
        }
    }
    #[inline(always)]
    pub(super) fn load<F: Float>(&self) -> C<F, N> {
        Chan(std::array::from_fn(|k| F::load(&self.0[k])))
    }
}

/// Per-lane results gathered one lane at a time, loaded into lanes afterwards.
pub(super) struct Scratch3 {
    pub(super) x: [f32; MAX_W],
    pub(super) y: [f32; MAX_W],
    pub(super) z: [f32; MAX_W],
}

impl Scratch3 {
    #[inline(always)]
    pub(super) fn new() -> Self {
        Scratch3 {
            x: [0.0; MAX_W],
            y: [0.0; MAX_W],
            z: [0.0; MAX_W],
        }
    }
    #[inline(always)]
    pub(super) fn set(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }
    #[inline(always)]
    pub(super) fn v3<F: Float>(&self) -> V3<F> {
        V3::new(F::load(&self.x), F::load(&self.y), F::load(&self.z))
    }
}

/// glam's `Vec3::dot` over lanes: unfused, in the same order, so the decisions the scalar
/// code (e.g. `Lights::sample`) takes on glam's dot products come out the same.
#[inline(always)]
pub(super) fn gdot<F: Float>(a: V3<F>, b: V3<F>) -> F {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// glam's `Vec3::normalize` over lanes.
#[inline(always)]
pub(super) fn gnormalize<F: Float>(v: V3<F>) -> V3<F> {
    v * gdot(v, v).sqrt().recip()
}

#[inline(always)]
pub(super) fn power_heuristic<F: Float>(a: F, b: F) -> F {
    let (a2, b2) = (a * a, b * b);
    let s = a2 + b2;
    F::select(s.eq(F::zero()), F::zero(), a2 / s)
}

impl<F: Float, const N: usize> C<F, N> {
    #[inline(always)]
    pub(super) fn is_zero(&self) -> M<F> {
        let mut z = self.0[0].eq(F::zero());
        for c in &self.0[1..] {
            z &= c.eq(F::zero());
        }
        z
    }
    /// The largest channel (the scalar `max_element`).
    #[inline(always)]
    pub(super) fn max_element(&self) -> F {
        let mut m = self.0[0];
        for &c in &self.0[1..] {
            m = m.max(c);
        }
        m
    }
}

/// Whether every channel is finite.
#[inline(always)]
pub(super) fn finite<F: Float, const N: usize>(c: &C<F, N>) -> M<F> {
    let mut m = c.0[0].is_finite();
    for x in &c.0[1..] {
        m &= x.is_finite();
    }
    m
}
