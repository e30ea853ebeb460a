//! MEDIA over lanes: each lane inside a medium samples its free flight; lanes that scatter
//! there take a light sample through the phase function, an equiangular sample and a
//! phase-sampled continuation, and lanes that pass go on to their surface. Shadow rays from
//! any lane carry their medium's transmittance.
//!
//! Lane math throughout, with the per-path integrator's operations in the same order, except
//! the equiangular set-ups, which stay per lane in f64 (their accuracy as the light nears the
//! ray line is the point of [`Equiangular`]'s formulation).

use super::{C, M, MAX_W, Paths, ScratchC, U, chan_lane, gdot, lane_radiance, select_c};
use crate::geometry::{Ray, offset_ray_origin_lanes};
use crate::integrator::RenderStats;
use crate::integrator::bsdf::Chan;
use crate::integrator::path::{
    self, Ctx, DIM_MEDIA, DIMS_PER_SEGMENT, PathState, Segment, ShadowRequest,
};
use crate::integrator::transport::{ChannelArray, MediumOps, Transport};
use crate::medium::lanes;
use crate::simd::{Float, Mask, UInt, V3};
use crate::spectrum::Channels;
use crate::systems::packet::PacketHit;
use crate::systems::primitives::NO_MEDIUM;

/// Lane `i`'s path as the per-path integrator's state.
#[inline(always)]
pub(super) fn lane_state<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize>(
    st: &Paths<F, T, N>,
    i: usize,
) -> PathState<T> {
    PathState::<T> {
        ray: Ray::new(st.o.lane(i), st.d.lane(i)),
        beta: chan_lane(&st.beta, i),
        l: chan_lane(&st.l, i),
        lambda: st.lam[i],
        eta_scale: st.eta_scale.lane(i),
        depth: st.depth.lane(i),
        specular: st.specular.lane(i),
        prev_pdf: st.prev_pdf.lane(i),
        prev_p: st.prev_p.lane(i),
        time: st.time.lane(i),
        pixel: st.pixel.lane(i),
        sample: st.sample.lane(i),
        alive: true,
        medium: st.medium[i],
        segments: st.segments[i],
    }
}

/// Shadow rays of the lanes in `shoot`, from their current medium: a packet any-hit first;
/// a ray that meets nothing stays in that medium and takes its transmittance over the
/// whole length, one that meets something may cross boundaries and takes
/// `transmittance_with` per lane. Adds `contrib` times the transmittance to the radiance.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn shadows<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    o: V3<F>,
    d: V3<F>,
    t_max: F,
    contrib: C<F, N>,
    shoot: M<F>,
    stats: &mut RenderStats,
) {
    if shoot.none() {
        return;
    }
    stats.shadow_rays += u64::from(shoot.count());
    let scene = ctx.scene;
    let blocked = scene.occluded_packet::<F, MOTION>(o, d, shoot, t_max, st.time);
    let clear = shoot.and_not(blocked);
    let mut tr = ScratchC::<N>::new();
    // Clear lanes inside a medium take its transmittance over the whole length; those outside
    // any transmit everything, and without such lanes no exponential is evaluated at all.
    let bits = clear.bits();
    let mut inside = 0u32;
    let mut sigma_t = ScratchC::<N>::new();
    for i in 0..F::WIDTH {
        if bits >> i & 1 != 0 && st.medium[i] != NO_MEDIUM {
            inside |= 1 << i;
            sigma_t.set(i, T::medium(ctx, st.medium[i], &st.lam[i]).sigma_t());
        }
    }
    if inside != 0 {
        let len = gdot(d, d).sqrt();
        let t: [F; N] = lanes::transmittance(&sigma_t.load::<F>().0, t_max * len);
        for (k, c) in t.iter().enumerate() {
            c.store(&mut tr.0[k]);
        }
    }
    let outside = bits & !inside;
    for i in 0..F::WIDTH {
        if outside >> i & 1 != 0 {
            tr.set(i, T::S::ONE);
        }
    }
    let bits = blocked.bits();
    for i in 0..F::WIDTH {
        if bits >> i & 1 != 0 {
            let lam = &st.lam[i];
            let t: T::S = scene.transmittance_with::<MOTION, T::S>(
                &Ray::new(o.lane(i), d.lane(i)),
                t_max.lane(i),
                st.time.lane(i),
                st.medium[i],
                #[inline(always)]
                |m, d| T::medium(ctx, m, lam).transmittance(d),
            );
            tr.set(i, t);
        }
    }
    st.l = select_c(shoot, st.l + contrib * tr.load(), st.l);
}

