//! SAH kd-tree over primitive bounding boxes.
//!
//! **Build** (Wald & Havran 2006, "On building fast kd-trees for ray tracing, and on doing that
//! in O(N log N)"). Each primitive gives, per axis, a start and an end event at its box faces,
//! or one planar event where the box is flat. All events are sorted once. In each node one
//! sweep over its sorted events counts the primitives left of, in and right of every candidate
//! plane and prices the plane with the surface area heuristic (planar primitives go to the
//! cheaper side; a side with volume but no primitives earns pbrt's empty-space bonus). The
//! node becomes a leaf when no plane beats intersecting everything, at the depth limit, or at
//! `max_leaf_prims`. Otherwise the primitives are classified left, right or both; events of
//! one-sided primitives keep their order, straddlers get fresh events from
//! [`KdPrimitives::clipped_bounds`] that are sorted and merged in, so no child is re-sorted
//! and the whole build stays O(N log N).
//!
//! Nodes of more than [`KdParams::binned_above`] references take a cheaper path: each
//! reference is its primitive's bounds clipped to the node; per axis their faces are counted
//! into 32 bins and the planes between bins are priced, together with the two planes through
//! the extreme faces (which cut empty space as exactly as the sweep). Nodes of six
//! references or fewer price every face of every box exactly. Straddlers are clipped to both
//! children; children of large nodes are built with `rayon::join` and joined in a fixed order,
//! so the tree does not depend on the thread count.
//!
//! **Layout** (as in pbrt). Nodes are 8 bytes in one depth-first array: an interior node holds
//! the split position and, beside the axis in two low bits, the index of its above child; its
//! below child is the next node. A leaf holds its primitive count and either its only primitive
//! or an offset into the primitive index array. Those runs can be made to start at multiples
//! of [`KdParams::run_align`], so that a caller may keep per-primitive data beside the index
//! array in aligned blocks and test a leaf's primitives together ([`KdTree::closest_hit_leaves`]).
//!
//! **Traversal** clips the ray to the tree bounds, then walks front to back with a fixed stack
//! of far children; a closest-hit query stops once its best hit lies before the current leaf's
//! far end. A ray lying in a split plane visits both children, so boxes touching the plane
//! from either side are seen.

mod build;
mod node;
mod packet;
mod traverse;

use crate::geometry::Aabb;
use node::KdNode;
use std::time::Instant;

pub use build::MAX_PRIMS;

/// Deepest tree the traversal stack can walk; deeper requested limits are clamped to this.
pub const MAX_DEPTH: u32 = 64;

/// Largest tree [`KdParams::select_walk`] applies to. The select walk loads both children at
/// every step; once the nodes outgrow the L2 cache the extra loads miss and the branches win
/// again. Against obvhs on 100k rays, half leaving the surface and half arriving from outside,
/// the full bunny's tree (35,613 nodes) ran at 1.23x with selects and 1.14x with branches
/// (medians of three runs), the dragon's (188,093 nodes) at 1.35x and 1.46x (of seven). The
/// limit lies between the two.
pub const SELECT_WALK_MAX_NODES: usize = 1 << 16;

/// Cost model and limits of the build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdParams {
    /// Cost of one traversal step.
    pub traversal_cost: f32,
    /// Cost of one ray–primitive test, in the same unit.
    pub intersect_cost: f32,
    /// Fraction of a split's cost forgiven when one side is empty space.
    pub empty_bonus: f32,
    /// Nodes with at most this many primitives become leaves.
    pub max_leaf_prims: u32,
    /// Depth limit; `None` picks 8 + `depth_per_doubling` · log2(N). Clamped to [`MAX_DEPTH`].
    pub max_depth: Option<u32>,
    /// Levels the automatic depth limit grows by each time N doubles (pbrt: 1.3).
    pub depth_per_doubling: f32,
    /// Nodes with more primitive references than this pick their split from binned counts
    /// (and build their children in parallel when large); smaller ones sweep exact events.
    pub binned_above: usize,
    /// Leaf runs of two or more primitives start at multiples of this in the index array
    /// (padded with the run's last primitive), so that data a caller lays out beside that
    /// array can be read in aligned blocks ([`KdTree::runs`]). 1 packs runs tightly.
    pub run_align: u32,
    /// Walk oblique rays with selects instead of branches at each node, on trees of at most
    /// [`SELECT_WALK_MAX_NODES`] nodes: faster for the incoherent rays that reach a mesh,
    /// slower where branches are predicted well (camera rays, and the scene-level tree over a
    /// few large shapes). Mesh trees use it.
    pub select_walk: bool,
}

