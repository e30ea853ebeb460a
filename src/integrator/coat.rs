//! Plastic: a dielectric coat (smooth or GGX-rough) over a Lambertian base, energy
//! conserving with the coat's internal reflections accounted for.
//!
//! Light the coat does not reflect enters, scatters in the base and leaves through the coat;
//! what the coat reflects back inside bounces on the base again. With E(μ) the coat's
//! directional reflectance from outside (F(μ) for a smooth coat, the GGX lobe's albedo with
//! the coat's Fresnel term for a rough one), E_avg = 2∫E(μ)μ dμ and F_in the coat's internal
//! reflectance of diffuse light, the BSDF is
//!
//! f = f_coat + ρ_eff·(1 − E(μo))(1 − E(μi)) / (π(1 − E_avg)),  ρ_eff = ρ(1 − F_in)/(1 − ρF_in),
//!
//! ρ_eff summing the base's bounces under the coat. For a smooth coat (1 − E_avg) =
//! η²(1 − F_in), which makes the second term Mitsuba's `plastic` exactly:
//! ρ(1 − F(μo))(1 − F(μi)) / (πη²(1 − ρF_in)). The form is reciprocal, and with ρ = 1 a
//! direction's albedo is E(μo) + (1 − E(μo)) = 1 exactly, whatever the accuracy of E, as long
//! as E_avg is the integral of the same (interpolated) E: the tables hold it so.
//!
//! The tables depend on the coat's IOR, so they are built per IOR a scene uses (once per
//! process) by f64 quadrature, on the grid of the GGX energy tables.

use super::bsdf::{BsdfSample, Chan, fresnel_dielectric, lobe, reflect_local};
use super::ggx_tables::GGX_TABLE_SIZE;
use super::microfacet::{Ggx, table_bilinear, table_linear};
use crate::simd::{Float, Mask, UInt, V3};
use std::f32::consts::FRAC_1_PI;

use crate::energy::{AVG, F_IN, SMOOTH_AVG};
pub use crate::energy::{COAT_TABLE_LEN, coat_table, coat_table_cached};

// The coat tables share the grid of the GGX energy tables.
const _: () = assert!(crate::energy::TABLE_SIZE == GGX_TABLE_SIZE);

/// A plastic's BSDF over lanes: each lane's coat tables start at `base` in `tables`.
#[derive(Clone, Copy, Debug)]
pub struct Plastic<'a, F: Float, const N: usize> {
    /// The coat's microfacet distribution (ignored in smooth lanes).
    pub dist: Ggx<F>,
    /// Lanes whose coat is smooth: a delta lobe.
    pub smooth: F::Mask,
    /// The coat's IOR over the outside's.
    pub eta: F,
    /// The base's reflectance ρ per channel.
    pub albedo: Chan<F, N>,
    /// Every coat table of the scene.
    pub tables: &'a [f32],
    /// Each lane's offset into `tables` (a valid offset in every lane).
    pub base: F::U32,
}

