//! Loading triangle meshes from Wavefront OBJ and Stanford PLY files.
//!
//! OBJ goes through `tobj` with every group and object merged into one mesh, polygons
//! triangulated as fans and a single index per vertex, so that normals and UVs line up with
//! positions. `tobj` reports errors without a line, so on failure the file is scanned again
//! here to find the line at fault. PLY is read by a small reader of its own (ASCII and both
//! binary byte orders; `x y z`, optional `nx ny nz`, optional `u v` / `s t` /
//! `texture_u texture_v` / `texture_s texture_t`, faces as a `vertex_indices` or
//! `vertex_index` list, polygons as fans; other elements and properties are skipped).
//!
//! UVs are kept as the file stores them (OBJ's v axis points up). A vertex without a normal
//! or UV in a file that gives them elsewhere gets a NaN marker: its normal is computed and its
//! triangles fall back to the default parameterisation (see [`TriangleMesh::surface`]).

pub use super::mesh::MeshError;
use super::mesh::TriangleMesh;
use glam::{Vec2, Vec3};
use std::path::{Path, PathBuf};

/// The arrays a file holds, before `TriangleMesh::new` validates them and builds the tree.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions, object space.
    pub positions: Vec<Vec3>,
    /// Vertex indices of each triangle.
    pub indices: Vec<[u32; 3]>,
    /// Per-vertex normals, one per position, if the file has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, one per position, if the file has them.
    pub uvs: Option<Vec<Vec2>>,
}

impl MeshData {
    /// Builds the mesh; errors name `path`.
    pub fn build(self, path: &Path) -> Result<TriangleMesh, MeshError> {
        TriangleMesh::new(self.positions, self.indices, self.normals, self.uvs)
            .map_err(|e| e.in_file(path))
    }
}

/// Loads a mesh by the file's extension: `.obj` or `.ply` (either case).
pub fn load_mesh(path: &Path) -> Result<TriangleMesh, MeshError> {
    match Format::of(path)? {
        Format::Obj => load_obj(path),
        Format::Ply => read_ply(path)?.build(path),
    }
}

/// Reads a mesh file's arrays without building the mesh.
pub fn read_mesh(path: &Path) -> Result<MeshData, MeshError> {
    match Format::of(path)? {
        Format::Obj => read_obj(path).map(|(data, _)| data),
        Format::Ply => read_ply(path),
    }
}

enum Format {
    Obj,
    Ply,
}

impl Format {
    fn of(path: &Path) -> Result<Self, MeshError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => Ok(Format::Obj),
            Some("ply") => Ok(Format::Ply),
            _ => Err(MeshError::Unsupported {
                path: path.to_path_buf(),
            }),
        }
    }
}

