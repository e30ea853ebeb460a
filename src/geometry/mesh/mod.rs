//! Triangle meshes in object space, each with its own kd-tree.
//!
//! **Storage.** The hot loop reads vertex positions copied out of the index buffer at
//! construction: per triangle (`tris`) for leaves of one triangle and for the whole test, and
//! in leaf blocks for screening (below). The indexed vertex data (positions, unit shading
//! normals, optional UVs) is read only for the winning hit.
//!
//! **Intersection** is the watertight test of Woop, Benthin and Wald (2013, "Watertight
//! Ray/Triangle Intersection", JCGT 2(1)). Per ray, the largest direction component becomes
//! z and a shear maps the direction onto +z; every vertex is translated, permuted and sheared
//! with those constants, so a vertex shared by two triangles lands on the same 2D point for
//! both. The 2D edge functions of neighbouring triangles are then evaluated on identical
//! inputs with opposite signs, so a ray through an edge or vertex cannot slip between them.
//! An edge function that rounds to exactly 0 is redone in f64, where the products are exact
//! and its sign is right. The hit distance must exceed its own rounding bound (pbrt's
//! conservative test), so a hit found "behind" the origin by rounding is never reported.
//!
//! **Tree.** A bottom-level SAH kd-tree with perfect splits: a triangle straddling a split
//! plane is clipped against each child's box (Sutherland–Hodgman) and enters the child with
//! the bounds of the clipped polygon, not of its whole box.
//!
//! **Leaves.** The tree's runs of two or more triangles start at multiples of sixteen in its
//! index array, and beside that array the mesh keeps their vertices in blocks of sixteen, one
//! lane per triangle (`TriBlock`). A leaf is screened at the render's lane width (one AVX-512
//! register, two AVX2, four SSE at width 1) by the first half of the watertight test (shear
//! and edge functions, the same operations in the same order, so the same roundings), with no
//! branch per triangle; only the triangles it cannot reject take the whole scalar test.
//! Screening is most of a leaf's cost for incoherent rays, whose per-triangle branches the
//! predictor cannot learn.
//!
//! **Shading data.** Vertex normals come from the file; missing or unusable ones are computed
//! from the adjacent faces, each weighted by its angle at the vertex (Thürmer & Wüthrich 1998).
//! Plain averaging would tilt a normal towards whichever side happens to be cut into more
//! triangles; the angle weight gives the same normal however the surface is tessellated.
//! Vertices at the same position count as one for computed normals and for closedness: files
//! split vertices at UV seams (and OBJ groups), and neither may show in the shading.

mod clip;
mod error;
mod icosphere;
mod normals;
mod tree;
mod watertight;

pub use error::{MeshError, MeshStats};
pub use icosphere::icosphere;
pub use tree::MeshTree;
pub use watertight::{RayFrame, TriBlock};

use super::{Aabb, Ray};
use crate::kdtree::{KdParams, KdTree, MAX_PRIMS};
use crate::simd::Float;
use glam::{Vec2, Vec3};
use normals::{
    is_closed_surface, is_degenerate, tri_normal_f64, uv_derivatives, vertex_normals,
    weld_positions,
};
use std::time::Instant;
use tree::{MeshQuery, build_mesh_tree};

/// A ray–mesh hit: distance and barycentric coordinates of vertices 1 and 2 (vertex 0 has
/// `1 − b1 − b2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshHit {
    /// Distance along the ray, in units of its direction's length.
    pub t: f32,
    /// The triangle: an index into [`TriangleMesh::indices`].
    pub tri: u32,
    /// Barycentric coordinate of vertex 1.
    pub b1: f32,
    /// Barycentric coordinate of vertex 2.
    pub b2: f32,
}

