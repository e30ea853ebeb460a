//! The O(N log N) SAH builder (Wald & Havran 2006).
//!
//! An event is one `u64` whose natural order is the sweep order: axis, then position, then
//! kind (end < planar < start, so that at equal positions the primitives closing there count
//! as left of the plane and those opening there as right of it), then primitive. A node's
//! events for all three axes live in one sorted vector, three consecutive runs.

use super::node::KdNode;
use super::{KdParams, KdPrimitives, KdStats, MAX_DEPTH};

use crate::geometry::Aabb;
use glam::{Vec3, Vec4};

const AXIS_SHIFT: u32 = 62;
const POS_SHIFT: u32 = 30;
const KIND_SHIFT: u32 = 28;
const PRIM_BITS: u32 = 28;

/// Most primitives a tree can hold: the index shares the event word with axis, position and kind.
pub const MAX_PRIMS: usize = 1 << PRIM_BITS;

const END: u64 = 0;
const PLANAR: u64 = 1;
const START: u64 = 2;

/// Maps a float to a `u32` with the same order (for finite values); −0 is folded onto +0 so
/// that the two compare as the one plane they are.
#[inline]
fn ord_bits(x: f32) -> u32 {
    let b = (x + 0.0).to_bits();
    if b >> 31 != 0 { !b } else { b | 1 << 31 }
}

#[inline]
fn from_ord_bits(k: u32) -> f32 {
    f32::from_bits(if k >> 31 != 0 { k & !(1 << 31) } else { !k })
}

#[inline]
fn event(axis: usize, pos: f32, kind: u64, prim: u32) -> u64 {
    ((axis as u64) << AXIS_SHIFT)
        | ((ord_bits(pos) as u64) << POS_SHIFT)
        | (kind << KIND_SHIFT)
        | prim as u64
}

#[inline]
fn ev_axis(e: u64) -> usize {
    (e >> AXIS_SHIFT) as usize
}

#[inline]
fn ev_pos(e: u64) -> f32 {
    from_ord_bits((e >> POS_SHIFT) as u32)
}

#[inline]
fn ev_kind(e: u64) -> u64 {
    (e >> KIND_SHIFT) & 3
}

#[inline]
fn ev_prim(e: u64) -> u32 {
    (e & ((1 << PRIM_BITS) - 1)) as u32
}

/// Axis and position together: events with the same value describe the same plane.
#[inline]
fn ev_plane(e: u64) -> u64 {
    e >> POS_SHIFT
}

/// Appends the three axes' events of a box (already clipped to its cell).
fn push_events(out: &mut Vec<u64>, prim: u32, b: &Aabb) {
    for a in 0..3 {
        if b.min[a] == b.max[a] {
            out.push(event(a, b.min[a], PLANAR, prim));
        } else {
            out.push(event(a, b.min[a], START, prim));
            out.push(event(a, b.max[a], END, prim));
        }
    }
}

/// The primitives of a node: each has exactly one start or planar event on axis 0, which
/// comes first in the list.
fn node_prims(events: &[u64]) -> impl Iterator<Item = u32> + '_ {
    events
        .iter()
        .take_while(|&&e| ev_axis(e) == 0)
        .filter(|&&e| ev_kind(e) != END)
        .map(|&e| ev_prim(e))
}

/// Index range of one axis's events.
fn axis_run(events: &[u64], axis: usize) -> (usize, usize) {
    let lo = events.partition_point(|&e| ev_axis(e) < axis);
    let hi = events.partition_point(|&e| ev_axis(e) <= axis);
    (lo, hi)
}

