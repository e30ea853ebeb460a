//! Shadow rays: built from light samples over lanes and traced as one packet any-hit query;
//! with MEDIA they carry the transmittance of the media they cross.

use super::RenderStats;
use super::bsdf::{Chan, LaneChannels};
use super::ctx::Ctx;
use super::state::{C, M, Paths, ScratchC, gdot, select_c};
use super::transport::{ChannelArray, MediumOps, Transport};
use crate::geometry::{Ray, offset_ray_origin_lanes};
use crate::medium::lanes;
use crate::scene::light_lanes::LaneLightSample;
use crate::simd::{Float, Mask, V3};

/// The shadow rays of light samples taken at surface points `p` (normals `nf` on the side the
/// paths are on): towards the sampled point of an area light (offset at both ends, so
/// neither surface occludes itself), a point light's position (stopping just short of it:
/// it lies on no surface), or along `wi` to the environment.
#[inline(always)]
pub(super) fn from_surface<F: Float>(
    p: V3<F>,
    nf: V3<F>,
    ls: &LaneLightSample<F>,
) -> (V3<F>, V3<F>, F) {
    // Area lights: `geometry::spawn_ray_to` over lanes.
    let d = ls.q - p;
    let n = V3::select(gdot(nf, d).ge(F::zero()), nf, -nf);
    let o_area = offset_ray_origin_lanes(p, n);
    let nt = V3::select(gdot(ls.nq, d).le(F::zero()), ls.nq, -ls.nq);
    let end = offset_ray_origin_lanes(ls.q, nt);
    // Point lights and the environment: from the side the light is on (behind a rough
    // dielectric it is the far side).
    let o_up = offset_ray_origin_lanes(p, V3::select(gdot(nf, ls.wi).ge(F::zero()), nf, -nf));
    let area = ls.at_point.and_not(ls.delta);
    let o = V3::select(area, o_area, o_up);
    let dir = V3::select(
        area,
        end - o_area,
        V3::select(ls.at_point, ls.q - o_up, ls.wi),
    );
    let t_max = F::select(
        area,
        F::one(),
        F::select(ls.at_point, F::splat(1.0 - 1e-4), F::splat(f32::INFINITY)),
    );
    (o, dir, t_max)
}

/// Traces the shadow rays of the lanes in `shoot` as one packet any-hit query and adds
/// `contrib` to the radiance of the lanes they reach (with MEDIA, times the transmittance
/// along them).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn trace<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
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
    if MEDIA {
        through_media::<F, T, N, MOTION>(ctx, st, o, d, t_max, contrib, shoot, stats);
        return;
    }
    stats.shadow_rays += u64::from(shoot.count());
    let blocked = ctx
        .scene
        .occluded_packet::<F, MOTION>(o, d, shoot, t_max, st.time);
    let lit = shoot.and_not(blocked);
    st.l = select_c(lit, st.l + contrib, st.l);
}

/// MEDIA: shadow rays of the lanes in `shoot`, from their current medium: a packet any-hit
/// first; a ray that meets nothing stays in that medium and takes its transmittance over the
/// whole length. One that meets something is blocked, unless the scene has pure medium
/// boundaries: then it walks its ray again per lane (`transmittance_with`), crossing them.
/// Adds `contrib` times the transmittance to the radiance of the lanes reached.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn through_media<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize, const MOTION: bool>(
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
    // Clear lanes inside a medium take its transmittance over the whole length; those outside
    // any transmit everything, and without such lanes no exponential is evaluated at all.
    let inside = clear & st.in_medium;
    let mut tr = C::<F, N>::splat(F::one());
    if inside.any() {
        let mut sigma_t = ScratchC::<N>::new();
        let bits = inside.bits();
        for i in 0..F::WIDTH {
            if bits >> i & 1 != 0 {
                sigma_t.set(
                    i,
                    T::medium(ctx, st.medium[i], &T::lane(&st.lam, i)).sigma_t(),
                );
            }
        }
        let len = gdot(d, d).sqrt();
        let t: [F; N] = lanes::transmittance(&sigma_t.load::<F>().0, t_max * len);
        tr = select_c(inside, Chan(t), tr);
    }
    // Only a medium's boundary lets a shadow ray through what it meets: in a scene without
    // boundaries a blocked ray is blocked, and no lane walks its ray again.
    let mut reach = clear;
    if ctx.boundaries && blocked.any() {
        let mut through = ScratchC::<N>::new();
        let bits = blocked.bits();
        for i in 0..F::WIDTH {
            if bits >> i & 1 != 0 {
                let lam = &T::lane(&st.lam, i);
                let t: T::S = scene.transmittance_with::<MOTION, T::S>(
                    &Ray::new(o.lane(i), d.lane(i)),
                    t_max.lane(i),
                    st.time.lane(i),
                    st.medium[i],
                    #[inline(always)]
                    |m, d| T::medium(ctx, m, lam).transmittance(d),
                );
                through.set(i, t);
            }
        }
        tr = select_c(blocked, through.load(), tr);
        reach = shoot;
    }
    st.l = select_c(reach, st.l + contrib * tr, st.l);
}
