//! Errors of image I/O, each naming the file(s) involved.

use std::io;
use std::path::{Path, PathBuf};

/// Errors from image I/O and comparison. Every message names the file(s)
/// involved; in-memory images without a path are called "image"/"reference".
#[derive(Debug, thiserror::Error)]
pub enum FilmError {
    /// The file's extension names no format this operation handles (writes take `.png` and
    /// `.exr`; reads also `.jpg`, `.jpeg` and `.hdr`).
    #[error("'{path}': unsupported image format ({found}); supported extensions: {supported}")]
    UnsupportedFormat {
        /// The file that was to be read or written.
        path: PathBuf,
        /// The extension as written, quoted, or "no extension".
        found: String,
        /// The extensions the operation accepts, comma-separated.
        supported: &'static str,
    },
    /// The missing parent directory of a file being written could not be created.
    #[error("cannot create directory '{dir}' for '{path}': {}", io_reason(.error))]
    CreateDir {
        /// The directory that could not be created.
        dir: PathBuf,
        /// The file that was to be written into it.
        path: PathBuf,
        /// The OS error.
        error: io::Error,
    },
    /// Writing the temporary file, flushing it to disk or renaming it over the target failed,
    /// or the path names no file; the target is left as it was.
    #[error("cannot write '{path}': {}", io_reason(.error))]
    Write {
        /// The target file.
        path: PathBuf,
        /// The OS error.
        error: io::Error,
    },
    /// The file could not be opened or read.
    #[error("cannot read '{path}': {}", io_reason(.error))]
    Read {
        /// The file being read.
        path: PathBuf,
        /// The OS error.
        error: io::Error,
    },
    /// The PNG or EXR encoder refused the image.
    #[error("cannot encode '{path}': {}", one_line(.message))]
    Encode {
        /// The file that was to be written.
        path: PathBuf,
        /// The encoder's message.
        message: String,
    },
    /// The file's contents are not a valid image of its format, or are valid but unsupported
    /// (subsampled EXR channels, sides beyond `u32`).
    #[error("cannot decode '{path}': {}", one_line(.message))]
    Decode {
        /// The file being read.
        path: PathBuf,
        /// The decoder's message, or what is unsupported.
        message: String,
    },
    /// No layer of an EXR file has all of the `R`, `G` and `B` channels.
    #[error("'{path}' has no '{channel}' channel (channels present: {present})")]
    MissingChannel {
        /// The EXR file.
        path: PathBuf,
        /// The first of `R`, `G`, `B` that the first layer lacks.
        channel: &'static str,
        /// The first layer's channel names, comma-separated, or "none".
        present: String,
    },
    /// An [`Image`](super::Image)'s pixel buffer does not hold `width × height` pixels.
    #[error(
        "{}: {width}×{height} needs {} pixels but the buffer holds {len}",
        label(.path.as_deref(), "image"),
        *.width as u64 * *.height as u64
    )]
    BadBuffer {
        /// The file the image is written to or came from; `None` for an image in memory.
        path: Option<PathBuf>,
        /// The image's width in pixels.
        width: u32,
        /// The image's height in pixels.
        height: u32,
        /// The number of pixels the buffer actually holds.
        len: usize,
    },
    /// An image with a zero width or height was to be written.
    #[error("cannot write '{path}': image is {width}×{height}; both sides must be non-zero")]
    EmptyImage {
        /// The file that was to be written.
        path: PathBuf,
        /// The image's width in pixels.
        width: u32,
        /// The image's height in pixels.
        height: u32,
    },
    /// Two images being compared differ in size.
    #[error(
        "{} is {}×{} but {} is {}×{}",
        label(.a.as_deref(), "image"), .a_size.0, .a_size.1,
        label(.b.as_deref(), "reference"), .b_size.0, .b_size.1
    )]
    SizeMismatch {
        /// The compared image's file; `None` for an image in memory.
        a: Option<PathBuf>,
        /// The compared image's (width, height) in pixels.
        a_size: (u32, u32),
        /// The reference's file; `None` for an image in memory.
        b: Option<PathBuf>,
        /// The reference's (width, height) in pixels.
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

/// A decoder's message on one line: some end theirs with a newline or spread it over several.
fn one_line(message: &str) -> String {
    let lines: Vec<&str> = message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    lines.join("; ")
}