fn merge(a: Vec<u64>, b: &[u64]) -> Vec<u64> {
    if b.is_empty() {
        return a;
    }
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i] <= b[j] {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

/// One axis of a cell, for pricing planes across it: a side of width w has surface area
/// 2 (cap + w · rim), and its hit probability is that over the cell's.
#[derive(Clone, Copy)]
struct AxisCell {
    lo: f32,
    hi: f32,
    cap: f32,
    rim: f32,
    inv_sa: f32,
}

impl AxisCell {
    fn new(cell: &Aabb, axis: usize, inv_sa: f32) -> Self {
        let d = cell.diagonal();
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        Self {
            lo: cell.min[axis],
            hi: cell.max[axis],
            cap: d[u] * d[v],
            rim: d[u] + d[v],
            inv_sa,
        }
    }

    /// Widths and hit probabilities of the sides below and above `pos`.
    #[inline]
    fn sides(&self, pos: f32) -> (f32, f32, f32, f32) {
        let (wl, wr) = (pos - self.lo, self.hi - pos);
        let pl = 2.0 * (self.cap + wl * self.rim) * self.inv_sa;
        let pr = 2.0 * (self.cap + wr * self.rim) * self.inv_sa;
        (wl, wr, pl, pr)
    }
}

/// The cheapest split offered so far; of equal costs the first offered stays, so the order
/// of the offers (and nothing else) decides ties.
struct Cheapest(Option<Split>);

impl Cheapest {
    #[inline]
    fn offer(&mut self, axis: usize, pos: f32, planar_left: bool, cost: f32) {
        if cost < self.0.map_or(f32::INFINITY, |b| b.cost) {
            self.0 = Some(Split {
                axis,
                pos,
                planar_left,
                cost,
            });
        }
    }
}

/// A flat side holding nothing leaves the other side the whole node: no split.
#[inline]
fn useless(wl: f32, wr: f32, l: u32, r: u32) -> bool {
    (wl == 0.0 && l == 0) || (wr == 0.0 && r == 0)
}

#[derive(Clone, Copy, Debug)]
struct Split {
    axis: usize,
    pos: f32,
    /// Which side primitives lying in the plane go to.
    planar_left: bool,
    cost: f32,
}

const BOTH: u8 = 0;
const LEFT: u8 = 1;
const RIGHT: u8 = 2;

/// Bins per axis of the binned SAH.
const BINS: usize = 32;

/// Where the planes between bins lie, as fractions of the cell (plane k at k / BINS).
const PLANE_AT: [f32; BINS] = {
    let mut a = [0.0; BINS];
    let mut k = 0;
    while k < BINS {
        a[k] = k as f32 / BINS as f32;
        k += 1;
    }
    a
};

/// The bins of offsets measured in bin widths, clamped to the bins: ⌊x⌋ in [0, BINS − 1].
///
/// Without float-to-int conversions (Rust's saturating ones are long sequences on x86-64, and
/// they were a fifth of the build's instructions): for x in [0, BINS − 0.25],
/// (x − 0.5) + 1.5 · 2^23 lies in [2^23, 2^24), where floats are the integers, so it rounds to
/// 1.5 · 2^23 + ⌊x⌋ and the low mantissa bits hold the bin. An offset exactly on a bin
/// boundary may land one bin low, which only makes its reference count on both sides of that
/// plane.
#[inline]
fn bins(x: Vec4) -> [usize; 3] {
    const { assert!(BINS.is_power_of_two() && BINS <= 1 << 20) };
    let v = x.clamp(Vec4::ZERO, Vec4::splat(BINS as f32 - 0.25)) - Vec4::splat(0.5)
        + Vec4::splat(12_582_912.0);
    let [x, y, z, _] = v.to_array();
    [x, y, z].map(|f| (f.to_bits() & (BINS as u32 - 1)) as usize)
}

/// Nodes with at least this many references build their two children in parallel. Fixed, so
/// that the tree is the same whatever the thread count.
const PARALLEL_ABOVE: usize = 4096;

/// What `build` hands back to `KdTree`.
pub(crate) struct Built {
    pub nodes: Vec<KdNode>,
    pub indices: Vec<u32>,
    pub bounds: Aabb,
    pub stats: KdStats,
}

/// A subtree in depth-first order, its above-child indices and leaf offsets relative to its
/// own arrays; appending it to another shifts them.
#[derive(Default)]
struct Frag {
    nodes: Vec<KdNode>,
    indices: Vec<u32>,
    leaves: usize,
    empty_leaves: usize,
    depth: u32,
    prim_refs: usize,
}

impl Frag {
    fn append(&mut self, other: Frag) {
        let (dn, di) = (self.nodes.len() as u32, self.indices.len() as u32);
        self.nodes
            .extend(other.nodes.into_iter().map(|n| n.shifted(dn, di)));
        self.indices.extend_from_slice(&other.indices);
        self.leaves += other.leaves;
        self.empty_leaves += other.empty_leaves;
        self.depth = self.depth.max(other.depth);
        self.prim_refs += other.prim_refs;
    }

    fn leaf(&mut self, prims: &mut [u32], depth: u32, align: u32) {
        // Sorted, so a leaf's order does not depend on how the build reached it.
        prims.sort_unstable();
        let count = prims.len() as u32;
        let node = match prims.len() {
            0 => KdNode::leaf(0, 0),
            1 => KdNode::leaf(1, prims[0]),
            _ => {
                let offset = u32::try_from(self.indices.len()).expect("kd-tree index count");
                self.indices.extend_from_slice(prims);
                // Every run starts aligned because every run before it ends padded, and so
                // do fragments appended to one another.
                let padded = self.indices.len().next_multiple_of(align as usize);
                self.indices.resize(padded, prims[prims.len() - 1]);
                KdNode::leaf(count, offset)
            }
        };
        self.nodes.push(node);
        self.leaves += 1;
        self.empty_leaves += usize::from(count == 0);
        self.prim_refs += prims.len();
        self.depth = self.depth.max(depth);
    }
}

/// Reference buffers of finished nodes, reused by later ones: one depth-first task allocates
/// about two per level instead of two per node.
#[derive(Default)]
struct Pool(Vec<Vec<Ref>>);

impl Pool {
    fn take(&mut self) -> Vec<Ref> {
        self.0.pop().unwrap_or_default()
    }

    fn put(&mut self, mut v: Vec<Ref>) {
        v.clear();
        self.0.push(v);
    }
}

/// Nodes of at most this many references have every box face priced exactly.
const FEW: usize = 6;

/// A primitive's part inside a node: the bounds of that part in SIMD registers' layout (the
/// binning reads every reference at every level), the primitive's index in the spare lane.
#[derive(Clone, Copy)]
struct Ref {
    lo: Vec4,
    hi: Vec4,
}

/// Set in the spare lane's bits so that it always holds a normal float, whatever the index:
/// the lane goes through the binning arithmetic, where a denormal may be slow.
const PRIM_TAG: u32 = 0x4000_0000;

impl Ref {
    #[inline]
    fn new(b: &Aabb, prim: u32) -> Self {
        const { assert!(PRIM_BITS <= 28) };
        Self {
            lo: b.min.extend(f32::from_bits(PRIM_TAG | prim)),
            hi: b.max.extend(0.0),
        }
    }

    #[inline]
    fn prim(&self) -> u32 {
        self.lo.w.to_bits() & !PRIM_TAG
    }

    #[inline]
    fn bounds(&self) -> Aabb {
        Aabb {
            min: self.lo.truncate(),
            max: self.hi.truncate(),
        }
    }
}

/// The cost model and limits, shared by every task of a build.
struct Ctx<'a, P: KdPrimitives + ?Sized> {
    prims: &'a P,
    traversal_cost: f32,
    intersect_cost: f32,
    empty_bonus: f32,
    max_leaf_prims: u32,
    max_depth: u32,
    binned_above: usize,
    run_align: u32,
}