impl<F: Float, const N: usize> Plastic<'_, F, N> {
    /// E(μ): the coat's directional reflectance from outside.
    #[inline(always)]
    fn e(&self, mu: F) -> F {
        let smooth = fresnel_dielectric(mu, self.eta);
        if self.smooth.all() {
            return smooth;
        }
        let rough = table_bilinear(self.tables, self.base, mu, self.dist.alpha());
        F::select(self.smooth, smooth, rough)
    }

    /// E_avg, linear in α (the smooth coat's from its own entry).
    #[inline(always)]
    fn e_avg(&self) -> F {
        let t = self.tables;
        let smooth = F::gather(t, self.base.wrapping_add(F::U32::splat(SMOOTH_AVG as u32)));
        if self.smooth.all() {
            return smooth;
        }
        let row = self.base.wrapping_add(F::U32::splat(AVG as u32));
        F::select(self.smooth, smooth, table_linear(t, row, self.dist.alpha()))
    }

    /// ρ_eff = ρ(1 − F_in)/(1 − ρF_in) per channel: the base's bounces under the coat.
    #[inline(always)]
    fn rho_eff(&self) -> Chan<F, N> {
        let f_in = F::gather(
            self.tables,
            self.base.wrapping_add(F::U32::splat(F_IN as u32)),
        );
        let one = F::one();
        // A loop, not `map`: the closure of a `map` that is not inlined is compiled without
        // the entry point's target features, and every lane operation in it becomes a call.
        let mut rho = self.albedo.0;
        for r in &mut rho {
            *r = *r * (one - f_in) / (one - *r * f_in).max(F::splat(1e-6));
        }
        Chan(rho)
    }

    /// The probability of sampling the coat's lobe from `wo`: its share of the albedo,
    /// E(μo) against (1 − E(μo)) times the base's mean ρ_eff.
    #[inline(always)]
    fn coat_probability(&self, e_o: F, rho: &Chan<F, N>) -> F {
        let mean = rho.0.iter().fold(F::zero(), |a, &r| a + r) * F::splat(1.0 / N as f32);
        let total = e_o + (F::one() - e_o) * mean;
        F::select(total.gt(F::zero()), e_o / total, F::one())
    }

    /// The base's lobe: ρ_eff(1 − E(μo))(1 − E(μi))/(π(1 − E_avg)).
    #[inline(always)]
    fn base_lobe(&self, rho: &Chan<F, N>, e_o: F, e_i: F) -> Chan<F, N> {
        let one = F::one();
        let k = (one - e_o) * (one - e_i)
            / (F::splat(std::f32::consts::PI) * (one - self.e_avg()).max(F::splat(1e-6)));
        *rho * k
    }

    /// The coat's lobe with probability P(coat) (a mirror direction in smooth lanes, a
    /// visible normal's reflection in rough ones), else a cosine-distributed direction.
    #[inline(always)]
    pub fn sample(&self, wo: V3<F>, uc: F, u1: F, u2: F) -> BsdfSample<F, Chan<F, N>> {
        let zero = F::zero();
        let rho = self.rho_eff();
        let e_o = self.e(wo.z);
        let p = self.coat_probability(e_o, &rho);
        let coat = uc.lt(p);
        let h = self.dist.sample_visible_normal(wo, u1, u2);
        let rough_wi = h * (F::splat(2.0) * wo.dot(h)) - wo;
        let coat_wi = V3::select(self.smooth, reflect_local(wo), rough_wi);
        let cosine = crate::sampling::warp::lanes::square_to_cosine_hemisphere(u1, u2);
        let wi = V3::select(coat, coat_wi, cosine);
        let ok = wo.z.gt(zero) & wi.z.gt(zero);
        let specular = self.smooth & coat;
        // The smooth coat's delta lobe: F(μo)/P(coat), chosen with probability P(coat).
        let mirror = F::select(p.gt(zero), e_o / p, zero);
        let pdf_mix = self.pdf_with(wo, wi, p);
        let f = self.eval_with(wo, wi, &rho, e_o);
        let w = F::select(ok & pdf_mix.gt(zero), wi.z / pdf_mix, zero);
        let mut weight = f * w;
        for c in weight.0.iter_mut() {
            *c = F::select(specular, F::select(ok, mirror, zero), *c);
        }
        BsdfSample {
            wi,
            weight,
            pdf: F::select(ok, F::select(specular, p, pdf_mix), zero),
            lobe: F::U32::select(
                specular,
                F::U32::splat(lobe::SPECULAR_REFLECTION),
                F::U32::select(
                    coat,
                    F::U32::splat(lobe::GLOSSY_REFLECTION),
                    F::U32::splat(lobe::DIFFUSE_REFLECTION),
                ),
            ),
            eta: F::one(),
        }
    }

    /// f(wo, wi) (no cosine): the rough coat's lobe and the base's; a smooth coat's delta
    /// lobe has no value here.
    #[inline(always)]
    pub fn eval(&self, wo: V3<F>, wi: V3<F>) -> Chan<F, N> {
        let rho = self.rho_eff();
        self.eval_with(wo, wi, &rho, self.e(wo.z))
    }

    #[inline(always)]
    fn eval_with(&self, wo: V3<F>, wi: V3<F>, rho: &Chan<F, N>, e_o: F) -> Chan<F, N> {
        let zero = F::zero();
        let (zo, zi) = (wo.z, wi.z);
        let ok = zo.gt(zero) & zi.gt(zero);
        let base = self.base_lobe(rho, e_o, self.e(zi));
        let rough = ok & !self.smooth;
        let coat = if rough.any() {
            let h = (wo + wi).normalize();
            let so = self.dist.stretched_len(wo);
            let si = self.dist.stretched_len(wi);
            let v = self.dist.d(h) / (F::splat(2.0) * (so * zi + si * zo));
            F::select(rough, fresnel_dielectric(wo.dot(h), self.eta) * v, zero)
        } else {
            zero
        };
        let mut out = base;
        for c in out.0.iter_mut() {
            *c = F::select(ok, *c + coat, zero);
        }
        out
    }

    /// The solid-angle density of [`Plastic::sample`] drawing `wi` (the base's lobe only in
    /// smooth lanes).
    #[inline(always)]
    pub fn pdf(&self, wo: V3<F>, wi: V3<F>) -> F {
        let rho = self.rho_eff();
        let p = self.coat_probability(self.e(wo.z), &rho);
        self.pdf_with(wo, wi, p)
    }

    #[inline(always)]
    fn pdf_with(&self, wo: V3<F>, wi: V3<F>, p: F) -> F {
        let zero = F::zero();
        let ok = wo.z.gt(zero) & wi.z.gt(zero);
        let cosine = (F::one() - p) * wi.z * F::splat(FRAC_1_PI);
        let h = (wo + wi).normalize();
        let vis = self.dist.d(h) / (F::splat(2.0) * (wo.z + self.dist.stretched_len(wo)));
        let pdf = F::select(self.smooth, cosine, cosine + p * vis);
        F::select(ok, pdf, zero)
    }
}
