//! Scattering at surfaces, written once over lanes: Fresnel terms, reflection and refraction,
//! and the BSDFs of the materials, each with `sample`, `eval` and `pdf` in the local shading
//! frame.
//!
//! Conventions (those of pbrt-v4, with prism's orientation):
//! - Directions point away from the surface, in a frame whose `+z` is the shading normal on the
//!   side the path arrived from, so `wo.z ≥ 0` up to a tilted shading normal.
//! - `eval` returns f (no cosine) and `pdf` the solid-angle density of `sample` producing `wi`;
//!   a specular (delta) lobe has neither, and `sample` reports it in its lobe flags, with `pdf`
//!   the probability of having chosen that lobe.
//! - A sample's `weight` is `f · |cos θi| / pdf` in the path's colour channels `S`, so the
//!   caller multiplies its throughput by it and nothing else.
//! - [`Mode`] says which quantity the path carries: radiance (paths from the camera) or
//!   importance (paths from lights, for light tracing and bidirectional estimators). Only
//!   refraction differs between them here: radiance is compressed by 1/η² entering a denser
//!   medium, importance is not.
//!
//! The scalar functions are these at width 1, so every width simulates the same physics bit
//! for bit.

use crate::simd::{Float, UInt, V3};
use crate::spectrum::Channels;
use glam::Vec3;
use std::ops::{Add, Mul};

/// What a path carries: the BSDF's `sample` scales radiance at refraction, importance not.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// Radiance, on paths traced from the camera.
    #[default]
    Radiance,
    /// Importance, on paths traced from lights.
    Importance,
}

/// Lobe flags of a BSDF sample (bits of a `U32` lane).
pub mod lobe {
    /// Lambertian reflection.
    pub const DIFFUSE_REFLECTION: u32 = 1;
    /// Mirror reflection (a delta lobe).
    pub const SPECULAR_REFLECTION: u32 = 2;
    /// Refraction through a smooth interface (a delta lobe).
    pub const SPECULAR_TRANSMISSION: u32 = 4;
    /// Either specular lobe: no density, so no MIS with light sampling.
    pub const SPECULAR: u32 = SPECULAR_REFLECTION | SPECULAR_TRANSMISSION;
    /// Reflection from a rough surface: a density, so light sampling evaluates it.
    pub const GLOSSY_REFLECTION: u32 = 8;
    /// Refraction through a rough interface: a density, like glossy reflection.
    pub const GLOSSY_TRANSMISSION: u32 = 16;
    /// Either transmission lobe: the path crosses into the other medium.
    pub const TRANSMISSION: u32 = SPECULAR_TRANSMISSION | GLOSSY_TRANSMISSION;
}

/// Colour channels over lanes: what BSDF weights are made of. The transports' scalar channel
/// types (`Vec3` for RGB, `SampledSpectrum` for four wavelengths) are the width-1 forms.
pub trait LaneChannels<F: Float>:
    Copy + Mul<Output = Self> + Mul<F, Output = Self> + Add<Output = Self>
{
    /// The same value `v` in every channel.
    fn splat(v: F) -> Self;
}

impl<S: Channels> LaneChannels<f32> for S {
    #[inline(always)]
    fn splat(v: f32) -> Self {
        S::ONE * v
    }
}

/// `N` colour channels of lanes: three for RGB, four hero wavelengths for spectral transport.
#[derive(Clone, Copy, Debug)]
pub struct Chan<F, const N: usize>(pub [F; N]);

impl<F: Float, const N: usize> Mul for Chan<F, N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Chan(std::array::from_fn(|i| self.0[i] * o.0[i]))
    }
}

impl<F: Float, const N: usize> Mul<F> for Chan<F, N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: F) -> Self {
        Chan(self.0.map(|c| c * s))
    }
}

impl<F: Float, const N: usize> Add for Chan<F, N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Chan(std::array::from_fn(|i| self.0[i] + o.0[i]))
    }
}

impl<F: Float, const N: usize> LaneChannels<F> for Chan<F, N> {
    #[inline(always)]
    fn splat(v: F) -> Self {
        Chan([v; N])
    }
}