pub(crate) fn build<P: KdPrimitives + ?Sized>(prims: &P, params: &KdParams) -> Built {
    let n = prims.len();
    assert!(
        n <= MAX_PRIMS,
        "kd-tree holds at most {MAX_PRIMS} primitives, got {n}"
    );

    // Boxes that are empty or not finite cannot take part in plane sweeps; they are left out.
    let mut bounds = Aabb::EMPTY;
    let mut refs = Vec::with_capacity(n);
    for i in 0..n as u32 {
        let b = prims.bounds(i);
        if b.is_empty() || !b.min.is_finite() || !b.max.is_finite() {
            continue;
        }
        bounds = bounds.union(&b);
        refs.push(Ref::new(&b, i));
    }
    let kept = refs.len();

    let ctx = Ctx {
        prims,
        traversal_cost: params.traversal_cost,
        intersect_cost: params.intersect_cost,
        empty_bonus: params.empty_bonus,
        max_leaf_prims: params.max_leaf_prims,
        max_depth: params.depth_limit(kept),
        binned_above: params.binned_above,
        run_align: params.run_align.max(1),
    };
    let mut frag = Frag::default();
    if kept > 0 {
        ctx.binned(refs, bounds, 0, &mut frag, &mut Pool::default());
    }

    let non_empty = frag.leaves - frag.empty_leaves;
    let stats = KdStats {
        primitives: n,
        skipped: n - kept,
        nodes: frag.nodes.len(),
        leaves: frag.leaves,
        empty_leaves: frag.empty_leaves,
        max_depth: frag.depth,
        mean_leaf_prims: if non_empty > 0 {
            frag.prim_refs as f32 / non_empty as f32
        } else {
            0.0
        },
        prim_refs: frag.prim_refs,
        build_seconds: 0.0,
    };
    Built {
        nodes: frag.nodes,
        indices: frag.indices,
        bounds,
        stats,
    }
}

