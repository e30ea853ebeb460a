//! `--set` on entities: `entities["bunny"].material.albedo=(0.8, 0.1, 0.1)` or
//! `entities[3].transform=(translate: (0.0, 1.0, 0.0))` replaces (or adds) that value in the
//! scene's RON text before it is parsed, so the value is checked exactly as if the file held
//! it, whatever the field's type.
//!
//! A path is `entities[INDEX]` or `entities["NAME"]` followed by `.field` steps. Each step
//! descends into the value of the previous one: a struct `( .. )`, an enum variant or named
//! struct `Name( .. )`, or `Some( .. )`. The last field is replaced if present and added
//! otherwise; the fields before it must exist.

use std::ops::Range;

/// One step of a path.
#[derive(Clone, Debug, PartialEq)]
enum Step {
    Field(String),
    Index(usize),
    Named(String),
}

/// Whether `key` is a path this module handles.
pub fn is_entity_path(key: &str) -> bool {
    key.starts_with("entities[")
}

/// Applies `key = value` to `text`: the new text and the byte range the edit occupies in it
/// (the value, or `name: value` for an added field). Errors say which step of the path fails.
pub fn apply(text: &str, key: &str, value: &str) -> Result<(String, Range<usize>), String> {
    let steps = parse_path(key)?;
    let b = text.as_bytes();
    let top = skip_ws(b, 0);
    let top = skip_attributes(b, top);
    let mut body = struct_body(b, top, text.len())
        .ok_or("the scene file is not a RON struct at its top level")?;
    let mut at = String::new();
    let last = steps.len() - 1;
    let mut cur: Option<Range<usize>> = None;
    for (k, step) in steps.iter().enumerate() {
        match step {
            Step::Field(name) => {
                let body_now = match &cur {
                    None => body.clone(),
                    Some(v) => struct_body(b, v.start, v.end).ok_or_else(|| {
                        format!("{at} is not a struct with fields, so it has no '{name}'")
                    })?,
                };
                body = body_now;
                let fields = fields(b, body.clone()).ok_or_else(|| {
                    format!(
                        "cannot read the fields of {}",
                        if at.is_empty() { "the scene" } else { &at }
                    )
                })?;
                match fields.iter().find(|f| &text[f.0.clone()] == name) {
                    Some(f) => cur = Some(f.1.clone()),
                    None if k == last => {
                        // Added as the first field of the struct.
                        let insert = format!("{name}: ");
                        let pos = body.start;
                        let new = format!("{}{insert}{value}, {}", &text[..pos], &text[pos..]);
                        // The span covers the added name too: a struct without that field
                        // is refused at the name, and the error must still blame `--set`.
                        return Ok((new, pos..pos + insert.len() + value.len()));
                    }
                    None => return Err(format!("{at} has no field '{name}' to set a field of")),
                }
                at = if at.is_empty() {
                    name.clone()
                } else {
                    format!("{at}.{name}")
                };
            }
            Step::Index(_) | Step::Named(_) => {
                let v = cur.clone().ok_or("a path starts with a field")?;
                let elems = list(b, v).ok_or_else(|| format!("{at} is not a list"))?;
                let (found, label) = match step {
                    Step::Index(i) => (
                        elems.get(*i).cloned().ok_or_else(|| {
                            format!(
                                "{at}[{i}] does not exist: the file has {} entities",
                                elems.len()
                            )
                        })?,
                        format!("{at}[{i}]"),
                    ),
                    Step::Named(n) => (
                        elems
                            .iter()
                            .find(|e| name_of(text, (*e).clone()).as_deref() == Some(n.as_str()))
                            .cloned()
                            .ok_or_else(|| format!("no entity is named \"{n}\""))?,
                        format!("{at}[\"{n}\"]"),
                    ),
                    Step::Field(_) => unreachable!("handled above"),
                };
                at = label;
                cur = Some(found);
            }
        }
    }
    let v = cur.expect("a path has at least one step");
    let new = format!("{}{value}{}", &text[..v.start], &text[v.end..]);
    Ok((new, v.start..v.start + value.len()))
}

