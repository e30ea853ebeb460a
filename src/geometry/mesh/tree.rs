//! The mesh's kd-tree with its leaf blocks, and the walks that answer the mesh's queries
//! through it.

use super::clip::TriBoxes;
use super::watertight::{BLOCK, RayFrame, TriBlock};
use super::{MeshHit, TriangleMesh};
use crate::geometry::Ray;
use crate::kdtree::{KdParams, KdTree, Leaf};
use crate::simd::{Float, LaneKernel};
use glam::Vec3;

/// A mesh's kd-tree with its leaf blocks.
pub struct MeshTree {
    /// The kd-tree over the mesh's triangles.
    pub tree: KdTree,
    /// The triangles of the tree's leaf runs, sixteen to a block, laid out beside its index
    /// array.
    pub blocks: Vec<TriBlock>,
}

/// The tree and its blocks; runs are aligned to the blocks whatever `params.run_align` says.
pub(super) fn build_mesh_tree(tris: &[[Vec3; 3]], params: &KdParams) -> MeshTree {
    let params = KdParams {
        run_align: BLOCK as u32,
        ..*params
    };
    let tree = KdTree::build(&TriBoxes(tris), &params);
    let mut blocks = vec![TriBlock::default(); tree.index_len().div_ceil(BLOCK)];
    for (at, prims) in tree.runs() {
        for (k, &p) in prims.iter().enumerate() {
            let slot = at as usize + k;
            let block = &mut blocks[slot / BLOCK].c;
            for (j, v) in tris[p as usize].iter().enumerate() {
                for a in 0..3 {
                    block[j][a][slot % BLOCK] = v[a];
                }
            }
        }
    }
    MeshTree { tree, blocks }
}

/// A mesh query run inside the entry point of a lane type's instruction set: (any hit,
/// closest hit), whichever was asked.
pub(super) struct MeshQuery<'a> {
    pub(super) mesh: &'a TriangleMesh,
    pub(super) ray: &'a Ray,
    pub(super) t_max: f32,
    pub(super) any: bool,
}

impl LaneKernel for MeshQuery<'_> {
    type Output = (bool, Option<MeshHit>);

    #[inline(always)]
    fn run<F: Float>(self) -> Self::Output {
        if self.any {
            (self.mesh.occluded_screened::<F>(self.ray, self.t_max), None)
        } else {
            (
                false,
                self.mesh.intersect_screened::<F>(self.ray, self.t_max),
            )
        }
    }
}

// The walks behind `intersect`, `occluded` and their lane forms.
impl TriangleMesh {
    #[inline(always)]
    pub(super) fn intersect_screened<F: Float>(&self, ray: &Ray, t_max: f32) -> Option<MeshHit> {
        // Built at the first triangle: most rays that reach a mesh's box in a scene miss the
        // mesh without testing one, and the frame's setup branches on the ray's direction.
        // The walk itself never starts for a non-finite ray, so the frame's own check of the
        // ray (a zero direction) is left to that point too.
        let mut frame = None;
        let mut best = None;
        // The closures always inline: out of line they would be compiled without the entry
        // point's instructions.
        self.tree.closest_hit_leaves(
            ray,
            t_max,
            #[inline(always)]
            |leaf, mut limit| {
                let frame = frame.get_or_insert_with(|| RayFrame::new(ray)).as_ref()?;
                let mut found = None;
                self.leaf_candidates::<F>(
                    frame,
                    leaf,
                    #[inline(always)]
                    |i, tri| {
                        if let Some((t, b1, b2)) = frame.hit(tri, limit) {
                            limit = t;
                            found = Some(t);
                            best = Some(MeshHit { t, tri: i, b1, b2 });
                        }
                        false
                    },
                );
                found
            },
        );
        best
    }

    #[inline(always)]
    pub(super) fn occluded_screened<F: Float>(&self, ray: &Ray, t_max: f32) -> bool {
        let mut frame = None;
        self.tree.any_hit_leaves(
            ray,
            t_max,
            #[inline(always)]
            |leaf, limit| {
                let Some(frame) = frame.get_or_insert_with(|| RayFrame::new(ray)) else {
                    return false;
                };
                self.leaf_candidates::<F>(
                    frame,
                    leaf,
                    #[inline(always)]
                    |_, tri| frame.hit(tri, limit).is_some(),
                )
            },
        )
    }