impl<P: KdPrimitives + ?Sized> Ctx<'_, P> {
    /// SAH cost of a split; an empty side earns the bonus only if it has volume, since cutting
    /// off a flat empty slab saves nothing.
    #[inline]
    fn cost(&self, pl: f32, pr: f32, nl: u32, nr: u32, wl: f32, wr: f32) -> f32 {
        let empty = (nl == 0 && wl > 0.0) || (nr == 0 && wr > 0.0);
        let scale = if empty { 1.0 - self.empty_bonus } else { 1.0 };
        self.traversal_cost + self.intersect_cost * scale * (pl * nl as f32 + pr * nr as f32)
    }

    /// The parts of the primitives straddling a plane, clipped to each side (perfect splits).
    fn clip_both(&self, p: u32, split: &Split, below: &Aabb, above: &Aabb) -> (Aabb, Aabb) {
        let cell = below.union(above);
        let (bl, br) = self.prims.split_bounds(p, &cell, split.axis, split.pos);
        let (bl, br) = (bl.intersection(below), br.intersection(above));
        if bl.is_empty() && br.is_empty() {
            // A clip that finds the primitive on neither side is numerical trouble: fall
            // back to plain boxes rather than lose it.
            let b = self.prims.bounds(p);
            return (b.intersection(below), b.intersection(above));
        }
        (bl, br)
    }

    /// A node of the binned levels: the split comes from binned counts (or, for a handful of
    /// references, from every face of every box), the children are built in parallel when
    /// large; nodes of at most `binned_above` references go to the exact event sweep.
    fn binned(&self, refs: Vec<Ref>, cell: Aabb, depth: u32, out: &mut Frag, pool: &mut Pool) {
        let n = refs.len();
        if n <= self.binned_above {
            self.exact(&refs, cell, depth, out);
            pool.put(refs);
            return;
        }
        let split = if n as u32 <= self.max_leaf_prims || depth >= self.max_depth {
            None
        } else if n <= FEW {
            self.few_split(&refs, &cell, n as u32)
        } else {
            self.binned_split(&refs, &cell, n as u32)
        };
        let Some(split) = split.filter(|s| s.cost < self.intersect_cost * n as f32) else {
            let mut prims: Vec<u32> = refs.iter().map(Ref::prim).collect();
            out.leaf(&mut prims, depth, self.run_align);
            pool.put(refs);
            return;
        };
        let mut below = cell;
        below.max[split.axis] = split.pos;
        let mut above = cell;
        above.min[split.axis] = split.pos;
        let (left, right) = self.partition_refs(&refs, &split, &below, &above, pool);
        if left.len() == n && right.len() == n {
            // No reference settled on one side (rounding in a degenerate cell): the exact
            // sweep decides, and always terminates.
            self.exact(&refs, cell, depth, out);
            pool.put(refs);
            pool.put(left);
            pool.put(right);
            return;
        }
        pool.put(refs);

        let me = out.nodes.len();
        out.nodes.push(KdNode::leaf(0, 0)); // patched once the above child's index is known
        // On one thread the join would only copy finished subtrees up the tree; the layout
        // is the same either way.
        if n >= PARALLEL_ABOVE && rayon::current_num_threads() > 1 {
            let (l, r) = rayon::join(
                || {
                    let mut f = Frag::default();
                    self.binned(left, below, depth + 1, &mut f, &mut Pool::default());
                    f
                },
                || {
                    let mut f = Frag::default();
                    self.binned(right, above, depth + 1, &mut f, &mut Pool::default());
                    f
                },
            );
            out.append(l);
            let above_index = u32::try_from(out.nodes.len()).expect("kd-tree node count");
            out.nodes[me] = KdNode::interior(split.axis, split.pos, above_index);
            out.append(r);
        } else {
            self.binned(left, below, depth + 1, out, pool);
            let above_index = u32::try_from(out.nodes.len()).expect("kd-tree node count");
            out.nodes[me] = KdNode::interior(split.axis, split.pos, above_index);
            self.binned(right, above, depth + 1, out, pool);
        }
    }

    /// Exact SAH for a handful of references: every face of every box is a candidate, its
    /// counts taken by looking at every reference (what the event sweep finds, without
    /// sorting or allocating).
    fn few_split(&self, refs: &[Ref], cell: &Aabb, n: u32) -> Option<Split> {
        let sa = cell.surface_area();
        if sa <= 0.0 {
            return None;
        }
        let mut best = Cheapest(None);
        for axis in 0..3 {
            let ac = AxisCell::new(cell, axis, 1.0 / sa);
            if ac.hi <= ac.lo {
                continue;
            }
            for c in refs {
                for pos in [c.lo[axis], c.hi[axis]] {
                    if pos < ac.lo || pos > ac.hi {
                        continue;
                    }
                    let (mut l, mut r, mut planar) = (0u32, 0u32, 0u32);
                    for x in refs {
                        let (a, b) = (x.lo[axis], x.hi[axis]);
                        if a == pos && b == pos {
                            planar += 1;
                        } else {
                            l += u32::from(a < pos);
                            r += u32::from(b > pos);
                        }
                    }
                    debug_assert!(l + r + planar >= n);
                    let (wl, wr, pl, pr) = ac.sides(pos);
                    let mut consider = |l: u32, r: u32, planar_left: bool| {
                        if !useless(wl, wr, l, r) {
                            best.offer(axis, pos, planar_left, self.cost(pl, pr, l, r, wl, wr));
                        }
                    };
                    consider(l + planar, r, true);
                    if planar > 0 {
                        consider(l, r + planar, false);
                    }
                }
            }
        }
        best.0
    }

    /// Binned SAH: per axis, the references' box faces counted into equal bins; the planes
    /// between bins are priced from the running counts (a reference whose box ends in a bin
    /// before the plane is left of it, one starting in a bin before it reaches left).
    fn binned_split(&self, refs: &[Ref], cell: &Aabb, n: u32) -> Option<Split> {
        let sa = cell.surface_area();
        if sa <= 0.0 {
            return None;
        }
        // One pass bins all three axes, so each reference is read once rather than three
        // times; a flat axis gets scale 0 and is skipped below.
        let ext = cell.diagonal();
        let scale = Vec3::select(
            ext.cmpgt(Vec3::ZERO),
            Vec3::splat(BINS as f32) / ext,
            Vec3::ZERO,
        );
        let mut starts = [[0u32; BINS]; 3];
        let mut ends = [[0u32; BINS]; 3];
        // In SIMD registers: as `Vec3` each step is three scalar ones.
        let (scale, origin) = (scale.extend(0.0), cell.min.extend(0.0));
        let (mut span_lo, mut span_hi) = (Vec4::INFINITY, Vec4::NEG_INFINITY);
        for r in refs {
            let (lo, hi) = (r.lo, r.hi);
            let s = bins((lo - origin) * scale);
            let e = bins((hi - origin) * scale);
            for a in 0..3 {
                starts[a][s[a]] += 1;
                ends[a][e[a]] += 1;
            }
            span_lo = span_lo.min(lo);
            span_hi = span_hi.max(hi);
        }
        let span = Aabb {
            min: span_lo.truncate(),
            max: span_hi.truncate(),
        };
        let mut best = Cheapest(None);
        for axis in 0..3 {
            let ac = AxisCell::new(cell, axis, 1.0 / sa);
            let (lo, hi) = (ac.lo, ac.hi);
            if hi <= lo {
                continue;
            }
            let (starts, ends) = (&starts[axis], &ends[axis]);
            let (first, last) = (span.min[axis], span.max[axis]);
            // Bins cut empty space only to their width; the planes through the references'
            // extreme faces cut it exactly, with all references on one side (flat ones in
            // the plane go with them).
            for (pos, planar_left) in [(first, false), (last, true)] {
                if pos <= lo || pos >= hi {
                    continue;
                }
                let (wl, wr, pl, pr) = ac.sides(pos);
                let (l, r) = if planar_left { (n, 0) } else { (0, n) };
                best.offer(axis, pos, planar_left, self.cost(pl, pr, l, r, wl, wr));
            }
            // Every plane between bins, priced four at a time: the same arithmetic as
            // `AxisCell::sides` and `cost`, lane for lane.
            let (mut nl, mut nr) = ([0.0f32; BINS], [0.0f32; BINS]);
            let (mut l, mut r) = (0u32, n);
            for k in 1..BINS {
                l += starts[k - 1];
                r -= ends[k - 1];
                nl[k] = l as f32;
                nr[k] = r as f32;
            }
            let (lo4, hi4, width) = (Vec4::splat(lo), Vec4::splat(hi), Vec4::splat(hi - lo));
            let (cap, rim, inv_sa) = (
                Vec4::splat(ac.cap),
                Vec4::splat(ac.rim),
                Vec4::splat(ac.inv_sa),
            );
            let two = Vec4::splat(2.0);
            let bonus = Vec4::splat(1.0 - self.empty_bonus);
            let mut costs = [Vec4::INFINITY; BINS / 4];
            let mut least = Vec4::INFINITY;
            for (g, c) in costs.iter_mut().enumerate() {
                let at = |a: &[f32; BINS]| Vec4::from_slice(&a[4 * g..4 * g + 4]);
                let (nl, nr) = (at(&nl), at(&nr));
                let pos = lo4 + width * Vec4::from_slice(&PLANE_AT[4 * g..4 * g + 4]);
                let (wl, wr) = (pos - lo4, hi4 - pos);
                let pl = two * (cap + wl * rim) * inv_sa;
                let pr = two * (cap + wr * rim) * inv_sa;
                let empty = (nl.cmpeq(Vec4::ZERO) & wl.cmpgt(Vec4::ZERO))
                    | (nr.cmpeq(Vec4::ZERO) & wr.cmpgt(Vec4::ZERO));
                let scale = Vec4::select(empty, bonus, Vec4::ONE);
                let cost = Vec4::splat(self.traversal_cost)
                    + Vec4::splat(self.intersect_cost) * scale * (pl * nl + pr * nr);
                // Plane 0 is the cell's face, and rounding may put others on a face too.
                let inside = pos.cmpgt(lo4) & pos.cmplt(hi4);
                *c = Vec4::select(inside, cost, Vec4::INFINITY);
                least = least.min(*c);
            }
            let least = least.min_element();
            // The first plane at the least cost, as offering them in order would keep; none
            // when every plane is priced out (all infinite).
            let first = costs.iter().enumerate().find_map(|(g, c)| {
                let m = c.cmpeq(Vec4::splat(least)).bitmask();
                (least < f32::INFINITY && m != 0).then(|| 4 * g + m.trailing_zeros() as usize)
            });
            if let Some(k) = first {
                best.offer(axis, lo + (hi - lo) * PLANE_AT[k], true, least);
            }
        }
        best.0
    }

    /// References wholly on one side keep their bounds; straddlers are clipped to each side.
    fn partition_refs(
        &self,
        refs: &[Ref],
        split: &Split,
        below: &Aabb,
        above: &Aabb,
        pool: &mut Pool,
    ) -> (Vec<Ref>, Vec<Ref>) {
        let (a, pos) = (split.axis, split.pos);
        let mut left = pool.take();
        let mut right = pool.take();
        // Either side holds at most every reference: no growth, no copies on the way.
        left.reserve(refs.len());
        right.reserve(refs.len());
        // The axis's lane picked from whole-register compares: indexing a lane by the axis
        // compiled to a branch on the axis for every reference.
        let (bit, at) = (1 << a, Vec4::splat(pos));
        for r in refs {
            let hi_le = r.hi.cmple(at).bitmask() & bit != 0;
            let lo_lt = r.lo.cmplt(at).bitmask() & bit != 0;
            if hi_le && (lo_lt || split.planar_left) {
                left.push(*r);
            } else if !lo_lt {
                right.push(*r);
            } else {
                let (bl, br) = self.clip_both(r.prim(), split, below, above);
                if !bl.is_empty() {
                    left.push(Ref::new(&bl, r.prim()));
                }
                if !br.is_empty() {
                    right.push(Ref::new(&br, r.prim()));
                }
            }
        }
        (left, right)
    }

    /// The exact sweep over sorted events (Wald & Havran) for the subtree of these references,
    /// with primitives renumbered locally so that its scratch is sized by the subtree.
    fn exact(&self, refs: &[Ref], cell: Aabb, depth: u32, out: &mut Frag) {
        let mut events = Vec::with_capacity(6 * refs.len());
        for (k, r) in refs.iter().enumerate() {
            push_events(&mut events, k as u32, &r.bounds());
        }
        events.sort_unstable();
        let mut b = Exact {
            ctx: self,
            ids: refs.iter().map(Ref::prim).collect(),
            side: vec![BOTH; refs.len()],
            scratch: Vec::new(),
            out,
        };
        b.node(events, cell, depth);
    }
}