/// An orthonormal shading frame: `n` is local `+z`.
#[derive(Clone, Copy, Debug)]
pub struct Frame<F: Float> {
    /// Unit tangent, local `+x`.
    pub t: V3<F>,
    /// Unit bitangent, local `+y`.
    pub b: V3<F>,
    /// Unit shading normal, local `+z`.
    pub n: V3<F>,
}

impl<F: Float> Frame<F> {
    /// The frame of `coordinate_system` around the unit normal `n`.
    #[inline(always)]
    pub fn from_normal(n: V3<F>) -> Self {
        let (t, b) = crate::sampling::warp::lanes::coordinate_system(n);
        Frame { t, b, n }
    }
    /// The frame with its tangent along `t` (projected onto the tangent plane) in the lanes
    /// `m`; a lane whose `t` is (nearly) parallel to the normal, as ∂p/∂u at a sphere's pole,
    /// keeps its tangent.
    #[inline(always)]
    pub fn with_tangent(&self, m: F::Mask, t: V3<F>) -> Self {
        let tp = t - self.n * t.dot(self.n);
        let len2 = tp.dot(tp);
        let m = m & len2.gt(F::splat(1e-12));
        let tp = tp * len2.max(F::splat(1e-30)).sqrt().recip();
        Frame {
            t: V3::select(m, tp, self.t),
            b: V3::select(m, self.n.cross(tp), self.b),
            n: self.n,
        }
    }
    /// A world direction in the local frame.
    #[inline(always)]
    pub fn to_local(&self, v: V3<F>) -> V3<F> {
        V3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
    /// A local direction in world space (not renormalised).
    #[inline(always)]
    pub fn to_world(&self, v: V3<F>) -> V3<F> {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

/// A direction sampled from a BSDF.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample<F: Float, S> {
    /// Local frame.
    pub wi: V3<F>,
    /// `f · |cos θi| / pdf`.
    pub weight: S,
    /// Solid-angle density of `wi`, or for a specular lobe the probability it was chosen.
    pub pdf: F,
    /// The lobe sampled: one of the [`lobe`] flags per lane.
    pub lobe: F::U32,
    /// Relative IOR crossed (transmitted over incident): 1 unless the sample refracted.
    pub eta: F,
}

impl<F: Float, S> BsdfSample<F, S> {
    /// Lanes whose sample is a delta lobe.
    #[inline(always)]
    pub fn is_specular(&self) -> F::Mask {
        !(self.lobe & F::U32::splat(lobe::SPECULAR)).eq(F::U32::splat(0))
    }
    /// Lanes whose sample refracted.
    #[inline(always)]
    pub fn is_transmission(&self) -> F::Mask {
        !(self.lobe & F::U32::splat(lobe::TRANSMISSION)).eq(F::U32::splat(0))
    }
}

/// Lambertian reflection: f = albedo / π on the side of `+z`.
#[derive(Clone, Copy, Debug)]
pub struct Diffuse<S> {
    /// Reflectance per channel.
    pub albedo: S,
}

impl<S> Diffuse<S> {
    /// Cosine-weighted: the weight is the albedo itself.
    #[inline(always)]
    pub fn sample<F: Float>(&self, _wo: V3<F>, ux: F, uy: F) -> BsdfSample<F, S>
    where
        S: LaneChannels<F>,
    {
        let wi = crate::sampling::warp::lanes::square_to_cosine_hemisphere(ux, uy);
        BsdfSample {
            wi,
            weight: self.albedo,
            pdf: cosine_pdf(wi.z),
            lobe: F::U32::splat(lobe::DIFFUSE_REFLECTION),
            eta: F::one(),
        }
    }

    /// f = albedo / π above the surface, 0 below.
    #[inline(always)]
    pub fn eval<F: Float>(&self, _wo: V3<F>, wi: V3<F>) -> S
    where
        S: LaneChannels<F>,
    {
        let above = wi.z.gt(F::zero());
        self.albedo * F::select(above, F::splat(std::f32::consts::FRAC_1_PI), F::zero())
    }

    /// Cosine-weighted solid-angle density of `wi`.
    #[inline(always)]
    pub fn pdf<F: Float>(&self, _wo: V3<F>, wi: V3<F>) -> F {
        cosine_pdf(wi.z)
    }
}

#[inline(always)]
fn cosine_pdf<F: Float>(cos: F) -> F {
    cos.max(F::zero()) * F::splat(std::f32::consts::FRAC_1_PI)
}

/// A perfect mirror tinted by `tint`: one specular lobe.
#[derive(Clone, Copy, Debug)]
pub struct Mirror<S> {
    /// Reflectance per channel.
    pub tint: S,
}

impl<S> Mirror<S> {
    /// The mirror direction of `wo`, weighted by the tint.
    #[inline(always)]
    pub fn sample<F: Float>(&self, wo: V3<F>) -> BsdfSample<F, S>
    where
        S: LaneChannels<F>,
    {
        BsdfSample {
            wi: reflect_local(wo),
            weight: self.tint,
            pdf: F::one(),
            lobe: F::U32::splat(lobe::SPECULAR_REFLECTION),
            eta: F::one(),
        }
    }

    /// A delta lobe: zero for every pair of directions.
    #[inline(always)]
    pub fn eval<F: Float>(&self, _wo: V3<F>, _wi: V3<F>) -> S
    where
        S: LaneChannels<F>,
    {
        S::splat(F::zero())
    }

    /// A delta lobe: zero density for every pair of directions.
    #[inline(always)]
    pub fn pdf<F: Float>(&self, _wo: V3<F>, _wi: V3<F>) -> F {
        F::zero()
    }
}

/// A smooth dielectric interface: specular reflection with probability F (exact or Schlick),
/// else refraction. `eta` is the relative IOR across it in the direction of travel
/// (transmitted over incident), so a ray leaving glass has `eta` < 1.
#[derive(Clone, Copy, Debug)]
pub struct Dielectric<F> {
    /// Relative IOR, transmitted over incident.
    pub eta: F,
    /// Use Schlick's approximation for the Fresnel term instead of the exact formula.
    pub schlick: bool,
}

impl<F: Float> Dielectric<F> {
    /// Fresnel reflectance for `wo` (the incident direction reversed).
    #[inline(always)]
    pub fn reflectance(&self, wo: V3<F>) -> F {
        let cos_i = wo.z.max(F::zero());
        if self.schlick {
            fresnel_schlick(cos_i, self.eta)
        } else {
            fresnel_dielectric(cos_i, self.eta)
        }
    }

    /// Reflects with probability F (always under total internal reflection), else refracts;
    /// either way the weight is F or 1 − F over its own probability, times 1/η² for radiance
    /// crossing into the other medium.
    #[inline(always)]
    pub fn sample<S: LaneChannels<F>>(&self, wo: V3<F>, u: F, mode: Mode) -> BsdfSample<F, S> {
        let r = self.reflectance(wo);
        let (wt, can_refract) = refract_local(wo, self.eta);
        let t = can_refract & u.ge(r);
        let scale = match mode {
            Mode::Radiance => (self.eta * self.eta).recip(),
            Mode::Importance => F::one(),
        };
        BsdfSample {
            wi: V3::select(t, wt, reflect_local(wo)),
            weight: S::splat(F::select(t, scale, F::one())),
            pdf: F::select(t, F::one() - r, r),
            lobe: F::U32::select(
                t,
                F::U32::splat(lobe::SPECULAR_TRANSMISSION),
                F::U32::splat(lobe::SPECULAR_REFLECTION),
            ),
            eta: F::select(t, self.eta, F::one()),
        }
    }
}

/// Mirror reflection about the local normal.
#[inline(always)]
pub fn reflect_local<F: Float>(wo: V3<F>) -> V3<F> {
    V3::new(-wo.x, -wo.y, wo.z)
}

/// Refraction of `wo` through the local `+z` interface with relative IOR `eta`, and the lanes
/// where it exists (elsewhere total internal reflection; the direction there is meaningless).
#[inline(always)]
pub fn refract_local<F: Float>(wo: V3<F>, eta: F) -> (V3<F>, F::Mask) {
    let n = V3::new(F::zero(), F::zero(), F::one());
    refract_lanes(wo, n, eta)
}

/// Unpolarised Fresnel reflectance of a smooth dielectric interface. `cos_i` is the cosine of
/// the incident angle (≥ 0) and `eta` the relative IOR n_transmitted / n_incident. Returns 1
/// under total internal reflection.
#[inline(always)]
pub fn fresnel_dielectric<F: Float>(cos_i: F, eta: F) -> F {
    let one = F::one();
    let cos_i = cos_i.clamp(F::zero(), one);
    // cos²θt = 1 − sin²θi/η², formed without the cancellation of 1 − sin²θt when the
    // transmitted ray grazes (its cosine sets 1 − F there).
    let e2 = eta * eta;
    let cos2_t = (e2 - one + cos_i * cos_i) / e2;
    let tir = cos2_t.le(F::zero());
    let cos_t = cos2_t.max(F::zero()).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r = F::splat(0.5) * (r_parl * r_parl + r_perp * r_perp);
    F::select(tir, one, r)
}

/// Schlick's approximation, evaluated with the cosine on the optically thinner side (the
/// transmitted angle when leaving the denser medium), so it also reproduces total internal
/// reflection.
#[inline(always)]
pub fn fresnel_schlick<F: Float>(cos_i: F, eta: F) -> F {
    let one = F::one();
    let cos_i = cos_i.clamp(F::zero(), one);
    let q = (eta - one) / (eta + one);
    let r0 = q * q;
    let sin2_t = (one - cos_i * cos_i) / (eta * eta);
    let denser = eta.ge(one);
    let tir = !denser & sin2_t.ge(one);
    let c = F::select(denser, cos_i, (one - sin2_t).max(F::zero()).sqrt());
    let m = one - c;
    let m2 = m * m;
    let r = r0 + (one - r0) * (m2 * m2 * m);
    F::select(tir, one, r)
}

/// Mirror reflection of `wo` (pointing away from the surface) about `n`.
#[inline(always)]
pub fn reflect_lanes<F: Float>(wo: V3<F>, n: V3<F>) -> V3<F> {
    n * (F::splat(2.0) * wo.dot(n)) - wo
}

/// Refraction of `wo` (pointing away, on the side `n` faces) into the other side, with
/// relative IOR `eta` = n_transmitted / n_incident, and the lanes where it exists.
#[inline(always)]
pub fn refract_lanes<F: Float>(wo: V3<F>, n: V3<F>, eta: F) -> (V3<F>, F::Mask) {
    let one = F::one();
    let cos_i = wo.dot(n);
    let sin2_t = (one - cos_i * cos_i).max(F::zero()) / (eta * eta);
    let ok = sin2_t.lt(one);
    let cos_t = (one - sin2_t).max(F::zero()).sqrt();
    let inv = eta.recip();
    let wt = (wo * -inv + n * (cos_i * inv - cos_t)).normalize();
    (wt, ok)
}

/// Mirror reflection of `wo` (pointing away from the surface) about `n`.
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    reflect_lanes::<f32>(wo.into(), n.into()).into()
}

/// Refraction of `wo` (pointing away, on the side `n` faces) into the other side, with
/// relative IOR `eta` = n_transmitted / n_incident. `None` under total internal reflection.
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let (wt, ok) = refract_lanes::<f32>(wo.into(), n.into(), eta);
    ok.then(|| wt.into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_matches_closed_form() {
        for eta in [1.0f32, 1.33, 1.5, 2.42] {
            let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, eta) - r0).abs() < 1e-6);
            assert!((fresnel_schlick(1.0, eta) - r0).abs() < 1e-6);
        }
    }

    #[test]
    fn refract_obeys_snell() {
        let n = Vec3::Z;
        for deg in [0.0f32, 10.0, 30.0, 60.0, 89.0] {
            let th = deg.to_radians();
            let wo = Vec3::new(th.sin(), 0.0, th.cos());
            let wt = refract(wo, n, 1.5).unwrap();
            let sin_t = (wt.x * wt.x + wt.y * wt.y).sqrt();
            assert!((th.sin() - 1.5 * sin_t).abs() < 1e-5, "{deg}");
            assert!(wt.z < 0.0 && (wt.length() - 1.0).abs() < 1e-5);
        }
    }
}