/// Dimension `k` of a segment's block.
#[inline(always)]
fn plus<F: Float>(dim: U<F>, k: u32) -> U<F> {
    dim.wrapping_add(U::<F>::splat(k))
}

/// Whether every channel is finite.
#[inline(always)]
fn finite<F: Float, const N: usize>(c: &C<F, N>) -> M<F> {
    let mut m = c.0[0].is_finite();
    for x in &c.0[1..] {
        m &= x.is_finite();
    }
    m
}

/// The free flight of every lane in `started` that is inside a medium, and the scattering
/// events it samples. Returns the lanes that scattered in a medium (their vertex is done);
/// the others that were in a medium have their throughput weighted for reaching their hit.
#[inline(always)]
pub(super) fn medium_stage<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    hits: &PacketHit<F>,
    started: M<F>,
    stats: &mut RenderStats,
) -> M<F> {
    let mut inside = 0u32;
    for i in 0..F::WIDTH {
        inside |= u32::from(st.medium[i] != NO_MEDIUM) << i;
    }
    let inm = started & super::mask_from_bits::<F>(inside);
    if inm.none() {
        return inm;
    }
    let bits = inm.bits();
    let (mut sigma_s, mut sigma_t) = (ScratchC::<N>::new(), ScratchC::<N>::new());
    let mut g = [0.0f32; MAX_W];
    let mut dims = [0u32; MAX_W];
    let mut meds: [Option<T::Med>; MAX_W] = [None; MAX_W];
    for i in 0..F::WIDTH {
        if bits >> i & 1 != 0 {
            let med = T::medium(ctx, st.medium[i], &st.lam[i]);
            sigma_s.set(i, med.sigma_s());
            sigma_t.set(i, med.sigma_t());
            g[i] = med.g();
            meds[i] = Some(med);
            dims[i] = DIM_MEDIA.wrapping_add(st.segments[i].wrapping_mul(DIMS_PER_SEGMENT));
            st.segments[i] = st.segments[i].wrapping_add(1);
        }
    }
    let (sigma_s, sigma_t) = (sigma_s.load::<F>().0, sigma_t.load::<F>().0);
    let g = F::load(&g);
    let dim = U::<F>::from_fn(|i| dims[i]);
    let t_hit = F::select(hits.hit, hits.t, F::splat(f32::INFINITY));
    let sampler = &ctx.sampler;
    let u_c = sampler.get_1d_lanes::<F>(st.pixel, st.sample, dim);
    let u_t = sampler.get_1d_lanes::<F>(st.pixel, st.sample, plus::<F>(dim, 1));
    let probs = st.beta;
    let below_max = st.depth.lt(U::<F>::splat(ctx.max_depth));
    if ctx.equiangular && ctx.nee {
        equiangular_lanes::<F, T, N, MOTION>(ctx, st, inm & below_max, &meds, t_hit, &dims, stats);
    }
    let ff = lanes::sample_free_flight(&sigma_s, &sigma_t, t_hit, u_c, u_t, &probs.0);
    st.beta = select_c(inm, st.beta * Chan(ff.weight), st.beta);
    let scat = inm & ff.scatter;
    // Passing lanes go on to their hit, unless the flight left them nothing.
    st.alive = st
        .alive
        .and_not(inm.and_not(ff.scatter) & st.beta.is_zero());
    let live = scat & below_max;
    st.alive = st.alive.and_not(scat.and_not(live));
    if live.none() {
        return scat;
    }
    st.depth = U::<F>::select(live, st.depth.wrapping_add(U::<F>::splat(1)), st.depth);
    let t = ff.t;
    let p = st.o + st.d * t;
    let wo = -st.d;
    if ctx.nee {
        let u_sel = sampler.get_1d_lanes::<F>(st.pixel, st.sample, plus::<F>(dim, 2));
        let (ux, uy) = sampler.get_2d_lanes::<F>(st.pixel, st.sample, plus::<F>(dim, 3));
        let scene = ctx.scene;
        let ls = scene.lights.sample_lanes::<F, MOTION>(
            &scene.prims,
            p,
            live,
            u_sel,
            ux,
            uy,
            st.time,
            ctx.textures,
            T::SPECTRAL || ctx.equiangular,
        );
        if ls.has.any() {
            let ph = lanes::hg_phase_dirs(wo, ls.wi, g);
            let w = if ctx.equiangular {
                let p_ff = lanes::free_flight_pdf(&sigma_t, t, &probs.0);
                let mut w = [0.0f32; MAX_W];
                let has = ls.has.bits();
                for (i, w) in w.iter_mut().enumerate().take(F::WIDTH) {
                    if has >> i & 1 != 0 {
                        let seg = Segment {
                            ray: Ray::new(st.o.lane(i), st.d.lane(i)),
                            t: t.lane(i),
                            t_hit: t_hit.lane(i),
                            p_ff: p_ff.lane(i),
                        };
                        let point = ls.at_point.lane(i).then(|| (ls.q.lane(i), ls.nq.lane(i)));
                        *w = path::medium_light_weight::<MOTION>(
                            ctx,
                            point,
                            ls.delta.lane(i),
                            ls.sources[i],
                            ls.pdf.lane(i),
                            ph.lane(i),
                            p.lane(i),
                            &seg,
                            st.time.lane(i),
                        );
                    }
                }
                F::load(&w)
            } else {
                F::select(ls.delta, F::one(), super::power_heuristic(ls.pdf, ph))
            };
            let rad = lane_radiance(ctx, st, &ls, ls.has);
            let contrib = st.beta * rad * (ph * w / ls.pdf);
            let shoot = ls.has & !contrib.is_zero() & finite(&contrib);
            // A point in a medium lies on no surface: no offset at this end.
            let to_q = ls.q - p;
            let nt = V3::select(gdot(ls.nq, to_q).le(F::zero()), ls.nq, -ls.nq);
            let area = ls.at_point.and_not(ls.delta);
            let dir = V3::select(
                area,
                offset_ray_origin_lanes(ls.q, nt) - p,
                V3::select(ls.at_point, to_q, ls.wi),
            );
            let t_max = F::select(
                area,
                F::one(),
                F::select(ls.at_point, F::splat(1.0 - 1e-4), F::splat(f32::INFINITY)),
            );
            shadows::<F, T, N, MOTION>(ctx, st, p, dir, t_max, contrib, shoot, stats);
        }
    }
    let (ux, uy) = sampler.get_2d_lanes::<F>(st.pixel, st.sample, plus::<F>(dim, 5));
    let (wi, pdf) = lanes::sample_hg(wo, g, ux, uy);
    st.prev_pdf = F::select(live, pdf, st.prev_pdf);
    st.specular = st.specular.and_not(live);
    st.prev_p = V3::select(live, p, st.prev_p);
    st.o = V3::select(live, p, st.o);
    st.d = V3::select(live, wi, st.d);
    super::russian_roulette(ctx, st, live, plus::<F>(dim, 7));
    scat
}

