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
//!
//! Single scattering loses the energy of light that meets a second microfacet (41 % survives
//! at α = 1). Kulla & Conty 2017 restore it with a diffuse-like lobe
//! f_ms = F_ms·(1 − E(μo))(1 − E(μi)) / (π(1 − E_avg)), E(μ) the single-scattering albedo
//! with F = 1, E_avg = 2∫E(μ)μ dμ, and F_ms = F_avg²·E_avg / (1 − F_avg(1 − E_avg)) the
//! Fresnel term of the light that bounces on, F_avg = 2∫F(μ)μ dμ: a white conductor then
//! reflects all the light at every roughness. E and E_avg come from tables this module's
//! quadrature generates (`examples/ggx_tables.rs`, committed in `ggx_tables.rs`).

use super::bsdf::{
    BsdfSample, Chan, LaneChannels, Mode, fresnel_dielectric, fresnel_schlick, lobe, reflect_local,
    refract_lanes,
};
use super::dielectric_energy::Slices;
use super::ggx_tables::{GGX_E, GGX_E_AVG, GGX_TABLE_SIZE};
use crate::simd::{Float, Mask, TypedKernel, UInt, V3, math};
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

    /// The isotropic α of the same roughness, √(αx·αy): what the energy tables take.
    #[inline(always)]
    pub fn alpha(&self) -> F {
        (self.ax * self.ay).sqrt()
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
    /// Rough lanes with multiple-scattering compensation (ignored in smooth lanes).
    pub multiscatter: F::Mask,
    /// The Fresnel term.
    pub fresnel: ConductorFresnel<F, N>,
}

impl<F: Float, const N: usize> Conductor<F, N> {
    /// The lanes whose multiple-scattering lobe is on.
    #[inline(always)]
    fn ms_lanes(&self) -> F::Mask {
        self.multiscatter.and_not(self.smooth)
    }

    /// The probability of sampling the multiple-scattering lobe from `wo`: the share of the
    /// energy it adds, 1 − E(μo); zero where compensation is off.
    #[inline(always)]
    fn ms_probability(&self, wo: V3<F>, ms: F::Mask) -> F {
        let e = ggx_albedo_lanes(wo.z, self.dist.alpha());
        F::select(ms, F::one() - e, F::zero())
    }

