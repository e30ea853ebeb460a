//! The scene as the commands see it: loaded with the command line's overrides, prepared for
//! a frame with the forced effects on.

use super::CliError;
use crate::kdtree::KdParams;
use crate::scene::{Effect, RenderScene};
use crate::scene_file::{self, LoadedScene};
use crate::systems;
use std::path::Path;

/// Loads a scene with the command line's overrides folded into `--set` form.
pub(super) fn load_scene(
    path: &Path,
    set: &[(String, String)],
    extra: &[(String, String)],
) -> Result<LoadedScene, CliError> {
    let mut all = set.to_vec();
    all.extend_from_slice(extra);
    Ok(scene_file::load(path, &all)?)
}

/// The scene prepared for `frame`, with the `--force` effects on.
pub(super) fn prepare(
    scene: &LoadedScene,
    force: &[String],
    frame: u32,
) -> Result<RenderScene, CliError> {
    let mut rs = systems::prepare_frame(scene, &KdParams::default(), frame);
    force_effects(&mut rs, force)?;
    Ok(rs)
}

/// Turns on the effects named by `--force`.
pub(super) fn force_effects(rs: &mut RenderScene, force: &[String]) -> Result<(), CliError> {
    for f in force {
        let e = Effect::parse(f).ok_or_else(|| CliError::UnknownEffect(f.clone()))?;
        rs.effects.force(e).map_err(CliError::Force)?;
    }
    Ok(())
}