/// The surface at a hit, in object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSurface {
    /// Hit point from the barycentrics (more accurate than `o + t d`).
    pub p: Vec3,
    /// Unit geometric normal, oriented as `(v1 − v0) × (v2 − v0)`.
    pub ng: Vec3,
    /// Unit interpolated shading normal, on the same side as `ng`.
    pub ns: Vec3,
    /// Texture coordinates: the vertices' UVs interpolated, or the default parameterisation.
    pub uv: Vec2,
    /// ∂p/∂u in the triangle's plane.
    pub dpdu: Vec3,
    /// ∂p/∂v in the triangle's plane.
    pub dpdv: Vec3,
}

/// Parameterisation of a triangle without UVs (as pbrt): vertex 0, 1, 2 at (0,0), (1,0), (1,1).
const DEFAULT_UV: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::ONE];

/// Triangle mesh in object space, with its own kd-tree (built once; instances share it).
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    /// Vertex positions per triangle: what the intersection loop reads.
    tris: Vec<[Vec3; 3]>,
    indices: Vec<[u32; 3]>,
    positions: Vec<Vec3>,
    /// Unit shading normal per vertex (zero only where none could be computed).
    normals: Vec<Vec3>,
    /// Per-vertex UVs; a triangle with a non-finite corner uses `DEFAULT_UV`.
    uvs: Option<Vec<Vec2>>,
    tree: KdTree,
    /// The triangles of the tree's leaf runs, sixteen to a block, laid out beside its index
    /// array.
    blocks: Vec<TriBlock>,
    bounds: Aabb,
    area: f32,
    stats: MeshStats,
}

impl TriangleMesh {
    /// Builds a mesh: validates the input, drops degenerate triangles, fills in normals and
    /// builds the kd-tree. `normals` and `uvs`, when given, are per vertex. Normals need not
    /// be unit length; zero or non-finite ones are replaced by computed ones.
    pub fn new(
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
    ) -> Result<Self, MeshError> {
        Self::with_params(positions, indices, normals, uvs, &Self::kd_params())
    }

    /// The tree parameters `new` uses: the defaults with a smaller empty-space bonus, and
    /// binned splits in every node of more than six references.
    ///
    /// A closed surface leaves empty corners in every cell it passes through. With the default
    /// bonus (0.5) cutting off any sliver of empty space halves a split's cost, so the SAH keeps
    /// shaving corners instead of separating triangles and reaches the depth limit with ~10
    /// triangles per leaf on dense meshes. At 0.3 (measured with the depth limit then in use,
    /// 8 + 1.3 log2 N), a 330k-triangle sphere needed 6 instead of 26 triangle tests per ray,
    /// and on a 1.3M-triangle one camera rays ran twice as fast for a 1.8× longer build.
    pub fn kd_params() -> KdParams {
        KdParams {
            empty_bonus: 0.3,
            // On a dense mesh the SAH never makes a leaf by itself (each split still looks
            // cheaper), so the depth limit shapes the tree and each extra level doubles it.
            // Leaves are screened several triangles at a time, so a leaf of ~18 costs little
            // more than one of ~8: at 8 + 0.8 log2(N) instead of 8 + log2(N) the full bunny's
            // tree has a third of the nodes, builds in 0.6x the time and traces diffuse rays
            // faster (measured with blocks of four; at pbrt's 8 + 1.3 log2(N) it had five
            // times the nodes again).
            depth_per_doubling: 0.8,
            // Binned down to six references, then exact: the event sweep below 4096 made
            // the full bunny's build about 3x slower for a 1.7% lower SAH cost.
            binned_above: 0,
            // Most rays that reach a mesh's tree are incoherent. On the bunny in the Cornell
            // box the select walk took diffuse rays 10-19 % faster for camera rays 0-8 % slower,
            // whole renders within noise; on the scene-level tree, over a few large shapes,
            // the branches stay better.
            select_walk: true,
            ..KdParams::default()
        }
    }