    /// A visible normal, and `wo` reflected about it; in smooth lanes the mirror direction;
    /// with compensation, with probability 1 − E(μo) a cosine-distributed direction instead.
    /// Lanes where `wo` or the reflection lies below the surface have weight 0 (pdf 0).
    #[inline(always)]
    pub fn sample(&self, wo: V3<F>, u1: F, u2: F) -> BsdfSample<F, Chan<F, N>> {
        let zero = F::zero();
        let ms = self.ms_lanes();
        let any_ms = ms.any();
        // The lobe choice reuses u1, rescaled to [0, 1) within the chosen lobe.
        let (p_ms, diffuse, u1) = if any_ms {
            let p = self.ms_probability(wo, ms);
            let d = ms & u1.lt(p);
            let u = F::select(d, u1 / p, (u1 - p) / (F::one() - p));
            (p, d, F::select(ms, u.min(F::splat(ONE_MINUS_EPS)), u1))
        } else {
            (zero, F::Mask::splat(false), u1)
        };
        let h = self.dist.sample_visible_normal(wo, u1, u2);
        let cos_h = wo.dot(h);
        let rough_wi = h * (F::splat(2.0) * cos_h) - wo;
        let mut wi = V3::select(self.smooth, reflect_local(wo), rough_wi);
        if any_ms {
            let c = crate::sampling::warp::lanes::square_to_cosine_hemisphere(u1, u2);
            wi = V3::select(diffuse, c, wi);
        }
        let (zo, zi) = (wo.z, wi.z);
        let ok = zo.gt(zero) & zi.gt(zero);
        let cos_f = F::select(self.smooth, wo.z, cos_h);
        let fr = self.fresnel.eval(cos_f);
        let so = self.dist.stretched_len(wo);
        let si = self.dist.stretched_len(wi);
        // F·G2/G1(wo), and the visible-normal pdf D(h)/(2(zo + s(wo))).
        let g = F::select(self.smooth, F::one(), zi * (zo + so) / (so * zi + si * zo));
        let mut pdf = F::select(
            self.smooth,
            F::one(),
            self.dist.d(h) / (F::splat(2.0) * (zo + so)),
        );
        let mut weight = fr * F::select(ok, g, zero);
        if any_ms {
            // The mixture's weight f·cos/pdf from eval and pdf, in the compensated lanes only,
            // so a lane's numbers do not depend on its neighbours.
            let mixture = self.pdf_with(wo, wi, ms, p_ms);
            let w = F::select(ok & mixture.gt(zero), zi / mixture, zero);
            let f = self.eval(wo, wi) * w;
            for (c, m) in weight.0.iter_mut().zip(f.0) {
                *c = F::select(ms, m, *c);
            }
            pdf = F::select(ms, mixture, pdf);
        }
        BsdfSample {
            wi,
            weight,
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
        let single = self.fresnel.eval(wo.dot(h)) * F::select(ok, v, zero);
        let ms = self.ms_lanes() & ok;
        if ms.none() {
            return single;
        }
        // f_ms = F_ms (1 − E(μo))(1 − E(μi)) / (π (1 − E_avg)).
        let a = self.dist.alpha();
        let (eo, ei) = (ggx_albedo_lanes(zo, a), ggx_albedo_lanes(zi, a));
        let e_avg = ggx_average_albedo_lanes(a);
        let lobe = (F::one() - eo) * (F::one() - ei)
            / (F::splat(std::f32::consts::PI) * (F::one() - e_avg).max(F::splat(1e-6)));
        let f_avg = self.fresnel_average();
        let mut out = single;
        for (o, fa) in out.0.iter_mut().zip(f_avg.0) {
            let f_ms = fa * fa * e_avg / (F::one() - fa * (F::one() - e_avg));
            *o = F::select(ms, *o + f_ms * lobe, *o);
        }
        out
    }

    /// The solid-angle density of [`Conductor::sample`] drawing `wi`; zero in smooth lanes.
    #[inline(always)]
    pub fn pdf(&self, wo: V3<F>, wi: V3<F>) -> F {
        let ms = self.ms_lanes();
        if ms.none() {
            return self.pdf_with(wo, wi, ms, F::zero());
        }
        self.pdf_with(wo, wi, ms, self.ms_probability(wo, ms))
    }

    /// The mixture density with the multiple-scattering lobe chosen with probability `p_ms`.
    #[inline(always)]
    fn pdf_with(&self, wo: V3<F>, wi: V3<F>, ms: F::Mask, p_ms: F) -> F {
        let zero = F::zero();
        let h = (wo + wi).normalize();
        let ok = wo.z.gt(zero) & wi.z.gt(zero) & !self.smooth;
        let single = self.dist.d(h) / (F::splat(2.0) * (wo.z + self.dist.stretched_len(wo)));
        let pdf = if ms.none() {
            single
        } else {
            let cosine = wi.z * F::splat(std::f32::consts::FRAC_1_PI);
            (F::one() - p_ms) * single + p_ms * cosine
        };
        F::select(ok, pdf, zero)
    }

    /// F_avg = 2∫F(μ)μ dμ per channel: Gauss–Legendre in x = μ² (F(√x) is smooth), four
    /// nodes, which hold every metal's and Schlick's average to 1e-3.
    #[inline(always)]
    fn fresnel_average(&self) -> Chan<F, N> {
        let mut acc = [F::zero(); N];
        for (x, w) in GAUSS4 {
            let f = self.fresnel.eval(F::splat(x.sqrt() as f32));
            for (a, f) in acc.iter_mut().zip(f.0) {
                *a = f.mul_add(F::splat(w as f32), *a);
            }
        }
        Chan(acc)
    }
}

/// A rough dielectric interface (Walter et al. 2007): GGX microfacets that each reflect with
/// their Fresnel probability and otherwise refract. `eta` is the relative IOR across it in the
/// direction of travel (transmitted over incident, the incident side being `+z`), as for the
/// smooth [`super::bsdf::Dielectric`].
///
/// Sampling draws a visible normal h, then reflection with probability F(wo·h) or refraction
/// about h. With the generalised half vector h ∝ η·wi + wo of a refraction and
/// dωh/dωi = |wi·h| / (wi·h + wo·h/η)²,
/// - f_r = D·F·G2 / (4 zo zi) and pdf_r = F·D / (2(zo + s(wo))),
/// - f_t = (1 − F)·D·G2·|wi·h||wo·h| / (|zi| zo (wi·h + wo·h/η)²), over η² for radiance,
///   and pdf_t = (1 − F)·G1(wo)·D·(wo·h)/zo · dωh/dωi,
///
/// so every sample's weight is G2/G1(wo), over η² for refracted radiance.
///
/// With compensation, the energy 1 − E(μo) that single scattering loses returns through a
/// diffuse-like lobe on each side (Kulla & Conty 2017; the tables and the reciprocal split
/// between the sides are [`crate::energy::dielectric_energy_table`]'s), sampled with
/// probability 1 − E(μo): the interface then neither absorbs nor creates light.
#[derive(Clone, Copy, Debug)]
pub struct RoughDielectric<F: Float> {
    /// The microfacet distribution.
    pub dist: Ggx<F>,
    /// Relative IOR, transmitted over incident; not 1 (an interface that is none refracts
    /// every normal into the same direction, a delta the smooth form handles).
    pub eta: F,
    /// Use Schlick's Fresnel approximation instead of the exact formula.
    pub schlick: bool,
    /// Lanes with multiple-scattering compensation.
    pub multiscatter: F::Mask,
}

/// A rough dielectric's out-of-line work, each run inside the entry point of its lanes'
/// instruction set ([`Float::enter_typed`]), each its own function.
struct SampleIn<F: Float>(RoughDielectric<F>, V3<F>, [F; 3], Mode);
struct EvalIn<F: Float>(RoughDielectric<F>, V3<F>, V3<F>, Mode);
struct PdfIn<F: Float>(RoughDielectric<F>, V3<F>, V3<F>);

impl<F: Float> TypedKernel<F> for SampleIn<F> {
    type Output = BsdfSample<F, F>;
    #[inline(always)]
    fn run(self) -> Self::Output {
        let [uc, u1, u2] = self.2;
        self.0.sample_in(self.1, uc, u1, u2, self.3)
    }
}

impl<F: Float> TypedKernel<F> for EvalIn<F> {
    type Output = F;
    #[inline(always)]
    fn run(self) -> F {
        self.0.eval_in(self.1, self.2, self.3)
    }
}

impl<F: Float> TypedKernel<F> for PdfIn<F> {
    type Output = F;
    #[inline(always)]
    fn run(self) -> F {
        self.0.pdf_in(self.1, self.2)
    }
}

/// The compensation lobe of a rough dielectric at one (wo, wi) pair: its f (importance
/// form) and the density of sampling it once chosen.
struct MsLobe<F> {
    f: F,
    pdf: F,
    /// 1 − E(μo): the probability of choosing it.
    p: F,
}

impl<F: Float> RoughDielectric<F> {
    /// The microfacet's Fresnel reflectance at `cos` = wo·h.
    #[inline(always)]
    fn fresnel(&self, cos: F) -> F {
        if self.schlick {
            fresnel_schlick(cos, self.eta)
        } else {
            fresnel_dielectric(cos, self.eta)
        }
    }