/// The byte offset in `text` of the value at `key` (`entities[3].material`, `camera.look_at`,
/// `animation.keyframes[2]`), or of the deepest value on the way to it that the text has (the
/// entity, when the field is absent): where an error about that value points. `None` when not
/// even the first step is found.
pub fn locate(text: &str, key: &str) -> Option<usize> {
    let steps = parse_steps(key).ok()?;
    let b = text.as_bytes();
    let top = skip_attributes(b, skip_ws(b, 0));
    let mut cur = top..text.len();
    let mut found = None;
    for step in &steps {
        let next = match step {
            Step::Field(name) => struct_body(b, cur.start, cur.end)
                .and_then(|body| fields(b, body))
                .and_then(|fs| fs.into_iter().find(|f| &text[f.0.clone()] == name))
                .map(|f| f.1),
            Step::Index(i) => list(b, cur.clone()).and_then(|l| l.get(*i).cloned()),
            Step::Named(n) => list(b, cur.clone()).and_then(|l| {
                l.into_iter()
                    .find(|e| name_of(text, e.clone()).as_deref() == Some(n.as_str()))
            }),
        };
        match next {
            Some(v) => {
                found = Some(v.start);
                cur = v;
            }
            None => break,
        }
    }
    found
}

fn parse_path(key: &str) -> Result<Vec<Step>, String> {
    let steps = parse_steps(key)?;
    if steps.len() < 2
        || steps[0] != Step::Field("entities".into())
        || matches!(steps[1], Step::Field(_))
    {
        return Err(path_help("no entity selected"));
    }
    Ok(steps)
}

fn path_help(why: &str) -> String {
    format!(
        "{why}; an entity path is entities[INDEX] or entities[\"NAME\"] then .field steps, \
         e.g. entities[\"floor\"].material.albedo"
    )
}

/// The steps of `key`, fields joined by `.` and list elements as `[INDEX]` or `["NAME"]`.
fn parse_steps(key: &str) -> Result<Vec<Step>, String> {
    let bad = path_help;
    let mut steps = Vec::new();
    let mut rest = key;
    let mut first = true;
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix('[') {
            let close = if let Some(q) = r.strip_prefix('"') {
                let end = q.find('"').ok_or_else(|| bad("an unclosed quote"))?;
                if q.as_bytes().get(end + 1) != Some(&b']') {
                    return Err(bad("a name must be followed by ]"));
                }
                steps.push(Step::Named(q[..end].to_string()));
                end + 2
            } else {
                let end = r.find(']').ok_or_else(|| bad("an unclosed ["))?;
                let i = r[..end]
                    .trim()
                    .parse::<usize>()
                    .map_err(|_| bad(&format!("'{}' is not an index", &r[..end])))?;
                steps.push(Step::Index(i));
                end
            };
            rest = &r[close + 1..];
        } else {
            let r = if first {
                rest
            } else {
                rest.strip_prefix('.')
                    .ok_or_else(|| bad("steps are joined by '.'"))?
            };
            let end = r.find(['.', '[']).unwrap_or(r.len());
            let name = &r[..end];
            if name.is_empty() || !name.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_') {
                return Err(bad(&format!("'{name}' is not a field name")));
            }
            steps.push(Step::Field(name.to_string()));
            rest = &r[end..];
        }
        first = false;
    }
    Ok(steps)
}

/// Skips whitespace and comments.
fn skip_ws(b: &[u8], mut i: usize) -> usize {
    loop {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            i += 2;
            while i < b.len() && !b[i..].starts_with(b"*/") {
                i += 1;
            }
            i = (i + 2).min(b.len());
        } else {
            return i;
        }
    }
}

/// Skips `#![enable(..)]` attributes at the top of a file.
fn skip_attributes(b: &[u8], mut i: usize) -> usize {
    while b[i..].starts_with(b"#!") {
        match b[i..].iter().position(|&c| c == b']') {
            Some(p) => i = skip_ws(b, i + p + 1),
            None => return b.len(),
        }
    }
    i
}

/// The end of the string or char literal starting at `i`.
fn skip_quoted(b: &[u8], i: usize) -> usize {
    let q = b[i];
    let mut j = i + 1;
    while j < b.len() && b[j] != q {
        if b[j] == b'\\' {
            j += 1;
        }
        j += 1;
    }
    (j + 1).min(b.len())
}

