//! The walk of a packet of rays: one shared stack, every lane with its own parametric range.
//!
//! Each node is visited once for the whole packet, with the lanes whose range still overlaps
//! it; its plane distance is one lane operation. Lanes may disagree on which child comes
//! first (their directions need not share an octant): the packet follows its first live lane
//! and pushes the other child with every lane's range in it, so no lane misses a leaf its ray
//! crosses. A leaf is handed to the caller once, with the mask of lanes to test and their
//! current limits, which the caller lowers as it finds hits; pending entries whose lanes all
//! start beyond their limits are dropped.
//!
//! The set of leaves a lane visits is the scalar walk's (the same ranges, the same plane
//! tests), only the order can differ, so a closest-hit query finds the same nearest hit.

use super::{KdTree, Leaf, MAX_DEPTH};
use crate::geometry::bounds::GAMMA3;
use crate::simd::{Float, Mask, V3};

#[inline(always)]
fn finite<F: Float>(v: V3<F>) -> F::Mask {
    v.x.is_finite() & v.y.is_finite() & v.z.is_finite()
}

/// Lanes live at a node: a range that is not empty and starts within the limit.
#[inline(always)]
fn live<F: Float>(t0: F, t1: F, limit: F) -> F::Mask {
    t0.le(t1) & t0.le(limit)
}

impl KdTree {
    /// The lanes the packet walk can take: a finite origin and a direction whose components
    /// are finite, non-zero and have finite reciprocals (`inv`). The scalar walk calls such
    /// rays oblique; others go through it one at a time.
    #[inline(always)]
    pub fn packet_lanes<F: Float>(o: V3<F>, d: V3<F>, inv: V3<F>) -> F::Mask {
        finite(o) & finite(d) & finite(inv)
    }

