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
