//! Materials: one scattering event per lane, a BSDF sample for each material class present
//! (a class no lane needs is skipped), light samples at the lanes whose BSDF has a density
//! (diffuse and rough conductors), then Russian roulette.

use super::bsdf::{Dielectric, Diffuse, Frame, Mirror, Mode};
use super::ctx::{Ctx, DIM_BOUNCE, DIMS_PER_BOUNCE};
use super::state::{C, M, MAX_W, Paths, U, gdot, gnormalize, mask_from_bits, select_c};
use super::surface::{CLASS_CONDUCTOR, CLASS_DIELECTRIC, CLASS_DIFFUSE, CLASS_MIRROR, Surface};
use super::transport::{ChannelArray, Transport};
use super::{RenderStats, light, media, roulette};
use crate::components::Material;
use crate::geometry::offset_ray_origin_lanes;
use crate::simd::{Float, Mask, UInt, V3};

/// One scattering event in every lane of `live`: light samples at diffuse and rough
/// conductor lanes, then a BSDF sample per material class present, then Russian roulette.
#[inline(always)]
pub(super) fn scatter<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
    live: M<F>,
    stats: &mut RenderStats,
) {
    let dim = U::<F>::splat(DIM_BOUNCE)
        .wrapping_add(st.depth.wrapping_mul(U::<F>::splat(DIMS_PER_BOUNCE)));
    st.depth = U::<F>::select(live, st.depth.wrapping_add(U::<F>::splat(1)), st.depth);
    let wo = -st.d;
    let frame = Frame::from_normal(sf.nsf);
    let wo_l = frame.to_local(wo);
    let class = |c: u32| live & sf.class.eq(U::<F>::splat(c));
    let (dm, mm, em) = (
        class(CLASS_DIFFUSE),
        class(CLASS_MIRROR),
        class(CLASS_DIELECTRIC),
    );
    let cm = class(CLASS_CONDUCTOR);
    // Rough conductors have a density: light sampling evaluates them, as it does diffuse
    // surfaces. Smooth ones are delta lobes, like mirrors.
    let conductor = sf.conductor();
    let glossy = cm.and_not(conductor.smooth);
    let up = offset_ray_origin_lanes(sf.p, sf.nf);
    let mut scattered = M::<F>::splat(false);
    let nee = dm | glossy;
    if ctx.nee && nee.any() {
        light::light_samples::<F, T, N, MOTION, MEDIA>(
            ctx, st, sf, nee, glossy, &frame, dim, stats,
        );
    }
    if dm.any() {
        let (ux, uy) =
            ctx.sampler
                .get_2d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(4)));
        let bs = Diffuse { albedo: sf.color }.sample(wo_l, ux, uy);
        let wi = frame.to_world(bs.wi).normalize();
        // Sampled around a tilted shading normal into the geometric back side: absorbed.
        let ok = dm & gdot(wi, sf.nf).gt(F::zero());
        st.alive = st.alive.and_not(dm.and_not(ok));
        st.beta = select_c(ok, st.beta * bs.weight, st.beta);
        st.prev_pdf = F::select(ok, bs.pdf, st.prev_pdf);
        st.specular = st.specular.and_not(ok);
        st.o = V3::select(ok, up, st.o);
        st.d = V3::select(ok, wi, st.d);
        scattered |= ok;
    }
    if cm.any() {
        let (ux, uy) =
            ctx.sampler
                .get_2d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(4)));
        let bs = conductor.sample(wo_l, ux, uy);
        let smooth = cm & conductor.smooth;
        let wi = frame.to_world(bs.wi).normalize();
        // A rough reflection about a tilted shading normal can point into the geometric back
        // side: absorbed, as for diffuse lanes. A smooth one is kept above, as a mirror's.
        let ok = cm & bs.pdf.gt(F::zero()) & (smooth | gdot(wi, sf.nf).gt(F::zero()));
        st.alive = st.alive.and_not(cm.and_not(ok));
        st.beta = select_c(ok, st.beta * bs.weight, st.beta);
        st.prev_pdf = F::select(ok, bs.pdf, st.prev_pdf);
        st.specular = st.specular.and_not(ok) | (ok & smooth);
        st.o = V3::select(ok, up, st.o);
        st.d = V3::select(ok, V3::select(smooth, reflect_above(wi, sf.nf), wi), st.d);
        scattered |= ok;
    }
    if mm.any() {
        let bs = Mirror { tint: sf.color }.sample(wo_l);
        st.beta = select_c(mm, st.beta * bs.weight, st.beta);
        st.specular |= mm;
        let wi = frame.to_world(bs.wi);
        st.o = V3::select(mm, up, st.o);
        st.d = V3::select(mm, reflect_above(wi, sf.nf), st.d);
        scattered |= mm;
    }
    if em.any() {
        // The IOR per lane; a dispersive one ends the lane's secondary wavelengths.
        let prims = &ctx.scene.prims;
        let mut ior = [1.0f32; MAX_W];
        let mut dispersive = 0u32;
        let bits = em.bits();
        for (i, n) in ior.iter_mut().enumerate().take(F::WIDTH) {
            if bits >> i & 1 != 0 {
                let Material::Dielectric { ior: model } = prims.materials[sf.mat[i] as usize]
                else {
                    continue;
                };
                let (eta, disperses) = T::ior(&model, &st.lam, i);
                *n = eta;
                dispersive |= (disperses as u32) << i;
            }
        }
        if dispersive != 0 {
            T::terminate_secondary(&mut st.lam, &mut st.beta, mask_from_bits::<F>(dispersive));
        }
        let ior = F::load(&ior);
        let eta = F::select(sf.front, ior, ior.recip());
        let u =
            ctx.sampler
                .get_1d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(3)));
        let bsdf = Dielectric {
            eta,
            schlick: ctx.schlick,
        };
        let bs = bsdf.sample::<C<F, N>>(wo_l, u, Mode::Radiance);
        st.specular |= em;
        st.beta = select_c(em, st.beta * bs.weight, st.beta);
        let wi = frame.to_world(bs.wi);
        let t = em & bs.is_transmission();
        st.eta_scale = F::select(t, st.eta_scale * (bs.eta * bs.eta), st.eta_scale);
        let down = offset_ray_origin_lanes(sf.p, -sf.nf);
        let o = V3::select(t, down, up);
        let d = V3::select(t, below(wi, sf.nf), reflect_above(wi, sf.nf));
        if MEDIA {
            media::cross(ctx, st, sf, t);
        }
        st.o = V3::select(em, o, st.o);
        st.d = V3::select(em, d, st.d);
        scattered |= em;
    }
    st.prev_p = V3::select(scattered, sf.p, st.prev_p);
    roulette::russian_roulette(ctx, st, scattered, dim.wrapping_add(U::<F>::splat(6)));
}

/// A reflected direction kept on the side of `n`: at grazing angles (or about a tilted
/// shading normal) it can point a hair below the surface, and it must leave on the side it
/// is spawned.
#[inline(always)]
fn reflect_above<F: Float>(r: V3<F>, n: V3<F>) -> V3<F> {
    let c = gdot(r, n);
    let flipped = gnormalize(r - n * (F::splat(2.0) * c));
    V3::select(c.ge(F::zero()), r, flipped)
}

/// A transmitted direction kept strictly below the surface `n` faces.
#[inline(always)]
fn below<F: Float>(wt: V3<F>, n: V3<F>) -> V3<F> {
    let c = gdot(wt, n);
    let flipped = gnormalize(wt - n * (F::splat(2.0) * c));
    V3::select(c.le(F::zero()), wt, flipped)
}
