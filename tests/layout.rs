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

/// Every line of the `.rs` files under `src/<module>` that names one of `forbidden`.
fn uses(module: &str, forbidden: &[&str]) -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("src")
        .join(module);
    let files = sources(&dir);
    assert!(!files.is_empty(), "src/{module} holds sources");
    let mut found = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if forbidden.iter().any(|m| code.contains(m)) {
                found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
            }
        }
    }
    found
}

#[test]
fn the_scene_depends_on_neither_systems_nor_integrator() {
    let found = uses(
        "scene",
        &["crate::systems", "crate::integrator", "crate::cli"],
    );
    assert!(found.is_empty(), "{found:#?}");
}

#[test]
fn the_systems_do_not_depend_on_the_integrator() {
    let found = uses("systems", &["crate::integrator", "crate::cli"]);
    assert!(found.is_empty(), "{found:#?}");
}
