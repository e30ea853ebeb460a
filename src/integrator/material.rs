//! Materials: one scattering event per lane, a BSDF sample for each material class present
//! (a class no lane needs is skipped), light samples at the lanes whose BSDF has a density
//! (diffuse, rough conductors and rough dielectrics), then Russian roulette.

use super::bsdf::{BsdfSample, Dielectric, Diffuse, Frame, Mirror, Mode};
use super::ctx::{Ctx, DIMS_PER_BOUNCE};
use super::light::Glossy;
use super::microfacet::RoughDielectric;
use super::state::{C, M, MAX_W, Paths, U, gdot, gnormalize, mask_from_bits, select_c};
use super::surface::{
    CLASS_CONDUCTOR, CLASS_DIELECTRIC, CLASS_DIFFUSE, CLASS_MIRROR, CLASS_PLASTIC, Surface,
};
use super::transport::{ChannelArray, Transport};
use super::{RenderStats, light, media, roulette};
use crate::components::Material;
use crate::geometry::offset_ray_origin_lanes;
use crate::simd::{Float, Mask, UInt, V3};

/// What a scattering event does at the lanes whose BSDF has a density, before its BSDF
/// sample: next-event estimation on camera paths ([`Nee`]), a connection to the camera on
/// light paths. The mode says what the path carries, and so which BSDF it samples.
pub(super) trait Vertex<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize> {
    /// Radiance on camera paths, importance on light paths.
    const MODE: Mode;
    /// The event's work at the lanes `m`, whose BSDF is diffuse but where `glossy` says
    /// otherwise; `dim` is the event's first sample dimension.
    #[allow(clippy::too_many_arguments)]
    fn connect<const MOTION: bool, const MEDIA: bool>(
        &mut self,
        ctx: &Ctx,
        st: &mut Paths<F, T, N>,
        sf: &Surface<F, N>,
        m: M<F>,
        glossy: &Glossy<'_, F>,
        frame: &Frame<F>,
        dim: U<F>,
        stats: &mut RenderStats,
    );
}

/// Camera paths: a light sample at each event (when the scene samples lights).
pub(super) struct Nee;

impl<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize> Vertex<F, T, N> for Nee {
    const MODE: Mode = Mode::Radiance;
    #[inline(always)]
    fn connect<const MOTION: bool, const MEDIA: bool>(
        &mut self,
        ctx: &Ctx,
        st: &mut Paths<F, T, N>,
        sf: &Surface<F, N>,
        m: M<F>,
        glossy: &Glossy<'_, F>,
        frame: &Frame<F>,
        dim: U<F>,
        stats: &mut RenderStats,
    ) {
        if ctx.nee {
            light::light_samples::<F, T, N, MOTION, MEDIA>(
                ctx, st, sf, m, glossy, frame, dim, stats,
            );
        }
    }
}

/// One scattering event in every lane of `live`: `vertex`'s work at the lanes whose BSDF has
/// a density, then a BSDF sample per material class present, then Russian roulette. Event k
/// of a path takes the sample dimensions from `first + k * DIMS_PER_BOUNCE`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn scatter<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
    V: Vertex<F, T, N>,
