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
    if env == Vec3::ZERO || miss.none() {
        return;
    }
    let first = st.depth.eq(U::<F>::splat(0)) | st.specular | M::<F>::splat(!ctx.nee);
    let w = F::select(
        first,
        F::one(),
        power_heuristic(st.prev_pdf, F::splat(scene.lights.pdf_environment())),
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

/// The radiance of the emitters the surface stage found, with its MIS weight.
#[inline(always)]
pub(super) fn emitters<F: Float, T: Transport, const N: usize>(
    st: &mut Paths<F, T, N>,
    sf: &Surface<F, N>,
) {
    st.l = select_c(sf.emits, st.l + st.beta * sf.le * sf.le_w, st.l);
}