/// The end of the bracketed group opening at `i` (one past its closing bracket).
fn skip_group(b: &[u8], i: usize) -> Option<usize> {
    let mut depth = 0usize;
    let mut j = i;
    while j < b.len() {
        let k = skip_ws(b, j);
        if k != j {
            j = k;
            continue;
        }
        match b[j] {
            b'"' | b'\'' => {
                j = skip_quoted(b, j);
                continue;
            }
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(j + 1);
                }
            }
            _ => {}
        }
        j += 1;
    }
    None
}

/// The end of the value starting at `i`: a literal, an identifier or number, optionally
/// followed by a group (`Diffuse( .. )`), or a group.
fn skip_value(b: &[u8], i: usize, end: usize) -> Option<usize> {
    let i = skip_ws(b, i);
    if i >= end {
        return None;
    }
    match b[i] {
        b'"' | b'\'' => Some(skip_quoted(b, i)),
        b'(' | b'[' | b'{' => skip_group(b, i),
        _ => {
            let mut j = i;
            while j < end
                && (b[j].is_ascii_alphanumeric() || matches!(b[j], b'_' | b'.' | b'-' | b'+'))
            {
                j += 1;
            }
            if j == i {
                return None;
            }
            let k = skip_ws(b, j);
            if k < end && b[k] == b'(' {
                skip_group(b, k)
            } else {
                Some(j)
            }
        }
    }
}

/// The inside of the struct a value spells (`( .. )`, `Name( .. )` or `Some( .. )` around
/// one), without its parentheses.
fn struct_body(b: &[u8], start: usize, end: usize) -> Option<Range<usize>> {
    let mut i = skip_ws(b, start);
    let ident_start = i;
    while i < end && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
        i += 1;
    }
    let ident = &b[ident_start..i];
    i = skip_ws(b, i);
    if i >= end || b[i] != b'(' {
        return None;
    }
    let close = skip_group(b, i)?;
    if ident == b"Some" {
        let inner = skip_ws(b, i + 1);
        if inner < close && b[inner] == b'(' {
            return struct_body(b, inner, close - 1);
        }
    }
    Some(i + 1..close - 1)
}

/// The `name: value` pairs of a struct body: (name range, value range).
fn fields(b: &[u8], body: Range<usize>) -> Option<Vec<(Range<usize>, Range<usize>)>> {
    let mut out = Vec::new();
    let mut i = skip_ws(b, body.start);
    while i < body.end {
        let s = i;
        while i < body.end && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
            i += 1;
        }
        let name = s..i;
        i = skip_ws(b, i);
        if name.is_empty() || i >= body.end || b[i] != b':' {
            return None;
        }
        let vs = skip_ws(b, i + 1);
        let ve = skip_value(b, vs, body.end)?;
        out.push((name, vs..ve));
        i = skip_ws(b, ve);
        if i < body.end && b[i] == b',' {
            i = skip_ws(b, i + 1);
        }
    }
    Some(out)
}

/// The elements of a list value `[ .. ]`.
fn list(b: &[u8], v: Range<usize>) -> Option<Vec<Range<usize>>> {
    let open = skip_ws(b, v.start);
    if open >= v.end || b[open] != b'[' {
        return None;
    }
    let end = v.end - 1;
    let mut out = Vec::new();
    let mut i = skip_ws(b, open + 1);
    while i < end {
        let e = skip_value(b, i, end)?;
        out.push(i..e);
        i = skip_ws(b, e);
        if i < end && b[i] == b',' {
            i = skip_ws(b, i + 1);
        }
    }
    Some(out)
}