/// State of one exact subtree build: local primitive k is `ids[k]`.
struct Exact<'a, 'c, P: KdPrimitives + ?Sized> {
    ctx: &'a Ctx<'c, P>,
    ids: Vec<u32>,
    side: Vec<u8>,
    scratch: Vec<u32>,
    out: &'a mut Frag,
}

impl<P: KdPrimitives + ?Sized> Exact<'_, '_, P> {
    fn node(&mut self, events: Vec<u64>, cell: Aabb, depth: u32) {
        let n = node_prims(&events).count() as u32;
        let split = if n <= self.ctx.max_leaf_prims || depth >= self.ctx.max_depth {
            None
        } else {
            self.find_split(&events, &cell, n)
                .filter(|s| s.cost < self.ctx.intersect_cost * n as f32)
        };
        let Some(split) = split else {
            self.scratch.clear();
            self.scratch
                .extend(node_prims(&events).map(|k| self.ids[k as usize]));
            let mut prims = std::mem::take(&mut self.scratch);
            self.out.leaf(&mut prims, depth, self.ctx.run_align);
            self.scratch = prims;
            return;
        };

        let mut below = cell;
        below.max[split.axis] = split.pos;
        let mut above = cell;
        above.min[split.axis] = split.pos;
        let (left, right) = self.partition(&events, &split, &below, &above);
        drop(events);

        let me = self.out.nodes.len();
        self.out.nodes.push(KdNode::leaf(0, 0)); // patched once the above child's index is known
        self.node(left, below, depth + 1);
        let above_index = u32::try_from(self.out.nodes.len()).expect("kd-tree node count");
        self.out.nodes[me] = KdNode::interior(split.axis, split.pos, above_index);
        self.node(right, above, depth + 1);
    }

    /// One sweep over the sorted events: at each candidate plane the counts of primitives
    /// left of, in and right of it are known, and the plane's SAH cost follows.
    fn find_split(&self, events: &[u64], cell: &Aabb, n: u32) -> Option<Split> {
        let sa = cell.surface_area();
        // A cell flat in two axes (a line or point of primitives) has no area to split.
        if sa <= 0.0 {
            return None;
        }
        let mut best = Cheapest(None);

        let mut i = 0;
        while i < events.len() {
            let axis = ev_axis(events[i]);
            let run = events[i..].partition_point(|&e| ev_axis(e) == axis);
            let run = &events[i..i + run];
            i += run.len();

            let ac = AxisCell::new(cell, axis, 1.0 / sa);
            let (mut nl, mut nr) = (0u32, n);
            let mut j = 0;
            while j < run.len() {
                let plane = ev_plane(run[j]);
                let pos = ev_pos(run[j]);
                let (mut ends, mut planars, mut starts) = (0u32, 0u32, 0u32);
                while j < run.len() && ev_plane(run[j]) == plane {
                    let kind = ev_kind(run[j]);
                    ends += u32::from(kind == END);
                    planars += u32::from(kind == PLANAR);
                    starts += u32::from(kind == START);
                    j += 1;
                }
                nr -= ends + planars;

                let (wl, wr, pl, pr) = ac.sides(pos);
                let mut consider = |l: u32, r: u32, planar_left: bool| {
                    if !useless(wl, wr, l, r) {
                        best.offer(axis, pos, planar_left, self.ctx.cost(pl, pr, l, r, wl, wr));
                    }
                };
                consider(nl + planars, nr, true);
                if planars > 0 {
                    consider(nl, nr + planars, false);
                }
                nl += starts + planars;
            }
        }
        best.0
    }