    /// 1/η² on refracted radiance, 1 on importance (and on reflection).
    #[inline(always)]
    fn scale(&self, mode: Mode) -> F {
        match mode {
            Mode::Radiance => (self.eta * self.eta).recip(),
            Mode::Importance => F::one(),
        }
    }

    /// A visible normal, then reflection about it with probability F or refraction. Lanes
    /// whose direction ends on the wrong side for its lobe have weight 0 and pdf 0.
    ///
    /// Out of line, as `eval` and `pdf`: inlined into the kernel with the compensation lobe,
    /// the kernel's register allocation took most of a release build; the call is one per
    /// packet of lanes, into the entry point of the lanes' instruction set.
    #[inline(never)]
    pub fn sample<S: LaneChannels<F>>(
        &self,
        wo: V3<F>,
        uc: F,
        u1: F,
        u2: F,
        mode: Mode,
    ) -> BsdfSample<F, S> {
        let s = F::enter_typed(SampleIn(*self, wo, [uc, u1, u2], mode));
        BsdfSample {
            wi: s.wi,
            weight: S::splat(s.weight),
            pdf: s.pdf,
            lobe: s.lobe,
            eta: s.eta,
        }
    }

    /// [`RoughDielectric::sample`] with a colourless weight.
    #[inline(always)]
    fn sample_in(&self, wo: V3<F>, uc: F, u1: F, u2: F, mode: Mode) -> BsdfSample<F, F> {
        let (zero, one) = (F::zero(), F::one());
        let ms = self.multiscatter;
        let any_ms = ms.any();
        // The compensation lobe is chosen with probability 1 − E(μo), reusing uc rescaled.
        let (slices, diffuse, uc, u_side) = if any_ms {
            let sl = Slices::new(self.eta);
            let e = sl.albedo(F::Mask::splat(false), wo.z, self.dist.alpha());
            let p = F::select(ms, one - e, zero);
            let d = ms & uc.lt(p);
            let lim = F::splat(ONE_MINUS_EPS);
            let u_side = (uc / p).min(lim);
            let u_rest = F::select(ms, ((uc - p) / (one - p)).min(lim), uc);
            (Some(sl), d, u_rest, u_side)
        } else {
            (None, F::Mask::splat(false), uc, zero)
        };
        let h = self.dist.sample_visible_normal(wo, u1, u2);
        let cos_o = wo.dot(h);
        let r = self.fresnel(cos_o);
        let (wt, can_refract) = refract_lanes(wo, h, self.eta);
        let t = can_refract & uc.ge(r);
        let wi = V3::select(t, wt, h * (F::splat(2.0) * cos_o) - wo);
        let (zo, zi) = (wo.z, wi.z);
        let single_ok = zo.gt(zero) & cos_o.gt(zero) & F::select(t, -zi, zi).gt(zero);
        let ok = single_ok;
        let (so, si) = (self.dist.stretched_len(wo), self.dist.stretched_len(wi));
        let azi = zi.abs();
        // G2/G1(wo) with both in the stretched-length form.
        let g = azi * (zo + so) / (so * azi + si * zo);
        let d = self.dist.d(h);
        let pdf_r = d * r / (F::splat(2.0) * (zo + so));
        let cos_i = wi.dot(h);
        let denom = cos_i + cos_o / self.eta;
        let pdf_t =
            F::splat(2.0) * d * cos_o / (zo + so) * cos_i.abs() / (denom * denom) * (one - r);
        let mut pdf = F::select(ok, F::select(t, pdf_t, pdf_r), zero);
        let mut weight = F::select(ok, g * F::select(t, self.scale(mode), one), zero);
        let (mut wi, mut t) = (wi, t);
        if let Some(sl) = slices {
            // In the compensated lanes: in `diffuse` ones a cosine-distributed direction,
            // transmitted with the lobe's transmitted share; the weight is the mixture's
            // f·|zi|/pdf, so a lane's numbers do not depend on its neighbours.
            let c = crate::sampling::warp::lanes::square_to_cosine_hemisphere(u1, u2);
            let through = u_side.lt(sl.transmitted_share(self.dist.alpha(), self.eta));
            let c = V3::new(c.x, c.y, F::select(through, -c.z, c.z));
            wi = V3::select(diffuse, c, wi);
            t = (diffuse & through) | t.and_not(diffuse);
            let (f, mix) = self.eval_pdf(wo, wi, mode, &sl);
            // A failed single-scattering draw stays failed: its direction was not drawn
            // from the mixture.
            let ok = ms & (diffuse | single_ok) & zo.gt(zero) & !wi.z.eq(zero) & mix.gt(zero);
            weight = F::select(ms, F::select(ok, f * wi.z.abs() / mix, zero), weight);
            pdf = F::select(ms, F::select(ok, mix, zero), pdf);
        }
        BsdfSample {
            wi,
            weight,
            pdf,
            lobe: F::U32::select(
                t,
                F::U32::splat(lobe::GLOSSY_TRANSMISSION),
                F::U32::splat(lobe::GLOSSY_REFLECTION),
            ),
            eta: F::select(t, self.eta, one),
        }
    }

