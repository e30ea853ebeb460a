//! The studies: `compare` (image against reference), `converge` (error per second of render)
//! and `costs` (time per sample with each effect forced on).

use super::CliError;
use super::args::ConvergeArgs;
use super::scene::load_scene;
use crate::film;
use std::path::{Path, PathBuf};

/// `prism compare`: RMSE, relMSE and the largest error of image `a` against reference `b`.
pub(super) fn compare(a: &Path, b: &Path) -> Result<(), CliError> {
    let m = film::compare_files(a, b)?;
    println!("RMSE: {:.6e}", m.rmse);
    println!("relMSE: {:.6e}", m.relmse);
    println!("max error: {:.6e}", m.max_abs);
    Ok(())
}

/// `prism converge`: error against a converged reference per second of render, one curve per
/// configuration.
pub(super) fn converge(a: ConvergeArgs) -> Result<(), CliError> {
    if !(a.budget.is_finite() && a.budget > 0.0) {
        return Err(CliError::Budget(a.budget));
    }
    let mut set = a.set.clone();
    if let Some((w, h)) = a.size {
        set.push(("render.width".into(), w.to_string()));
        set.push(("render.height".into(), h.to_string()));
    }
    // Check the scene and the overrides once, with located errors, before the study.
    load_scene(&a.scene, &set, &[])?;
    let r = crate::report::converge(&crate::report::ConvergeOptions {
        scene: a.scene.clone(),
        set,
        reference: a.reference.clone(),
        reference_spp: a.reference_spp.max(2),
        budget: a.budget,
        vary: a.vary.clone(),
        out: a.output.clone(),
        quiet: a.quiet,
    })
    .map_err(CliError::Report)?;
    if !a.quiet {
        eprintln!(
            "wrote {}/converge.csv, converge.png, converge.svg, summary.md",
            a.output.display()
        );
    }
    print!("{}", r.summary);
    Ok(())
}

/// `prism costs`: time per sample of each scene, and with each effect it does not need forced
/// on; `size` is WxH in pixels.
pub(super) fn costs(
    scenes: Vec<PathBuf>,
    spp: u32,
    runs: usize,
    size: Option<(u32, u32)>,
) -> Result<(), CliError> {
    // The effects are specialised in the path tracer's kernels: measure those, whatever
    // `Auto` would pick (`converge --vary integrator.kind=...` compares the estimators).
    let mut set = vec![("render.integrator.kind".to_string(), "Path".to_string())];
    if let Some((w, h)) = size {
        set.push(("render.width".to_string(), w.to_string()));
        set.push(("render.height".to_string(), h.to_string()));
    }
    let t = crate::report::costs::effect_costs(&scenes, &set, spp.max(1), runs.max(1))
        .map_err(CliError::Report)?;
    print!("{t}");
    Ok(())
}