    /// Splits the node's events into the children's, both still sorted: events of primitives
    /// wholly on one side keep their order, straddling primitives get fresh clipped events
    /// that are sorted and merged in.
    fn partition(
        &mut self,
        events: &[u64],
        split: &Split,
        below: &Aabb,
        above: &Aabb,
    ) -> (Vec<u64>, Vec<u64>) {
        // Every primitive has a planar event or a start before its end on the split axis, so
        // one pass over that axis sets every side: a start left of the plane says both, until
        // an end at or left of the plane says left only.
        let (lo, hi) = axis_run(events, split.axis);
        for &e in &events[lo..hi] {
            let pos = ev_pos(e);
            let side = &mut self.side[ev_prim(e) as usize];
            match ev_kind(e) {
                START => *side = if pos >= split.pos { RIGHT } else { BOTH },
                END => {
                    if pos <= split.pos {
                        *side = LEFT;
                    }
                }
                _ => {
                    *side = if pos < split.pos || (pos == split.pos && split.planar_left) {
                        LEFT
                    } else {
                        RIGHT
                    }
                }
            }
        }

        // Sides are as good as random, so every event is written to both outputs and only the
        // cursor of its own side advances: no branch to mispredict.
        let mut left = vec![0u64; events.len()];
        let mut right = vec![0u64; events.len()];
        let (mut nl, mut nr) = (0, 0);
        for &e in events {
            let side = self.side[ev_prim(e) as usize];
            left[nl] = e;
            right[nr] = e;
            nl += usize::from(side == LEFT);
            nr += usize::from(side == RIGHT);
        }
        left.truncate(nl);
        right.truncate(nr);

        let mut new_left = Vec::new();
        let mut new_right = Vec::new();
        for k in node_prims(events) {
            if self.side[k as usize] != BOTH {
                continue;
            }
            let (bl, br) = self
                .ctx
                .clip_both(self.ids[k as usize], split, below, above);
            if !bl.is_empty() {
                push_events(&mut new_left, k, &bl);
            }
            if !br.is_empty() {
                push_events(&mut new_right, k, &br);
            }
        }
        new_left.sort_unstable();
        new_right.sort_unstable();
        (merge(left, &new_left), merge(right, &new_right))
    }
}

/// Clamps a requested depth to what the traversal stack holds.
pub(crate) fn clamp_depth(d: u32) -> u32 {
    d.min(MAX_DEPTH)
}

#[cfg(test)]
mod tests {
    use super::super::KdTree;
    use super::*;
    use glam::Vec3;

    /// Deterministic xorshift so that the unit tests need no dev-dependency.
    struct Rng(u64);
    impl Rng {
        fn f(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn v(&mut self) -> Vec3 {
            Vec3::new(self.f(), self.f(), self.f())
        }
    }

    fn random_boxes(n: usize, size: f32, seed: u64) -> Vec<Aabb> {
        let mut r = Rng(seed);
        (0..n)
            .map(|_| {
                let c = r.v() * 10.0;
                Aabb::new(c, c + r.v() * size)
            })
            .collect()
    }