/// The equiangular technique's light sample for each lane in `m`, set up per lane (see
/// [`path::equiangular_nee`]), its shadow rays as a packet.
#[inline(always)]
fn equiangular_lanes<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    m: M<F>,
    meds: &[Option<T::Med>; MAX_W],
    t_hit: F,
    dims: &[u32; MAX_W],
    stats: &mut RenderStats,
) {
    let (mut o, mut d) = (super::Scratch3::new(), super::Scratch3::new());
    let mut t_max = [0.0f32; MAX_W];
    let mut contrib = ScratchC::<N>::new();
    let mut shoot = 0u32;
    let bits = m.bits();
    for i in 0..F::WIDTH {
        if bits >> i & 1 == 0 {
            continue;
        }
        let Some(med) = &meds[i] else {
            continue;
        };
        let s = lane_state(st, i);
        let r: Option<ShadowRequest<T::S>> =
            path::equiangular_nee::<T, MOTION>(ctx, &s, med, t_hit.lane(i), dims[i]);
        if let Some(r) = r {
            o.set(i, r.ray.o);
            d.set(i, r.ray.d);
            t_max[i] = r.t_max;
            contrib.set(i, r.contrib);
            shoot |= 1 << i;
        }
    }
    if shoot != 0 {
        let shoot = super::mask_from_bits::<F>(shoot);
        shadows::<F, T, N, MOTION>(
            ctx,
            st,
            o.v3(),
            d.v3(),
            F::load(&t_max),
            contrib.load(),
            shoot,
            stats,
        );
    }
}
