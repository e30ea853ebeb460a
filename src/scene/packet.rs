//! Closest hits and shadow rays of a packet of rays, one per lane: the kd-tree walked once for
//! the packet, spheres, rectangles, disks and boxes tested for all its lanes at once. Meshes,
//! revolution surfaces and moving primitives are tested one lane at a time inside the walk;
//! rays the packet walk does not take (an axis-parallel direction, a non-finite value) take
//! the scalar query.
//!
//! Every primitive test gives the scalar test's bits, and every lane visits the leaves its
//! scalar walk visits, so the hits are the scalar ones (an exact tie between two primitives at
//! one distance may resolve to the other primitive).

use super::RenderScene;
use super::primitives::{Hit, NO_MOTION, PrimKind};
use crate::geometry::Ray;
use crate::kdtree::KdTree;
use crate::simd::{Float, Mask, UInt, V3};

type M<F> = <F as Float>::Mask;
type U<F> = <F as Float>::U32;

/// The closest hit of each lane of a packet; lanes outside `hit` hold no hit.
#[derive(Clone, Copy)]
pub struct PacketHit<F: Float> {
    /// Lanes that hit something.
    pub hit: M<F>,
    /// Ray parameter of each hit.
    pub t: F,
    /// Primitive index of each hit.
    pub prim: U<F>,
    /// The part of the primitive hit (a mesh's triangle), as [`Hit::sub`].
    pub sub: U<F>,
    /// First hit coordinate, as [`Hit::u`].
    pub u: F,
    /// Second hit coordinate, as [`Hit::v`].
    pub v: F,
}

impl<F: Float> PacketHit<F> {
    /// Lane `i` as a scalar hit.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Option<Hit> {
        self.hit.lane(i).then(|| Hit {
            t: self.t.lane(i),
            prim: self.prim.lane(i),
            sub: self.sub.lane(i),
            u: self.u.lane(i),
            v: self.v.lane(i),
        })
    }

    /// Records `hit` in lane `i`.
    #[inline(always)]
    fn set_lane(&mut self, i: usize, hit: Hit) {
        let m = M::<F>::from_fn(|l| l == i);
        self.record(
            m,
            F::splat(hit.t),
            U::<F>::splat(hit.prim),
            U::<F>::splat(hit.sub),
            F::splat(hit.u),
            F::splat(hit.v),
        );
    }

    #[inline(always)]
    fn record(&mut self, m: M<F>, t: F, prim: U<F>, sub: U<F>, u: F, v: F) {
        self.hit |= m;
        self.t = F::select(m, t, self.t);
        self.prim = U::<F>::select(m, prim, self.prim);
        self.sub = U::<F>::select(m, sub, self.sub);
        self.u = F::select(m, u, self.u);
        self.v = F::select(m, v, self.v);
    }
}

/// Records the hits of a closed shape's lane test; "started outside" goes in u, as the
/// scalar test keeps it.
#[inline(always)]
fn closed<F: Float>(
    (t, hit, out): (F, M<F>, M<F>),
    m: M<F>,
    at: U<F>,
    h: &mut PacketHit<F>,
    limit: &mut F,
) {
    let m = m & hit & t.lt(*limit);
    let u = F::select(out, F::one(), F::zero());
    h.record(m, t, at, U::<F>::splat(0), u, F::zero());
    *limit = F::select(m, t, *limit);
}

#[inline(always)]
fn lane_mask<F: Float>(i: usize) -> M<F> {
    M::<F>::from_fn(|l| l == i)
}

#[inline(always)]
fn ray_lane<F: Float>(o: &V3<F>, d: &V3<F>, i: usize) -> Ray {
    Ray::new(o.lane(i), d.lane(i))
}

#[inline(always)]
fn recip<F: Float>(d: V3<F>) -> V3<F> {
    V3::new(d.x.recip(), d.y.recip(), d.z.recip())
}

impl RenderScene {
    /// [`RenderScene::intersect`] of the rays of `lanes`, one per lane, with no distance limit.
    #[inline(always)]
    pub fn intersect_packet<F: Float, const MOTION: bool>(
        &self,
        o: V3<F>,
        d: V3<F>,
        lanes: M<F>,
        time: F,
    ) -> PacketHit<F> {
        let inv = recip(d);
        let packet = lanes & KdTree::packet_lanes(o, d, inv);
        let mut h = PacketHit {
            hit: M::<F>::splat(false),
            t: F::splat(f32::INFINITY),
            prim: U::<F>::splat(0),
            sub: U::<F>::splat(0),
            u: F::zero(),
            v: F::zero(),
        };
        let mut limit = F::splat(f32::INFINITY);
        self.accel.walk_packet(
            o,
            inv,
            packet,
            &mut limit,
            #[inline(always)]
            |leaf, m, limit| {
                for &p in leaf.prims {
                    self.closest_in_lanes::<F, MOTION>(p, &o, &d, m, time, limit, &mut h);
                }
            },
        );
        let rest = lanes.and_not(packet).bits();
        for i in 0..F::WIDTH {
            if rest >> i & 1 != 0
                && let Some(hit) =
                    self.intersect::<MOTION>(&ray_lane(&o, &d, i), f32::INFINITY, time.lane(i))
            {
                h.set_lane(i, hit);
            }
        }
        h
    }

