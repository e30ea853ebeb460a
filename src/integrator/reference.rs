//! The reference integrator: one path at a time, the plainest loop over the same camera,
//! shading and light sampling as the wavefront stages. Tests compare the two; benches show
//! what batching buys.

use super::path::{Ctx, camera_ray, shade};
use super::transport::{MediumOps, Transport};
use super::{RenderStats, Tile};

#[inline(always)]
pub fn render_tile<T: Transport, const MOTION: bool, const MEDIA: bool>(
    ctx: &Ctx,
    tile: &Tile,
    s0: u32,
    s1: u32,
    film: &mut [[f64; 3]],
    stats: &mut RenderStats,
) {
    for p in 0..tile.pixels() {
        let (x, y) = tile.pixel(p);
        for k in s0..s1 {
            let mut s = camera_ray::<T, MOTION>(ctx, x, y, k);
            while s.alive {
                let hit = ctx.scene.intersect::<MOTION>(&s.ray, f32::INFINITY, s.time);
                stats.rays += 1;
                let mut extra = None;
                let first = shade::<T, MOTION, MEDIA>(ctx, &mut s, hit, &mut extra);
                for r in [first, extra].into_iter().flatten() {
                    stats.shadow_rays += 1;
                    if MEDIA {
                        let lambda = s.lambda;
                        s.l += r.contrib
                            * ctx.scene.transmittance_with::<MOTION, T::S>(
                                &r.ray,
                                r.t_max,
                                s.time,
                                r.medium,
                                |m, d| T::medium(ctx, m, &lambda).transmittance(d),
                            );
                    } else if !ctx.scene.occluded::<MOTION>(&r.ray, r.t_max, s.time) {
                        s.l += r.contrib;
                    }
                }
            }
            let l = T::to_rgb(s.l, &s.lambda);
            super::accumulate(film, tile, ctx.width, s.pixel, l, stats);
        }
    }
}
