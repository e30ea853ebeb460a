//! Light samples: next-event estimation at the lanes whose BSDF has a density (diffuse, rough
//! conductors and rough dielectrics), a light chosen and sampled per lane, its BSDF value and
//! MIS weight over lanes, then its shadow ray (from the far side of a rough dielectric when
//! the light is behind it).

use super::RenderStats;
use super::bsdf::{Chan, Diffuse, Frame, LaneChannels, Mode};
use super::ctx::Ctx;
use super::microfacet::RoughDielectric;
use super::state::{C, M, MAX_W, Paths, U, gdot, power_heuristic, select_c};
use super::surface::Surface;
use super::transport::{ChannelArray, Transport};
use super::{media, shadow};
use crate::scene::light_lanes::LaneLightSample;
use crate::scene::lights::LightSource;
use crate::simd::{Float, Mask, UInt, V3};

/// The lanes whose BSDF has a density other than the diffuse one.
pub(super) struct Glossy<'a, F: Float> {
    /// Plastics (their BSDF is the surface's [`Surface::plastic`] over `coat`).
    pub(super) plastic: M<F>,
    pub(super) coat: &'a [f32],
    /// Rough conductors (their BSDF is the surface's [`Surface::conductor`]).
    pub(super) conductor: M<F>,
    /// Rough dielectrics, and their BSDF.
    pub(super) dielectric: M<F>,
    pub(super) rough_dielectric: RoughDielectric<F>,
}

impl<F: Float> Glossy<'_, F> {
    /// The BSDF value (no cosine) at `wo_l`, `wi_l` (shading frame) of the lanes whose BSDF
    /// has a density (diffuse, albedo `sf.color`, where no glossy lane is set), and the
    /// density of sampling `wi_l`. `mode` matters only for the rough dielectrics.
    #[inline(always)]
    pub(super) fn eval<const N: usize>(
        &self,
        sf: &Surface<F, N>,
        wo_l: V3<F>,
        wi_l: V3<F>,
        mode: Mode,
    ) -> (C<F, N>, F) {
        let bsdf = Diffuse { albedo: sf.color };
        let mut pdf = bsdf.pdf(wo_l, wi_l);
        let mut f = bsdf.eval(wo_l, wi_l);
        if self.conductor.any() {
            let (c, m) = (sf.conductor(), self.conductor);
            pdf = F::select(m, c.pdf(wo_l, wi_l), pdf);
            f = select_c(m, c.eval(wo_l, wi_l), f);
        }
        if self.plastic.any() {
            let (p, m) = (sf.plastic(self.coat), self.plastic);
            pdf = F::select(m, p.pdf(wo_l, wi_l), pdf);
            f = select_c(m, p.eval(wo_l, wi_l), f);
        }
        if self.dielectric.any() {
            let (d, m) = (&self.rough_dielectric, self.dielectric);
            pdf = F::select(m, d.pdf(wo_l, wi_l), pdf);
            f = select_c(m, C::<F, N>::splat(d.eval(wo_l, wi_l, mode)), f);
        }
        (f, pdf)
    }
}

/// Next-event estimation at the lanes `dm`, diffuse but for those in `glossy`: a light sample
/// per lane, its BSDF value and MIS weight over lanes, then a shadow ray per lane whose
/// contribution is not zero.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn light_samples<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
    dm: M<F>,
    glossy: &Glossy<'_, F>,
    frame: &Frame<F>,
    dim: U<F>,
    stats: &mut RenderStats,
) {
    let wo_l = frame.to_local(-st.d);
    let scene = ctx.scene;
    let prims = &scene.prims;
    let u_sel = ctx.sampler.get_1d_lanes::<F>(st.pixel, st.sample, dim);
    let (ux, uy) =
        ctx.sampler
            .get_2d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(1)));
    // Spectral transport evaluates each lane's emitter at the lane's wavelengths.
    let mut sources = [LightSource::Environment; MAX_W];
    let ls = scene.lights.sample_lanes::<F, MOTION>(
        prims,
        sf.p,
        dm,
        u_sel,
        ux,
        uy,
        st.time,
        ctx.textures,
        T::SPECTRAL.then_some(&mut sources),
    );
    let wi = ls.wi;
    let wi_l = frame.to_local(wi);
    let cos = wi_l.z;
    let side = gdot(wi, sf.nf);
    // Lights behind a rough dielectric are seen through it: below both the shading and the
    // geometric surface.
    let through = glossy.dielectric & cos.lt(F::zero()) & side.lt(F::zero());
    let ok = ls.has & ((cos.gt(F::zero()) & side.gt(F::zero())) | through);
    if ok.none() {
        return;
    }
    let (f, bsdf_pdf) = glossy.eval(sf, wo_l, wi_l, Mode::Radiance);
    let f = f * cos.abs();
    let pdf = ls.pdf;
    let w = F::select(ls.delta, F::one(), power_heuristic(pdf, bsdf_pdf));
    let rad = lane_radiance(ctx, st, &ls, &sources, ok);
    let contrib = st.beta * f * rad * (w / pdf);
    let shoot = ok & !contrib.is_zero();
    let (so, sd, t_max) = shadow::from_surface(sf.p, sf.nf, &ls);
    let crossing = shoot & through;
    if MEDIA && crossing.any() {
        // A shadow ray through the interface starts in the medium beyond it.
        let (medium, in_medium) = (st.medium, st.in_medium);
        media::cross(ctx, st, sf, crossing);
        shadow::trace::<F, T, N, MOTION, MEDIA>(ctx, st, so, sd, t_max, contrib, shoot, stats);
        (st.medium, st.in_medium) = (medium, in_medium);
    } else {
        shadow::trace::<F, T, N, MOTION, MEDIA>(ctx, st, so, sd, t_max, contrib, shoot, stats);
    }
}

/// Each lane's light-sample radiance in the transport's channels, for the lanes in `m`.
#[inline(always)]
pub(super) fn lane_radiance<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    st: &Paths<F, T, N>,
    ls: &LaneLightSample<F>,
    sources: &[LightSource; MAX_W],
    m: M<F>,
) -> C<F, N> {
    if T::SPECTRAL {
        let mut rad = T::colours();
        let bits = m.bits();
        for (i, source) in sources.iter().enumerate().take(F::WIDTH) {
            if bits >> i & 1 != 0 {
                let rgb = ls.radiance.lane(i);
                T::set_source(&mut rad, i, ctx, source, rgb, &st.lam);
            }
        }
        T::eval(&rad, &st.lam)
    } else {
        // RGB: N = 3.
        let r = [ls.radiance.x, ls.radiance.y, ls.radiance.z];
        Chan(std::array::from_fn(|k| r[k]))
    }
}
