//! The documentation cannot fall behind the code: `docs/scene-format.md` names every field and
//! variant of the scene schema, every RON snippet in the docs parses as what it claims to be, and
//! the tutorial's scenes render.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

use prism::scene_file::load::ron_options;
use prism::scene_file::schema;
use serde::de::DeserializeOwned;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The identifiers a user writes for one `#[derive(Deserialize)]` item: a struct's field names,
/// an enum's variant names and the fields of its struct variants. Items deserialised through
/// another type (`try_from`, `from`) are skipped: the user writes that other type, which is
/// collected on its own.
fn schema_names(source: &str, file: &str) -> Vec<(String, String)> {
    let lines: Vec<&str> = source.lines().collect();
    let mut names = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim();
        if line.starts_with("#[cfg(test)]") {
            break;
        }
        if !(line.starts_with("#[derive(") && line.contains("Deserialize")) {
            i += 1;
            continue;
        }
        // Attributes up to the item itself.
        let mut converted = false;
        i += 1;
        while i < lines.len() && !is_item(lines[i].trim()) {
            let l = lines[i].trim();
            converted |=
                l.starts_with("#[serde(") && (l.contains("try_from") || l.contains("from ="));
            i += 1;
        }
        let Some(head) = lines.get(i).map(|l| l.trim()) else {
            break;
        };
        let is_enum = head.contains("enum ");
        let item = head
            .split_whitespace()
            .skip_while(|w| *w != "struct" && *w != "enum")
            .nth(1)
            .unwrap_or("?")
            .trim_end_matches(['{', '(', ';'])
            .to_owned();
        if !head.ends_with('{') {
            i += 1; // tuple or unit struct: nothing named inside
            continue;
        }
        let mut depth = 1;
        i += 1;
        while i < lines.len() && depth > 0 {
            let l = lines[i].trim();
            let code = l.split("//").next().unwrap_or("");
            if !converted && !l.starts_with("//") && !l.starts_with("#[") {
                let rest = code
                    .trim_start_matches("pub(crate) ")
                    .trim_start_matches("pub ");
                let word: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let after = rest[word.len()..].trim_start();
                let variant = is_enum
                    && depth == 1
                    && word.chars().next().is_some_and(|c| c.is_ascii_uppercase())
                    && (after.is_empty() || after.starts_with([',', '(', '{']));
                if variant {
                    names.push((format!("{file}: {item}"), word));
                }
                // Field names: every `name:` (not a `::` path) on the line, so that a struct
                // variant written on one line (`Named { radius: f32 }`) counts too. Types hold
                // no such pattern.
                names.extend(field_names(code).map(|f| (format!("{file}: {item}"), f)));
            }
            depth += code.matches(['{', '(']).count() as i32;
            depth -= code.matches(['}', ')']).count() as i32;
            i += 1;
        }
    }
    names
}

/// Identifiers followed by a single `:` in one line of code.
fn field_names(code: &str) -> impl Iterator<Item = String> + '_ {
    let b = code.as_bytes();
    (0..b.len()).filter_map(move |i| {
        let colon = b[i] == b':' && b.get(i + 1) != Some(&b':') && (i == 0 || b[i - 1] != b':');
        if !colon {
            return None;
        }
        let end = code[..i].trim_end().len();
        let start = code[..end]
            .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .map_or(0, |k| k + 1);
        let word = &code[start..end];
        (!word.is_empty() && !word.starts_with(|c: char| c.is_ascii_digit()))
            .then(|| word.to_owned())
    })
}

fn is_item(line: &str) -> bool {
    [
        "pub struct ",
        "struct ",
        "pub enum ",
        "enum ",
        "pub(crate) struct ",
        "pub(crate) enum ",
    ]
    .iter()
    .any(|p| line.starts_with(p))
}

/// Every word inside the document's inline code spans and fenced code blocks.
fn code_words(markdown: &str) -> BTreeSet<String> {
    let mut code = String::new();
    let mut in_block = false;
    for line in markdown.lines() {
        if line.trim_start().starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if in_block {
            code.push_str(line);
            code.push('\n');
        } else {
            for (k, span) in line.split('`').enumerate() {
                if k % 2 == 1 {
                    code.push_str(span);
                    code.push('\n');
                }
            }
        }
    }
    code.split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
        .map(str::to_owned)
        .collect()
}

