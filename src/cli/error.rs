//! Why a command failed: one variant per cause, each printed as one readable line after
//! `error: `.

use crate::film::FilmError;
use crate::scene::Effect;
use crate::scene_file::SceneError;
use crate::simd::SimdUnavailable;
use std::path::PathBuf;

/// A command-line failure. Its `Display` is the whole message, one line.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The scene file, an asset it names or a `--set` override could not be loaded.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// An image could not be read, written or compared, or its name has no known format.
    #[error(transparent)]
    Film(#[from] FilmError),
    /// The lane width asked for does not run on this CPU.
    #[error(transparent)]
    Simd(#[from] SimdUnavailable),
    /// `--budget` is not a positive number of seconds.
    #[error("--budget must be a positive number of seconds, got {0}")]
    Budget(f64),
    /// `--time-limit` is not a positive number of seconds.
    #[error("--time-limit must be a positive number of seconds, got {0}")]
    TimeLimit(f64),
    /// `--target-error` is not a relative MSE in (0, 1].
    #[error("--target-error must be a relative MSE in (0, 1], e.g. 0.01, got {0}")]
    TargetError(f64),
    /// `--batch` whose sample range runs past the last 32-bit sample index.
    #[error("--batch must be in 0..=255 (batch B draws sample indices from B·2²⁴), got {0}")]
    Batch(u32),
    /// `--sample-offset` plus the samples per pixel passes the last 32-bit sample index.
    #[error(
        "--sample-offset {offset} with {spp} samples per pixel runs past sample index \
         4294967295 (sample indices are 32-bit)"
    )]
    SampleRange {
        /// The first sample index.
        offset: u32,
        /// Samples per pixel.
        spp: u32,
    },
    /// `--threads` outside 1..=1024 (`MAX_THREADS`).
    #[error("--threads must be in 1..=1024, got {0}")]
    Threads(usize),
    /// The pool of worker threads could not be started.
    #[error("cannot start worker threads: {0}")]
    ThreadPool(#[source] rayon::ThreadPoolBuildError),
    /// `--force` names no effect.
    #[error("--force {0}: unknown effect; valid: {names}", names = effect_names())]
    UnknownEffect(String),
    /// `--force` names an effect this build does not simulate (the message of
    /// `Effects::force`).
    #[error("{0}")]
    Force(String),
    /// A study (`converge`, `costs`) failed; the message is the study's own.
    #[error("{0}")]
    Report(String),
    /// The `--frames` output template has no run of `#` for the frame number.
    #[error(
        "with --frames, the output '{}' needs a run of '#' for the frame number, e.g. out/frame_####.png",
        .0.display()
    )]
    FrameTemplate(PathBuf),
    /// SIGINT or SIGTERM stopped the render: a still is written with the samples it has
    /// (`written`), a frame series drops the frame in flight.
    #[error("{}", interrupted_message(.name, .written.as_deref(), *.series, *.spp, *.asked))]
    Interrupted {
        /// The signal's number (the exit status is 128 + it).
        signal: i32,
        /// The signal's name.
        name: &'static str,
        /// The still written, marked incomplete, if any samples were done.
        written: Option<PathBuf>,
        /// A frame series was stopped.
        series: bool,
        /// Samples per pixel in it.
        spp: u32,
        /// Samples per pixel asked for.
        asked: u32,
    },
    /// The GIF of a frame range could not be encoded.
    #[error("cannot write '{}': {error}", .path.display())]
    Gif {
        /// The GIF being written.
        path: PathBuf,
        /// What the encoder reported.
        #[source]
        error: image::ImageError,
    },
    /// `--shard-from-env` without `--shard-count`.
    #[error("--shard-from-env {var} needs --shard-count N (the number of shards)")]
    ShardCountMissing {
        /// The environment variable named.
        var: String,
    },
    /// The shard index's environment variable is not set (or not Unicode).
    #[error("--shard-from-env: environment variable {var} is not set")]
    ShardEnvUnset {
        /// The environment variable named.
        var: String,
        /// Why it could not be read.
        #[source]
        error: std::env::VarError,
    },
    /// The shard index's environment variable holds no whole number.
    #[error("--shard-from-env: {var}='{value}' is not a shard index (a whole number)")]
    ShardIndex {
        /// The environment variable named.
        var: String,
        /// Its value.
        value: String,
        /// Why it does not parse.
        #[source]
        error: std::num::ParseIntError,
    },
    /// The shard index is not below the shard count.
    #[error("--shard-from-env: {var}={index} is outside 0..{count} (--shard-count {count})")]
    ShardOutOfRange {
        /// The environment variable named.
        var: String,
        /// The index it holds.
        index: u32,
        /// `--shard-count`.
        count: u32,
    },
    /// `merge` without parts.
    #[error("merge needs at least one part")]
    MergeNoParts,
    /// A merge part lacks prism's sample-range header (not an EXR rendered by prism).
    #[error(
        "'{}' has no prism:spp / prism:sample_offset / prism:scene_hash header: only EXR files rendered by prism can be merged",
        .0.display()
    )]
    MergeNoHeader(PathBuf),
    /// Two merge parts were rendered with different `--force` settings (`prism:settings`).
    #[error(
        "'{}' and '{}' were rendered with different --force settings (prism:settings differ)",
        .first.display(),
        .other.display()
    )]
    MergeSettings {
        /// The first part.
        first: PathBuf,
        /// The part whose settings differ.
        other: PathBuf,
    },
    /// Two merge parts come from different scenes or settings.
    #[error(
        "'{}' and '{}' come from different scenes or settings (scene hash {first_hash:#018x} vs {other_hash:#018x})",
        .first.display(),
        .other.display()
    )]
    MergeScenes {
        /// The first part.
        first: PathBuf,
        /// The part that differs from it.
        other: PathBuf,
        /// The first part's `prism:scene_hash`.
        first_hash: u64,
        /// The other part's `prism:scene_hash`.
        other_hash: u64,
    },
    /// Two merge parts were rendered at different lane widths.
    #[error(
        "'{}' was rendered at lane width {first_width} but '{}' at {other_width}: widths round differently, so render every part with the same --simd",
        .first.display(),
        .other.display()
    )]
    MergeWidths {
        /// The first part.
        first: PathBuf,
        /// The part that differs from it.
        other: PathBuf,
        /// The first part's lane width.
        first_width: u32,
        /// The other part's lane width.
        other_width: u32,
    },
    /// Two merge parts differ in size.
    #[error(
        "'{}' is {}x{} but '{}' is {}x{}",
        .first.display(),
        .first_size.0,
        .first_size.1,
        .other.display(),
        .other_size.0,
        .other_size.1
    )]
    MergeSizes {
        /// The first part.
        first: PathBuf,
        /// Its width and height in pixels.
        first_size: (u32, u32),
        /// The part that differs from it.
        other: PathBuf,
        /// Its width and height in pixels.
        other_size: (u32, u32),
    },
    /// Two merge parts cover some of the same samples.
    #[error(
        "'{}' (samples {}..{}) and '{}' (samples {}..{}) overlap: they would count the same samples twice",
        .first.display(),
        .first_samples.0,
        .first_samples.1,
        .second.display(),
        .second_samples.0,
        .second_samples.1
    )]
    MergeOverlap {
        /// The part whose range starts first.
        first: PathBuf,
        /// Its sample range, end excluded.
        first_samples: (u64, u64),
        /// The part starting inside that range.
        second: PathBuf,
        /// Its sample range, end excluded.
        second_samples: (u64, u64),
    },
    /// The merge parts leave a gap in the sample range.
    #[error(
        "samples {}..{} are missing between '{}' and '{}'",
        .missing.0,
        .missing.1,
        .before.display(),
        .after.display()
    )]
    MergeGap {
        /// The samples no part covers, end excluded.
        missing: (u64, u64),
        /// The part ending before the gap.
        before: PathBuf,
        /// The part starting after it.
        after: PathBuf,
    },
    /// The merged sample count does not fit the image header's u32.
    #[error("merged sample count {0} is too large")]
    MergeTooLarge(u64),
    /// `--asset-root` is not a folder.
    #[error("--asset-root '{}' is not a folder", .0.display())]
    AssetRoot(PathBuf),
    /// A part holds no samples: its pixels are not an estimate of anything.
    #[error("'{}' holds no samples (prism:spp = 0): leave it out of the merge", .0.display())]
    MergeEmptyPart(PathBuf),
}

/// The names `--force` accepts, comma-separated.
impl CliError {
    /// The process exit status for this failure: 128 + the signal's number for a render a
    /// signal stopped (as a shell reports a process the signal killed), 1 otherwise.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Interrupted { signal, .. } => u8::try_from(128 + signal).unwrap_or(1),
            _ => 1,
        }
    }
}

fn interrupted_message(
    name: &str,
    written: Option<&std::path::Path>,
    series: bool,
    spp: u32,
    asked: u32,
) -> String {
    match written {
        Some(p) => format!(
            "interrupted by {name}: wrote '{}' with {spp} of {asked} samples per pixel, \
             marked incomplete (prism:complete = 0)",
            p.display()
        ),
        None if series => format!(
            "interrupted by {name}: the frames written are complete, the one in flight was \
             dropped; run again with --resume to finish the series"
        ),
        None => format!("interrupted by {name} before any pass finished: nothing written"),
    }
}

fn effect_names() -> String {
    Effect::ALL
        .iter()
        .map(|e| e.name().to_ascii_lowercase())
        .collect::<Vec<_>>()
        .join(", ")
}