>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
    live: M<F>,
    stats: &mut RenderStats,
    first: u32,
    vertex: &mut V,
) {
    let dim =
        U::<F>::splat(first).wrapping_add(st.depth.wrapping_mul(U::<F>::splat(DIMS_PER_BOUNCE)));
    st.depth = U::<F>::select(live, st.depth.wrapping_add(U::<F>::splat(1)), st.depth);
    let wo = -st.d;
    let frame = sf.frame();
    let wo_l = frame.to_local(wo);
    let class = |c: u32| live & sf.class.eq(U::<F>::splat(c));
    let (dm, mm, em) = (
        class(CLASS_DIFFUSE),
        class(CLASS_MIRROR),
        class(CLASS_DIELECTRIC),
    );
    let cm = class(CLASS_CONDUCTOR);
    let pm = class(CLASS_PLASTIC);
    // The dielectric lanes' relative IOR comes first: a dispersive one ends the lane's
    // secondary wavelengths before a light sample evaluates the interface at the hero's.
    let eta = if em.any() {
        dielectric_eta::<F, T, N>(ctx, st, sf, em)
    } else {
        F::one()
    };
    // Rough conductors and dielectrics have a density: light sampling evaluates them, as it
    // does diffuse surfaces. Smooth ones are delta lobes, like mirrors. An interface with
    // η = 1 is none: it refracts every microfacet normal into the same direction, a delta.
    let conductor = sf.conductor();
    let rough = !sf.smooth();
    let glossy = Glossy {
        plastic: pm,
        coat: &ctx.scene.prims.coat,
        conductor: cm & rough,
        dielectric: em & rough & !eta.eq(F::one()),
        rough_dielectric: RoughDielectric {
            dist: sf.dist(),
            eta,
            schlick: ctx.schlick,
            multiscatter: sf.multiscatter & em & rough,
        },
    };
    let up = offset_ray_origin_lanes(sf.p, sf.nf);
    let mut scattered = M::<F>::splat(false);
    // A plastic's base always has a density.
    let nee = dm | pm | glossy.conductor | glossy.dielectric;
    if nee.any() {
        vertex.connect::<MOTION, MEDIA>(ctx, st, sf, nee, &glossy, &frame, dim, stats);
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
        scattered |= reflected(st, cm, &bs, cm & conductor.smooth, &frame, sf, up);
    }
    if pm.any() {
        let uc =
            ctx.sampler
                .get_1d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(3)));
        let (ux, uy) =
            ctx.sampler
                .get_2d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(4)));
        let bs = sf.plastic(glossy.coat).sample(wo_l, uc, ux, uy);
        scattered |= reflected(st, pm, &bs, pm & bs.is_specular(), &frame, sf, up);
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
    let es = em.and_not(glossy.dielectric);
    if es.any() {
        let u =
            ctx.sampler
                .get_1d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(3)));
        let bsdf = Dielectric {
            eta,
            schlick: ctx.schlick,
        };
        let bs = bsdf.sample::<C<F, N>>(wo_l, u, V::MODE);
        st.specular |= es;
        st.beta = select_c(es, st.beta * bs.weight, st.beta);
        let wi = frame.to_world(bs.wi);
        let t = es & bs.is_transmission();
        st.eta_scale = F::select(t, st.eta_scale * (bs.eta * bs.eta), st.eta_scale);
        let down = offset_ray_origin_lanes(sf.p, -sf.nf);
        let o = V3::select(t, down, up);
        let d = V3::select(t, below(wi, sf.nf), reflect_above(wi, sf.nf));
        if MEDIA {
            media::cross(ctx, st, sf, t);
        }
        st.o = V3::select(es, o, st.o);
        st.d = V3::select(es, d, st.d);
        scattered |= es;
    }
    let er = glossy.dielectric;
    if er.any() {
        let u =
            ctx.sampler
                .get_1d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(3)));
        let (ux, uy) =
            ctx.sampler
                .get_2d_lanes::<F>(st.pixel, st.sample, dim.wrapping_add(U::<F>::splat(4)));
        let bs = glossy
            .rough_dielectric
            .sample::<C<F, N>>(wo_l, u, ux, uy, V::MODE);
        let wi = frame.to_world(bs.wi).normalize();
        // A direction on the wrong geometric side for its lobe (about a tilted shading
        // normal) is absorbed, as for rough conductors.
        let t = bs.is_transmission();
        let side = gdot(wi, sf.nf);
        let ok = er & bs.pdf.gt(F::zero()) & F::select(t, -side, side).gt(F::zero());
        let t = ok & t;
        st.alive = st.alive.and_not(er.and_not(ok));
        st.beta = select_c(ok, st.beta * bs.weight, st.beta);
        st.prev_pdf = F::select(ok, bs.pdf, st.prev_pdf);
        st.specular = st.specular.and_not(ok);
        st.eta_scale = F::select(t, st.eta_scale * (bs.eta * bs.eta), st.eta_scale);
        let down = offset_ray_origin_lanes(sf.p, -sf.nf);
        if MEDIA {
            media::cross(ctx, st, sf, t);
        }
        st.o = V3::select(ok, V3::select(t, down, up), st.o);
        st.d = V3::select(ok, wi, st.d);
        scattered |= ok;
    }
    st.prev_p = V3::select(scattered, sf.p, st.prev_p);
    roulette::russian_roulette(ctx, st, scattered, dim.wrapping_add(U::<F>::splat(6)));
}

/// Takes the reflection `bs` sampled at the lanes `m` (a delta lobe in `smooth`), leaving
/// from `up`; returns the lanes that scattered. A rough or diffuse direction about a tilted
/// shading normal can point into the geometric back side: absorbed, as for diffuse lanes. A
/// smooth one is kept above, as a mirror's.
#[inline(always)]
fn reflected<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize>(
    st: &mut Paths<F, T, N>,
    m: M<F>,
    bs: &BsdfSample<F, C<F, N>>,
    smooth: M<F>,
    frame: &Frame<F>,
    sf: &Surface<F, N>,
    up: V3<F>,
) -> M<F> {
    let wi = frame.to_world(bs.wi).normalize();
    let ok = m & bs.pdf.gt(F::zero()) & (smooth | gdot(wi, sf.nf).gt(F::zero()));
    st.alive = st.alive.and_not(m.and_not(ok));
    st.beta = select_c(ok, st.beta * bs.weight, st.beta);
    st.prev_pdf = F::select(ok, bs.pdf, st.prev_pdf);
    st.specular = st.specular.and_not(ok) | (ok & smooth);
    st.o = V3::select(ok, up, st.o);
    st.d = V3::select(ok, V3::select(smooth, reflect_above(wi, sf.nf), wi), st.d);
    ok
}

/// The relative IOR (transmitted over incident) of the dielectric lanes `em` at each lane's
/// hero wavelength; a dispersive interface ends the lane's secondary wavelengths.
#[inline(always)]
fn dielectric_eta<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
    em: M<F>,
) -> F {
    let prims = &ctx.scene.prims;
    let mut ior = [1.0f32; MAX_W];
    let mut dispersive = 0u32;
    let bits = em.bits();
    for (i, n) in ior.iter_mut().enumerate().take(F::WIDTH) {
        if bits >> i & 1 != 0 {
            let Material::Dielectric { ior: model, .. } = prims.materials[sf.mat[i] as usize]
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
    F::select(sf.front, ior, ior.recip())
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
