//! Rough surfaces over lanes: the GGX (Trowbridge–Reitz) distribution of microfacet normals,
//! height-correlated Smith masking–shadowing, visible-normal sampling, and the conductor built
//! from them, with the conventions of [`super::bsdf`] (local frame, `+z` the shading normal on
//! the side the path arrived from).
//!
//! With `s(w)` the length of the stretched direction `(αx·wx, αy·wy, wz)`, Smith's
//! Λ(w) = (s(w)/|wz| − 1)/2, so
//! - G1(wo) = 2|zo| / (|zo| + s(wo)),
//! - G2(wo, wi) = 1/(1 + Λ(wo) + Λ(wi)) = 2|zo||zi| / (s(wo)|zi| + s(wi)|zo|),
//! - f = D·F·G2 / (4 zo zi) = D·F / (2 (s(wo) zi + s(wi) zo)),
//! - the visible-normal pdf of the reflected wi, G1(wo)·D(h) / (4 zo) = D(h) / (2 (zo + s(wo))),
//! - and the sampled weight f·zi/pdf = F·zi (zo + s(wo)) / (s(wo) zi + s(wi) zo) = F·G2/G1(wo).
//!
//! These forms divide only by sums that vanish when both directions are grazing, where the
//! callers have already rejected the sample.

use super::bsdf::{BsdfSample, Chan, lobe, reflect_local};
use crate::simd::{Float, Mask, UInt, V3, math};
use std::f32::consts::TAU;

/// Below this α a rough surface is treated as smooth: a delta lobe, like a mirror. GGX
/// lobes narrower than this are a fraction of a pixel wide at any practical distance, and
/// their D overflows f32.
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// The GGX distribution with roughness `ax` along the local x axis and `ay` along y.
#[derive(Clone, Copy, Debug)]
pub struct Ggx<F> {
    /// α along the tangent (local x).
    pub ax: F,
    /// α along the bitangent (local y).
    pub ay: F,
}

impl<F: Float> Ggx<F> {
    /// An isotropic distribution.
    #[inline(always)]
    pub fn isotropic(alpha: F) -> Self {
        Ggx {
            ax: alpha,
            ay: alpha,
        }
    }

    /// D(h), the density of microfacet normals per unit macro-surface area and solid angle
    /// (∫ D(h) h.z dω = 1); zero below the surface.
    #[inline(always)]
    pub fn d(&self, h: V3<F>) -> F {
        let (x, y) = (h.x / self.ax, h.y / self.ay);
        let t = x * x + y * y + h.z * h.z;
        let v = (F::splat(std::f32::consts::PI) * self.ax * self.ay * t * t).recip();
        F::select(h.z.gt(F::zero()), v, F::zero())
    }

    /// s(w): the length of `w` stretched by α, which every Smith term is made of.
    #[inline(always)]
    pub fn stretched_len(&self, w: V3<F>) -> F {
        let (x, y) = (self.ax * w.x, self.ay * w.y);
        (x * x + y * y + w.z * w.z).sqrt()
    }

    /// Smith's masking G1(w) for a direction above the surface.
    #[inline(always)]
    pub fn g1(&self, w: V3<F>) -> F {
        let z = w.z.abs();
        F::splat(2.0) * z / (z + self.stretched_len(w))
    }

    /// Height-correlated masking–shadowing G2(wo, wi).
    #[inline(always)]
    pub fn g2(&self, wo: V3<F>, wi: V3<F>) -> F {
        let (zo, zi) = (wo.z.abs(), wi.z.abs());
        let d = self.stretched_len(wo) * zi + self.stretched_len(wi) * zo;
        F::splat(2.0) * zo * zi / d
    }