fn read_file(path: &Path) -> Result<Vec<u8>, MeshError> {
    crate::files::read_bounded(path, crate::files::MAX_MESH_BYTES).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn malformed(path: &Path, line: Option<usize>, message: impl Into<String>) -> MeshError {
    MeshError::Malformed {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

// ---------------------------------------------------------------------------------------------
// OBJ

/// The memory a mesh (OBJ or PLY) may take while it loads: 16 GiB.
pub const MESH_MEMORY_BUDGET: u64 = 16 << 30;
/// Bytes per triangle while a mesh loads: the file's text, the parser's arrays, their
/// copy, the mesh's own (positions, normals, UVs, indices, welding) and its kd-tree. Measured
/// about 400 at the peak (a 2M-triangle grid: 802 MB resident); 512 leaves a margin.
const BYTES_PER_TRIANGLE: u64 = 512;
/// The most triangles a mesh may have: the kd-tree's limit and the memory budget (2²⁵).
pub const MAX_MESH_TRIANGLES: u64 = {
    let budget = MESH_MEMORY_BUDGET / BYTES_PER_TRIANGLE;
    let tree = crate::kdtree::MAX_PRIMS as u64;
    if budget < tree { budget } else { tree }
};

/// Refuses an OBJ text whose faces make more than `limit` triangles.
fn check_obj_triangles(path: &Path, text: &[u8], limit: u64) -> Result<(), MeshError> {
    let triangles = obj_triangles(text);
    if triangles > limit {
        return Err(MeshError::TooLarge {
            path: Some(path.to_path_buf()),
            what: "triangles in its faces (counted before loading; the limit is 16 GiB at \
                   512 bytes per triangle)",
            count: usize::try_from(triangles).unwrap_or(usize::MAX),
            limit: limit as usize,
        });
    }
    Ok(())
}

/// Triangles the faces of an OBJ text make: a face of k corners makes k − 2.
fn obj_triangles(text: &[u8]) -> u64 {
    text.split(|&b| b == b'\n')
        .map(|line| {
            let line = line.trim_ascii_start();
            match line {
                [b'f', b' ' | b'\t', rest @ ..] => {
                    let corners = rest
                        .split(|b| b.is_ascii_whitespace())
                        .filter(|t| !t.is_empty())
                        .count() as u64;
                    corners.saturating_sub(2)
                }
                _ => 0,
            }
        })
        .sum()
}

/// Loads an OBJ file (all groups and objects merged, polygons triangulated).
pub fn load_obj(path: &Path) -> Result<TriangleMesh, MeshError> {
    let (data, text) = read_obj(path)?;
    data.build(path).map_err(|e| match e {
        // Vertices were renumbered by the single-index pass: find the file's own vertex.
        MeshError::NonFinite { .. } => match first_non_finite_vertex(&text) {
            Some((line, vertex)) => MeshError::NonFinite {
                path: Some(path.to_path_buf()),
                line: Some(line),
                vertex,
            },
            None => e,
        },
        e => e,
    })
}

/// The arrays of an OBJ file, and its bytes for locating later errors.
fn read_obj(path: &Path) -> Result<(MeshData, Vec<u8>), MeshError> {
    let text = read_file(path)?;
    // An OBJ file declares no counts: its faces are counted before the parser allocates for
    // them, and a file that would need more triangles than the kd-tree holds, or more memory
    // than the budget, is refused.
    check_obj_triangles(path, &text, MAX_MESH_TRIANGLES)?;
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are not the mesh's business: the loader never opens an .mtl file.
    let loaded = tobj::load_obj_buf(&mut &text[..], &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let models = match loaded {
        Ok((models, _materials)) => models,
        Err(err) => return Err(locate_obj_error(path, &text, err)),
    };

    let mut data = MeshData::default();
    let any_normals = models.iter().any(|m| !m.mesh.normals.is_empty());
    let any_uvs = models.iter().any(|m| !m.mesh.texcoords.is_empty());
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for m in &models {
        let mesh = &m.mesh;
        let n = mesh.positions.len() / 3;
        let base = data.positions.len();
        let too_many = || MeshError::TooLarge {
            path: Some(path.to_path_buf()),
            what: "vertices",
            count: base + n,
            limit: u32::MAX as usize,
        };
        let offset = u32::try_from(base).map_err(|_| too_many())?;
        u32::try_from(base + n).map_err(|_| too_many())?;
        data.positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        data.indices.extend(
            mesh.indices
                .chunks_exact(3)
                .map(|c| [c[0] + offset, c[1] + offset, c[2] + offset]),
        );
        // tobj leaves an attribute array short when some of a model's vertices lack it; it
        // then no longer lines up with the positions and is dropped for that model.
        if any_normals {
            if mesh.normals.len() == 3 * n {
                normals.extend(
                    mesh.normals
                        .chunks_exact(3)
                        .map(|c| Vec3::new(c[0], c[1], c[2])),
                );
            } else {
                normals.resize(base + n, Vec3::NAN);
            }
        }
        if any_uvs {
            if mesh.texcoords.len() == 2 * n {
                uvs.extend(
                    mesh.texcoords
                        .chunks_exact(2)
                        .map(|c| Vec2::new(c[0], c[1])),
                );
            } else {
                uvs.resize(base + n, Vec2::NAN);
            }
        }
    }
    data.normals = any_normals.then_some(normals);
    data.uvs = any_uvs.then_some(uvs);
    Ok((data, text))
}

/// Turns a `tobj` error into one with the file and, found by a second pass, the line.
fn locate_obj_error(path: &Path, text: &[u8], err: tobj::LoadError) -> MeshError {
    // The first problem in the file, whichever tobj tripped over (it checks indices only when
    // a group ends, so a later syntax error can be what it reports).
    match scan_obj(text) {
        Some(ObjProblem::VertexIndex {
            line,
            face,
            index,
            vertices,
        }) => MeshError::IndexOutOfRange {
            path: Some(path.to_path_buf()),
            line: Some(line),
            face: Some(face),
            index,
            vertices,
        },
        Some(ObjProblem::Line { line, message }) => malformed(path, Some(line), message),
        None => malformed(path, None, err.to_string()),
    }
}

enum ObjProblem {
    Line {
        line: usize,
        message: String,
    },
    VertexIndex {
        line: usize,
        /// 0-based face number in the file.
        face: usize,
        index: i64,
        vertices: usize,
    },
}

/// Finds the first line `tobj` would refuse, by the same rules: `v` needs 3 numbers (then
/// nothing, a non-zero w, or 3 colour values), `vt` 2, `vn` 3; face corners are `v`, `v/vt`,
/// `v//vn` or `v/vt/vn` with indices in range (negative ones count back from the current end).
fn scan_obj(text: &[u8]) -> Option<ObjProblem> {
    let totals = {
        let (mut v, mut vt, mut vn) = (0usize, 0usize, 0usize);
        for l in text.split(|&b| b == b'\n') {
            match l.split(u8::is_ascii_whitespace).find(|w| !w.is_empty()) {
                Some(b"v") => v += 1,
                Some(b"vt") => vt += 1,
                Some(b"vn") => vn += 1,
                _ => {}
            }
        }
        [v, vt, vn]
    };
    let mut seen = [0usize; 3];
    let mut faces = 0usize;
    for (k, raw) in text.split(|&b| b == b'\n').enumerate() {
        let line = k + 1;
        let bad = |message: String| Some(ObjProblem::Line { line, message });
        let Ok(l) = std::str::from_utf8(raw) else {
            return bad("not valid UTF-8 text".into());
        };
        let mut words = l.split_whitespace();
        let Some(key) = words.next() else { continue };
        let rest: Vec<&str> = words.collect();
        let floats =
            |n: usize| rest.len() >= n && rest[..n].iter().all(|w| w.parse::<f32>().is_ok());
        match key {
            "v" => {
                if !floats(3) {
                    return bad(format!("vertex needs three numbers: `{}`", l.trim()));
                }
                match rest.len() {
                    3 | 6 => {}
                    4 => match rest[3].parse::<f32>() {
                        Ok(w) if w != 0.0 => {}
                        _ => {
                            return bad(format!(
                                "vertex weight must be a non-zero number: `{}`",
                                l.trim()
                            ));
                        }
                    },
                    _ => {
                        return bad(format!(
                            "vertex has {} values (3, 4 or 6 expected): `{}`",
                            rest.len(),
                            l.trim()
                        ));
                    }
                }
                seen[0] += 1;
            }
            "vt" => {
                if !floats(2) {
                    return bad(format!(
                        "texture coordinate needs two numbers: `{}`",
                        l.trim()
                    ));
                }
                seen[1] += 1;
            }
            "vn" => {
                if !floats(3) {
                    return bad(format!("normal needs three numbers: `{}`", l.trim()));
                }
                seen[2] += 1;
            }
            "f" | "l" => {
                let is_face = key == "f";
                for corner in &rest {
                    let parts: Vec<&str> = corner.split('/').collect();
                    if parts.len() > 3 {
                        return bad(format!("bad face corner `{corner}`"));
                    }
                    for (slot, part) in parts.iter().enumerate() {
                        if part.is_empty() {
                            continue;
                        }
                        let Ok(x) = part.parse::<i64>() else {
                            return bad(format!("bad face corner `{corner}`"));
                        };
                        // Attributes tobj ignores (none of their kind in the file) are not checked.
                        if slot > 0 && totals[slot] == 0 {
                            continue;
                        }
                        let resolved = if x < 0 { seen[slot] as i64 + x } else { x - 1 };
                        if resolved < 0 || resolved >= totals[slot] as i64 {
                            if slot == 0 && is_face {
                                return Some(ObjProblem::VertexIndex {
                                    line,
                                    face: faces,
                                    index: x,
                                    vertices: totals[0],
                                });
                            }
                            let what = ["vertex", "texture coordinate", "normal"][slot];
                            return bad(format!(
                                "{what} index {x} out of range ({} in the file)",
                                totals[slot]
                            ));
                        }
                    }
                }
                faces += usize::from(is_face);
            }
            "usemtl" if rest.is_empty() => return bad("usemtl without a material name".into()),
            _ => {}
        }
    }
    None
}

/// Line and 0-based file index of the first `v` line with a NaN or infinite value.
fn first_non_finite_vertex(text: &[u8]) -> Option<(usize, usize)> {
    let mut vertex = 0;
    for (k, raw) in text.split(|&b| b == b'\n').enumerate() {
        let l = String::from_utf8_lossy(raw);
        let mut words = l.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        let vals: Vec<f32> = words.filter_map(|w| w.parse().ok()).collect();
        let w = if vals.len() == 4 { vals[3] } else { 1.0 };
        if vals.iter().take(3).any(|x| !(x / w).is_finite()) {
            return Some((k + 1, vertex));
        }
        vertex += 1;
    }
    None
}

// ---------------------------------------------------------------------------------------------
// PLY

#[derive(Clone, Copy, Debug, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Debug)]
enum Property {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<(String, Property)>,
    /// The header line that declares it.
    line: usize,
}

impl Element {
    /// The fewest body bytes one instance can take: each ASCII value is at least a digit and
    /// a separator, each binary one its size (a list at least its count).
    fn min_bytes(&self, encoding: Encoding) -> usize {
        self.props
            .iter()
            .map(|(_, p)| match (encoding, p) {
                (Encoding::Ascii, _) => 2,
                (_, Property::Scalar(s)) => s.size(),
                (_, Property::List { count, .. }) => count.size(),
            })
            .sum()
    }
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body: usize,
    /// Lines the header takes (the body's first line is the next).
    lines: usize,
}

/// Where each vertex attribute sits among the vertex element's properties.
struct VertexLayout {
    pos: [usize; 3],
    normal: Option<[usize; 3]>,
    uv: Option<[usize; 2]>,
}

/// Reads a PLY file's arrays.
pub fn read_ply(path: &Path) -> Result<MeshData, MeshError> {
    let bytes = read_file(path)?;
    let header = parse_ply_header(path, &bytes)?;
    let mut reader = PlyReader {
        path: path.to_path_buf(),
        bytes: &bytes,
        at: header.body,
        line: header.lines + 1,
        encoding: header.encoding,
    };

    let vertex_count = header
        .elements
        .iter()
        .find(|e| e.name == "vertex")
        .map(|e| e.count)
        .ok_or_else(|| malformed(path, None, "no `vertex` element"))?;

    let mut data = MeshData::default();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut scalars: Vec<f64> = Vec::new();
    let mut list: Vec<f64> = Vec::new();
    let mut corners: Vec<f64> = Vec::new();
    for el in &header.elements {
        match el.name.as_str() {
            "vertex" => {
                let layout = vertex_layout(path, el)?;
                data.positions.reserve(el.count);
                for k in 0..el.count {
                    let line = reader.next_line();
                    scalars.clear();
                    for (name, prop) in &el.props {
                        match prop {
                            Property::Scalar(s) => scalars.push(reader.value(*s, el, k, name)?),
                            Property::List { count, item } => {
                                reader.list(*count, *item, el, k, name, &mut list)?;
                                scalars.push(f64::NAN);
                            }
                        }
                    }
                    let p = Vec3::from_array(layout.pos.map(|i| scalars[i] as f32));
                    if !p.is_finite() {
                        return Err(MeshError::NonFinite {
                            path: Some(path.to_path_buf()),
                            line: (reader.encoding == Encoding::Ascii).then_some(line),
                            vertex: k,
                        });
                    }
                    data.positions.push(p);
                    if let Some(n) = layout.normal {
                        normals.push(Vec3::from_array(n.map(|i| scalars[i] as f32)));
                    }
                    if let Some(t) = layout.uv {
                        uvs.push(Vec2::from_array(t.map(|i| scalars[i] as f32)));
                    }
                }
                data.normals = layout.normal.map(|_| std::mem::take(&mut normals));
                data.uvs = layout.uv.map(|_| std::mem::take(&mut uvs));
            }
            "face" => {
                let slot = el
                    .props
                    .iter()
                    .position(|(n, p)| {
                        matches!(p, Property::List { .. })
                            && (n == "vertex_indices" || n == "vertex_index")
                    })
                    .ok_or_else(|| {
                        malformed(path, None, "`face` element has no `vertex_indices` list")
                    })?;
                data.indices.reserve(el.count);
                for k in 0..el.count {
                    let line = reader.next_line();
                    for (j, (name, prop)) in el.props.iter().enumerate() {
                        match prop {
                            Property::Scalar(s) => {
                                reader.value(*s, el, k, name)?;
                            }
                            Property::List { count, item } => {
                                let out = if j == slot { &mut corners } else { &mut list };
                                reader.list(*count, *item, el, k, name, out)?;
                            }
                        }
                    }
                    let at = (reader.encoding == Encoding::Ascii).then_some(line);
                    if corners.len() < 3 {
                        return Err(malformed(
                            path,
                            at,
                            format!("face {k} has {} vertices; at least 3 needed", corners.len()),
                        ));
                    }
                    if let Some(&c) = corners
                        .iter()
                        .find(|&&c| !(c >= 0.0 && c < vertex_count as f64))
                    {
                        return Err(MeshError::IndexOutOfRange {
                            path: Some(path.to_path_buf()),
                            line: at,
                            face: Some(k),
                            index: c as i64,
                            vertices: vertex_count,
                        });
                    }
                    // Polygons become fans around their first corner.
                    let first = corners[0] as u32;
                    for w in corners[1..].windows(2) {
                        data.indices.push([first, w[0] as u32, w[1] as u32]);
                    }
                }
            }
            _ => {
                for k in 0..el.count {
                    for (name, prop) in &el.props {
                        match prop {
                            Property::Scalar(s) => {
                                reader.value(*s, el, k, name)?;
                            }
                            Property::List { count, item } => {
                                reader.list(*count, *item, el, k, name, &mut list)?;
                            }
                        }
                    }
                }
            }
        }
    }
    Ok(data)
}

fn vertex_layout(path: &Path, el: &Element) -> Result<VertexLayout, MeshError> {
    let find = |name: &str| {
        el.props
            .iter()
            .position(|(n, p)| n == name && matches!(p, Property::Scalar(_)))
    };
    let all = |names: &[&str]| -> Option<Vec<usize>> { names.iter().map(|n| find(n)).collect() };
    let pos = all(&["x", "y", "z"])
        .ok_or_else(|| malformed(path, None, "`vertex` element lacks x, y or z"))?;
    let normal = all(&["nx", "ny", "nz"]).map(|v| [v[0], v[1], v[2]]);
    let uv = [
        ["u", "v"],
        ["s", "t"],
        ["texture_u", "texture_v"],
        ["texture_s", "texture_t"],
    ]
    .iter()
    .find_map(|names| all(names))
    .map(|v| [v[0], v[1]]);
    Ok(VertexLayout {
        pos: [pos[0], pos[1], pos[2]],
        normal,
        uv,
    })
}

fn parse_ply_header(path: &Path, bytes: &[u8]) -> Result<Header, MeshError> {
    let mut at = 0usize;
    let mut line = 0usize;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if at >= bytes.len() {
            return Err(malformed(
                path,
                Some(line.max(1)),
                "header has no `end_header`",
            ));
        }
        let end = bytes[at..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| at + p);
        let raw = &bytes[at..end];
        at = (end + 1).min(bytes.len());
        line += 1;
        let text = String::from_utf8_lossy(raw);
        let text = text.trim_end_matches('\r');
        let words: Vec<&str> = text.split_whitespace().collect();
        let bad = |m: String| Err(malformed(path, Some(line), m));
        if line == 1 {
            if text.trim() != "ply" {
                return bad("not a PLY file (the first line must be `ply`)".into());
            }
            continue;
        }
        match words.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                encoding = Some(match words.get(1).copied() {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::Little,
                    Some("binary_big_endian") => Encoding::Big,
                    other => {
                        return bad(format!("unknown format `{}`", other.unwrap_or("")));
                    }
                });
            }
            Some("element") => {
                let (Some(name), Some(Ok(count))) =
                    (words.get(1), words.get(2).map(|c| c.parse::<usize>()))
                else {
                    return bad(format!("bad element line `{text}`"));
                };
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line,
                });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return bad("property before any element".into());
                };
                let prop = match words.get(1).copied() {
                    Some("list") => {
                        let (Some(c), Some(i), Some(name)) = (
                            words.get(2).and_then(|t| Scalar::parse(t)),
                            words.get(3).and_then(|t| Scalar::parse(t)),
                            words.get(4),
                        ) else {
                            return bad(format!("bad list property `{text}`"));
                        };
                        if c.is_float() {
                            return bad(format!("list count must be an integer type: `{text}`"));
                        }
                        (name.to_string(), Property::List { count: c, item: i })
                    }
                    Some(t) => {
                        let (Some(s), Some(name)) = (Scalar::parse(t), words.get(2)) else {
                            return bad(format!("bad property `{text}`"));
                        };
                        (name.to_string(), Property::Scalar(s))
                    }
                    None => return bad("empty property line".into()),
                };
                el.props.push(prop);
            }
            Some("end_header") => break,
            Some(other) => return bad(format!("unknown header keyword `{other}`")),
        }
    }
    let encoding = encoding.ok_or_else(|| malformed(path, None, "header has no `format` line"))?;
    // Each face makes at least one triangle: the same budget as an OBJ file's.
    let limit = MAX_MESH_TRIANGLES;
    if let Some(face) = elements.iter().find(|e| e.name == "face")
        && face.count as u64 > limit
    {
        return Err(malformed(
            path,
            Some(face.line),
            format!(
                "element `face` claims {} faces, more than the {limit} triangles a mesh may have \
                 (16 GiB at 512 bytes per triangle while loading)",
                face.count
            ),
        ));
    }
    // The header's counts are the file's claim, not its content: an element claiming more
    // instances than the bytes after the header can hold is refused before anything is
    // allocated for it (`element vertex 18446744073709551615` would overflow a reservation).
    let body = bytes.len() - at;
    let mut left = body;
    for el in &elements {
        match el.count.checked_mul(el.min_bytes(encoding).max(1)) {
            Some(n) if n <= left => left -= n,
            _ => {
                return Err(malformed(
                    path,
                    Some(el.line),
                    format!(
                        "element `{}` claims {} instances, more than the {body} bytes after \
                         the header can hold",
                        el.name, el.count
                    ),
                ));
            }
        }
    }
    Ok(Header {
        encoding,
        elements,
        body: at,
        lines: line,
    })
}

