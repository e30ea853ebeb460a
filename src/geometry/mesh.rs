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
//! **Leaves.** The tree's runs of two or more triangles start at multiples of four in its
//! index array, and beside that array the mesh keeps their vertices in blocks of four, one
//! SSE lane per triangle (`Tri4`). A leaf is screened a block at a time by the first half of
//! the watertight test (shear and edge functions, the same operations in the same order, so
//! the same roundings), with no branch per triangle; only the triangles it cannot reject take
//! the whole scalar test. Screening is most of a leaf's cost for incoherent rays, whose
//! per-triangle branches the predictor cannot learn.
//!
//! **Shading data.** Vertex normals come from the file; missing or unusable ones are computed
//! from the adjacent faces, each weighted by its angle at the vertex (Thürmer & Wüthrich 1998).
//! Plain averaging would tilt a normal towards whichever side happens to be cut into more
//! triangles; the angle weight gives the same normal however the surface is tessellated.
//! Vertices at the same position count as one for computed normals and for closedness: files
//! split vertices at UV seams (and OBJ groups), and neither may show in the shading.

use super::{Aabb, Ray};
use crate::kdtree::{KdParams, KdPrimitives, KdStats, KdTree, Leaf, MAX_PRIMS};
use crate::simd::{Float, LaneKernel, Mask};
use glam::{DVec3, Vec2, Vec3, Vec4};
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Relative bounds padding: covers the rounding of the f64 clip converted back to f32, so
/// the tree never culls a point the exact triangle has.
const PAD_REL: f32 = 8.0 * f32::EPSILON;

/// Most vertices a clipped triangle can have: 3, plus one per clipping plane for a convex
/// polygon. Rounding can in principle make more; the clip then falls back to box bounds.
const CLIP_CAP: usize = 12;

/// pbrt's γ(n) = n u / (1 − n u), u the unit roundoff of f32.
#[inline]
const fn gamma(n: f32) -> f32 {
    let u = f32::EPSILON * 0.5;
    n * u / (1.0 - n * u)
}

/// Why a mesh could not be built or loaded. Every variant names the file when there is one,
/// and the line when the format has lines to count.
#[derive(Debug)]
pub enum MeshError {
    /// The file could not be opened or read.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The extension names no format this build reads.
    Unsupported { path: PathBuf },
    /// The file breaks its format.
    Malformed {
        path: PathBuf,
        line: Option<usize>,
        message: String,
    },
    /// A face refers to a vertex the mesh does not have.
    IndexOutOfRange {
        path: Option<PathBuf>,
        line: Option<usize>,
        /// The face (in file order) or triangle (in `TriangleMesh::new`'s input).
        face: Option<usize>,
        index: i64,
        vertices: usize,
    },
    /// A vertex position is NaN or infinite.
    NonFinite {
        path: Option<PathBuf>,
        line: Option<usize>,
        vertex: usize,
    },
    /// A per-vertex attribute array does not match the positions.
    AttributeCount {
        path: Option<PathBuf>,
        what: &'static str,
        expected: usize,
        got: usize,
    },
    /// No triangle is left once degenerate ones are dropped.
    Empty {
        path: Option<PathBuf>,
        dropped: usize,
    },
    /// More triangles or vertices than the tree or the u32 indices can address.
    TooLarge {
        path: Option<PathBuf>,
        what: &'static str,
        count: usize,
        limit: usize,
    },
}

impl MeshError {
    /// Attaches the file an error of `TriangleMesh::new` came from (kept if one is set).
    pub fn in_file(mut self, file: &Path) -> Self {
        match &mut self {
            MeshError::IndexOutOfRange { path, .. }
            | MeshError::NonFinite { path, .. }
            | MeshError::AttributeCount { path, .. }
            | MeshError::Empty { path, .. }
            | MeshError::TooLarge { path, .. } => {
                if path.is_none() {
                    *path = Some(file.to_path_buf());
                }
            }
            MeshError::Io { .. } | MeshError::Unsupported { .. } | MeshError::Malformed { .. } => {}
        }
        self
    }

    /// The file the error is about, if any.
    pub fn path(&self) -> Option<&Path> {
        match self {
            MeshError::Io { path, .. }
            | MeshError::Unsupported { path }
            | MeshError::Malformed { path, .. } => Some(path),
            MeshError::IndexOutOfRange { path, .. }
            | MeshError::NonFinite { path, .. }
            | MeshError::AttributeCount { path, .. }
            | MeshError::Empty { path, .. }
            | MeshError::TooLarge { path, .. } => path.as_deref(),
        }
    }

