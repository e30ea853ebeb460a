//! Front-to-back traversal.

use super::{KdTree, Leaf, MAX_DEPTH, node::KdNode};
use crate::geometry::Ray;
use glam::{Vec3, Vec3A};
use std::hint::select_unpredictable as sel;

/// A far child still to visit, with the ray's parametric range inside it.
#[derive(Clone, Copy)]
struct Todo {
    node: u32,
    t0: f32,
    t1: f32,
}

// Each interior node on the current path pushes at most one entry, so the depth bounds the stack.
const STACK: usize = MAX_DEPTH as usize;
// The select walk indexes its stack with a mask.
const _: () = assert!(STACK.is_power_of_two());

/// Pushes a far child to visit later over `[t0, t1]`.
#[inline(always)]
fn push<const N: usize>(stack: &mut [Todo; N], sp: &mut usize, node: usize, t0: f32, t1: f32) {
    stack[*sp] = Todo {
        node: node as u32,
        t0,
        t1,
    };
    *sp += 1;
}

/// How a closest-hit walk goes on after a leaf: hits are sorted by leaf, so one found before
/// this leaf's far end beats all later leaves and ends the walk; otherwise the limit is the
/// best hit so far.
#[inline(always)]
fn after_leaf(found: bool, limit: f32, t_far: f32) -> Option<f32> {
    if found && limit < t_far {
        None
    } else {
        Some(limit)
    }
}

impl KdTree {
    /// Closest hit. Calls `isect(prim, t_max_now)` for candidate primitives in front-to-back
    /// order; the callback returns `Some(t)` only for a hit with `0 < t < t_max_now` (the caller
    /// records u, v, etc.). Returns the closest `t` found, or `None`. Stops as soon as the best
    /// hit lies before the current leaf's far distance.
    ///
    /// A primitive that spans several leaves may be offered more than once.
    pub fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        mut isect: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<f32> {
        // Not written over `closest_hit_leaves`: the nested closures measured 16 % slower on
        // the scene-level tree.
        let mut best = None;
        self.walk(ray, t_max, |leaf, t_far, mut limit| {
            for &p in leaf.prims {
                // Re-check the contract so a careless callback cannot move the hit backwards.
                if let Some(t) = isect(p, limit).filter(|&t| t < limit) {
                    limit = t;
                    best = Some(t);
                }
            }
            after_leaf(best.is_some(), limit, t_far)
        });
        best
    }

    /// Closest hit, a leaf at a time: `isect(leaf, t_max_now)` returns the closest hit among
    /// the leaf's primitives with `0 < t < t_max_now`, if any. For callers that test a leaf's
    /// primitives together (several at once, from data laid out along [`KdTree::runs`]).
    /// Always inlined: a mesh's walk runs inside a lane type's entry point, so that its leaf
    /// test is compiled for that instruction set.
    #[inline(always)]
    pub fn closest_hit_leaves(
        &self,
        ray: &Ray,
        t_max: f32,
        mut isect: impl FnMut(Leaf<'_>, f32) -> Option<f32>,
    ) -> Option<f32> {
        let mut best = None;
        // Inlined into the walk, so that the caller's leaf test is too (callgrind, box-crossing
        // diffuse misses on the bunny: 0.5 % fewer instructions, 3 % fewer mispredictions).
        self.walk(
            ray,
            t_max,
            #[inline(always)]
            |leaf, t_far, mut limit| {
                if let Some(t) = isect(leaf, limit).filter(|&t| t < limit) {
                    limit = t;
                    best = Some(t);
                }
                after_leaf(best.is_some(), limit, t_far)
            },
        );
        best
    }

    /// Any hit before `t_max` (shadow rays): stops at the first `occluded(prim, t_max)` that
    /// returns true.
    pub fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        mut occluded: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        let mut hit = false;
        self.walk(ray, t_max, |leaf, _, limit| {
            if leaf.prims.iter().any(|&p| occluded(p, t_max)) {
                hit = true;
                None
            } else {
                Some(limit)
            }
        });
        hit
    }

