//! Light samples: next-event estimation at the lanes whose BSDF has a density (diffuse and
//! rough conductors), a light chosen and sampled per lane, its BSDF value and MIS weight over
//! lanes, then its shadow ray.

use super::RenderStats;
use super::bsdf::{Chan, Diffuse, Frame};
use super::ctx::Ctx;
use super::shadow;
use super::state::{C, M, MAX_W, Paths, U, gdot, power_heuristic, select_c};
use super::surface::Surface;
use super::transport::{ChannelArray, Transport};
use crate::scene::light_lanes::LaneLightSample;
use crate::scene::lights::LightSource;
use crate::simd::{Float, Mask, UInt};

/// Next-event estimation at the lanes `dm`, diffuse but for the rough conductors `glossy`: a
/// light sample per lane, its BSDF value and MIS weight over lanes, then a shadow ray per lane
/// whose contribution is not zero.
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
    glossy: M<F>,
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
    let ok = ls.has & cos.gt(F::zero()) & gdot(wi, sf.nf).gt(F::zero());
    if ok.none() {
        return;
    }
    let bsdf = Diffuse { albedo: sf.color };
    let mut bsdf_pdf = bsdf.pdf(wo_l, wi_l);
    let mut f = bsdf.eval(wo_l, wi_l) * cos;
    if glossy.any() {
        let c = sf.conductor();
        bsdf_pdf = F::select(glossy, c.pdf(wo_l, wi_l), bsdf_pdf);
        f = select_c(glossy, c.eval(wo_l, wi_l) * cos, f);
    }
    let pdf = ls.pdf;
    let w = F::select(ls.delta, F::one(), power_heuristic(pdf, bsdf_pdf));
    let rad = lane_radiance(ctx, st, &ls, &sources, ok);
    let contrib = st.beta * f * rad * (w / pdf);
    let shoot = ok & !contrib.is_zero();
    let (so, sd, t_max) = shadow::from_surface(sf.p, sf.nf, &ls);
    shadow::trace::<F, T, N, MOTION, MEDIA>(ctx, st, so, sd, t_max, contrib, shoot, stats);
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