    /// The line the error is on, if the format has lines and it is known.
    pub fn line(&self) -> Option<usize> {
        match self {
            MeshError::Malformed { line, .. }
            | MeshError::IndexOutOfRange { line, .. }
            | MeshError::NonFinite { line, .. } => *line,
            _ => None,
        }
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // "file:line: message", as compilers print it, so editors can jump there.
        match (self.path(), self.line()) {
            (Some(p), Some(l)) => write!(f, "{}:{l}: ", p.display())?,
            (Some(p), None) => write!(f, "{}: ", p.display())?,
            (None, _) => write!(f, "mesh: ")?,
        }
        match self {
            MeshError::Io { source, .. } => write!(f, "cannot read mesh file: {source}"),
            MeshError::Unsupported { .. } => write!(
                f,
                "unsupported mesh format (expected a .obj or .ply file; compressed .ply.gz is \
                 not read)"
            ),
            MeshError::Malformed { message, .. } => write!(f, "malformed mesh file: {message}"),
            MeshError::IndexOutOfRange {
                face,
                index,
                vertices,
                ..
            } => {
                match face {
                    Some(i) => write!(f, "face {i} refers to vertex {index}")?,
                    None => write!(f, "a face refers to vertex {index}")?,
                }
                write!(f, ", but the mesh has {vertices} vertices")
            }
            MeshError::NonFinite { vertex, .. } => {
                write!(f, "vertex {vertex} has a NaN or infinite coordinate")
            }
            MeshError::AttributeCount {
                what,
                expected,
                got,
                ..
            } => write!(f, "{got} {what} for {expected} vertices"),
            MeshError::Empty { dropped, .. } => write!(
                f,
                "mesh has no triangles ({dropped} degenerate ones were dropped)"
            ),
            MeshError::TooLarge {
                what, count, limit, ..
            } => write!(f, "{count} {what}; at most {limit} are supported"),
        }
    }
}

impl std::error::Error for MeshError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            MeshError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Figures of a built mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshStats {
    pub vertices: usize,
    /// Triangles kept (after dropping degenerate ones).
    pub triangles: usize,
    /// Zero-area triangles (repeated index, coincident or collinear vertices) left out.
    pub degenerate_dropped: usize,
    /// Whether the vertex normals were computed because the input had none.
    pub normals_computed: bool,
    /// Input normals that were zero or not finite and were replaced by computed ones.
    pub normals_repaired: usize,
    pub has_uvs: bool,
    /// Distinct vertex positions: vertices split only for their normals or UVs count once.
    pub welded_vertices: usize,
    /// Every edge shared by exactly two triangles with opposite directions.
    pub closed: bool,
    /// Whole construction: validation, normals, topology and tree.
    pub build_seconds: f64,
    pub tree: KdStats,
}

impl fmt::Display for MeshStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} vertices ({} distinct positions), {} triangles ({} degenerate dropped), \
             normals {}, {}uvs, {}, {:.3} s; tree: {}",
            self.vertices,
            self.welded_vertices,
            self.triangles,
            self.degenerate_dropped,
            if self.normals_computed {
                "computed".to_string()
            } else if self.normals_repaired > 0 {
                format!("from input ({} repaired)", self.normals_repaired)
            } else {
                "from input".to_string()
            },
            if self.has_uvs { "" } else { "no " },
            if self.closed { "closed" } else { "open" },
            self.build_seconds,
            self.tree
        )
    }
}