    /// Calls `f(triangle, corners)` in order for the triangles of a leaf that the ray may hit,
    /// until it returns true (and then returns true). The triangles of a run are screened
    /// several at a time by the first half of the watertight test, which computes exactly what
    /// [`RayFrame::hit`] computes, so it only skips triangles that `hit` would miss too.
    #[inline(always)]
    fn leaf_candidates<F: Float>(
        &self,
        frame: &RayFrame,
        leaf: Leaf<'_>,
        mut f: impl FnMut(u32, &[Vec3; 3]) -> bool,
    ) -> bool {
        let Some(run) = leaf.run else {
            return leaf.prims.iter().any(|&i| f(i, &self.tris[i as usize]));
        };
        let first = run as usize / BLOCK;
        let n = leaf.prims.len();
        let blocks = &self.blocks[first..first + n.div_ceil(BLOCK)];
        for (b, block) in blocks.iter().enumerate() {
            let lanes = (n - BLOCK * b).min(BLOCK);
            let mut mask = frame.screen::<F>(block, lanes);
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if f(leaf.prims[BLOCK * b + lane], &block.corners(lane)) {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mesh::icosphere;

    #[test]
    fn degenerate_rays_meet_nothing() {
        let (p, f) = icosphere(2);
        let mesh = TriangleMesh::new(p, f, None, None).unwrap();
        let inside = Vec3::new(0.1, 0.2, 0.05);
        // The same origin with a good direction hits the sphere around it.
        assert!(
            mesh.intersect(&Ray::new(inside, Vec3::X), f32::INFINITY)
                .is_some()
        );
        let nan = f32::NAN;
        for ray in [
            Ray::new(inside, Vec3::ZERO),
            Ray::new(inside, Vec3::new(nan, 0.0, 1.0)),
            Ray::new(inside, Vec3::new(f32::INFINITY, 1.0, 1.0)),
            Ray::new(Vec3::new(nan, 0.0, 0.0), Vec3::X),
            Ray::new(Vec3::new(f32::NEG_INFINITY, 0.0, 0.0), Vec3::X),
            // Axis-parallel, with a non-finite origin: the general walk's path.
            Ray::new(Vec3::new(0.0, nan, 0.0), Vec3::X),
        ] {
            assert!(mesh.intersect(&ray, f32::INFINITY).is_none(), "{ray:?}");
            assert!(!mesh.occluded(&ray, f32::INFINITY), "{ray:?}");
        }
    }

    #[test]
    fn the_select_walk_finds_the_same_hits() {
        // Rays leaving the surface, crossing it from inside and passing it from outside: the
        // two oblique walks offer the same non-empty leaves in the same order (only the select
        // walk also steps into empty ones), so every answer agrees.
        let (p, f) = icosphere(4);
        let walk = |select_walk| {
            let params = KdParams {
                select_walk,
                ..TriangleMesh::kd_params()
            };
            TriangleMesh::with_params(p.clone(), f.clone(), None, None, &params).unwrap()
        };
        let (branches, selects) = (walk(false), walk(true));
        let (mut hits, mut occluded) = (0, 0);
        for i in 0..20_000u32 {
            let u = |k: u32| ((i.wrapping_mul(2_654_435_761) >> k) % 10_007) as f32 / 10_007.0;
            let o = Vec3::new(u(0), u(5), u(11)) * 3.0 - Vec3::splat(1.5);
            let ray = Ray::new(o, Vec3::new(u(3), u(7), u(13)) - Vec3::splat(0.5));
            let want = branches.intersect(&ray, f32::INFINITY);
            assert_eq!(selects.intersect(&ray, f32::INFINITY), want, "{ray:?}");
            let brute = branches.intersect_brute_force(&ray, f32::INFINITY);
            assert_eq!(want.map(|h| h.t), brute.map(|h| h.t), "{ray:?}");
            let shadow = branches.occluded(&ray, 0.5);
            assert_eq!(selects.occluded(&ray, 0.5), shadow, "{ray:?}");
            hits += usize::from(want.is_some());
            occluded += usize::from(shadow);
        }
        // Origins inside the sphere (15.5 % of the cube, about 3,100) all hit it.
        assert!(
            hits > 3_000 && occluded > 500,
            "{hits} hits, {occluded} occluded"
        );
    }
}