impl Default for KdParams {
    fn default() -> Self {
        Self {
            traversal_cost: 1.0,
            // Measured, a watertight triangle test costs 3–4 node steps; but on meshes the
            // depth limit, not this ratio, shapes the tree: on the bunnies values from 1 to 40
            // gave trees of the same ray speed, so it stays where it was.
            intersect_cost: 20.0,
            empty_bonus: 0.5,
            max_leaf_prims: 1,
            max_depth: None,
            depth_per_doubling: 1.3,
            binned_above: 4096,
            run_align: 1,
            select_walk: false,
        }
    }
}

impl KdParams {
    /// The depth limit a build over `n` primitives uses.
    pub fn depth_limit(&self, n: usize) -> u32 {
        let d = self.max_depth.unwrap_or_else(|| {
            (8.0 + f64::from(self.depth_per_doubling) * (n.max(1) as f64).log2()).round() as u32
        });
        build::clamp_depth(d)
    }
}

/// What the builder needs to know of the primitives: it knows boxes, never shapes.
pub trait KdPrimitives: Sync {
    /// Number of primitives; indices run over `0..len()`.
    fn len(&self) -> usize;

    /// Whether there are no primitives.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Must hold every point the primitive's intersection can report, rounding included
    /// (see [`Aabb::padded`]): rays only reach the cells they pass through. Empty or non-finite
    /// bounds leave the primitive out of the tree.
    fn bounds(&self, i: u32) -> Aabb;

    /// Bounds of the part of primitive i inside `node` (perfect splits clip triangles here
    /// later); default: bounds ∩ node. An empty box says the primitive misses the node.
    fn clipped_bounds(&self, i: u32, node: &Aabb) -> Aabb {
        self.bounds(i).intersection(node)
    }

    /// [`KdPrimitives::clipped_bounds`] for both children of `node` split at `pos` on `axis`
    /// (below, above); an implementation may clip to the node once and split the result.
    fn split_bounds(&self, i: u32, node: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
        let (mut below, mut above) = (*node, *node);
        below.max[axis] = pos;
        above.min[axis] = pos;
        (
            self.clipped_bounds(i, &below),
            self.clipped_bounds(i, &above),
        )
    }
}

impl KdPrimitives for [Aabb] {
    fn len(&self) -> usize {
        <[Aabb]>::len(self)
    }

    fn bounds(&self, i: u32) -> Aabb {
        self[i as usize]
    }
}

impl KdPrimitives for Vec<Aabb> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        self[i as usize]
    }
}

/// Figures of a finished build.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KdStats {
    /// Primitives handed to the build.
    pub primitives: usize,
    /// Of those, left out because their bounds were empty or not finite.
    pub skipped: usize,
    /// Nodes in the tree, interior and leaf.
    pub nodes: usize,
    /// Leaf nodes, empty ones included.
    pub leaves: usize,
    /// Leaves holding no primitive.
    pub empty_leaves: usize,
    /// Depth of the deepest leaf (the root is at depth 0).
    pub max_depth: u32,
    /// Mean primitive count of the non-empty leaves.
    pub mean_leaf_prims: f32,
    /// Primitive references over all leaves (a straddling primitive counts once per leaf).
    pub prim_refs: usize,
    /// Wall-clock time of the build, seconds.
    pub build_seconds: f64,
}

impl std::fmt::Display for KdStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} prims ({} skipped), {} nodes, {} leaves ({} empty), depth {}, {:.2} prims/leaf, \
             {} refs, {:.3} s",
            self.primitives,
            self.skipped,
            self.nodes,
            self.leaves,
            self.empty_leaves,
            self.max_depth,
            self.mean_leaf_prims,
            self.prim_refs,
            self.build_seconds
        )
    }
}

/// A kd-tree over primitive indices; intersection is left to the caller's callbacks.
#[derive(Clone, Debug)]
pub struct KdTree {
    nodes: Vec<KdNode>,
    indices: Vec<u32>,
    bounds: Aabb,
    stats: KdStats,
    select_walk: bool,
}

