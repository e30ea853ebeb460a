//! Scene errors, each located: file, line:column, entity and field where they are known.

use std::fmt;
use std::path::PathBuf;

/// Why a scene could not be loaded.
#[derive(Debug)]
pub enum SceneError {
    /// The scene file (or an asset it names) could not be read.
    Io {
        /// The file that could not be read.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Syntax or schema error, with the position RON reported.
    Parse {
        /// The scene file.
        path: PathBuf,
        /// Line of the error, 1-based.
        line: usize,
        /// Column of the error in characters, 1-based.
        col: usize,
        /// Name of the entity the position falls in, if any.
        entity: Option<String>,
        /// The innermost field the position falls in, if any.
        field: Option<String>,
        /// What RON or the schema reported.
        message: String,
    },
    /// A semantic error found while building the world.
    Entity {
        /// The scene file.
        path: PathBuf,
        /// Line and column (1-based, columns in characters) of the value at fault, or of its
        /// entity when the field is absent; `None` until the error is located in the text.
        at: Option<(u32, u32)>,
        /// Where the value at fault is, as `--set` writes a path (`entities[3].material`,
        /// `camera.look_at`): what `at` is found from.
        key: Box<str>,
        /// Name of the entity.
        entity: String,
        /// The field at fault.
        field: &'static str,
        /// What is wrong with it.
        message: String,
    },
    /// A `--set KEY=VALUE` override that does not apply.
    Override {
        /// The key as given, e.g. `render.spp`.
        key: String,
        /// Why the override does not apply.
        message: String,
    },
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneError::Io { path, source } => {
                write!(f, "cannot read scene '{}': {}", path.display(), source)
            }
            SceneError::Parse {
                path,
                line,
                col,
                entity,
                field,
                message,
            } => {
                write!(f, "{}:{}:{}: ", path.display(), line, col)?;
                if let Some(e) = entity {
                    write!(f, "entity {}: ", crate::components::quoted(e))?;
                }
                if let Some(fi) = field {
                    write!(f, "field `{fi}`: ")?;
                }
                f.write_str(&crate::components::escape_controls(message))
            }
            SceneError::Entity {
                path,
                at,
                entity,
                field,
                message,
                ..
            } => {
                write!(f, "{}", path.display())?;
                if let Some((line, col)) = at {
                    write!(f, ":{line}:{col}")?;
                }
                write!(
                    f,
                    ": entity {}: field `{}`: {}",
                    crate::components::quoted(entity),
                    field,
                    crate::components::escape_controls(message)
                )
            }
            SceneError::Override { key, message } => write!(
                f,
                "--set {}: {}",
                crate::components::escape_controls(key),
                crate::components::escape_controls(message)
            ),
        }
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SceneError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl SceneError {
    /// `self` with the position of an [`SceneError::Entity`] error's value in `text`, the
    /// scene's text, filled in.
    pub(crate) fn located(self, text: &str) -> SceneError {
        match self {
            SceneError::Entity {
                path,
                at: None,
                key,
                entity,
                field,
                message,
            } => SceneError::Entity {
                path,
                at: super::patch::locate(text, &key).map(|o| {
                    let (l, c) = line_col(text, o);
                    (l as u32, c as u32)
                }),
                key,
                entity,
                field,
                message,
            },
            e => e,
        }
    }
}

/// The 1-based (line, column) of byte offset `at`; columns count characters.
pub(crate) fn line_col(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

/// Byte offset of a 1-based (line, column) position; columns count characters.
pub(crate) fn offset_of(text: &str, line: usize, col: usize) -> usize {
    let mut off = 0;
    for (i, l) in text.split_inclusive('\n').enumerate() {
        if i + 1 == line {
            return off
                + l.char_indices()
                    .nth(col.saturating_sub(1))
                    .map_or(l.len(), |(b, _)| b);
        }
        off += l.len();
    }
    text.len()
}

/// One token of the coarse RON scan used to put names on error positions.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tok<'a> {
    Open(usize),
    Close(usize),
    /// `ident:` with the identifier.
    Field(&'a str, usize),
    Str(&'a str, usize),
}

/// Splits RON text into brackets, `field:` labels and strings, skipping comments; enough
/// structure to find which field and which entity an error position falls in.
fn scan(text: &str) -> Vec<Tok<'_>> {
    let b = text.as_bytes();
    let mut toks = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        match c {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                    i += 1;
                }
                i += 2;
            }
            b'"' => {
                let start = i + 1;
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    if b[i] == b'\\' {
                        i += 1;
                    }
                    i += 1;
                }
                toks.push(Tok::Str(&text[start..i.min(b.len())], start));
                i += 1;
            }
            b'(' | b'[' | b'{' => {
                toks.push(Tok::Open(i));
                i += 1;
            }
            b')' | b']' | b'}' => {
                toks.push(Tok::Close(i));
                i += 1;
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                let start = i;
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                let mut j = i;
                while j < b.len() && (b[j] == b' ' || b[j] == b'\t') {
                    j += 1;
                }
                if b.get(j) == Some(&b':') && b.get(j + 1) != Some(&b':') {
                    toks.push(Tok::Field(&text[start..i], start));
                }
            }
            _ => i += 1,
        }
    }
    toks
}