    /// Visits, front to back for the packet's first live lane, the non-empty leaves that the
    /// rays of `lanes` cross before their `limit`. `leaf(leaf, m, limit)` tests the lanes of
    /// `m` and may lower their limits (closest hit: to the best hit; any hit: to −∞ once the
    /// lane is blocked). Every lane of `lanes` must be a [`KdTree::packet_lanes`] lane, with
    /// `inv` the reciprocal of `d`.
    #[inline(always)]
    pub fn walk_packet<F: Float>(
        &self,
        o: V3<F>,
        inv: V3<F>,
        lanes: F::Mask,
        limit: &mut F,
        leaf: impl FnMut(Leaf<'_>, F::Mask, &mut F),
    ) {
        if self.nodes.is_empty() || lanes.none() {
            return;
        }
        match self.stats.max_depth {
            0..=16 => self.walk_packet_with::<F, 16>(o, inv, lanes, limit, leaf),
            17..=32 => self.walk_packet_with::<F, 32>(o, inv, lanes, limit, leaf),
            _ => self.walk_packet_with::<F, { MAX_DEPTH as usize }>(o, inv, lanes, limit, leaf),
        }
    }

    #[inline(always)]
    fn walk_packet_with<F: Float, const N: usize>(
        &self,
        o: V3<F>,
        inv: V3<F>,
        lanes: F::Mask,
        limit: &mut F,
        mut leaf: impl FnMut(Leaf<'_>, F::Mask, &mut F),
    ) {
        let inf = F::splat(f32::INFINITY);
        // The root box, as `Aabb::intersect_oblique` clips the scalar ray.
        let (lo, hi) = (
            V3::<F>::splat(self.bounds.min),
            V3::<F>::splat(self.bounds.max),
        );
        let a = (lo - o).mul_elem(inv);
        let b = (hi - o).mul_elem(inv);
        let grow = F::splat(1.0 + 2.0 * GAMMA3);
        let near = a.x.min(b.x).max(a.y.min(b.y)).max(a.z.min(b.z));
        let far = (a.x.max(b.x) * grow)
            .min(a.y.max(b.y) * grow)
            .min(a.z.max(b.z) * grow);
        let mut t0 = F::select(lanes, near.max(F::zero()), inf);
        let mut t1 = F::select(lanes, far.min(*limit), -inf);
        if live(t0, t1, *limit).none() {
            return;
        }
        let org = [o.x, o.y, o.z, o.z];
        let rcp = [inv.x, inv.y, inv.z, inv.z];
        // Lane i of `neg[axis]`: ray i moves down that axis.
        let neg = [
            inv.x.lt(F::zero()),
            inv.y.lt(F::zero()),
            inv.z.lt(F::zero()),
            inv.z.lt(F::zero()),
        ];
        let mut st_node = [0u32; N];
        let mut st_t0 = [F::zero(); N];
        let mut st_t1 = [F::zero(); N];
        let mut sp = 0usize;
        let mut index = 0usize;
        loop {
            let node = &self.nodes[index];
            if !node.is_leaf() {
                let axis = node.axis() & 3;
                let tp = (F::splat(node.split()) - org[axis]) * rcp[axis];
                let down = neg[axis];
                // The side before the plane ends at it, the side after starts there; a plane
                // at either end of the range keeps both sides, as in the scalar walk.
                let before_t1 = t1.min(tp);
                let after_t0 = t0.max(tp);
                let (b0, b1) = (
                    F::select(down, after_t0, t0),
                    F::select(down, t1, before_t1),
                );
                let (a0, a1) = (
                    F::select(down, t0, after_t0),
                    F::select(down, before_t1, t1),
                );
                let (vb, va) = (live(b0, b1, *limit), live(a0, a1, *limit));
                let (below, above) = (index + 1, node.above() as usize);
                match (vb.any(), va.any()) {
                    (true, true) => {
                        let lead = (vb | va).bits().trailing_zeros();
                        debug_assert!(sp < N);
                        let k = sp & (N - 1);
                        if down.bits() >> lead & 1 == 0 {
                            (st_node[k], st_t0[k], st_t1[k]) = (above as u32, a0, a1);
                            (index, t0, t1) = (below, b0, b1);
                        } else {
                            (st_node[k], st_t0[k], st_t1[k]) = (below as u32, b0, b1);
                            (index, t0, t1) = (above, a0, a1);
                        }
                        sp += 1;
                        continue;
                    }
                    (true, false) => {
                        (index, t0, t1) = (below, b0, b1);
                        continue;
                    }
                    (false, true) => {
                        (index, t0, t1) = (above, a0, a1);
                        continue;
                    }
                    (false, false) => {}
                }
            } else if node.prim_count() != 0 {
                let m = live(t0, t1, *limit);
                if m.any() {
                    leaf(self.leaf(node), m, limit);
                }
            }
            // The next pending entry with a live lane.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                if live(st_t0[sp], st_t1[sp], *limit).any() {
                    (index, t0, t1) = (st_node[sp] as usize, st_t0[sp], st_t1[sp]);
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{KdParams, KdTree};
    use crate::geometry::{Aabb, Ray};
    use crate::simd::{Float, Mask, PortableF32, V3};
    use glam::Vec3;

    type F8 = PortableF32<8>;

    fn boxes() -> Vec<Aabb> {
        let mut v = Vec::new();
        for i in 0..300u32 {
            let f = |k: u32| ((i.wrapping_mul(2_654_435_761) >> k) % 1000) as f32 / 1000.0;
            let p = Vec3::new(f(0), f(5), f(9)) * 10.0;
            v.push(Aabb::new(p, p + Vec3::new(f(2), f(7), f(11)) * 1.5));
        }
        v
    }

    /// The slab test of a box (entry, or exit from inside) in (0, t_max).
    fn hit_box(b: &Aabb, ray: &Ray, t_max: f32) -> Option<f32> {
        let inv = Vec3::ONE / ray.d;
        let (n, f) = ((b.min - ray.o) * inv, (b.max - ray.o) * inv);
        let (t0, t1) = (n.min(f).max_element(), n.max(f).min_element());
        if t0 > t1 {
            return None;
        }
        [t0, t1].into_iter().find(|&t| t > 0.0 && t < t_max)
    }

    #[test]
    fn packet_walk_finds_each_lanes_scalar_hit() {
        let bx = boxes();
        for select_walk in [false, true] {
            let tree = KdTree::build(
                &bx,
                &KdParams {
                    select_walk,
                    ..KdParams::default()
                },
            );
            let (mut hits, mut checked) = (0, 0);
            for k in 0..400u32 {
                let g = |j: u32, s: u32| ((k * 8 + j).wrapping_mul(0x9e37_79b1) >> s) % 1000 + 1;
                let rays: Vec<Ray> = (0..8)
                    .map(|j| {
                        let o = Vec3::new(g(j, 1) as f32, g(j, 3) as f32, g(j, 5) as f32) * 0.014
                            - Vec3::splat(1.0);
                        // Packets of every coherence: all lanes alike for small k, random
                        // directions otherwise.
                        let s = if k < 100 { 0 } else { j };
                        let d = Vec3::new(g(s, 7) as f32, g(s, 9) as f32, g(s, 11) as f32)
                            - Vec3::splat(500.5);
                        Ray::new(o, d)
                    })
                    .collect();
                let o = V3::<F8>::from_fn(|i| rays[i].o);
                let d = V3::<F8>::from_fn(|i| rays[i].d);
                let inv = V3::new(d.x.recip(), d.y.recip(), d.z.recip());
                let t_max = if k % 3 == 0 { 6.0 } else { f32::INFINITY };
                // Alternate lanes off in some packets.
                let lanes = <F8 as Float>::Mask::from_fn(|i| k % 4 != 1 || i % 2 == 0)
                    & KdTree::packet_lanes(o, d, inv);
                let mut limit = F8::splat(t_max);
                let mut best = [None; 8];
                tree.walk_packet(o, inv, lanes, &mut limit, |leaf, m, limit| {
                    for &p in leaf.prims {
                        for i in 0..8 {
                            if !m.lane(i) {
                                continue;
                            }
                            let lim = limit.lane(i);
                            if let Some(t) = hit_box(&bx[p as usize], &rays[i], lim) {
                                best[i] = Some(t);
                                *limit = F8::select(
                                    <F8 as Float>::Mask::from_fn(|l| l == i),
                                    F8::splat(t),
                                    *limit,
                                );
                            }
                        }
                    }
                });
                for i in 0..8 {
                    if !lanes.lane(i) {
                        assert_eq!(best[i], None);
                        continue;
                    }
                    let want = tree.closest_hit(&rays[i], t_max, |p, lim| {
                        hit_box(&bx[p as usize], &rays[i], lim)
                    });
                    assert_eq!(best[i], want, "packet {k} lane {i} {:?}", rays[i]);
                    hits += usize::from(want.is_some());
                    checked += 1;
                }
            }
            assert!(hits > checked / 4 && hits < checked, "{hits} of {checked}");
        }
    }
}