/// A ray–mesh hit: distance and barycentric coordinates of vertices 1 and 2 (vertex 0 has
/// `1 − b1 − b2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshHit {
    pub t: f32,
    pub tri: u32,
    pub b1: f32,
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
    pub uv: Vec2,
    pub dpdu: Vec3,
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
            // Leaves are screened four triangles at a time, so a leaf of ~18 costs little
            // more than one of ~8: at 8 + 0.8 log2(N) instead of 8 + log2(N) the full bunny's
            // tree has a third of the nodes, builds in 0.6x the time and traces diffuse rays
            // faster (and at pbrt's 8 + 1.3 log2(N) it had five times the nodes again).
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

    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

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

    #[inline(always)]
    fn intersect_screened<F: Float>(&self, ray: &Ray, t_max: f32) -> Option<MeshHit> {
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
    fn occluded_screened<F: Float>(&self, ray: &Ray, t_max: f32) -> bool {
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

/// ∂p/∂u and ∂p/∂v of the plane through the triangle (pbrt's formulation), or a frame
/// around `ng` when the UVs do not span the triangle (repeated or collinear UVs).
fn uv_derivatives(p: [Vec3; 3], uv: [Vec2; 3], ng: Vec3) -> (Vec3, Vec3) {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det.abs() > 1e-12 {
        let inv = 1.0 / det;
        let dpdu = (duv12.y * dp02 - duv02.y * dp12) * inv;
        let dpdv = (duv02.x * dp12 - duv12.x * dp02) * inv;
        let c = dpdu.cross(dpdv);
        if c.is_finite() && c.length_squared() > 0.0 {
            return (dpdu, dpdv);
        }
    }
    let (t, b) = crate::sampling::coordinate_system(ng);
    // Keep dpdu × dpdv along ng, as a valid UV mapping of this winding would.
    if t.cross(b).dot(ng) < 0.0 {
        (b, t)
    } else {
        (t, b)
    }
}

/// `(v1 − v0) × (v2 − v0)` in f64: exact enough to tell zero area from tiny area.
#[inline]
fn tri_normal_f64(t: &[Vec3; 3]) -> DVec3 {
    let p0 = t[0].as_dvec3();
    (t[1].as_dvec3() - p0).cross(t[2].as_dvec3() - p0)
}

/// Zero area: a repeated index, coincident positions or collinear vertices.
fn is_degenerate(positions: &[Vec3], tri: [u32; 3]) -> bool {
    if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
        return true;
    }
    let t = tri.map(|i| positions[i as usize]);
    let n = tri_normal_f64(&t);
    // Products of f32 differences are exact in f64 unless the exponents are far apart, so a
    // zero here is a true zero (or an area no f32 ray test could resolve anyway).
    n == DVec3::ZERO || !n.is_finite()
}

/// One id per distinct position (bit-equal, with −0 = +0), so that vertices split only for
/// their attributes share normals and edges. Returns the id of each vertex and the count.
fn weld_positions(positions: &[Vec3]) -> (Vec<u32>, usize) {
    let key = |p: Vec3| -> (u32, u32, u32) {
        let b = |x: f32| (x + 0.0).to_bits();
        (b(p.x), b(p.y), b(p.z))
    };
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.sort_unstable_by_key(|&i| key(positions[i as usize]));
    let mut weld = vec![0u32; positions.len()];
    let mut next = 0u32;
    for (k, &i) in order.iter().enumerate() {
        if k > 0 && key(positions[order[k - 1] as usize]) != key(positions[i as usize]) {
            next += 1;
        }
        weld[i as usize] = next;
    }
    let count = if positions.is_empty() {
        0
    } else {
        next as usize + 1
    };
    (weld, count)
}

/// Unit vertex normals: the input's where usable, elsewhere the angle-weighted mean of the
/// face normals around the vertex's position. Returns them with the number repaired.
fn vertex_normals(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    weld: &[u32],
    input: Option<Vec<Vec3>>,
) -> (Vec<Vec3>, usize) {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    let given = input.is_some();
    let mut missing = 0usize;
    match input {
        Some(input) => {
            for (n, g) in normals.iter_mut().zip(input) {
                match g.try_normalize() {
                    Some(u) => *n = u,
                    None => missing += 1,
                }
            }
        }
        None => missing = positions.len(),
    }
    if missing == 0 {
        return (normals, 0);
    }

    let groups = weld.iter().max().map_or(0, |&m| m as usize + 1);
    let mut sum = vec![DVec3::ZERO; groups];
    for tri in indices {
        let p = tri.map(|i| positions[i as usize].as_dvec3());
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let n = n / n.length();
        for k in 0..3 {
            let e1 = p[(k + 1) % 3] - p[k];
            let e2 = p[(k + 2) % 3] - p[k];
            // atan2 of |cross| and dot stays accurate for angles near 0 and π, unlike acos.
            let angle = e1.cross(e2).length().atan2(e1.dot(e2));
            sum[weld[tri[k] as usize] as usize] += angle * n;
        }
    }
    for (i, n) in normals.iter_mut().enumerate() {
        if *n == Vec3::ZERO {
            // A vertex no kept triangle uses, or where the faces cancel, stays zero: shading
            // then falls back to the geometric normal.
            *n = sum[weld[i] as usize]
                .try_normalize()
                .map_or(Vec3::ZERO, |d| d.as_vec3().normalize_or_zero());
        }
    }
    (normals, if given { missing } else { 0 })
}

/// Closed and consistently oriented: every directed edge occurs once and its reverse occurs
/// too, so each edge has exactly two triangles traversing it in opposite directions.
fn is_closed_surface(indices: &[[u32; 3]], weld: &[u32]) -> bool {
    let mut edges: Vec<u64> = Vec::with_capacity(indices.len() * 3);
    for tri in indices {
        for k in 0..3 {
            let a = weld[tri[k] as usize] as u64;
            let b = weld[tri[(k + 1) % 3] as usize] as u64;
            edges.push(a << 32 | b);
        }
    }
    edges.sort_unstable();
    if edges.windows(2).any(|w| w[0] == w[1]) {
        return false;
    }
    // Rotating by 32 swaps the halves: the reverse edge.
    edges
        .iter()
        .all(|&e| edges.binary_search(&e.rotate_right(32)).is_ok())
}

/// Sixteen triangles of a leaf run, component-major: `c[corner][axis][lane]`, so that the
/// shear and the edge functions of the watertight test run on a lane type's width of them at
/// once (16 in one AVX-512 register; a typical leaf of ~10 triangles fits in one block).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct TriBlock {
    c: [[[f32; BLOCK]; 3]; 3],
}

