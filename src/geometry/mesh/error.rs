//! Why a mesh could not be built or loaded, and the figures of one that was.

use crate::kdtree::KdStats;
use std::fmt;
use std::path::{Path, PathBuf};

/// Why a mesh could not be built or loaded. Every variant names the file when there is one,
/// and the line when the format has lines to count.
#[derive(Debug)]
pub enum MeshError {
    /// The file could not be opened or read.
    Io {
        /// The mesh file.
        path: PathBuf,
        /// Why reading it failed.
        source: std::io::Error,
    },
    /// The extension names no format this build reads.
    Unsupported {
        /// The file with the unknown extension.
        path: PathBuf,
    },
    /// The file breaks its format.
    Malformed {
        /// The mesh file.
        path: PathBuf,
        /// The line (counted from 1), where the format has lines.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// A face refers to a vertex the mesh does not have.
    IndexOutOfRange {
        /// The mesh file, if the mesh came from one.
        path: Option<PathBuf>,
        /// The line (counted from 1), where the format has lines.
        line: Option<usize>,
        /// The face (in file order) or triangle (in `TriangleMesh::new`'s input).
        face: Option<usize>,
        /// The index as read (OBJ's may be negative).
        index: i64,
        /// How many vertices the mesh has.
        vertices: usize,
    },
    /// A vertex position is NaN or infinite.
    NonFinite {
        /// The mesh file, if the mesh came from one.
        path: Option<PathBuf>,
        /// The line (counted from 1), where the format has lines.
        line: Option<usize>,
        /// The vertex's index.
        vertex: usize,
    },
    /// A per-vertex attribute array does not match the positions.
    AttributeCount {
        /// The mesh file, if the mesh came from one.
        path: Option<PathBuf>,
        /// The attribute: "normals" or "uvs".
        what: &'static str,
        /// The vertex count.
        expected: usize,
        /// The attribute's count.
        got: usize,
    },
    /// No triangle is left once degenerate ones are dropped.
    Empty {
        /// The mesh file, if the mesh came from one.
        path: Option<PathBuf>,
        /// Degenerate triangles dropped.
        dropped: usize,
    },
    /// More triangles or vertices than the tree or the u32 indices can address.
    TooLarge {
        /// The mesh file, if the mesh came from one.
        path: Option<PathBuf>,
        /// "vertices" or "triangles".
        what: &'static str,
        /// How many the mesh has.
        count: usize,
        /// The most that are supported.
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
    /// Vertices of the input.
    pub vertices: usize,
    /// Triangles kept (after dropping degenerate ones).
    pub triangles: usize,
    /// Zero-area triangles (repeated index, coincident or collinear vertices) left out.
    pub degenerate_dropped: usize,
    /// Whether the vertex normals were computed because the input had none.
    pub normals_computed: bool,
    /// Input normals that were zero or not finite and were replaced by computed ones.
    pub normals_repaired: usize,
    /// Whether the input had per-vertex UVs.
    pub has_uvs: bool,
    /// Distinct vertex positions: vertices split only for their normals or UVs count once.
    pub welded_vertices: usize,
    /// Every edge shared by exactly two triangles with opposite directions.
    pub closed: bool,
    /// Whole construction: validation, normals, topology and tree.
    pub build_seconds: f64,
    /// Figures of the mesh's kd-tree.
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