    /// f and the mixture density at (wo, wi) with the compensation lobe, its tables read
    /// once.
    #[inline(always)]
    fn eval_pdf(&self, wo: V3<F>, wi: V3<F>, mode: Mode, sl: &Slices<F>) -> (F, F) {
        let ms = self.ms_lobe(wo, wi, sl, mode);
        let f = self.eval_single(wo, wi, mode) + ms.f;
        let pdf = (F::one() - ms.p) * self.pdf_single(wo, wi) + ms.p * ms.pdf;
        (f, pdf)
    }

    /// The compensation lobe at (wo, wi), zero outside the compensated lanes: its share of
    /// the side wi is on times (1 − E(μo))(1 − E'(|μi|)) / (π(1 − E'_avg)), over η² for
    /// transmitted radiance.
    #[inline(always)]
    fn ms_lobe(&self, wo: V3<F>, wi: V3<F>, sl: &Slices<F>, mode: Mode) -> MsLobe<F> {
        let (zero, one) = (F::zero(), F::one());
        let a = self.dist.alpha();
        let far = wi.z.lt(zero);
        let eo = sl.albedo(F::Mask::splat(false), wo.z, a);
        let ei = sl.albedo(far, wi.z.abs(), a);
        let avg = sl.average(far, a);
        let x = sl.transmitted_share(a, self.eta);
        let share = F::select(far, x, one - x);
        let ok = self.multiscatter & wo.z.gt(zero) & !wi.z.eq(zero);
        let p = F::select(self.multiscatter & wo.z.gt(zero), one - eo, zero);
        let cosine = wi.z.abs() * F::splat(std::f32::consts::FRAC_1_PI);
        let lobe = share * (one - eo) * (one - ei) * F::splat(std::f32::consts::FRAC_1_PI)
            / (one - avg).max(F::splat(1e-6));
        let scale = F::select(far, self.scale(mode), one);
        MsLobe {
            f: F::select(ok, lobe * scale, zero),
            pdf: F::select(ok, share * cosine, zero),
            p,
        }
    }

