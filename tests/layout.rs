//! The module graph follows the pipeline: `systems` builds the render-time `scene` from the
//! world, the `integrator` reads the scene, and neither the scene nor the systems reach back
//! into the integrator (nor the scene into the systems), so no cycle runs between them.

use std::path::{Path, PathBuf};

fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(sources(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out
}

/// Every place in the `.rs` files under `src/<module>` that names one of the modules in
/// `forbidden`: a `crate::m` path, or `m` inside a `crate::{..}` group (comments skipped).
fn uses(module: &str, forbidden: &[&str]) -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("src")
        .join(module);
    let files = sources(&dir);
    assert!(!files.is_empty(), "src/{module} holds sources");
    let mut found = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let code: String = text
            .lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n");
        for m in forbidden {
            if code.contains(&format!("crate::{m}")) || code.contains("super::super::") {
                found.push(format!("{}: crate::{m}", f.display()));
            }
            // Grouped imports: `use crate::{a, m::b};`.
            let mut rest = code.as_str();
            while let Some(i) = rest.find("crate::{") {
                let group = &rest[i + 8..];
                let end = group.find('}').unwrap_or(group.len());
                let names = group[..end].split([',', ' ', '\n']);
                if names
                    .map(|n| n.split("::").next().unwrap_or(""))
                    .any(|n| n == *m)
                {
                    found.push(format!("{}: crate::{{{m}, ..}}", f.display()));
                }
                rest = &group[end..];
            }
        }
    }
    found
}

#[test]
fn the_scene_depends_on_neither_systems_nor_integrator() {
    let found = uses("scene", &["systems", "integrator", "cli"]);
    assert!(found.is_empty(), "{found:#?}");
}

#[test]
fn the_systems_do_not_depend_on_the_integrator() {
    let found = uses("systems", &["integrator", "cli"]);
    assert!(found.is_empty(), "{found:#?}");
}

#[test]
fn image_files_and_textures_stand_apart_from_the_film_and_the_scene_file() {
    // Image files are a leaf both the film and textures use; textures know neither the film
    // nor the scene file (the scene file builds textures, not the other way round).
    let found = uses(
        "imageio",
        &[
            "film",
            "texture",
            "scene_file",
            "scene",
            "integrator",
            "cli",
            "components",
        ],
    );
    assert!(found.is_empty(), "{found:#?}");
    let found = uses("texture", &["film", "scene_file", "integrator", "cli"]);
    assert!(found.is_empty(), "{found:#?}");
}
