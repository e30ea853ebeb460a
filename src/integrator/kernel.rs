//! The kernel: one worker traces `F::WIDTH` paths at once, one per lane, their state in
//! lane-SoA registers, and refills a lane with the tile's next sample as soon as its path
//! ends. The stages run in pipeline order, each a function over the packet in its own file:
//!
//! ```text
//! generate → intersect → media → surface → emission → material (light + shadow) → roulette
//!    ↑        (packet kd walk)   (MEDIA)                                                |
//!    |________________________________ film ←___________________________________________|
//! ```
//!
//! Width 1 is this same code over `f32`: the reference, the oracle every wider
//! packet is tested against (`tests/simd_widths.rs`).

use super::bsdf::LaneChannels;
use super::ctx::{Ctx, DIM_BOUNCE};
use super::state::{C, M, MAX_W, Paths, U};
use super::surface::{CLASS_BOUNDARY, CLASS_NONE};
use super::transport::{ChannelArray, Transport};
use super::{RenderStats, emission, generate, material, media, surface};
use crate::film::{Tile, TileFilm, TileWork};
use crate::geometry::offset_ray_origin_lanes;
use crate::scene::primitives::NO_MEDIUM;
use crate::simd::{Float, Mask, UInt, V3};

/// Renders the samples `work` names of every pixel of `tile` with packets of `F::WIDTH`
/// paths, adding each finished path's radiance to `film`.
#[inline(always)]
pub fn render_tile<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    tile: &Tile,
    work: &TileWork,
    film: &mut TileFilm,
    stats: &mut RenderStats,
) {
    let mut cursor = generate::Cursor::default();
    let zero3 = V3::<F>::zero();
    let mut st = Paths::<F, T, N> {
        o: zero3,
        d: zero3,
        beta: C::<F, N>::splat(F::zero()),
        l: C::<F, N>::splat(F::zero()),
        lam: T::no_lanes(),
        eta_scale: F::one(),
        depth: U::<F>::splat(0),
        specular: M::<F>::splat(false),
        prev_pdf: F::zero(),
        prev_p: zero3,
        time: F::zero(),
        pixel: U::<F>::splat(0),
        sample: U::<F>::splat(0),
        alive: M::<F>::splat(false),
        medium: [NO_MEDIUM; MAX_W],
        in_medium: M::<F>::splat(false),
        segments: [0; MAX_W],
    };
    let scene = ctx.scene;
    let max_depth = U::<F>::splat(ctx.max_depth);
    loop {
        generate::refill::<F, T, N, MOTION>(ctx, tile, work, &mut cursor, &mut st);
        let started = st.alive;
        if started.none() {
            break;
        }
        stats.rays += started.count() as u64;
        stats.lane_slots += F::WIDTH as u64;
        let hits = scene.intersect_packet::<F, MOTION>(st.o, st.d, st.alive, st.time);
        // MEDIA: lanes in a medium first sample their flight; those that scatter there are
        // done with this vertex, the rest reach their hit.
        let scattered_in_medium = if MEDIA {
            media::free_flight::<F, T, N, MOTION>(ctx, &mut st, &hits, started, stats)
        } else {
            M::<F>::splat(false)
        };
        let at = st.alive.and_not(scattered_in_medium);
        let sf = surface::surfaces::<F, T, N, MOTION, MEDIA>(ctx, &st, &hits, at);
        // Misses see the environment; emitters add their radiance and absorb the rest.
        emission::escaped::<F, T, N>(ctx, &mut st, at.and_not(sf.hit));
        emission::emitters(&mut st, &sf);
        let boundary = sf.hit & sf.class.eq(U::<F>::splat(CLASS_BOUNDARY));
        let scatters = !sf.class.eq(U::<F>::splat(CLASS_NONE)) & !boundary;
        let surface = sf.hit & scatters & st.depth.lt(max_depth);
        st.alive = (st.alive & scattered_in_medium) | surface | boundary;
        if surface.any() {
            material::scatter::<F, T, N, MOTION, MEDIA, _>(
                ctx,
                &mut st,
                &sf,
                surface,
                stats,
                DIM_BOUNCE,
                &mut material::Nee,
            );
        }
        if MEDIA && boundary.any() {
            // Carry on in the same direction, in the medium beyond.
            st.o = V3::select(boundary, offset_ray_origin_lanes(sf.p, -sf.nf), st.o);
            media::cross(ctx, &mut st, &sf, boundary);
        }
        // Finished paths go to the film.
        let ended = started.and_not(st.alive).bits();
        if ended != 0 {
            let mut rgb = [glam::Vec3::ZERO; MAX_W];
            T::ended_rgb(&st.l, &st.lam, ended, &mut rgb);
            for (i, rgb) in rgb.iter().enumerate().take(F::WIDTH) {
                if ended >> i & 1 != 0 {
                    film.add(st.pixel.lane(i), *rgb);
                }
            }
        }
    }
}