    /// The generalised half vector of `wo` and `wi` (turned to `+z`), its cosines with both,
    /// and the lanes where it is a microfacet normal that scatters `wo` into `wi` (both
    /// directions on its front, `wo` above the surface).
    #[inline(always)]
    fn half(&self, wo: V3<F>, wi: V3<F>) -> (V3<F>, F, F, F::Mask, F::Mask) {
        let zero = F::zero();
        let reflect = wi.z.gt(zero);
        let etap = F::select(reflect, F::one(), self.eta);
        let m = wi * etap + wo;
        let len2 = m.dot(m);
        let inv = len2.sqrt().recip();
        let h = m * F::select(m.z.lt(zero), -inv, inv);
        let (cos_o, cos_i) = (wo.dot(h), wi.dot(h));
        let ok = wo.z.gt(zero)
            & !wi.z.eq(zero)
            & len2.gt(zero)
            & cos_o.gt(zero)
            & (cos_i * wi.z).gt(zero);
        (h, cos_o, cos_i, reflect, ok)
    }

    /// f(wo, wi) (no cosine): colourless, one value per lane.
    #[inline(never)]
    pub fn eval(&self, wo: V3<F>, wi: V3<F>, mode: Mode) -> F {
        F::enter_typed(EvalIn(*self, wo, wi, mode))
    }

    #[inline(always)]
    fn eval_in(&self, wo: V3<F>, wi: V3<F>, mode: Mode) -> F {
        let sl = self.multiscatter.any().then(|| Slices::new(self.eta));
        self.eval_with(wo, wi, mode, sl.as_ref())
    }

    /// [`RoughDielectric::eval`], with the compensation lobe where `sl` is given.
    #[inline(always)]
    fn eval_with(&self, wo: V3<F>, wi: V3<F>, mode: Mode, sl: Option<&Slices<F>>) -> F {
        let single = self.eval_single(wo, wi, mode);
        match sl {
            Some(sl) => single + self.ms_lobe(wo, wi, sl, mode).f,
            None => single,
        }
    }

    /// The single-scattering f(wo, wi).
    #[inline(always)]
    fn eval_single(&self, wo: V3<F>, wi: V3<F>, mode: Mode) -> F {
        let (zero, two) = (F::zero(), F::splat(2.0));
        let (h, cos_o, cos_i, reflect, ok) = self.half(wo, wi);
        let (zo, azi) = (wo.z, wi.z.abs());
        let d = self.dist.d(h);
        let r = self.fresnel(cos_o);
        // D·G2/(4 zo |zi|) = D / (2 (s(wo)|zi| + s(wi) zo)).
        let dg = d / (two * (self.dist.stretched_len(wo) * azi + self.dist.stretched_len(wi) * zo));
        let denom = cos_i + cos_o / self.eta;
        let ft = (F::one() - r) * dg * F::splat(4.0) * (cos_i * cos_o).abs() / (denom * denom)
            * self.scale(mode);
        F::select(ok, F::select(reflect, r * dg, ft), zero)
    }

    /// The solid-angle density of [`RoughDielectric::sample`] drawing `wi`.
    #[inline(never)]
    pub fn pdf(&self, wo: V3<F>, wi: V3<F>) -> F {
        F::enter_typed(PdfIn(*self, wo, wi))
    }

    #[inline(always)]
    fn pdf_in(&self, wo: V3<F>, wi: V3<F>) -> F {
        let sl = self.multiscatter.any().then(|| Slices::new(self.eta));
        self.pdf_with(wo, wi, sl.as_ref())
    }

