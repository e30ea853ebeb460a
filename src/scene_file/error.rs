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
                f.write_str(message)
            }
            SceneError::Entity {
                path,
                entity,
                field,
                message,
            } => write!(
                f,
                "{}: entity {}: field `{}`: {}",
                path.display(),
                crate::components::quoted(entity),
                field,
                message
            ),
            SceneError::Override { key, message } => write!(f, "--set {key}: {message}"),
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
    }
}