impl Default for TriBlock {
    fn default() -> Self {
        Self {
            c: [[[0.0; BLOCK]; 3]; 3],
        }
    }
}

impl TriBlock {
    #[inline]
    fn corners(&self, lane: usize) -> [Vec3; 3] {
        let corner = |[x, y, z]: &[[f32; BLOCK]; 3]| Vec3::new(x[lane], y[lane], z[lane]);
        [corner(&self.c[0]), corner(&self.c[1]), corner(&self.c[2])]
    }
}

/// A mesh's kd-tree with its leaf blocks.
pub struct MeshTree {
    pub tree: KdTree,
    pub blocks: Vec<TriBlock>,
}

/// Triangles per leaf block: [`KdParams::run_align`] of mesh trees.
const BLOCK: usize = 16;

/// The tree and its blocks; runs are aligned to the blocks whatever `params.run_align` says.
fn build_mesh_tree(tris: &[[Vec3; 3]], params: &KdParams) -> MeshTree {
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
struct MeshQuery<'a> {
    mesh: &'a TriangleMesh,
    ray: &'a Ray,
    t_max: f32,
    any: bool,
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

/// The constants of the watertight test for one ray: the translation to its origin and the
/// permute-and-shear rows that carry the direction onto +z (Woop et al. 2013). Public so that
/// other acceleration structures can be measured with the same triangle test.
#[derive(Clone, Copy, Debug)]
pub struct RayFrame {
    /// The axes that become x, y and z: z is the direction's largest component.
    k: [usize; 3],
    /// The origin's components along `k`.
    o: [f32; 3],
    /// Shear: `x' = p[kx] − Sx p[kz]`, `y' = p[ky] − Sy p[kz]`, `z' = Sz p[kz]`, with `p`
    /// relative to the origin; reading the vertices' components through `k` costs nothing
    /// more than loading them.
    sx: f32,
    sy: f32,
    sz: f32,
    /// |d[kz]|: turns the sheared z (a distance along the ray in units of t) back into the
    /// length unit of x and y for the error bounds.
    dz: f32,
}

impl RayFrame {
    /// `None` for a ray with a zero or non-finite direction or a non-finite origin.
    #[inline]
    pub fn new(ray: &Ray) -> Option<Self> {
        let usable = ray.d.is_finite() && ray.o.is_finite() && ray.d != Vec3::ZERO;
        usable.then(|| Self::build(ray))
    }

    /// The frame of a ray that [`RayFrame::new`] accepts.
    #[inline]
    fn build(ray: &Ray) -> Self {
        let d = ray.d.to_array();
        let o = ray.o.to_array();
        let a = ray.d.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        // Swapping x and y for a negative z keeps the triangles' winding, and so the sign
        // convention of the edge functions, the same for every ray.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            k: [kx, ky, kz],
            o: [o[kx], o[ky], o[kz]],
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
            dz: d[kz].abs(),
        }
    }

    /// A vertex relative to the origin, permuted and sheared: (x', y', z before scaling).
    #[inline]
    fn shear(&self, v: &Vec3) -> (f32, f32, f32) {
        let v: &[f32; 3] = v.as_ref();
        let [kx, ky, kz] = self.k;
        let z = v[kz] - self.o[2];
        (
            v[kx] - self.o[0] - self.sx * z,
            v[ky] - self.o[1] - self.sy * z,
            z,
        )
    }

    /// Bit per lane of the first `n` of the block: set where the triangle may be hit, clear
    /// where the edge functions have mixed signs (all nonzero), which [`RayFrame::hit`]
    /// rejects. Lane for lane the same operations as `hit`, so the same roundings. Width 1
    /// screens four at a time in SSE registers.
    #[inline(always)]
    fn screen<F: Float>(&self, b: &TriBlock, n: usize) -> u32 {
        let mut bits = 0;
        let mut at = 0;
        while at < n {
            bits |= if F::WIDTH == 1 {
                self.screen4(b, at)
            } else {
                self.screen_lanes::<F>(b, at)
            } << at;
            at += F::WIDTH.max(4);
        }
        // Padding lanes (all-zero triangles) pass the screen; they are not the leaf's.
        bits & (u32::MAX >> (32 - n))
    }

    /// The screen of lanes `at..at + F::WIDTH`.
    #[inline(always)]
    fn screen_lanes<F: Float>(&self, b: &TriBlock, at: usize) -> u32 {
        // Clamped so the compiler sees the rows are in range (they are: k permutes 0..3).
        let (kx, ky, kz) = (self.k[0].min(2), self.k[1].min(2), self.k[2].min(2));
        let (ox, oy, oz) = (
            F::splat(self.o[0]),
            F::splat(self.o[1]),
            F::splat(self.o[2]),
        );
        let (sx, sy) = (F::splat(self.sx), F::splat(self.sy));
        let load = |c: &[[f32; BLOCK]; 3], axis: usize| F::load(&c[axis][at..]);
        // No closures or array maps over lane values here: those were left uninlined.
        let (ax, ay) = {
            let z = load(&b.c[0], kz) - oz;
            (
                load(&b.c[0], kx) - ox - sx * z,
                load(&b.c[0], ky) - oy - sy * z,
            )
        };
        let (bx, by) = {
            let z = load(&b.c[1], kz) - oz;
            (
                load(&b.c[1], kx) - ox - sx * z,
                load(&b.c[1], ky) - oy - sy * z,
            )
        };
        let (cx, cy) = {
            let z = load(&b.c[2], kz) - oz;
            (
                load(&b.c[2], kx) - ox - sx * z,
                load(&b.c[2], ky) - oy - sy * z,
            )
        };
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = F::zero();
        let is_zero = u.eq(zero) | v.eq(zero) | w.eq(zero);
        let neg = u.lt(zero) | v.lt(zero) | w.lt(zero);
        let pos = u.gt(zero) | v.gt(zero) | w.gt(zero);
        (is_zero | !(neg & pos)).bits()
    }

    /// The screen of lanes `at..at + 4` in SSE registers.
    #[inline(always)]
    fn screen4(&self, b: &TriBlock, at: usize) -> u32 {
        let (kx, ky, kz) = (self.k[0].min(2), self.k[1].min(2), self.k[2].min(2));
        let (ox, oy, oz) = (
            Vec4::splat(self.o[0]),
            Vec4::splat(self.o[1]),
            Vec4::splat(self.o[2]),
        );
        let (sx, sy) = (Vec4::splat(self.sx), Vec4::splat(self.sy));
        let shear = |c: &[[f32; BLOCK]; 3]| {
            let get = |axis: usize| Vec4::from_slice(&c[axis][at..at + 4]);
            let z = get(kz) - oz;
            (get(kx) - ox - sx * z, get(ky) - oy - sy * z)
        };
        let (ax, ay) = shear(&b.c[0]);
        let (bx, by) = shear(&b.c[1]);
        let (cx, cy) = shear(&b.c[2]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = u.cmpeq(Vec4::ZERO) | v.cmpeq(Vec4::ZERO) | w.cmpeq(Vec4::ZERO);
        let neg = u.cmplt(Vec4::ZERO) | v.cmplt(Vec4::ZERO) | w.cmplt(Vec4::ZERO);
        let pos = u.cmpgt(Vec4::ZERO) | v.cmpgt(Vec4::ZERO) | w.cmpgt(Vec4::ZERO);
        (zero | !(neg & pos)).bitmask()
    }

    /// `(t, b1, b2)` of a hit with `t` in (0, t_max).
    #[inline]
    pub fn hit(&self, tri: &[Vec3; 3], t_max: f32) -> Option<(f32, f32, f32)> {
        let (ax, ay, az) = self.shear(&tri[0]);
        let (bx, by, bz) = self.shear(&tri[1]);
        let (cx, cy, cz) = self.shear(&tri[2]);

        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // On an edge to f32 precision: the f64 products are exact, so the sign is right
            // and both triangles of the edge agree on it.
            let e = |px: f32, py: f32, qx: f32, qy: f32| {
                (f64::from(px) * f64::from(qy) - f64::from(py) * f64::from(qx)) as f32
            };
            u = e(cx, cy, bx, by);
            v = e(ax, ay, cx, cy);
            w = e(bx, by, ax, ay);
        }
        // Both orientations count (no back-face culling); a mix of signs is a miss.
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }

        let (az, bz, cz) = (self.sz * az, self.sz * bz, self.sz * cz);
        let t_scaled = u * az + v * bz + w * cz;
        // The range test before dividing, with det's sign folded in.
        if det < 0.0 {
            if t_scaled >= 0.0 || t_scaled < t_max * det {
                return None;
            }
        } else if t_scaled <= 0.0 || t_scaled > t_max * det {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        // NaN only from overflow in extreme coordinates: not a hit either.
        if t >= t_max || t.is_nan() {
            return None;
        }

        // Conservative: t must exceed the bound on its rounding error (pbrt-v3, 3.9.6), or
        // a hit at or just behind the origin could be reported in front of it. The x and y
        // bounds take z before the 1/d_z scaling (pbrt's form assumes |d| ≈ 1; for a short or
        // long direction the scaled z is in other units and the bound would reject real hits).
        let max_zt = az.abs().max(bz.abs()).max(cz.abs());
        let max_z_len = max_zt * self.dz;
        let max_xt = ax.abs().max(bx.abs()).max(cx.abs());
        let max_yt = ay.abs().max(by.abs()).max(cy.abs());
        let delta_z = gamma(3.0) * max_zt;
        let delta_x = gamma(5.0) * (max_xt + max_z_len);
        let delta_y = gamma(5.0) * (max_yt + max_z_len);
        let delta_e = 2.0 * (gamma(2.0) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t = 3.0
            * (gamma(3.0) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
            * inv_det.abs();
        if t <= delta_t {
            return None;
        }
        Some((t, v * inv_det, w * inv_det))
    }
}

/// The triangles as the kd-tree builder sees them: padded boxes, clipped for perfect splits.
struct TriBoxes<'a>(&'a [[Vec3; 3]]);

impl KdPrimitives for TriBoxes<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        Aabb::from_points(&self.0[i as usize]).padded(PAD_REL, 0.0)
    }

    fn clipped_bounds(&self, i: u32, node: &Aabb) -> Aabb {
        clip_triangle(&self.0[i as usize], node)
    }

    fn split_bounds(&self, i: u32, node: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
        split_triangle(&self.0[i as usize], node, axis, pos)
    }
}