    /// A microfacet normal visible from `wo` (wo.z > 0), drawn with density
    /// G1(wo)·max(0, wo·h)·D(h)/wo.z: the spherical-cap form of visible-normal sampling
    /// (Dupuy & Benyoub 2023, equivalent to Heitz 2018): in the stretched space where the
    /// distribution is a hemisphere, a uniform point on the cap of the unit sphere below
    /// the plane perpendicular to the stretched `wo`, plus that direction.
    #[inline(always)]
    pub fn sample_visible_normal(&self, wo: V3<F>, u1: F, u2: F) -> V3<F> {
        let one = F::one();
        let ws = V3::new(self.ax * wo.x, self.ay * wo.y, wo.z).normalize();
        let (s, c) = math::sin_cos(F::splat(TAU) * u1);
        let z = (one - u2) * (one + ws.z) - ws.z;
        let r = (one - z * z).max(F::zero()).sqrt();
        let hs = V3::new(r * c + ws.x, r * s + ws.y, z + ws.z);
        V3::new(self.ax * hs.x, self.ay * hs.y, hs.z.max(F::zero())).normalize()
    }
}

/// Unpolarised Fresnel reflectance of a conductor with complex IOR `eta + i·k` (relative to
/// the outside medium) at incidence cosine `cos` ∈ [0, 1], by the closed form of the two
/// polarisations' amplitudes (Born & Wolf §14.2): a² + b² = √((η² − k² − sin²θ)² + 4η²k²),
/// a = √((a² + b² + η² − k² − sin²θ)/2). With k = 0 and η < 1 beyond the critical angle it
/// is 1 (total reflection).
#[inline(always)]
pub fn fresnel_conductor<F: Float>(cos: F, eta: F, k: F) -> F {
    let one = F::one();
    let c = cos.clamp(F::zero(), one);
    let c2 = c * c;
    let s2 = one - c2;
    let (e2, k2) = (eta * eta, k * k);
    let t0 = e2 - k2 - s2;
    let a2b2 = (t0 * t0 + F::splat(4.0) * e2 * k2).sqrt();
    let a = (F::splat(0.5) * (a2b2 + t0)).max(F::zero()).sqrt();
    let t1 = a2b2 + c2;
    let t2 = F::splat(2.0) * a * c;
    // t1 + t2 vanishes only at grazing incidence on an interface that is no interface
    // (η = 1, k = 0), where 0/0 is taken as the grazing limit of every other interface, 1.
    let d1 = t1 + t2;
    let rs = F::select(d1.gt(F::zero()), (t1 - t2) / d1, one);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    F::splat(0.5) * (rs + rp)
}

/// Schlick's form with the normal-incidence reflectance `r0`: r0 + (1 − r0)(1 − cos)⁵.
#[inline(always)]
pub fn fresnel_schlick_r0<F: Float>(cos: F, r0: F) -> F {
    let m = (F::one() - cos.clamp(F::zero(), F::one())).max(F::zero());
    let m2 = m * m;
    r0 + (F::one() - r0) * (m2 * m2 * m)
}

/// A conductor's Fresnel term per colour channel: the exact one of the complex IOR
/// `eta + i·k`, or in the lanes of `schlick` Schlick's with normal-incidence reflectance
/// `eta` (an artist's colour).
#[derive(Clone, Copy, Debug)]
pub struct ConductorFresnel<F: Float, const N: usize> {
    /// η per channel, or the normal-incidence reflectance in Schlick lanes.
    pub eta: Chan<F, N>,
    /// k per channel (unused in Schlick lanes).
    pub k: Chan<F, N>,
    /// Lanes with Schlick's form.
    pub schlick: F::Mask,
}

impl<F: Float, const N: usize> ConductorFresnel<F, N> {
    /// F at incidence cosine `cos`, per channel.
    #[inline(always)]
    pub fn eval(&self, cos: F) -> Chan<F, N> {
        let mut out = [F::zero(); N];
        let (all, none) = (self.schlick.all(), self.schlick.none());
        for (c, o) in out.iter_mut().enumerate() {
            let (eta, k) = (self.eta.0[c], self.k.0[c]);
            *o = if all {
                fresnel_schlick_r0(cos, eta)
            } else if none {
                fresnel_conductor(cos, eta, k)
            } else {
                F::select(
                    self.schlick,
                    fresnel_schlick_r0(cos, eta),
                    fresnel_conductor(cos, eta, k),
                )
            };
        }
        Chan(out)
    }
}