/// Cursor over a PLY body: whitespace-separated tokens for ASCII (with the line they are
/// on), fixed-size values for binary.
struct PlyReader<'a> {
    path: PathBuf,
    bytes: &'a [u8],
    at: usize,
    line: usize,
    encoding: Encoding,
}

impl PlyReader<'_> {
    fn error(&self, el: &Element, k: usize, prop: &str, what: &str) -> MeshError {
        let (line, place) = match self.encoding {
            Encoding::Ascii => (Some(self.line), String::new()),
            _ => (None, format!(" (byte {})", self.at)),
        };
        malformed(
            &self.path,
            line,
            format!("{what} in property `{prop}` of {} {k}{place}", el.name),
        )
    }

    /// Skips whitespace (ASCII only) and returns the line the next value is on.
    fn next_line(&mut self) -> usize {
        if self.encoding == Encoding::Ascii {
            let b = self.bytes;
            while self.at < b.len() && b[self.at].is_ascii_whitespace() {
                if b[self.at] == b'\n' {
                    self.line += 1;
                }
                self.at += 1;
            }
        }
        self.line
    }

    fn token(&mut self) -> Option<&str> {
        self.next_line();
        let b = self.bytes;
        let start = self.at;
        while self.at < b.len() && !b[self.at].is_ascii_whitespace() {
            self.at += 1;
        }
        (self.at > start)
            .then(|| std::str::from_utf8(&b[start..self.at]).ok())
            .flatten()
    }

    fn value(&mut self, s: Scalar, el: &Element, k: usize, prop: &str) -> Result<f64, MeshError> {
        match self.encoding {
            Encoding::Ascii => {
                let Some(tok) = self.token() else {
                    return Err(self.error(el, k, prop, "unexpected end of file"));
                };
                // f32 values parse as f32, so that a shortest-form decimal comes back exactly.
                let v = if s == Scalar::F32 {
                    tok.parse::<f32>().ok().map(f64::from)
                } else if s == Scalar::F64 {
                    tok.parse::<f64>().ok()
                } else {
                    tok.parse::<i64>().ok().map(|i| i as f64)
                };
                match v {
                    Some(v) => Ok(v),
                    None => {
                        let msg = format!("`{tok}` is not a valid {s:?} value");
                        Err(self.error(el, k, prop, &msg))
                    }
                }
            }
            enc => {
                let n = s.size();
                let Some(raw) = self.bytes.get(self.at..self.at + n) else {
                    return Err(self.error(el, k, prop, "unexpected end of data"));
                };
                let mut buf = [0u8; 8];
                buf[..n].copy_from_slice(raw);
                if enc == Encoding::Big {
                    buf[..n].reverse();
                }
                self.at += n;
                let [b0, b1, b2, b3, ..] = buf;
                Ok(match s {
                    Scalar::I8 => f64::from(b0 as i8),
                    Scalar::U8 => f64::from(b0),
                    Scalar::I16 => f64::from(i16::from_le_bytes([b0, b1])),
                    Scalar::U16 => f64::from(u16::from_le_bytes([b0, b1])),
                    Scalar::I32 => f64::from(i32::from_le_bytes([b0, b1, b2, b3])),
                    Scalar::U32 => f64::from(u32::from_le_bytes([b0, b1, b2, b3])),
                    Scalar::F32 => f64::from(f32::from_le_bytes([b0, b1, b2, b3])),
                    Scalar::F64 => f64::from_le_bytes(buf),
                })
            }
        }
    }

    fn list(
        &mut self,
        count: Scalar,
        item: Scalar,
        el: &Element,
        k: usize,
        prop: &str,
        out: &mut Vec<f64>,
    ) -> Result<(), MeshError> {
        let n = self.value(count, el, k, prop)?;
        if n < 0.0 {
            return Err(self.error(el, k, prop, "negative list length"));
        }
        out.clear();
        for _ in 0..n as usize {
            out.push(self.value(item, el, k, prop)?);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_faces_are_counted_before_loading() {
        let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\n  f\t1 2 3 4\nf 1/1 2/2\n\
                     # f 1 2 3\nvf 1 2 3\nf 1 2 3 4 5 6\n";
        assert_eq!(obj_triangles(text), 1 + 2 + 4);
        let p = Path::new("m.obj");
        assert!(check_obj_triangles(p, text, 7).is_ok());
        let e = check_obj_triangles(p, text, 6).unwrap_err().to_string();
        assert!(
            e.contains("m.obj") && e.contains("7 triangles in its faces"),
            "{e}"
        );
        assert!(e.contains("at most 6"), "{e}");
    }
}