impl KdTree {
    /// Builds a tree over `prims` with `params`.
    pub fn build<P: KdPrimitives + ?Sized>(prims: &P, params: &KdParams) -> KdTree {
        let start = Instant::now();
        let built = build::build(prims, params);
        let mut stats = built.stats;
        stats.build_seconds = start.elapsed().as_secs_f64();
        let select_walk = params.select_walk && built.nodes.len() <= SELECT_WALK_MAX_NODES;
        KdTree {
            nodes: built.nodes,
            indices: built.indices,
            bounds: built.bounds,
            stats,
            select_walk,
        }
    }

    /// Whether oblique rays walk this tree with selects ([`KdParams::select_walk`], within
    /// [`SELECT_WALK_MAX_NODES`]).
    pub fn select_walk(&self) -> bool {
        self.select_walk
    }

    /// Union of the bounds of the primitives in the tree (`Aabb::EMPTY` when there are none).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Figures of the build that made this tree.
    pub fn stats(&self) -> &KdStats {
        &self.stats
    }

    /// Expected cost of a random ray through the root box under `params`' cost model: each
    /// node's traversal or intersection cost weighted by its cell's surface area over the
    /// root's. Compares the quality of trees over the same primitives.
    pub fn sah_cost(&self, params: &KdParams) -> f64 {
        if self.nodes.is_empty() {
            return 0.0;
        }
        let root = f64::from(self.bounds.surface_area());
        if root <= 0.0 {
            return 0.0;
        }
        let mut total = 0.0;
        let mut stack = vec![(0usize, self.bounds)];
        while let Some((i, cell)) = stack.pop() {
            let n = self.nodes[i];
            let w = f64::from(cell.surface_area()) / root;
            if n.is_leaf() {
                total += w * f64::from(params.intersect_cost) * f64::from(n.prim_count());
                continue;
            }
            total += w * f64::from(params.traversal_cost);
            let (mut below, mut above) = (cell, cell);
            below.max[n.axis()] = n.split();
            above.min[n.axis()] = n.split();
            stack.push((i + 1, below));
            stack.push((n.above() as usize, above));
        }
        total
    }

    /// The nodes' packed words and the primitive index array, to compare trees exactly.
    pub fn raw(&self) -> (Vec<[u32; 2]>, &[u32]) {
        (
            self.nodes.iter().map(|n| n.words()).collect(),
            &self.indices,
        )
    }

    /// A non-empty leaf node, which must be one of `self.nodes`, as the walk hands it out.
    #[inline]
    fn leaf<'a>(&'a self, leaf: &'a KdNode) -> Leaf<'a> {
        match leaf.prim_count() {
            0 => Leaf {
                prims: &[],
                run: None,
            },
            1 => Leaf {
                prims: std::slice::from_ref(leaf.payload()),
                run: None,
            },
            n => {
                let at = *leaf.payload() as usize;
                Leaf {
                    prims: &self.indices[at..at + n as usize],
                    run: Some(at as u32),
                }
            }
        }
    }

    /// Every leaf of two or more primitives, as its run's offset in the index array and its
    /// primitives; offsets are multiples of [`KdParams::run_align`].
    pub fn runs(&self) -> impl Iterator<Item = (u32, &[u32])> + '_ {
        self.nodes
            .iter()
            .filter(|n| n.is_leaf() && n.prim_count() > 1)
            .map(|n| {
                let at = *n.payload();
                (
                    at,
                    &self.indices[at as usize..(at + n.prim_count()) as usize],
                )
            })
    }

    /// Length of the index array: data laid out beside it ([`KdTree::runs`]) needs this many
    /// slots.
    pub fn index_len(&self) -> usize {
        self.indices.len()
    }
}

/// A non-empty leaf as a walk hands it to the caller.
#[derive(Clone, Copy, Debug)]
pub struct Leaf<'a> {
    /// Indices of the leaf's primitives.
    pub prims: &'a [u32],
    /// Where the leaf's run starts in the index array ([`KdTree::runs`]); `None` for a leaf
    /// of one primitive, which the node holds itself.
    pub run: Option<u32>,
}