    #[test]
    fn event_keys_round_trip_and_order() {
        for pos in [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            3.5e-30,
            -7.25e20,
            f32::MAX,
            -f32::MAX,
        ] {
            let e = event(2, pos, PLANAR, 12345);
            assert_eq!(ev_axis(e), 2);
            assert_eq!(ev_pos(e), pos);
            assert_eq!(ev_kind(e), PLANAR);
            assert_eq!(ev_prim(e), 12345);
        }
        assert_eq!(event(0, -0.0, END, 0), event(0, 0.0, END, 0));
        let sorted = [
            event(0, -2.0, START, 9),
            event(0, -1.0, END, 9),
            event(0, -1.0, PLANAR, 3),
            event(0, -1.0, START, 1),
            event(0, 0.0, END, 1),
            event(0, 1e-30, END, 0),
            event(1, -5.0, START, 0),
        ];
        assert!(sorted.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn bins_are_the_floor_of_the_offset_clamped() {
        let mut r = Rng(7);
        for _ in 0..100_000 {
            let x = r.f() * 40.0 - 4.0;
            let want = x.floor().clamp(0.0, (BINS - 1) as f32) as usize;
            let got = bins(Vec4::splat(x))[0];
            // Exactly on a boundary the bin below is allowed.
            let on_boundary = x == x.floor() && x > 0.0 && x < BINS as f32;
            assert!(
                got == want || (on_boundary && got + 1 == want),
                "{x}: bin {got}, floor {want}"
            );
        }
        assert_eq!(bins(Vec4::new(0.0, 31.999, 1e30, 0.0)), [0, 31, 31]);
        assert_eq!(bins(Vec4::new(-1e30, 0.49, 30.5, 0.0)), [0, 0, 30]);
    }

    #[test]
    fn merge_keeps_order() {
        let a = vec![1, 4, 6, 9];
        assert_eq!(merge(a, &[0, 5, 10]), vec![0, 1, 4, 5, 6, 9, 10]);
        assert_eq!(merge(vec![], &[2, 3]), vec![2, 3]);
    }

    /// Points of a primitive that lie in a cell must find the primitive in some leaf reached
    /// by descending to that point (either side when it is on a plane).
    fn leaves_at(tree: &KdTree, p: Vec3, node: usize, out: &mut Vec<Vec<u32>>) {
        let n = tree.nodes[node];
        if n.is_leaf() {
            out.push(tree.leaf(&tree.nodes[node]).prims.to_vec());
            return;
        }
        let (a, s) = (n.axis(), n.split());
        if p[a] <= s {
            leaves_at(tree, p, node + 1, out);
        }
        if p[a] >= s {
            leaves_at(tree, p, n.above() as usize, out);
        }
    }

    fn check_covered(tree: &KdTree, prim: u32, p: Vec3) {
        let mut found = Vec::new();
        leaves_at(tree, p, 0, &mut found);
        assert!(
            found.iter().any(|l| l.contains(&prim)),
            "primitive {prim} missing from the leaves at {p}"
        );
    }

    fn check_structure(tree: &KdTree, boxes: &[Aabb]) {
        let s = tree.stats();
        assert_eq!(s.nodes, 2 * s.leaves - 1, "a full binary tree");
        assert!(s.prim_refs >= boxes.len());
        let mut r = Rng(99);
        for (i, b) in boxes.iter().enumerate() {
            for _ in 0..4 {
                check_covered(tree, i as u32, b.min + r.v() * b.diagonal());
            }
            check_covered(tree, i as u32, b.min);
            check_covered(tree, i as u32, b.max);
        }
    }

    #[test]
    fn random_boxes_are_covered() {
        let boxes = random_boxes(2000, 0.6, 7);
        let tree = KdTree::build(&boxes, &KdParams::default());
        check_structure(&tree, &boxes);
        let s = tree.stats();
        assert_eq!(s.primitives, 2000);
        assert!(s.leaves > 200, "{s:?}");
        assert!(
            s.mean_leaf_prims >= 1.0 && s.mean_leaf_prims < 10.0,
            "{s:?}"
        );
        assert!(s.max_depth <= KdParams::default().depth_limit(2000));
        assert!(s.build_seconds >= 0.0);
    }

    #[test]
    fn aligned_runs_change_only_the_offsets() {
        // Parallel levels included: fragments appended to one another must keep alignment.
        let boxes = random_boxes(20_000, 0.3, 23);
        let leaves = |t: &KdTree| -> Vec<Vec<u32>> {
            let mut v = Vec::new();
            for i in 0..t.nodes.len() {
                if t.nodes[i].is_leaf() {
                    v.push(t.leaf(&t.nodes[i]).prims.to_vec());
                }
            }
            v
        };
        let tight = KdTree::build(&boxes, &KdParams::default());
        for align in [4, 8] {
            let params = KdParams {
                run_align: align,
                ..KdParams::default()
            };
            let tree = KdTree::build(&boxes, &params);
            assert_eq!(leaves(&tree), leaves(&tight));
            assert_eq!(tree.index_len() % align as usize, 0);
            let mut runs = 0;
            for (at, prims) in tree.runs() {
                assert_eq!(at % align, 0, "run at {at}");
                assert!(prims.len() > 1);
                runs += 1;
            }
            let multi = leaves(&tight).iter().filter(|l| l.len() > 1).count();
            assert!(runs == multi && runs > 100, "{runs} runs, {multi} leaves");
        }
    }

    #[test]
    fn binned_builds_cover_every_primitive() {
        let boxes = random_boxes(20_000, 0.3, 17);
        for binned_above in [8, 64, 4096] {
            let params = KdParams {
                binned_above,
                ..KdParams::default()
            };
            let tree = KdTree::build(&boxes, &params);
            check_structure(&tree, &boxes);
            assert!(tree.stats().max_depth <= params.depth_limit(boxes.len()));
        }
        // Clipped straddlers in the binned levels.
        let mut r = Rng(78);
        let segs = Segments(
            (0..6000)
                .map(|_| {
                    let a = r.v() * 10.0;
                    (a, a + (r.v() - 0.5) * 3.0)
                })
                .collect(),
        );
        let tree = KdTree::build(
            &segs,
            &KdParams {
                binned_above: 32,
                ..KdParams::default()
            },
        );
        for (i, &(a, b)) in segs.0.iter().enumerate() {
            for k in 0..=8 {
                check_covered(&tree, i as u32, a.lerp(b, k as f32 / 8.0));
            }
        }
    }

    #[test]
    fn tree_is_the_same_on_one_and_two_threads() {
        let boxes = random_boxes(40_000, 0.2, 23);
        let params = KdParams {
            binned_above: 256,
            ..KdParams::default()
        };
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| KdTree::build(&boxes, &params))
        };
        let (one, two) = (on(1), on(2));
        assert!(one.stats().nodes > 10_000);
        assert_eq!(one.raw(), two.raw());
        assert_eq!(one.bounds(), two.bounds());
        let strip = |t: &KdTree| KdStats {
            build_seconds: 0.0,
            ..t.stats().clone()
        };
        assert_eq!(strip(&one), strip(&two));
    }

    #[test]
    fn depth_limit_is_honoured() {
        let boxes = random_boxes(3000, 0.2, 3);
        for limit in [0, 1, 3, 6] {
            let params = KdParams {
                max_depth: Some(limit),
                ..KdParams::default()
            };
            let tree = KdTree::build(&boxes, &params);
            assert!(tree.stats().max_depth <= limit);
            check_structure(&tree, &boxes);
        }
        let tree = KdTree::build(
            &boxes,
            &KdParams {
                max_depth: Some(0),
                ..KdParams::default()
            },
        );
        assert_eq!(tree.stats().nodes, 1);
        assert_eq!(tree.stats().prim_refs, 3000);
        let huge = KdParams {
            max_depth: Some(1000),
            ..KdParams::default()
        };
        assert_eq!(huge.depth_limit(10), MAX_DEPTH);
    }

    #[test]
    fn default_depth_limit_follows_formula() {
        let p = KdParams::default();
        assert_eq!(p.depth_limit(0), 8);
        assert_eq!(p.depth_limit(1), 8);
        assert_eq!(p.depth_limit(1024), 21); // 8 + 13
        assert_eq!(p.depth_limit(1 << 20), 34); // 8 + 26
    }