/// The clipped bounds of a triangle in both children of `node` split at `pos`: one clip to
/// the node, then the polygon cut by the plane (half the work of two clips to the children).
/// Each side is as `clip_triangle` on that child: inclusive, against the child grown by the
/// pad, padded.
fn split_triangle(tri: &[Vec3; 3], node: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
    let child = |above: bool| {
        let mut c = *node;
        if above {
            c.min[axis] = pos;
        } else {
            c.max[axis] = pos;
        }
        c
    };
    let full = Aabb::from_points(tri);
    let pad = full.min.abs().max(full.max.abs()).max_element() * PAD_REL;
    let cell = Aabb {
        min: node.min - pad,
        max: node.max + pad,
    };
    let (lo, hi) = (f64::from(pos + pad), f64::from(pos - pad));
    let (below, above) = if full.min.cmpge(cell.min).all() && full.max.cmple(cell.max).all() {
        // Most straddlers lie inside the node but for the plane: the triangle is the polygon.
        split_polygon_bounds(&tri.map(Vec3::as_dvec3), axis, lo, hi)
    } else {
        let mut poly = [DVec3::ZERO; CLIP_CAP];
        let Some(n) = clip_to_cell(tri, &full, &cell, &mut poly) else {
            return (
                clip_triangle(tri, &child(false)),
                clip_triangle(tri, &child(true)),
            );
        };
        split_polygon_bounds(&poly[..n], axis, lo, hi)
    };
    let grow = |b: Aabb| {
        if b.is_empty() {
            Aabb::EMPTY
        } else {
            Aabb {
                min: b.min - pad,
                max: b.max + pad,
            }
        }
    };
    (grow(below), grow(above))
}