    /// [`RoughDielectric::pdf`], the mixture with the compensation lobe where `sl` is given.
    #[inline(always)]
    fn pdf_with(&self, wo: V3<F>, wi: V3<F>, sl: Option<&Slices<F>>) -> F {
        let single = self.pdf_single(wo, wi);
        match sl {
            Some(sl) => {
                // Mode only scales f, not the density.
                let ms = self.ms_lobe(wo, wi, sl, Mode::Importance);
                (F::one() - ms.p) * single + ms.p * ms.pdf
            }
            None => single,
        }
    }

    /// The single-scattering density of drawing `wi`.
    #[inline(always)]
    fn pdf_single(&self, wo: V3<F>, wi: V3<F>) -> F {
        let (zero, two) = (F::zero(), F::splat(2.0));
        let (h, cos_o, cos_i, reflect, ok) = self.half(wo, wi);
        let zo = wo.z;
        let vis = self.dist.d(h) / (two * (zo + self.dist.stretched_len(wo)));
        let r = self.fresnel(cos_o);
        let denom = cos_i + cos_o / self.eta;
        let pt = (F::one() - r) * vis * F::splat(4.0) * cos_o * cos_i.abs() / (denom * denom);
        F::select(ok, F::select(reflect, r * vis, pt), zero)
    }
}

/// The largest f32 below 1: where a rescaled uniform must stay.
const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

/// Four-node Gauss–Legendre rule on [0, 1]: (node, weight).
const GAUSS4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_7, 0.173_927_422_568_726_9),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_1),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_1),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_9),
];

/// `x` clamped to [0, 1], NaN to 0: a table index made of it stays inside the table.
#[inline(always)]
pub(crate) fn unit<F: Float>(x: F) -> F {
    F::select(x.gt(F::zero()), x.min(F::one()), F::zero())
}

/// A `GGX_TABLE_SIZE`² table of rows per α, starting at `base` in `t`, at (μ, α): bilinear,
/// μ and α clamped to [0, 1].
#[inline(always)]
pub(crate) fn table_bilinear<F: Float>(t: &[f32], base: F::U32, mu: F, alpha: F) -> F {
    let last = (GGX_TABLE_SIZE - 1) as f32;
    let x = unit(mu) * F::splat(last);
    let y = unit(alpha) * F::splat(last);
    let (xi, yi) = (
        x.floor().min(F::splat(last - 1.0)),
        y.floor().min(F::splat(last - 1.0)),
    );
    let (fx, fy) = (x - xi, y - yi);
    let i = base.wrapping_add((yi * F::splat(GGX_TABLE_SIZE as f32) + xi).to_i32_bits());
    let one = F::U32::splat(1);
    let row = F::U32::splat(GGX_TABLE_SIZE as u32);
    let a = F::gather(t, i);
    let b = F::gather(t, i.wrapping_add(one));
    let c = F::gather(t, i.wrapping_add(row));
    let d = F::gather(t, i.wrapping_add(row).wrapping_add(one));
    let top = a + (b - a) * fx;
    let bottom = c + (d - c) * fx;
    top + (bottom - top) * fy
}

/// A `GGX_TABLE_SIZE` row over α, starting at `base` in `t`, at α: linear, α clamped to
/// [0, 1].
#[inline(always)]
pub(crate) fn table_linear<F: Float>(t: &[f32], base: F::U32, alpha: F) -> F {
    let last = (GGX_TABLE_SIZE - 1) as f32;
    let y = unit(alpha) * F::splat(last);
    let yi = y.floor().min(F::splat(last - 1.0));
    let f = y - yi;
    let i = base.wrapping_add(yi.to_i32_bits());
    let a = F::gather(t, i);
    let b = F::gather(t, i.wrapping_add(F::U32::splat(1)));
    a + (b - a) * f
}

/// E(μ, α) from the table, bilinear, μ and α clamped to [0, 1].
#[inline(always)]
pub fn ggx_albedo_lanes<F: Float>(mu: F, alpha: F) -> F {
    table_bilinear(GGX_E.as_flattened(), F::U32::splat(0), mu, alpha)
}

/// E_avg(α) from the table, linear, α clamped to [0, 1].
#[inline(always)]
pub fn ggx_average_albedo_lanes<F: Float>(alpha: F) -> F {
    table_linear(&GGX_E_AVG, F::U32::splat(0), alpha)
}

pub use crate::energy::{ggx_albedo, ggx_albedo_with, ggx_average_albedo};