    /// Any hit before `t_max`, a leaf at a time: stops at the first leaf for which
    /// `occluded(leaf, t_max)` returns true. Always inlined, as `closest_hit_leaves`.
    #[inline(always)]
    pub fn any_hit_leaves(
        &self,
        ray: &Ray,
        t_max: f32,
        mut occluded: impl FnMut(Leaf<'_>, f32) -> bool,
    ) -> bool {
        let mut hit = false;
        // Inlined into the walk, as for `closest_hit_leaves`.
        self.walk(
            ray,
            t_max,
            #[inline(always)]
            |leaf, _, limit| {
                if occluded(leaf, t_max) {
                    hit = true;
                    None
                } else {
                    Some(limit)
                }
            },
        );
        hit
    }

    /// Visits the non-empty leaves the ray passes through, front to back.
    /// `leaf(leaf, t_far, limit)` returns the new limit (pending subtrees starting beyond it are
    /// skipped), or `None` to stop.
    #[inline(always)]
    fn walk(&self, ray: &Ray, t_max: f32, leaf: impl FnMut(Leaf<'_>, f32, f32) -> Option<f32>) {
        // The stack is a local array, initialised on every call: sized to the tree's depth
        // rather than to the deepest possible tree, a shallow instance tree does not clear
        // 768 bytes per ray (that memset was 3 % of the instructions of a Cornell pass).
        match self.stats.max_depth {
            0..=16 => self.walk_with::<16>(ray, t_max, leaf),
            17..=32 => self.walk_with::<32>(ray, t_max, leaf),
            _ => self.walk_with::<STACK>(ray, t_max, leaf),
        }
    }

    #[inline(always)]
    fn walk_with<const N: usize>(
        &self,
        ray: &Ray,
        t_max: f32,
        leaf: impl FnMut(Leaf<'_>, f32, f32) -> Option<f32>,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        // 1/±0 = ±inf: axis-parallel rays get infinite plane distances. The checks and the
        // box test run in SIMD registers: most rays that reach a mesh's tree miss its box.
        let (o, d) = (Vec3A::from(ray.o), Vec3A::from(ray.d));
        let inv = Vec3A::ONE / d;
        if (inv.is_finite_mask() & d.is_finite_mask() & o.is_finite_mask()).all() {
            if let Some((t0, t1)) = self.bounds.intersect_oblique(o, inv, t_max) {
                if self.select_walk {
                    self.walk_from::<N, true, true>(ray, inv.into(), t0, t1, t_max, leaf);
                } else {
                    self.walk_from::<N, true, false>(ray, inv.into(), t0, t1, t_max, leaf);
                }
            }
            return;
        }
        // A ray with a non-finite origin or direction meets nothing.
        if !(ray.d.is_finite() && ray.o.is_finite()) {
            return;
        }
        let inv_d = Vec3::from(inv);
        if let Some((t0, t1)) = self.bounds.intersect_p(ray, inv_d, t_max) {
            self.walk_from::<N, false, false>(ray, inv_d, t0, t1, t_max, leaf);
        }
    }

    /// The walk from the root over the ray's range `[t0, t1]` in the tree's box.
    ///
    /// `OBLIQUE` rays have no zero direction component, which covers nearly all of them: a
    /// plane distance is then never NaN, and the child the ray meets first depends only on the
    /// sign of its direction along the split axis. That leaves two tests per node (plane before
    /// or beyond the segment), done with selects instead of branches when `SELECTS` is set,
    /// since incoherent rays mispredict them often. Other rays, parallel to split planes or
    /// lying in them, take the general step.
    #[inline(always)]
    fn walk_from<const N: usize, const OBLIQUE: bool, const SELECTS: bool>(
        &self,
        ray: &Ray,
        inv_d: Vec3,
        mut t0: f32,
        mut t1: f32,
        t_max: f32,
        mut leaf: impl FnMut(Leaf<'_>, f32, f32) -> Option<f32>,
    ) {
        // Per-axis values in arrays indexed by the node's axis bits: indexing a `Vec3` compiles
        // to a chain of compares on the axis, two more unpredictable branches per node.
        let o = [ray.o.x, ray.o.y, ray.o.z, 0.0];
        let inv = [inv_d.x, inv_d.y, inv_d.z, 0.0];
        // Bit `axis` set where the direction is negative.
        let neg = u32::from(ray.d.x < 0.0)
            | u32::from(ray.d.y < 0.0) << 1
            | u32::from(ray.d.z < 0.0) << 2;
        let mut limit = t_max;
        let mut stack = [Todo {
            node: 0,
            t0: 0.0,
            t1: 0.0,
        }; N];
        let mut sp = 0;
        let mut index = 0usize;
        // The node being visited, carried by value so that an oblique step can pick it from
        // the two children it loaded.
        let mut cur = self.nodes[0];
        let opaque_zero = std::hint::black_box(0u64);
        loop {
            let node = &cur;
            if !node.is_leaf() {
                let axis = node.axis() & 3;
                let split = node.split();
                let t_plane = (split - o[axis]) * inv[axis];
                let (below, above) = (index + 1, node.above() as usize);
                if OBLIQUE && SELECTS {
                    // Moving up the axis the below child comes first, moving down the above.
                    // A plane exactly at either end of the segment visits both sides, so a
                    // primitive touching the plane from either is seen (as the general step
                    // does).
                    //
                    // Without branches: for incoherent rays the three-way branch of the other
                    // step mispredicts about once a node. Both children are loaded before the
                    // plane test decides between them, so the next step waits only on that
                    // test, not on a load behind it (loading the chosen child after the
                    // decision measured 8-15 % slower than the branches). `opaque_zero` keeps
                    // the compiler from folding the select of two loads back into one load
                    // from the selected address. The far child is written to the stack every
                    // step and kept only when the segment crosses the plane. Unlike the
                    // branchy step this one does not skip an empty near child: the test and
                    // the extra select cost more instructions than the visits they save
                    // (box-crossing diffuse misses on the bunny: 2,030 against 1,600 instructions
                    // per ray).
                    let down = neg >> axis & 1 != 0;
                    let near = sel(down, above, below);
                    let far = sel(down, below, above);
                    let (n_near, n_far) = (self.nodes[near].bits(), self.nodes[far].bits());
                    let far_only = t_plane < t0;
                    let near_only = t_plane > t1;
                    // N is a power of two above the tree's depth, which bounds `sp` at an
                    // interior node: the mask changes nothing but drops a bounds check.
                    debug_assert!(sp < N);
                    stack[sp & (N - 1)] = Todo {
                        node: far as u32,
                        t0: t_plane,
                        t1,
                    };
                    sp += usize::from(!(far_only | near_only));
                    let go_far = far_only;
                    index = sel(go_far, far, near);
                    // Before the plane the segment ends no later than it. Selected as bits: a
                    // select of floats compiles to a branch.
                    let sooner = if t_plane < t1 { t_plane } else { t1 };
                    t1 = f32::from_bits(sel(go_far, t1.to_bits(), sooner.to_bits()));
                    cur = KdNode::from_bits(sel(go_far, n_far ^ opaque_zero, n_near));
                    continue;
                }
                if OBLIQUE {
                    // Moving up the axis the below child comes first, moving down the above.
                    let (near, far) = if neg >> axis & 1 == 0 {
                        (below, above)
                    } else {
                        (above, below)
                    };
                    // As the selects above, with branches: better where the rays are coherent
                    // enough for them to be predicted (the scene-level tree). A near side
                    // that is an empty leaf is skipped, straight on to the far side with no
                    // push, visit and pop.
                    if t_plane < t0 {
                        index = far;
                    } else if t_plane > t1 {
                        index = near;
                    } else if self.nodes[near].is_empty_leaf() {
                        index = far;
                        t0 = t_plane;
                    } else {
                        push(&mut stack, &mut sp, far, t_plane, t1);
                        index = near;
                        t1 = t_plane;
                    }
                    cur = self.nodes[index];
                    continue;
                }
                // From on the plane, the side the ray heads into comes first.
                let d = [ray.d.x, ray.d.y, ray.d.z, 0.0];
                let below_first = o[axis] < split || (o[axis] == split && d[axis] <= 0.0);
                let (first, second) = if below_first {
                    (below, above)
                } else {
                    (above, below)
                };
                if t_plane.is_nan() {
                    // 0 · inf: the ray lies in the plane, touching both children all along.
                    push(&mut stack, &mut sp, second, t0, t1);
                    index = first;
                } else if t_plane > t1 || t_plane <= 0.0 || t_plane == f32::INFINITY {
                    index = first;
                } else if t_plane < t0 {
                    index = second;
                } else {
                    push(&mut stack, &mut sp, second, t_plane, t1);
                    index = first;
                    t1 = t_plane;
                }
                cur = self.nodes[index];
                continue;
            }

            // Empty leaves (over half of a mesh tree's) need no call: a hit found earlier
            // that ends the walk is caught by the check on the next pending entry.
            if node.prim_count() != 0 {
                match leaf(self.leaf(&self.nodes[index]), t1, limit) {
                    Some(l) => limit = l,
                    None => return,
                }
            }
            // Pending entries start no earlier than the top one, so one past the limit ends it.
            if sp == 0 {
                return;
            }
            sp -= 1;
            let todo = stack[sp];
            if todo.t0 > limit {
                return;
            }
            index = todo.node as usize;
            cur = self.nodes[index];
            t0 = todo.t0;
            t1 = todo.t1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{KdParams, KdTree};
    use crate::geometry::{Aabb, Ray};
    use glam::Vec3;

    /// Slab test that reports the entry distance, or the exit one from inside.
    fn hit_box(b: &Aabb, ray: &Ray, t_max: f32) -> Option<f32> {
        let inv = Vec3::ONE / ray.d;
        let (mut t0, mut t1) = (f32::NEG_INFINITY, f32::INFINITY);
        for a in 0..3 {
            let mut n = (b.min[a] - ray.o[a]) * inv[a];
            let mut f = (b.max[a] - ray.o[a]) * inv[a];
            if n.is_nan() || f.is_nan() {
                return None;
            }
            if n > f {
                std::mem::swap(&mut n, &mut f);
            }
            t0 = t0.max(n);
            t1 = t1.min(f);
        }
        if t0 > t1 {
            return None;
        }
        [t0, t1].into_iter().find(|&t| t > 0.0 && t < t_max)
    }

    fn grid_boxes() -> Vec<Aabb> {
        let mut v = Vec::new();
        for x in 0..8 {
            for y in 0..8 {
                for z in 0..8 {
                    let p = Vec3::new(x as f32, y as f32, z as f32) * 2.0;
                    v.push(Aabb::new(p, p + Vec3::splat(1.0)));
                }
            }
        }
        v
    }

    fn brute(boxes: &[Aabb], ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
        let mut best: Option<(u32, f32)> = None;
        for (i, b) in boxes.iter().enumerate() {
            let lim = best.map_or(t_max, |h| h.1);
            if let Some(t) = hit_box(b, ray, lim) {
                best = Some((i as u32, t));
            }
        }
        best
    }

    fn kd(tree: &KdTree, boxes: &[Aabb], ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
        let mut prim = None;
        let t = tree.closest_hit(ray, t_max, |p, lim| {
            let t = hit_box(&boxes[p as usize], ray, lim);
            if t.is_some() {
                prim = Some(p);
            }
            t
        })?;
        Some((prim.unwrap(), t))
    }

    /// Deepest leaf, walking the packed nodes (below child at `i + 1`, above at `above()`).
    fn depth_of(tree: &KdTree, i: usize) -> u32 {
        let n = &tree.nodes[i];
        if n.is_leaf() {
            0
        } else {
            1 + depth_of(tree, i + 1).max(depth_of(tree, n.above() as usize))
        }
    }

    #[test]
    fn recorded_depth_bounds_the_traversal_stack() {
        // The walk sizes its stack by `stats.max_depth`: it must be the true depth.
        for boxes in [
            grid_boxes(),
            grid_boxes()[..40].to_vec(),
            grid_boxes()[..3].to_vec(),
        ] {
            let tree = KdTree::build(&boxes, &KdParams::default());
            assert_eq!(depth_of(&tree, 0), tree.stats().max_depth);
        }
        let deep = KdParams {
            max_leaf_prims: 1,
            intersect_cost: 1000.0,
            ..KdParams::default()
        };
        let tree = KdTree::build(&grid_boxes(), &deep);
        assert!(tree.stats().max_depth > 16, "{}", tree.stats());
        assert_eq!(depth_of(&tree, 0), tree.stats().max_depth);
    }

    #[test]
    fn empty_tree_misses() {
        let tree = KdTree::build(&Vec::<Aabb>::new(), &KdParams::default());
        assert_eq!(tree.stats().nodes, 0);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(
            tree.closest_hit(&ray, f32::INFINITY, |_, _| Some(1.0)),
            None
        );
        assert!(!tree.any_hit(&ray, f32::INFINITY, |_, _| true));
    }

    #[test]
    fn axis_rays_through_grid_match_brute_force() {
        let boxes = grid_boxes();
        let tree = KdTree::build(&boxes, &KdParams::default());
        let mut checked = 0;
        // Origins on box faces (the candidate planes), between boxes and outside, along
        // every signed axis with ±0 in the other components.
        let coords = [-1.0f32, 0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 7.0, 15.0, 16.0];
        for &x in &coords {
            for &y in &coords {
                for &z in &coords {
                    let o = Vec3::new(x, y, z);
                    for a in 0..3 {
                        for s in [1.0f32, -1.0] {
                            for zero in [0.0f32, -0.0] {
                                let mut d = Vec3::splat(zero);
                                d[a] = s;
                                let ray = Ray::new(o, d);
                                for t_max in [f32::INFINITY, 3.0] {
                                    let want = brute(&boxes, &ray, t_max);
                                    assert_eq!(kd(&tree, &boxes, &ray, t_max), want, "{ray:?}");
                                    let any = tree.any_hit(&ray, t_max, |p, tm| {
                                        hit_box(&boxes[p as usize], &ray, tm).is_some()
                                    });
                                    assert_eq!(any, want.is_some());
                                    checked += 1;
                                }
                            }
                        }
                    }
                }
            }
        }
        assert_eq!(checked, 1000 * 24);
    }

    #[test]
    fn oblique_rays_through_planes_and_corners_match_brute_force() {
        oblique_rays_match_brute_force_with(false);
    }

    #[test]
    fn oblique_rays_match_brute_force_with_the_select_walk() {
        oblique_rays_match_brute_force_with(true);
    }

    fn oblique_rays_match_brute_force_with(select_walk: bool) {
        // Rays with no zero direction component take the sign-based walk. Origins and targets
        // on the box faces (the split planes) put plane distances exactly at segment ends.
        let boxes = grid_boxes();
        let params = KdParams {
            select_walk,
            ..KdParams::default()
        };
        let tree = KdTree::build(&boxes, &params);
        let coords = [-1.0f32, 0.0, 1.0, 2.0, 3.0, 8.0, 15.0, 16.0];
        let (mut checked, mut hits) = (0, 0);
        for (i, &x) in coords.iter().enumerate() {
            for (j, &y) in coords.iter().enumerate() {
                for &z in &coords {
                    let o = Vec3::new(x, y, z);
                    let target = Vec3::new(coords[(i + 3) % 8], coords[(j + 5) % 8], 7.0);
                    for d in [
                        target - o,
                        Vec3::new(1.0, -1.0, 1.0),
                        Vec3::new(-2.0, 1.0, -1.0),
                    ] {
                        if d.x == 0.0 || d.y == 0.0 || d.z == 0.0 {
                            continue;
                        }
                        let ray = Ray::new(o, d);
                        for t_max in [f32::INFINITY, 0.75] {
                            let want = brute(&boxes, &ray, t_max);
                            assert_eq!(kd(&tree, &boxes, &ray, t_max), want, "{ray:?}");
                            let any = tree.any_hit(&ray, t_max, |p, tm| {
                                hit_box(&boxes[p as usize], &ray, tm).is_some()
                            });
                            assert_eq!(any, want.is_some(), "{ray:?}");
                            checked += 1;
                            hits += usize::from(want.is_some());
                        }
                    }
                }
            }
        }
        assert!(
            checked > 2500 && hits > checked / 4,
            "{checked} rays, {hits} hits"
        );
    }

    #[test]
    fn leaf_queries_match_brute_force() {
        leaf_queries_match_brute_force_with(false);
    }

    #[test]
    fn leaf_queries_match_brute_force_with_the_select_walk() {
        leaf_queries_match_brute_force_with(true);
    }

    fn leaf_queries_match_brute_force_with(select_walk: bool) {
        // Leaves handed out whole, with runs aligned to four as mesh trees have them (and
        // several boxes to a leaf). Bars across the grid straddle split planes, so a leaf can
        // report a hit beyond its own far end, before which a later leaf may hold a nearer one.
        let mut boxes = grid_boxes();
        for k in 0..8 {
            let (y, z) = (k as f32 * 2.0 + 0.25, (7 - k) as f32 * 2.0 + 0.25);
            boxes.push(Aabb::new(
                Vec3::new(-1.0, y, z),
                Vec3::new(16.0, y + 0.5, z + 0.5),
            ));
            boxes.push(Aabb::new(
                Vec3::new(y, -1.0, z),
                Vec3::new(y + 0.5, 16.0, z + 0.5),
            ));
        }
        let params = KdParams {
            run_align: 4,
            max_leaf_prims: 8,
            select_walk,
            ..KdParams::default()
        };
        let tree = KdTree::build(&boxes, &params);
        let (mut checked, mut hits, mut runs) = (0, 0, 0);
        for i in 0..2000u32 {
            let f = |k: u32| ((i.wrapping_mul(2_654_435_761) >> k) % 1000) as f32 / 1000.0;
            let o = Vec3::new(f(0), f(3), f(7)) * 20.0 - Vec3::splat(2.0);
            let d = Vec3::new(f(11), f(13), f(17)) - Vec3::splat(0.5);
            let ray = Ray::new(o, d);
            for t_max in [f32::INFINITY, 4.0] {
                let want = brute(&boxes, &ray, t_max).map(|h| h.1);
                let got = tree.closest_hit_leaves(&ray, t_max, |leaf, limit| {
                    if let Some(at) = leaf.run {
                        assert!(at % 4 == 0 && leaf.prims.len() > 1);
                        runs += 1;
                    }
                    leaf.prims
                        .iter()
                        .filter_map(|&p| hit_box(&boxes[p as usize], &ray, limit))
                        .min_by(f32::total_cmp)
                });
                assert_eq!(got, want, "{ray:?} t_max {t_max}");
                let any = tree.any_hit_leaves(&ray, t_max, |leaf, tm| {
                    leaf.prims
                        .iter()
                        .any(|&p| hit_box(&boxes[p as usize], &ray, tm).is_some())
                });
                assert_eq!(any, want.is_some(), "{ray:?} t_max {t_max}");
                checked += 1;
                hits += usize::from(want.is_some());
            }
        }
        assert!(
            hits > checked / 10 && runs > 0,
            "{hits} of {checked}, {runs} runs"
        );
    }

    #[test]
    fn the_select_walk_stops_at_its_node_limit() {
        let params = KdParams {
            select_walk: true,
            ..KdParams::default()
        };
        let small = KdTree::build(&grid_boxes(), &params);
        assert!(small.select_walk());
        // 48³ separate boxes need a leaf each, about twice as many nodes as boxes.
        let mut boxes = Vec::new();
        for i in 0..48 * 48 * 48 {
            let p = Vec3::new((i % 48) as f32, (i / 48 % 48) as f32, (i / 2304) as f32) * 2.0;
            boxes.push(Aabb::new(p, p + Vec3::ONE));
        }
        let big = KdTree::build(&boxes, &params);
        assert!(big.stats().nodes > super::super::SELECT_WALK_MAX_NODES);
        assert!(!big.select_walk());
        assert!(!KdTree::build(&grid_boxes(), &KdParams::default()).select_walk());
    }

    #[test]
    fn callback_results_past_the_limit_are_ignored() {
        let boxes = grid_boxes();
        let tree = KdTree::build(&boxes, &KdParams::default());
        let ray = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
        // A callback that ignores t_max_now must not make the answer worse than the truth.
        let t = tree.closest_hit(&ray, f32::INFINITY, |p, _| {
            hit_box(&boxes[p as usize], &ray, f32::INFINITY)
        });
        assert_eq!(t, Some(1.0));
    }
}