/// The bounds of the parts of a polygon with `x[axis] <= below` and with `x[axis] >= above`:
/// the boxes of what two Sutherland–Hodgman steps ([`clip_polygon`]) would keep, the same
/// points computed the same way, in one pass and without building either polygon.
fn split_polygon_bounds(poly: &[DVec3], axis: usize, below: f64, above: f64) -> (Aabb, Aabb) {
    let (mut lo, mut hi) = (Aabb::EMPTY, Aabb::EMPTY);
    let cross = |cur: DVec3, next: DVec3, bound: f64| {
        let s = (bound - cur[axis]) / (next[axis] - cur[axis]);
        let mut x = cur + (next - cur) * s;
        x[axis] = bound;
        x.as_vec3()
    };
    for k in 0..poly.len() {
        let cur = poly[k];
        let next = poly[(k + 1) % poly.len()];
        let (c, n) = (cur[axis], next[axis]);
        if c <= below {
            lo = lo.union_point(cur.as_vec3());
        }
        if (c <= below) != (n <= below) {
            lo = lo.union_point(cross(cur, next, below));
        }
        if c >= above {
            hi = hi.union_point(cur.as_vec3());
        }
        if (c >= above) != (n >= above) {
            hi = hi.union_point(cross(cur, next, above));
        }
    }
    (lo, hi)
}

/// Clips a triangle (with box `full`) to `cell` in f64 into `poly`: the vertex count, or
/// `None` when rounding made the polygon too complex.
fn clip_to_cell(
    tri: &[Vec3; 3],
    full: &Aabb,
    cell: &Aabb,
    poly: &mut [DVec3; CLIP_CAP],
) -> Option<usize> {
    let mut scratch = [DVec3::ZERO; CLIP_CAP];
    for (k, p) in tri.iter().enumerate() {
        poly[k] = p.as_dvec3();
    }
    let mut n = 3;
    for axis in 0..3 {
        for (bound, keep_above) in [(cell.min[axis], true), (cell.max[axis], false)] {
            // Planes the triangle lies wholly inside of need no clip (nor its rounding).
            let inside = if keep_above {
                full.min[axis] >= bound
            } else {
                full.max[axis] <= bound
            };
            if inside {
                continue;
            }
            n = clip_polygon(&poly[..n], &mut scratch, axis, f64::from(bound), keep_above)?;
            std::mem::swap(poly, &mut scratch);
            if n == 0 {
                return Some(0);
            }
        }
    }
    Some(n)
}