    #[test]
    fn max_leaf_prims_stops_early() {
        let boxes = random_boxes(500, 0.3, 11);
        let params = KdParams {
            max_leaf_prims: 600,
            ..KdParams::default()
        };
        assert_eq!(KdTree::build(&boxes, &params).stats().nodes, 1);
    }

    #[test]
    fn identical_boxes_make_one_leaf() {
        let boxes = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 50];
        let tree = KdTree::build(&boxes, &KdParams::default());
        assert_eq!(tree.stats().nodes, 1);
        assert_eq!(tree.stats().prim_refs, 50);
    }

    #[test]
    fn empty_space_is_cut_off() {
        // A tight cluster in one corner of a large box: the bonus should carve empty leaves.
        let mut boxes = random_boxes(200, 0.05, 5)
            .into_iter()
            .map(|b| Aabb::new(b.min * 0.1, b.max * 0.1))
            .collect::<Vec<_>>();
        boxes.push(Aabb::new(Vec3::splat(9.0), Vec3::splat(10.0)));
        let tree = KdTree::build(&boxes, &KdParams::default());
        assert!(tree.stats().empty_leaves > 0);
        check_structure(&tree, &boxes);
    }

    #[test]
    fn planar_boxes_split_and_stay_covered() {
        // Rectangles in a few shared planes of every orientation, plus flat cells.
        let mut r = Rng(21);
        let mut boxes = Vec::new();
        for i in 0..600 {
            let axis = i % 3;
            let mut lo = r.v() * 10.0;
            let mut hi = lo + r.v() * 2.0;
            let plane = (r.f() * 5.0).floor() * 2.0;
            lo[axis] = plane;
            hi[axis] = plane;
            boxes.push(Aabb::new(lo, hi));
        }
        let tree = KdTree::build(&boxes, &KdParams::default());
        check_structure(&tree, &boxes);
        assert!(tree.stats().leaves > 50);

        // All primitives in one plane: the root cell itself is flat.
        let flat: Vec<Aabb> = (0..300)
            .map(|i| {
                let x = (i % 20) as f32;
                let y = (i / 20) as f32;
                Aabb::new(Vec3::new(x, y, 1.0), Vec3::new(x + 0.5, y + 0.5, 1.0))
            })
            .collect();
        let tree = KdTree::build(&flat, &KdParams::default());
        check_structure(&tree, &flat);
        assert!(tree.stats().leaves > 100);
        assert!(tree.bounds().min.z == 1.0 && tree.bounds().max.z == 1.0);
    }

    #[test]
    fn unusable_boxes_are_skipped() {
        let mut boxes = random_boxes(10, 1.0, 1);
        boxes.push(Aabb::EMPTY);
        boxes.push(Aabb::new(Vec3::ZERO, Vec3::new(f32::INFINITY, 1.0, 1.0)));
        boxes.push(Aabb {
            min: Vec3::splat(f32::NAN),
            max: Vec3::ONE,
        });
        let tree = KdTree::build(&boxes, &KdParams::default());
        assert_eq!(tree.stats().primitives, 13);
        assert_eq!(tree.stats().skipped, 3);
        assert!(tree.bounds().max.is_finite());
        check_structure(&tree, &boxes[..10]);
    }

    /// Thin diagonal segments whose clipped bounds are far tighter than box ∩ cell, and can be
    /// empty on one side of a straddled plane.
    struct Segments(Vec<(Vec3, Vec3)>);

    impl KdPrimitives for Segments {
        fn len(&self) -> usize {
            self.0.len()
        }
        fn bounds(&self, i: u32) -> Aabb {
            let (a, b) = self.0[i as usize];
            Aabb::new(a, b)
        }
        fn clipped_bounds(&self, i: u32, node: &Aabb) -> Aabb {
            // Liang–Barsky: the parameter range of the segment inside the cell.
            let (a, b) = self.0[i as usize];
            let d = b - a;
            let (mut t0, mut t1) = (0.0f32, 1.0f32);
            for k in 0..3 {
                if d[k] == 0.0 {
                    if a[k] < node.min[k] || a[k] > node.max[k] {
                        return Aabb::EMPTY;
                    }
                    continue;
                }
                let (mut n, mut f) = ((node.min[k] - a[k]) / d[k], (node.max[k] - a[k]) / d[k]);
                if n > f {
                    std::mem::swap(&mut n, &mut f);
                }
                t0 = t0.max(n);
                t1 = t1.min(f);
            }
            if t0 > t1 {
                return Aabb::EMPTY;
            }
            // Round outwards by the cell-independent box so the clip never loses a sliver.
            Aabb::new(a + d * t0, a + d * t1)
                .padded(1e-6, 1e-6)
                .intersection(&self.bounds(i))
        }
    }

    #[test]
    fn custom_clipping_is_used_and_covers() {
        let mut r = Rng(77);
        let segs = Segments(
            (0..1500)
                .map(|_| {
                    let a = r.v() * 10.0;
                    (a, a + (r.v() - 0.5) * 3.0)
                })
                .collect(),
        );
        let clipped = KdTree::build(&segs, &KdParams::default());
        let boxes: Vec<Aabb> = (0..segs.len() as u32).map(|i| segs.bounds(i)).collect();
        let plain = KdTree::build(&boxes, &KdParams::default());
        // Tighter clipped events mean fewer duplicated references.
        assert!(
            clipped.stats().prim_refs < plain.stats().prim_refs,
            "{:?} vs {:?}",
            clipped.stats(),
            plain.stats()
        );
        for (i, &(a, b)) in segs.0.iter().enumerate() {
            for k in 0..=8 {
                check_covered(&clipped, i as u32, a.lerp(b, k as f32 / 8.0));
            }
        }
    }
}