    /// Tests primitive `p` against the lanes of `m`, recording hits nearer than `limit` and
    /// lowering it to them.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn closest_in_lanes<F: Float, const MOTION: bool>(
        &self,
        p: u32,
        o: &V3<F>,
        d: &V3<F>,
        m: M<F>,
        time: F,
        limit: &mut F,
        h: &mut PacketHit<F>,
    ) {
        let prims = &self.prims;
        let (i, l) = (p as usize, prims.local[p as usize] as usize);
        let at = U::<F>::splat(p);
        let zero = U::<F>::splat(0);
        if !(MOTION && prims.motion[i] != NO_MOTION) {
            // "Started outside" goes in u, as the scalar test keeps it.
            match prims.kind[i] {
                PrimKind::Sphere => {
                    return closed(
                        prims.spheres[l].intersect_lanes(*o, *d, *limit),
                        m,
                        at,
                        h,
                        limit,
                    );
                }
                PrimKind::Box => {
                    return closed(
                        prims.boxes[l].intersect_lanes(*o, *d, *limit),
                        m,
                        at,
                        h,
                        limit,
                    );
                }
                PrimKind::Rect | PrimKind::Disk => {
                    let disk = prims.kind[i] == PrimKind::Disk;
                    let (t, a, b, hit) = prims.planars[l].intersect_lanes(*o, *d, *limit, disk);
                    let m = m & hit & t.lt(*limit);
                    h.record(m, t, at, zero, a, b);
                    *limit = F::select(m, t, *limit);
                    return;
                }
                PrimKind::Mesh | PrimKind::Revolution => {}
            }
        }
        let bits = m.bits();
        for k in 0..F::WIDTH {
            if bits >> k & 1 == 0 {
                continue;
            }
            let lim = limit.lane(k);
            if let Some((t, u, v, sub)) =
                prims.intersect_sub_at::<F, MOTION>(p, &ray_lane(o, d, k), lim, time.lane(k))
                && t < lim
            {
                h.set_lane(
                    k,
                    Hit {
                        t,
                        prim: p,
                        sub,
                        u,
                        v,
                    },
                );
                *limit = F::select(lane_mask::<F>(k), F::splat(t), *limit);
            }
        }
    }

    /// [`RenderScene::occluded`] of the rays of `lanes`, each before its own `t_max`: the mask
    /// of blocked lanes.
    #[inline(always)]
    pub fn occluded_packet<F: Float, const MOTION: bool>(
        &self,
        o: V3<F>,
        d: V3<F>,
        lanes: M<F>,
        t_max: F,
        time: F,
    ) -> M<F> {
        let inv = recip(d);
        let packet = lanes & KdTree::packet_lanes(o, d, inv);
        let mut blocked = M::<F>::splat(false);
        let mut limit = t_max;
        let prims = &self.prims;
        self.accel.walk_packet(
            o,
            inv,
            packet,
            &mut limit,
            #[inline(always)]
            |leaf, m, limit| {
                let mut open = m;
                for &p in leaf.prims {
                    let (i, l) = (p as usize, prims.local[p as usize] as usize);
                    let hit = if MOTION && prims.motion[i] != NO_MOTION {
                        self.any_per_lane::<F, MOTION>(p, &o, &d, open, t_max, time)
                    } else {
                        match prims.kind[i] {
                            PrimKind::Sphere => prims.spheres[l].intersect_lanes(o, d, t_max).1,
                            PrimKind::Box => prims.boxes[l].intersect_lanes(o, d, t_max).1,
                            PrimKind::Rect | PrimKind::Disk => {
                                let disk = prims.kind[i] == PrimKind::Disk;
                                prims.planars[l].intersect_lanes(o, d, t_max, disk).3
                            }
                            PrimKind::Mesh | PrimKind::Revolution => {
                                self.any_per_lane::<F, MOTION>(p, &o, &d, open, t_max, time)
                            }
                        }
                    } & open;
                    blocked |= hit;
                    open = open.and_not(hit);
                    if open.none() {
                        break;
                    }
                }
                // A blocked lane has nothing left to find.
                *limit = F::select(blocked, F::splat(f32::NEG_INFINITY), *limit);
            },
        );
        let rest = lanes.and_not(packet).bits();
        for i in 0..F::WIDTH {
            if rest >> i & 1 != 0
                && self.occluded::<MOTION>(&ray_lane(&o, &d, i), t_max.lane(i), time.lane(i))
            {
                blocked |= lane_mask::<F>(i);
            }
        }
        blocked
    }

    /// Which lanes of `m` primitive `p` blocks before their `t_max`, one lane at a time.
    #[inline(always)]
    fn any_per_lane<F: Float, const MOTION: bool>(
        &self,
        p: u32,
        o: &V3<F>,
        d: &V3<F>,
        m: M<F>,
        t_max: F,
        time: F,
    ) -> M<F> {
        let bits = m.bits();
        let mut hit = 0u32;
        for k in 0..F::WIDTH {
            if bits >> k & 1 != 0
                && self.prims.occluded_at::<F, MOTION>(
                    p,
                    &ray_lane(o, d, k),
                    t_max.lane(k),
                    time.lane(k),
                )
            {
                hit |= 1 << k;
            }
        }
        M::<F>::from_fn(|k| hit >> k & 1 != 0)
    }
}