/// Bounds of the part of a triangle inside `node`, padded. The clip is inclusive and runs
/// against the node grown by the pad, so a triangle touching or grazing a cell face stays in
/// that cell: the traversal may then reach it from either side.
fn clip_triangle(tri: &[Vec3; 3], node: &Aabb) -> Aabb {
    let full = Aabb::from_points(tri);
    let pad = full.min.abs().max(full.max.abs()).max_element() * PAD_REL;
    let cell = Aabb {
        min: node.min - pad,
        max: node.max + pad,
    };
    let grow = |b: Aabb| Aabb {
        min: b.min - pad,
        max: b.max + pad,
    };
    if full.min.cmpge(cell.min).all() && full.max.cmple(cell.max).all() {
        return grow(full);
    }

    let mut poly = [DVec3::ZERO; CLIP_CAP];
    match clip_to_cell(tri, &full, &cell, &mut poly) {
        Some(n) => {
            let mut b = Aabb::EMPTY;
            for p in &poly[..n] {
                b = b.union_point(p.as_vec3());
            }
            // Nothing left inside: an empty box, not a padded point.
            if n == 0 { b } else { grow(b) }
        }
        // Rounding made the polygon too complex: the plain box is still conservative.
        None => grow(full.intersection(&cell)),
    }
}

/// One Sutherland–Hodgman step: the part of the polygon on the kept side of the plane
/// `x[axis] = bound` (points on the plane kept). Intersections are placed exactly on the
/// plane. `None` if the result would not fit.
fn clip_polygon(
    poly: &[DVec3],
    out: &mut [DVec3; CLIP_CAP],
    axis: usize,
    bound: f64,
    keep_above: bool,
) -> Option<usize> {
    let inside = |p: &DVec3| {
        if keep_above {
            p[axis] >= bound
        } else {
            p[axis] <= bound
        }
    };
    let mut m = 0;
    let mut push = |p: DVec3| {
        if m == CLIP_CAP {
            return false;
        }
        out[m] = p;
        m += 1;
        true
    };
    for k in 0..poly.len() {
        let cur = poly[k];
        let next = poly[(k + 1) % poly.len()];
        let (cin, nin) = (inside(&cur), inside(&next));
        if cin && !push(cur) {
            return None;
        }
        if cin != nin {
            let s = (bound - cur[axis]) / (next[axis] - cur[axis]);
            let mut x = cur + (next - cur) * s;
            x[axis] = bound;
            if !push(x) {
                return None;
            }
        }
    }
    Some(m)
}

