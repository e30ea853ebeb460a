//! The `prism` command line: render, info, compare, converge, costs and merge.
//!
//! `main` parses with [`Cli`] and hands the result to [`run`]; a failure is a [`CliError`],
//! whose message `main` prints as one line.

mod args;
mod error;
pub mod farm;
pub mod frames;
mod info;
mod progress;
mod render;
mod scene;
mod study;

pub use args::Cli;
use args::Command;
pub use error::CliError;

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    use crate::scene_file::assets::{AssetPolicy, set_policy};
    if cli.allow_any_path {
        set_policy(AssetPolicy::Any);
    } else if let Some(root) = cli.asset_root {
        if !root.is_dir() {
            return Err(CliError::AssetRoot(root));
        }
        set_policy(AssetPolicy::Root(root));
    }
    match cli.command {
        Command::Render(a) => render::render(a),
        Command::Info(a) => info::info(a),
        Command::Converge(a) => study::converge(a),
        Command::Costs {
            scenes,
            spp,
            runs,
            size,
        } => study::costs(scenes, spp, runs, size),
        Command::Merge { parts, output } => farm::run_merge(&parts, &output),
        Command::Compare { a, b } => study::compare(&a, &b),
    }
}
