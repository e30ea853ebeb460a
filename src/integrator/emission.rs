//! Emission: paths that escape see the environment, paths that hit an emitter add its
//! radiance (both MIS-weighted against the light samples that could have found them).

use super::bsdf::Chan;
use super::ctx::Ctx;
use super::state::{M, Paths, U, power_heuristic, select_c};
use super::surface::Surface;
use super::transport::{ChannelArray, Transport};
use crate::simd::{Float, Mask, UInt};
use glam::Vec3;

/// The environment's radiance for the lanes in `miss`, whose rays left the scene.
#[inline(always)]
pub(super) fn escaped<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    miss: M<F>,
) {
    let scene = ctx.scene;
    let env = scene.environment;
    if miss.none() {
        return;
    }
    let first = st.depth.eq(U::<F>::splat(0)) | st.specular | M::<F>::splat(!ctx.nee);
    if let Some(map) = scene.lights.map.as_deref() {
        return escaped_map(ctx, st, miss, first, map);
    }
    if env == Vec3::ZERO {
        return;
    }
    let w = F::select(
        first,
        F::one(),
        power_heuristic(st.prev_pdf, F::splat(scene.lights.pdf_environment(Vec3::Y))),
    );
    let e = if T::SPECTRAL {
        let mut e = T::colours();
        let bits = miss.bits();
        for i in 0..F::WIDTH {
            if bits >> i & 1 != 0 {
                T::set_environment(&mut e, i, ctx, &st.lam);
            }
        }
        T::eval(&e, &st.lam)
    } else {
        // RGB: N = 3.
        let e = [env.x, env.y, env.z];
        Chan(std::array::from_fn(|k| F::splat(e[k])))
    };
    st.l = select_c(miss, st.l + st.beta * e * w, st.l);
}

/// [`escaped`] for an environment map: each lane looks up the map along its direction (a
/// bilinear lookup and the density of the map's sampling there, for MIS).
#[inline(always)]
fn escaped_map<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    miss: M<F>,
    first: M<F>,
    map: &crate::scene::envmap::EnvMap,
) {
    const MAX_W: usize = 16;
    let lights = &ctx.scene.lights;
    if let Some(sky) = lights.sky.as_deref() {
        return escaped_sky(ctx, st, miss, first, sky);
    }
    let mut pdf = [0.0f32; MAX_W];
    let mut rgb = [[0.0f32; MAX_W]; 3];
    let mut e = T::colours();
    let bits = miss.bits();
    for i in 0..F::WIDTH {
        if bits >> i & 1 != 0 {
            let d = st.d.lane(i).normalize_or_zero();
            let l = map.eval(d);
            (rgb[0][i], rgb[1][i], rgb[2][i]) = (l.x, l.y, l.z);
            pdf[i] = lights.pdf_environment(d);
            if T::SPECTRAL {
                T::set_map_radiance(&mut e, i, l, &st.lam);
            }
        }
    }
    let w = F::select(first, F::one(), power_heuristic(st.prev_pdf, F::load(&pdf)));
    let e = if T::SPECTRAL {
        T::eval(&e, &st.lam)
    } else {
        // RGB: N = 3.
        Chan(std::array::from_fn(|k| F::load(&rgb[k])))
    };
    st.l = select_c(miss, st.l + st.beta * e * w, st.l);
}

/// [`escaped`] for the daylight sky: each lane evaluates the model along its direction, and
/// the sun where the direction falls on its disc. Sky and sun are two lights, each with its
/// own MIS weight, computed per lane here.
#[inline(always)]
fn escaped_sky<F: Float, T: Transport<S: ChannelArray<N>>, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    miss: M<F>,
    first: M<F>,
    sky: &crate::scene::sky::Sky,
) {
    let lights = &ctx.scene.lights;
    let mut e = T::colours();
    let bits = miss.bits();
    let first = first.bits();
    for i in 0..F::WIDTH {
        if bits >> i & 1 == 0 {
            continue;
        }
        let d = st.d.lane(i).normalize_or_zero();
        let on_sun = sky.on_sun(d);
        let (w_sky, w_sun) = if first >> i & 1 != 0 {
            (1.0, 1.0)
        } else {
            let prev = st.prev_pdf.lane(i);
            let w = |light: f32| {
                let (a, b) = (prev * prev, light * light);
                if a + b == 0.0 { 0.0 } else { a / (a + b) }
            };
            let sun = if on_sun { w(lights.pdf_sun(d)) } else { 0.0 };
            (w(lights.pdf_environment(d)), sun)
        };
        T::set_sky(
            &mut e,
            i,
            sky,
            d,
            w_sky,
            if on_sun { w_sun } else { 0.0 },
            &st.lam,
        );
    }
    let e = T::eval(&e, &st.lam);
    st.l = select_c(miss, st.l + st.beta * e, st.l);
}

/// The radiance of the emitters the surface stage found, with its MIS weight.
#[inline(always)]
pub(super) fn emitters<F: Float, T: Transport, const N: usize>(
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
) {
    st.l = select_c(sf.emits, st.l + st.beta * sf.le * sf.le_w, st.l);
}