#[test]
fn scene_format_names_every_schema_field_and_variant() {
    let doc = fs::read_to_string(root().join("docs/scene-format.md")).unwrap();
    let words = code_words(&doc);
    let mut sources: Vec<PathBuf> = fs::read_dir(root().join("src/scene_file/schema"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    sources.sort();
    sources.push(root().join("src/texture/image_tex.rs"));
    let mut checked = 0;
    let mut missing = Vec::new();
    for path in &sources {
        let file = path.strip_prefix(root()).unwrap().display().to_string();
        for (item, name) in schema_names(&fs::read_to_string(path).unwrap(), &file) {
            checked += 1;
            if !words.contains(&name) {
                missing.push(format!("{item}.{name}"));
            }
        }
    }
    // The schema has well over a hundred names; a parser that found few is broken, not done.
    assert!(
        checked > 120,
        "only {checked} schema names found: the scan is broken"
    );
    assert!(
        missing.is_empty(),
        "docs/scene-format.md does not mention (in code) {} schema names:\n{}",
        missing.len(),
        missing.join("\n")
    );
}

#[test]
fn schema_scan_finds_fields_variants_and_skips_converted_types() {
    let source = r#"
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outer {
    #[serde(default)]
    pub width: u32,
    pub inner: Option<Vec<u8>>, // a comment: not_a_field
}
#[derive(Deserialize)]
pub enum Kind {
    Plain,
    Tuple(f32),
    Named { radius: f32, centre: (f32, f32) },
}
#[derive(Clone, Deserialize)]
#[serde(try_from = "Raw")]
pub struct Converted {
    pub hidden: f32,
}
#[derive(Deserialize)]
pub struct Pair(pub f32);
"#;
    let names: Vec<String> = schema_names(source, "f")
        .into_iter()
        .map(|(_, n)| n)
        .collect();
    assert_eq!(
        names,
        [
            "width", "inner", "Plain", "Tuple", "Named", "radius", "centre"
        ]
    );
}

/// Fenced blocks of `markdown` whose info string starts with `ron`: (info, text, line).
fn ron_blocks(markdown: &str) -> Vec<(String, String, usize)> {
    let mut blocks = Vec::new();
    let mut current: Option<(String, String, usize)> = None;
    for (n, line) in markdown.lines().enumerate() {
        let fence = line.trim_start().strip_prefix("```");
        match (&mut current, fence) {
            (None, Some(info)) => {
                current = Some((info.trim().to_owned(), String::new(), n + 2));
            }
            (Some(_), Some(_)) => {
                let block = current.take().unwrap();
                if block.0 == "ron" || block.0.starts_with("ron ") {
                    blocks.push(block);
                }
            }
            (Some((_, text, _)), None) => {
                text.push_str(line);
                text.push('\n');
            }
            (None, None) => {}
        }
    }
    blocks
}

fn fragment<T: DeserializeOwned>(text: &str) -> Result<(), String> {
    ron_options()
        .from_str::<T>(text)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// Parses a ```` ```ron TYPE ```` fragment as the named schema type.
fn parse_fragment(ty: &str, text: &str) -> Result<(), String> {
    match ty {
        "Scene" => fragment::<schema::Scene>(text),
        "Render" => fragment::<schema::Render>(text),
        "IntegratorSettings" => fragment::<schema::IntegratorSettings>(text),
        "Camera" => fragment::<schema::Camera>(text),
        "Lens" => fragment::<schema::Lens>(text),
        "Shutter" => fragment::<schema::Shutter>(text),
        "Motion" => fragment::<schema::Motion>(text),
        "Animation" => fragment::<schema::Animation>(text),
        "Keyframe" => fragment::<schema::Keyframe>(text),
        "LightSpec" => fragment::<schema::LightSpec>(text),
        "MediumSpec" => fragment::<schema::MediumSpec>(text),
        "Environment" => fragment::<schema::Environment>(text),
        "Entity" => fragment::<schema::Entity>(text),
        "Shape" => fragment::<schema::Shape>(text),
        "Transform" => fragment::<schema::Transform>(text),
        "Material" => fragment::<schema::Material>(text),
        "Ior" => fragment::<schema::Ior>(text),
        "Color" => fragment::<schema::Color>(text),
        "Emission" => fragment::<schema::Emission>(text),
        "TextureSpec" => fragment::<schema::TextureSpec>(text),
        "AlbedoSpec" => fragment::<schema::AlbedoSpec>(text),
        "NormalMapSpec" => fragment::<schema::NormalMapSpec>(text),
        other => Err(format!(
            "unknown fragment type '{other}' (add it to tests/docs.rs)"
        )),
    }
}

fn markdown_files() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md")];
    for entry in fs::read_dir(root().join("docs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            files.push(path);
        }
    }
    files.sort();
    files
}

#[test]
fn every_ron_snippet_in_the_docs_parses() {
    let mut failures = Vec::new();
    let mut count = 0;
    for file in markdown_files() {
        let text = fs::read_to_string(&file).unwrap();
        let name = file.strip_prefix(root()).unwrap().display().to_string();
        for (info, block, line) in ron_blocks(&text) {
            count += 1;
            let result = match info.strip_prefix("ron ") {
                Some(ty) => parse_fragment(ty.trim(), &block),
                // A whole scene, loaded as if it were a file beside the document (paths in it
                // resolve from there).
                None => prism::scene_file::load_str(&block, &file, &[])
                    .map(|_| ())
                    .map_err(|e| e.to_string()),
            };
            if let Err(e) = result {
                failures.push(format!("{name}:{line} ({info}): {e}"));
            }
        }
    }
    assert!(count >= 10, "only {count} RON snippets found in the docs");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn tutorial_scenes_load_and_render() {
    let dir = root().join("docs/tutorial");
    let mut scenes: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    scenes.sort();
    assert!(!scenes.is_empty(), "no scenes in {}", dir.display());
    let out = tempfile::tempdir().unwrap();
    for scene in &scenes {
        let png = out.path().join(format!(
            "{}.png",
            scene.file_stem().unwrap().to_string_lossy()
        ));
        let result = std::process::Command::new(env!("CARGO_BIN_EXE_prism"))
            .arg("render")
            .arg(scene)
            .args(["--spp", "1", "--quiet", "--set", "render.width=32"])
            // As the tutorial's commands: its mesh lies outside docs/, the default root.
            .arg("--asset-root")
            .arg(root())
            .args(["--set", "render.height=24", "-o"])
            .arg(&png)
            .output()
            .unwrap();
        assert!(
            result.status.success(),
            "{}: {}",
            scene.display(),
            String::from_utf8_lossy(&result.stderr)
        );
        assert!(png_is_nonblack(&png), "{} rendered black", scene.display());
    }
}

fn png_is_nonblack(path: &Path) -> bool {
    let (img, _) = prism::film::read_image(path).unwrap();
    img.pixels.iter().any(|p| p.iter().any(|&c| c > 0.0))
}
