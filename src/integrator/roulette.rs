//! Russian roulette.

use super::bsdf::Chan;
use super::ctx::Ctx;
use super::state::{M, Paths, U, select_c};
use super::transport::Transport;
use crate::simd::{Float, Mask, UInt};

/// Russian roulette for the lanes in `m` past `rr_depth`, on the throughput with the IOR
/// compression removed (so entering dense glass does not kill paths); lanes whose throughput
/// is zero end too.
#[inline(always)]
pub(super) fn russian_roulette<F: Float, T: Transport, const N: usize>(
    ctx: &Ctx,
    st: &mut Paths<F, T, N>,
    m: M<F>,
    dim: U<F>,
) {
    let deep = m & !st.depth.lt(U::<F>::splat(ctx.rr_depth));
    if deep.any() {
        let rr = (st.beta * st.eta_scale).max_element();
        let low = deep & rr.lt(F::one());
        if low.any() {
            let q = (F::one() - rr).max(F::zero());
            let u = ctx.sampler.get_1d_lanes::<F>(st.pixel, st.sample, dim);
            let kill = low & u.lt(q);
            st.alive = st.alive.and_not(kill);
            let keep = low.and_not(kill);
            let k = F::one() - q;
            st.beta = select_c(keep, Chan(st.beta.0.map(|c| c / k)), st.beta);
        }
    }
    st.alive = st.alive.and_not(m & st.beta.is_zero());
}