/// A generated closed mesh for tests and benchmarks: an icosahedron subdivided `levels` times
/// (20·4^levels triangles), vertices on the unit sphere, faces wound outwards.
pub fn icosphere(levels: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut p: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(f.len() * 4);
        for &[a, b, c] in &f {
            let mut m = |i: u32, j: u32| {
                *mid.entry((i.min(j), i.max(j))).or_insert_with(|| {
                    p.push(((p[i as usize] + p[j as usize]) * 0.5).normalize());
                    p.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    for tri in &mut f {
        let [a, b, c] = tri.map(|i| p[i as usize]);
        if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
            tri.swap(1, 2);
        }
    }
    (p, f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_a_triangle_to_a_box() {
        let tri = [
            Vec3::ZERO,
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        ];
        // The corner cell [1,2]² holds the part of the triangle with x + y ≤ 4: all of it.
        let b = clip_triangle(
            &tri,
            &Aabb::new(Vec3::new(1.0, 1.0, -1.0), Vec3::splat(2.0)),
        );
        assert!(
            (b.min.x - 1.0).abs() < 1e-5 && (b.max.x - 2.0).abs() < 1e-5,
            "{b:?}"
        );
        // Beyond the hypotenuse: only the part with x + y ≤ 4 in [2,3]², i.e. up to (2,2).
        let b = clip_triangle(
            &tri,
            &Aabb::new(Vec3::new(2.0, 2.0, -1.0), Vec3::splat(3.0)),
        );
        assert!(b.max.x < 2.0 + 1e-5 && b.max.y < 2.0 + 1e-5, "{b:?}");
        // Entirely beyond it.
        let b = clip_triangle(
            &tri,
            &Aabb::new(Vec3::new(2.5, 2.5, -1.0), Vec3::splat(3.0)),
        );
        assert!(b.is_empty());
        // Clipping the far side off keeps the part under x = 1: the box [0,1]×[0,4].
        let b = clip_triangle(
            &tri,
            &Aabb::new(Vec3::splat(-1.0), Vec3::new(1.0, 5.0, 1.0)),
        );
        assert!(
            (b.max.x - 1.0).abs() < 1e-5 && (b.max.y - 4.0).abs() < 1e-5,
            "{b:?}"
        );
    }

    #[test]
    fn a_triangle_touching_a_cell_face_stays_in_the_cell() {
        let tri = [Vec3::X, Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0)];
        let b = clip_triangle(&tri, &Aabb::new(Vec3::new(0.0, -1.0, -1.0), Vec3::ONE));
        assert!(!b.is_empty());
        assert!(b.max.x >= 1.0 && b.max.x < 1.0 + 1e-5, "{b:?}");
    }

    #[test]
    fn block_screen_keeps_every_triangle_the_scalar_test_hits() {
        use crate::simd::PortableF32;
        use rand::{RngExt, SeedableRng};
        // Triangles of a small grid, so that rays aimed at its vertices and edge midpoints
        // make edge functions exactly zero, and random ones elsewhere; each block is screened
        // at every width and every lane checked against the scalar test.
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut rnd = |lo: f32, hi: f32| lo + (hi - lo) * rng.random::<f32>();
        let mut tris = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let p = |a: u32, b: u32| Vec3::new(a as f32, b as f32, 0.0);
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        while tris.len() < 64 {
            let mut v = || Vec3::new(rnd(-1.0, 5.0), rnd(-1.0, 5.0), rnd(-2.0, 2.0));
            tris.push([v(), v(), v()]);
        }
        let blocks: Vec<TriBlock> = tris
            .chunks(BLOCK)
            .map(|some| {
                let mut b = TriBlock::default();
                for (lane, t) in some.iter().enumerate() {
                    for (j, v) in t.iter().enumerate() {
                        for a in 0..3 {
                            b.c[j][a][lane] = v[a];
                        }
                    }
                }
                b
            })
            .collect();
        let (mut hits, mut rejected, mut lanes) = (0, 0, 0);
        for k in 0..4000 {
            let target = if k % 2 == 0 {
                // A grid vertex or an edge midpoint.
                let (a, b) = ((k / 2 % 9) as f32 * 0.5, (k / 18 % 9) as f32 * 0.5);
                Vec3::new(a, b, 0.0)
            } else {
                Vec3::new(rnd(-1.0, 5.0), rnd(-1.0, 5.0), rnd(-1.0, 1.0))
            };
            let o = Vec3::new(rnd(-3.0, 7.0), rnd(-3.0, 7.0), rnd(-4.0, 4.0));
            let ray = Ray::new(o, target - o);
            let Some(frame) = RayFrame::new(&ray) else {
                continue;
            };
            for (b, block) in blocks.iter().enumerate() {
                // Every width screens with the same roundings; a short run masks its padding.
                let n = 1 + (k + b) % BLOCK;
                let mask = frame.screen::<f32>(block, n);
                assert_eq!(frame.screen::<PortableF32<8>>(block, n), mask);
                assert_eq!(frame.screen::<PortableF32<16>>(block, n), mask);
                assert_eq!(mask >> n, 0, "padding lanes are never candidates");
                for lane in 0..n {
                    let tri = &tris[BLOCK * b + lane];
                    assert_eq!(block.corners(lane), *tri);
                    let hit = frame.hit(tri, f32::INFINITY);
                    lanes += 1;
                    hits += usize::from(hit.is_some());
                    if mask >> lane & 1 == 0 {
                        rejected += 1;
                        assert!(hit.is_none(), "{ray:?} lane {lane} of block {b}");
                    }
                }
            }
        }
        // The screen must do its job too: it rejects most of the misses.
        assert!(hits > 500, "{hits} hits");
        assert!(rejected > (lanes - hits) / 2, "{rejected} of {lanes}");
    }

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

    #[test]
    fn welding_and_closedness() {
        // A tetrahedron with one vertex duplicated (as a UV seam would do).
        let p = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            Vec3::Z, // copy of 3
        ];
        let (weld, n) = weld_positions(&p);
        assert_eq!(n, 4);
        assert_eq!(weld[3], weld[4]);
        let closed = [[0, 2, 1], [0, 1, 3], [1, 2, 4], [2, 0, 3]];
        assert!(is_closed_surface(&closed, &weld));
        // One face flipped: edges no longer pair up in opposite directions.
        let flipped = [[0, 1, 2], [0, 1, 3], [1, 2, 4], [2, 0, 3]];
        assert!(!is_closed_surface(&flipped, &weld));
        assert!(!is_closed_surface(&closed[..3], &weld));
    }
}