    /// As [`TriangleMesh::new`], with the kd-tree's cost model and limits given.
    pub fn with_params(
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
        params: &KdParams,
    ) -> Result<Self, MeshError> {
        let start = Instant::now();
        let nv = positions.len();
        if nv > u32::MAX as usize {
            return Err(MeshError::TooLarge {
                path: None,
                what: "vertices",
                count: nv,
                limit: u32::MAX as usize,
            });
        }
        if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite {
                path: None,
                line: None,
                vertex,
            });
        }
        for (what, got) in [
            ("normals", normals.as_ref().map(Vec::len)),
            ("uvs", uvs.as_ref().map(Vec::len)),
        ] {
            if let Some(got) = got.filter(|&g| g != nv) {
                return Err(MeshError::AttributeCount {
                    path: None,
                    what,
                    expected: nv,
                    got,
                });
            }
        }

        let mut kept = Vec::with_capacity(indices.len());
        for (face, &tri) in indices.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= nv) {
                return Err(MeshError::IndexOutOfRange {
                    path: None,
                    line: None,
                    face: Some(face),
                    index: i64::from(bad),
                    vertices: nv,
                });
            }
            if !is_degenerate(&positions, tri) {
                kept.push(tri);
            }
        }
        let dropped = indices.len() - kept.len();
        drop(indices);
        if kept.is_empty() {
            return Err(MeshError::Empty {
                path: None,
                dropped,
            });
        }
        if kept.len() > MAX_PRIMS {
            return Err(MeshError::TooLarge {
                path: None,
                what: "triangles",
                count: kept.len(),
                limit: MAX_PRIMS,
            });
        }
        let indices = kept;

        let (weld, welded_vertices) = weld_positions(&positions);
        let normals_computed = normals.is_none();
        let (normals, normals_repaired) = vertex_normals(&positions, &indices, &weld, normals);
        let closed = is_closed_surface(&indices, &weld);

        let tris: Vec<[Vec3; 3]> = indices
            .iter()
            .map(|t| t.map(|i| positions[i as usize]))
            .collect();
        let area = tris.iter().map(|t| tri_normal_f64(t).length()).sum::<f64>() * 0.5;
        let bounds = tris
            .iter()
            .fold(Aabb::EMPTY, |b, t| b.union(&Aabb::from_points(t)));
        let MeshTree { tree, blocks } = build_mesh_tree(&tris, params);

        let stats = MeshStats {
            vertices: nv,
            triangles: tris.len(),
            degenerate_dropped: dropped,
            normals_computed,
            normals_repaired,
            has_uvs: uvs.is_some(),
            welded_vertices,
            closed,
            build_seconds: start.elapsed().as_secs_f64(),
            tree: tree.stats().clone(),
        };
        Ok(Self {
            tris,
            indices,
            positions,
            normals,
            uvs,
            tree,
            blocks,
            bounds,
            area: area as f32,
            stats,
        })
    }

    /// Exact bounds of the vertices (unpadded).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Figures of the build.
    pub fn stats(&self) -> &MeshStats {
        &self.stats
    }

    /// The mesh's kd-tree.
    pub fn tree(&self) -> &KdTree {
        &self.tree
    }

    /// Builds the mesh's kd-tree and leaf blocks again (with other parameters, or to time the
    /// build alone).
    pub fn build_tree(&self, params: &KdParams) -> MeshTree {
        build_mesh_tree(&self.tris, params)
    }

    /// Triangles kept (degenerate ones dropped).
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Vertex positions, as given.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Vertex indices of the kept triangles; `MeshHit::tri` indexes this.
    pub fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }

    /// Unit shading normal per vertex (from the input, or computed).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Per-vertex UVs, if the input had them.
    pub fn uvs(&self) -> Option<&[Vec2]> {
        self.uvs.as_deref()
    }

    /// The three vertex positions of triangle `tri`.
    pub fn triangle(&self, tri: u32) -> [Vec3; 3] {
        self.tris[tri as usize]
    }

    /// Total surface area.
    pub fn area(&self) -> f32 {
        self.area
    }

    /// Whether every edge is shared by exactly two triangles that traverse it in opposite
    /// directions: the mesh is closed and consistently oriented, so it has an inside.
    /// Vertices at the same position count as one, since files split vertices at UV seams.
    pub fn is_closed(&self) -> bool {
        self.stats.closed
    }

    /// Closest hit with `t` in (0, t_max).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<MeshHit> {
        self.intersect_screened::<f32>(ray, t_max)
    }

    /// Whether anything lies on the ray with `t` in (0, t_max).
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.occluded_screened::<f32>(ray, t_max)
    }

    /// [`TriangleMesh::intersect`] with leaf blocks screened `F::WIDTH` triangles at a time,
    /// the walk compiled for `F`'s instruction set. Every width finds the same hit: the screen
    /// only skips triangles that the scalar test would miss.
    #[inline]
    pub fn intersect_lanes<F: Float>(&self, ray: &Ray, t_max: f32) -> Option<MeshHit> {
        if F::WIDTH == 1 {
            return self.intersect_screened::<f32>(ray, t_max);
        }
        F::enter(MeshQuery {
            mesh: self,
            ray,
            t_max,
            any: false,
        })
        .1
    }

    /// [`TriangleMesh::occluded`] as [`TriangleMesh::intersect_lanes`] screens.
    #[inline]
    pub fn occluded_lanes<F: Float>(&self, ray: &Ray, t_max: f32) -> bool {
        if F::WIDTH == 1 {
            return self.occluded_screened::<f32>(ray, t_max);
        }
        F::enter(MeshQuery {
            mesh: self,
            ray,
            t_max,
            any: true,
        })
        .0
    }

    /// Closest hit by testing every triangle: the reference the tree is checked against.
    pub fn intersect_brute_force(&self, ray: &Ray, t_max: f32) -> Option<MeshHit> {
        let frame = RayFrame::new(ray)?;
        let mut best: Option<MeshHit> = None;
        for (i, tri) in self.tris.iter().enumerate() {
            let limit = best.map_or(t_max, |h| h.t);
            if let Some((t, b1, b2)) = frame.hit(tri, limit) {
                best = Some(MeshHit {
                    t,
                    tri: i as u32,
                    b1,
                    b2,
                });
            }
        }
        best
    }

    /// The one-triangle test the mesh queries use, for callers that pick triangles themselves.
    pub fn intersect_triangle(&self, tri: u32, ray: &Ray, t_max: f32) -> Option<MeshHit> {
        let (t, b1, b2) = RayFrame::new(ray)?.hit(&self.tris[tri as usize], t_max)?;
        Some(MeshHit { t, tri, b1, b2 })
    }

    /// Surface data at a hit (or at any barycentric point of a triangle).
    pub fn surface(&self, hit: &MeshHit) -> MeshSurface {
        let i = hit.tri as usize;
        let [p0, p1, p2] = self.tris[i];
        let [i0, i1, i2] = self.indices[i].map(|k| k as usize);
        let (b1, b2) = (hit.b1, hit.b2);
        let b0 = 1.0 - b1 - b2;
        let p = b0 * p0 + b1 * p1 + b2 * p2;
        // Degenerate triangles were dropped, so the f64 normal is never zero.
        let ng = tri_normal_f64(&self.tris[i]).normalize().as_vec3();

        let n = b0 * self.normals[i0] + b1 * self.normals[i1] + b2 * self.normals[i2];
        let mut ns = n.try_normalize().unwrap_or(ng);
        if ns.dot(ng) < 0.0 {
            ns = -ns;
        }

        let uv_corners = self
            .uvs
            .as_ref()
            .map(|uv| [uv[i0], uv[i1], uv[i2]])
            .filter(|c| c.iter().all(|u| u.is_finite()))
            .unwrap_or(DEFAULT_UV);
        let uv = b0 * uv_corners[0] + b1 * uv_corners[1] + b2 * uv_corners[2];
        let (dpdu, dpdv) = uv_derivatives([p0, p1, p2], uv_corners, ng);
        MeshSurface {
            p,
            ng,
            ns,
            uv,
            dpdu,
            dpdv,
        }
    }
}