/// The `name` of an entity element, if it has one.
fn name_of(text: &str, e: Range<usize>) -> Option<String> {
    let b = text.as_bytes();
    let body = struct_body(b, e.start, e.end)?;
    let f = fields(b, body)?;
    let (_, v) = f.into_iter().find(|(n, _)| &text[n.clone()] == "name")?;
    let s = &text[v];
    let s = s
        .strip_prefix("Some(")
        .and_then(|s| s.strip_suffix(')'))
        .unwrap_or(s);
    Some(s.strip_prefix('"')?.strip_suffix('"')?.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"#![enable(implicit_some)]
// A comment with ( and [ and "quotes".
(
    camera: (position: (0.0, 1.0, 5.0), look_at: (0.0, 1.0, 0.0)),
    entities: [
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), size: (4.0, 4.0)),
         material: Diffuse(albedo: (0.7, 0.7, 0.7))),
        /* the lamp */
        (name: "lamp [a]", shape: Sphere(center: (0.0, 3.0, 0.0), radius: 0.5),
         material: Light(emission: (4.0, 4.0, 4.0))),
        (shape: Sphere(center: (1.0, 0.5, 0.0), radius: 0.5), material: Mirror),
    ],
)"#;

    fn set(key: &str, value: &str) -> Result<String, String> {
        let (text, span) = apply(SCENE, key, value)?;
        assert!(text[span].ends_with(value));
        Ok(text)
    }

    #[test]
    fn replaces_a_nested_field_by_name_and_by_index() {
        let t = set("entities[\"floor\"].material.albedo", "(0.9, 0.1, 0.1)").unwrap();
        assert!(t.contains("Diffuse(albedo: (0.9, 0.1, 0.1))"), "{t}");
        let t = set("entities[1].material", "Diffuse(albedo: (0.5, 0.5, 0.5))").unwrap();
        assert!(
            t.contains("material: Diffuse(albedo: (0.5, 0.5, 0.5)))"),
            "{t}"
        );
        let t = set("entities[\"lamp [a]\"].shape.radius", "0.25").unwrap();
        assert!(t.contains("radius: 0.25),"), "{t}");
        assert_eq!(t.matches("radius: 0.5").count(), 1);
    }

    #[test]
    fn adds_a_missing_last_field() {
        let t = set("entities[2].transform", "(translate: (0.0, 1.0, 0.0))").unwrap();
        assert!(
            t.contains("(transform: (translate: (0.0, 1.0, 0.0)), shape: Sphere"),
            "{t}"
        );
        let t = set("entities[\"floor\"].name", "\"ground\"").unwrap();
        assert!(t.contains("(name: \"ground\", shape"), "{t}");
    }

    #[test]
    fn locates_values_or_the_deepest_part_present() {
        let at = |key: &str| locate(SCENE, key).map(|o| &SCENE[o..o + 12]);
        assert_eq!(at("camera.look_at"), Some("(0.0, 1.0, 0"));
        assert_eq!(at("entities[1].material"), Some("Light(emissi"));
        assert_eq!(
            at("entities[\"floor\"].material.albedo"),
            Some("(0.7, 0.7, 0")
        );
        // An absent field: its entity; an absent entity: the list.
        assert_eq!(at("entities[2].texture"), Some("(shape: Sphe"));
        assert_eq!(at("entities[9].material"), Some("[\n        (n"));
        assert_eq!(locate(SCENE, "lens.aperture"), None);
        assert_eq!(locate(SCENE, "entities[x"), None);
    }

    #[test]
    fn says_which_step_fails() {
        let e = set("entities[7].material", "Mirror").unwrap_err();
        assert!(
            e.contains("entities[7] does not exist: the file has 3 entities"),
            "{e}"
        );
        let e = set("entities[\"wall\"].material", "Mirror").unwrap_err();
        assert!(e.contains("no entity is named \"wall\""), "{e}");
        let e = set("entities[2].motion.velocity", "(1.0, 0.0, 0.0)").unwrap_err();
        assert!(e.contains("entities[2] has no field 'motion'"), "{e}");
        let e = set("entities[2].material.albedo", "(1.0, 0.0, 0.0)").unwrap_err();
        assert!(e.contains("entities[2].material is not a struct"), "{e}");
        for bad in [
            "entities",
            "entities.material",
            "entities[x]",
            "entities[\"a",
            "entities[0]material",
        ] {
            let e = set(bad, "1").unwrap_err();
            assert!(e.contains("an entity path is"), "{bad}: {e}");
        }
    }
}
