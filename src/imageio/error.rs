//! Errors of image I/O, each naming the file(s) involved.

use std::io;
use std::path::{Path, PathBuf};

/// Errors from image I/O and comparison. Every message names the file(s)
/// involved; in-memory images without a path are called "image"/"reference".
#[derive(Debug, thiserror::Error)]
pub enum FilmError {
    #[error("'{path}': unsupported image format ({found}); supported extensions: {supported}")]
    UnsupportedFormat {
        path: PathBuf,
        found: String,
        supported: &'static str,
    },
    #[error("cannot create directory '{dir}' for '{path}': {}", io_reason(.error))]
    CreateDir {
        dir: PathBuf,
        path: PathBuf,
        error: io::Error,
    },
    #[error("cannot write '{path}': {}", io_reason(.error))]
    Write { path: PathBuf, error: io::Error },
    #[error("cannot read '{path}': {}", io_reason(.error))]
    Read { path: PathBuf, error: io::Error },
    #[error("cannot encode '{path}': {message}")]
    Encode { path: PathBuf, message: String },
    #[error("cannot decode '{path}': {message}")]
    Decode { path: PathBuf, message: String },
    #[error("'{path}' has no '{channel}' channel (channels present: {present})")]
    MissingChannel {
        path: PathBuf,
        channel: &'static str,
        present: String,
    },
    #[error(
        "{}: {width}×{height} needs {} pixels but the buffer holds {len}",
        label(.path.as_deref(), "image"),
        *.width as u64 * *.height as u64
    )]
    BadBuffer {
        path: Option<PathBuf>,
        width: u32,
        height: u32,
        len: usize,
    },
    #[error("cannot write '{path}': image is {width}×{height}; both sides must be non-zero")]
    EmptyImage {
        path: PathBuf,
        width: u32,
        height: u32,
    },
    #[error(
        "{} is {}×{} but {} is {}×{}",
        label(.a.as_deref(), "image"), .a_size.0, .a_size.1,
        label(.b.as_deref(), "reference"), .b_size.0, .b_size.1
    )]
    SizeMismatch {
        a: Option<PathBuf>,
        a_size: (u32, u32),
        b: Option<PathBuf>,
        b_size: (u32, u32),
    },
}

/// `'path'` when known, else a generic noun.
fn label(path: Option<&Path>, fallback: &str) -> String {
    match path {
        Some(p) => format!("'{}'", p.display()),
        None => fallback.to_owned(),
    }
}

/// An OS error as a short lowercase phrase ("permission denied") that reads
/// well after "cannot write 'x': "; the OS error number adds nothing there.
pub(crate) fn io_reason(error: &io::Error) -> String {
    let text = error.to_string();
    let text = match text.rfind(" (os error ") {
        Some(i) if text.ends_with(')') => &text[..i],
        _ => &text,
    };
    let mut chars = text.chars();
    match chars.next() {
        Some(first) => first.to_lowercase().chain(chars).collect(),
        None => String::new(),
    }
}