/// The innermost `field:` whose value contains byte offset `at`, and the name of the entity
/// (the element of the top-level `entities` list) that contains it.
pub(crate) fn context_at(text: &str, at: usize) -> (Option<String>, Option<String>) {
    let toks = scan(text);
    // Stack of open groups: (depth-owning field label, open offset).
    let mut stack: Vec<(Option<&str>, usize)> = Vec::new();
    let mut pending: Option<&str> = None;
    let mut field = None;
    let mut entity_open: Option<usize> = None;
    for t in &toks {
        let pos = match *t {
            Tok::Open(p) | Tok::Close(p) | Tok::Field(_, p) | Tok::Str(_, p) => p,
        };
        if pos >= at {
            break;
        }
        match *t {
            Tok::Field(name, _) => {
                pending = Some(name);
                field = Some(name);
            }
            Tok::Open(p) => {
                stack.push((pending.take(), p));
            }
            Tok::Close(_) => {
                stack.pop();
                pending = None;
                field = stack.iter().rev().find_map(|(f, _)| *f);
            }
            Tok::Str(..) => {}
        }
    }
    // Inside `entities: [ ( ... ) ]`, the element tuple is the group right after the list.
    if let Some(k) = stack.iter().position(|(f, _)| *f == Some("entities")) {
        entity_open = stack.get(k + 1).map(|(_, p)| *p);
    }
    let entity = entity_open.and_then(|open| entity_name(&toks, open));
    // A value error right after `field:` belongs to that field; inside a group, the label
    // of the innermost labelled group.
    let field = pending.or(field).map(str::to_string);
    (entity, field)
}

/// The `name: "..."` at depth 1 of the group opened at `open`.
fn entity_name(toks: &[Tok<'_>], open: usize) -> Option<String> {
    let start = toks.iter().position(|t| *t == Tok::Open(open))?;
    let mut depth = 0i32;
    let mut want = false;
    for t in &toks[start..] {
        match *t {
            Tok::Open(_) => depth += 1,
            Tok::Close(_) => {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            Tok::Field(n, _) => want = depth == 1 && n == "name",
            Tok::Str(s, _) if want => return Some(s.to_string()),
            Tok::Str(..) => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_field_and_entity() {
        let text = r#"Scene(entities: [
  (name: "a", shape: Sphere(center: (0,0,0), radius: 1.0)),
  (shape: Sphere(center: (0,0,0), radius: -1.0), name: "b // not a comment"),
])"#;
        let at = text.find("-1.0").unwrap() + 4;
        let (e, f) = context_at(text, at);
        assert_eq!(e.as_deref(), Some("b // not a comment"));
        assert_eq!(f.as_deref(), Some("radius"));
        let at = text.find("(0,0,0), radius: 1").unwrap() + 3;
        let (e, f) = context_at(text, at);
        assert_eq!(e.as_deref(), Some("a"));
        assert_eq!(f.as_deref(), Some("center"));
    }

    #[test]
    fn offsets() {
        let t = "ab\ncd\n";
        assert_eq!(offset_of(t, 2, 2), 4);
        assert_eq!(offset_of(t, 1, 1), 0);
        for (line, col) in [(1, 1), (1, 3), (2, 1), (2, 2), (3, 1)] {
            assert_eq!(line_col(t, offset_of(t, line, col)), (line, col));
        }
        // Columns count characters, not bytes.
        assert_eq!(line_col("é(x", 3), (1, 3));
    }

    /// Errors found after parsing (meshes, textures, lights on boxes, a missing material, the
    /// camera) point at the value at fault, or at its entity when the field is absent.
    #[test]
    fn errors_after_parsing_are_located() {
        use crate::scene_file::load_str;
        let scene = |entity: &str, camera: &str| {
            format!(
                "Scene(\n  render: (width: 8, height: 8),\n  camera: (position: (0.0, 0.0, 5.0), \
                 look_at: {camera}),\n  entities: [\n    (name: \"ok\", shape: Sphere(center: \
                 (0.0, 0.0, 0.0), radius: 1.0), material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),\n    \
                 {entity},\n  ],\n)"
            )
        };
        let path = std::path::Path::new("s.ron");
        // The entity, the camera's look_at, where the error must point (the first match of
        // the marker, plus an offset) and what it must say there.
        let cases = [
            (
                "(name: \"bare\", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0))",
                "(0.0, 0.0, 0.0)",
                ("(name: \"bare\"", 0),
                "entity \"bare\": field `material`:",
            ),
            (
                "(name: \"lit box\", shape: Box(min: (0.0, 0.0, 0.0), max: (1.0, 1.0, 1.0)), \
                 material: Light(emission: Rgb(1.0, 1.0, 1.0)))",
                "(0.0, 0.0, 0.0)",
                ("Light(emission", 0),
                "entity \"lit box\": field `material`:",
            ),
            (
                "(name: \"m\", shape: Mesh(path: \"missing.obj\"), material: Mirror(tint: \
                 Rgb(1.0, 1.0, 1.0)))",
                "(0.0, 0.0, 0.0)",
                ("Mesh(path", 0),
                "entity \"m\": field `shape`:",
            ),
            (
                "(name: \"p\", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), \
                 material: Mirror(tint: Rgb(1.0, 1.0, 1.0)))",
                "(0.0, 0.0, 5.0)",
                ("look_at: ", 9),
                "entity \"camera\": field `look_at`:",
            ),
        ];
        for (entity, look_at, (marker, skip), says) in cases {
            let text = scene(entity, look_at);
            let msg = match load_str(&text, path, &[]) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("{text} loaded"),
            };
            let (line, col) = line_col(&text, text.find(marker).unwrap() + skip);
            let want = format!("s.ron:{line}:{col}: {says}");
            assert!(line > 2 && col > 1, "{want}");
            assert!(msg.starts_with(&want), "{msg}\nwanted: {want}\n{text}");
        }
    }
}