/// A conductor: GGX microfacet reflection with a conductor's Fresnel term, or in the lanes of
/// `smooth` (α < [`SMOOTH_ALPHA`]) mirror reflection weighted by it.
#[derive(Clone, Copy, Debug)]
pub struct Conductor<F: Float, const N: usize> {
    /// The microfacet distribution (ignored in smooth lanes).
    pub dist: Ggx<F>,
    /// Lanes whose surface is smooth: a delta lobe.
    pub smooth: F::Mask,
    /// The Fresnel term.
    pub fresnel: ConductorFresnel<F, N>,
}

impl<F: Float, const N: usize> Conductor<F, N> {
    /// A visible normal, and `wo` reflected about it; in smooth lanes the mirror direction.
    /// Lanes where `wo` or the reflection lies below the surface have weight 0 (pdf 0).
    #[inline(always)]
    pub fn sample(&self, wo: V3<F>, u1: F, u2: F) -> BsdfSample<F, Chan<F, N>> {
        let zero = F::zero();
        let h = self.dist.sample_visible_normal(wo, u1, u2);
        let cos_h = wo.dot(h);
        let rough_wi = h * (F::splat(2.0) * cos_h) - wo;
        let wi = V3::select(self.smooth, reflect_local(wo), rough_wi);
        let cos_f = F::select(self.smooth, wo.z, cos_h);
        let fr = self.fresnel.eval(cos_f);
        let so = self.dist.stretched_len(wo);
        let si = self.dist.stretched_len(wi);
        let (zo, zi) = (wo.z, wi.z);
        let ok = zo.gt(zero) & zi.gt(zero);
        // F·G2/G1(wo), and the visible-normal pdf D(h)/(2(zo + s(wo))).
        let g = F::select(self.smooth, F::one(), zi * (zo + so) / (so * zi + si * zo));
        let pdf = F::select(
            self.smooth,
            F::one(),
            self.dist.d(h) / (F::splat(2.0) * (zo + so)),
        );
        let w = F::select(ok, g, zero);
        BsdfSample {
            wi,
            weight: fr * w,
            pdf: F::select(ok, pdf, zero),
            lobe: F::U32::select(
                self.smooth,
                F::U32::splat(lobe::SPECULAR_REFLECTION),
                F::U32::splat(lobe::GLOSSY_REFLECTION),
            ),
            eta: F::one(),
        }
    }

    /// f(wo, wi) (no cosine); zero in smooth lanes and unless both directions are above.
    #[inline(always)]
    pub fn eval(&self, wo: V3<F>, wi: V3<F>) -> Chan<F, N> {
        let zero = F::zero();
        let (zo, zi) = (wo.z, wi.z);
        let h = (wo + wi).normalize();
        let ok = zo.gt(zero) & zi.gt(zero) & !self.smooth;
        let d = self.dist.d(h);
        let so = self.dist.stretched_len(wo);
        let si = self.dist.stretched_len(wi);
        let v = d / (F::splat(2.0) * (so * zi + si * zo));
        self.fresnel.eval(wo.dot(h)) * F::select(ok, v, zero)
    }

    /// The solid-angle density of [`Conductor::sample`] drawing `wi`; zero in smooth lanes.
    #[inline(always)]
    pub fn pdf(&self, wo: V3<F>, wi: V3<F>) -> F {
        let zero = F::zero();
        let h = (wo + wi).normalize();
        let ok = wo.z.gt(zero) & wi.z.gt(zero) & !self.smooth;
        let pdf = self.dist.d(h) / (F::splat(2.0) * (wo.z + self.dist.stretched_len(wo)));
        F::select(ok, pdf, zero)
    }
}
