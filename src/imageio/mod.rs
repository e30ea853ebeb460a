//! Image files: the linear RGB image type, reading and writing PNG, EXR (with provenance), JPEG
//! and Radiance HDR, and atomic writes. The film writes renders through it and textures decode
//! their images through it, so neither depends on the other for file formats.
//!
//! Renders are kept as linear-light `f32` RGB. Two output formats are
//! supported: OpenEXR keeps the exact floats plus provenance metadata (so
//! partial renders can be merged later), PNG is a tone-clamped 8-bit sRGB
//! preview. Reading additionally accepts JPEG and Radiance HDR so reference
//! images from other tools can be compared against.

mod atomic;
mod error;
mod exr;
mod raster;
mod srgb;
#[cfg(test)]
mod tests;

use std::path::Path;

pub use atomic::write_atomic;
pub use error::FilmError;
pub(crate) use error::io_reason;
pub use raster::{ColorSpace, PngOptions, decode_raster};
pub use srgb::{srgb_decode, srgb_encode};

/// The most pixels an image read from a file may have in all (2²⁸, e.g. 16384 × 16384 or
/// 32768 × 8192: 3 GiB as the f32 RGB it becomes) and per side. Checked against the file's
/// header before any pixel is decoded, so a small file claiming a huge image is refused with a
/// message rather than aborting the process.
pub const MAX_READ_PIXELS: u64 = 1 << 28;
/// See [`MAX_READ_PIXELS`].
pub const MAX_READ_SIDE: u64 = 32_768;

/// The error for an image file whose header claims `width` × `height` pixels, if that is more
/// than [`MAX_READ_SIDE`] per side or [`MAX_READ_PIXELS`] in all.
pub(crate) fn check_read_size(path: &Path, width: u64, height: u64) -> Result<(), FilmError> {
    match width.checked_mul(height) {
        Some(n) if n <= MAX_READ_PIXELS && width <= MAX_READ_SIDE && height <= MAX_READ_SIDE => {
            Ok(())
        }
        _ => Err(FilmError::Decode {
            path: path.to_path_buf(),
            message: format!(
                "its header claims {width}×{height} pixels; an image may have at most \
                 {MAX_READ_SIDE} per side and {MAX_READ_PIXELS} (16384×16384) in all"
            ),
        }),
    }
}

/// Linear-light RGB image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB, row-major, top row first, `width × height` entries.
    pub pixels: Vec<[f32; 3]>,
}

impl Image {
    /// A `width`×`height` image filled with `value`.
    pub fn filled(width: u32, height: u32, value: [f32; 3]) -> Self {
        Self {
            width,
            height,
            pixels: vec![value; width as usize * height as usize],
        }
    }

    /// Number of pixels implied by the dimensions (not by the buffer).
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Checks that the buffer length matches the dimensions; `path` only
    /// labels the error.
    pub fn validate(&self, path: Option<&Path>) -> Result<(), FilmError> {
        if self.pixels.len() == self.pixel_count() {
            Ok(())
        } else {
            Err(FilmError::BadBuffer {
                path: path.map(Path::to_path_buf),
                width: self.width,
                height: self.height,
                len: self.pixels.len(),
            })
        }
    }
}

/// Provenance stored in EXR headers so partial renders can be merged and
/// mismatched ones refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageMeta {
    /// Samples per pixel averaged into the image (`prism:spp`).
    pub spp: u32,
    /// Index of the first of those samples per pixel (`prism:sample_offset`): the image holds
    /// samples `sample_offset .. sample_offset + spp`, so merged parts must not overlap.
    pub sample_offset: u64,
    /// Hash of the scene text and every override except the sample count
    /// (`prism:scene_hash`): parts with different hashes come from different renders.
    pub scene_hash: u64,
    /// The lane width the samples were computed at (`prism:simd`): widths round differently,
    /// so parts of one image must agree on it. `None` when unknown.
    pub simd: Option<u32>,
}

/// Header attribute names for [`ImageMeta`].
///
/// EXR's only integer attribute type is a signed 32-bit `int`, which cannot
/// hold a `u64` (nor every `u32`), so all three are stored as *text*
/// attributes: `prism:spp` and `prism:sample_offset` in decimal,
/// `prism:scene_hash` as `0x` followed by 16 lowercase hex digits.
pub const ATTR_SPP: &str = "prism:spp";
/// See [`ATTR_SPP`].
pub const ATTR_SAMPLE_OFFSET: &str = "prism:sample_offset";
/// See [`ATTR_SPP`].
pub const ATTR_SCENE_HASH: &str = "prism:scene_hash";
/// The lane width, in decimal (optional: images from before it existed lack it).
pub const ATTR_SIMD: &str = "prism:simd";

/// Output formats [`write_image`] can produce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit sRGB preview, clamped after [`PngOptions::exposure`]; no metadata.
    Png,
    /// 32-bit float linear RGB with [`ImageMeta`] in the header: exact, mergeable.
    Exr,
}

const WRITE_EXTENSIONS: &str = ".png, .exr";
const READ_EXTENSIONS: &str = ".exr, .png, .jpg, .jpeg, .hdr";

impl ImageFormat {
    /// Picks the output format from the file extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self, FilmError> {
        match lowercase_extension(path).as_deref() {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            _ => Err(unsupported(path, WRITE_EXTENSIONS)),
        }
    }
}

/// What [`read_image`] accepts; wider than [`ImageFormat`] because references
/// may come from other renderers or photo tools.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ReadFormat {
    Exr,
    /// Decoded by the `image` crate: PNG, JPEG (sRGB) or Radiance HDR
    /// (linear).
    Raster(image::ImageFormat),
}

impl ReadFormat {
    fn from_path(path: &Path) -> Result<Self, FilmError> {
        match lowercase_extension(path).as_deref() {
            Some("exr") => Ok(Self::Exr),
            Some("png") => Ok(Self::Raster(image::ImageFormat::Png)),
            Some("jpg" | "jpeg") => Ok(Self::Raster(image::ImageFormat::Jpeg)),
            Some("hdr") => Ok(Self::Raster(image::ImageFormat::Hdr)),
            _ => Err(unsupported(path, READ_EXTENSIONS)),
        }
    }
}

fn lowercase_extension(path: &Path) -> Option<String> {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
}

fn unsupported(path: &Path, supported: &'static str) -> FilmError {
    FilmError::UnsupportedFormat {
        path: path.to_path_buf(),
        found: match path.extension() {
            Some(e) => format!("'.{}'", e.to_string_lossy()),
            None => "no extension".to_owned(),
        },
        supported,
    }
}

/// Writes `img` to `path`; the format comes from the extension.
///
/// EXR stores the exact floats and `meta`; PNG ignores `meta` and applies
/// `png`. The file is encoded in memory, written to a hidden temporary file
/// in the target directory and renamed over `path`, so readers see either
/// the old file or the complete new one, and a failure leaves neither a
/// partial target nor a temporary file. A missing parent directory is
/// created (as `mkdir -p` would), since output paths like `out/run1/x.exr`
/// are routinely fresh.
pub fn write_image(
    path: &Path,
    img: &Image,
    meta: &ImageMeta,
    png: &PngOptions,
) -> Result<(), FilmError> {
    let format = ImageFormat::from_path(path)?;
    img.validate(Some(path))?;
    if img.width == 0 || img.height == 0 {
        return Err(FilmError::EmptyImage {
            path: path.to_path_buf(),
            width: img.width,
            height: img.height,
        });
    }
    let bytes = match format {
        ImageFormat::Png => raster::encode_png(path, img, png)?,
        ImageFormat::Exr => exr::encode_exr(path, img, meta)?,
    };
    write_atomic(path, &bytes)
}

/// Reads an image as linear RGB, choosing the decoder by extension.
///
/// - EXR: the first layer with `R`, `G` and `B` channels (f16, f32 or u32
///   samples; alpha and other channels ignored). Metadata is returned when
///   all three `prism:*` attributes are present and parse.
/// - PNG / JPEG: sRGB-encoded samples are decoded with [`srgb_decode`];
///   alpha is dropped. Metadata is `None`.
/// - HDR (Radiance): already linear, returned as is. Metadata is `None`.
pub fn read_image(path: &Path) -> Result<(Image, Option<ImageMeta>), FilmError> {
    let format = ReadFormat::from_path(path)?;
    let bytes =
        crate::files::read_bounded(path, crate::files::MAX_IMAGE_BYTES).map_err(|error| {
            FilmError::Read {
                path: path.to_path_buf(),
                error,
            }
        })?;
    match format {
        ReadFormat::Exr => exr::decode_exr(path, bytes),
        ReadFormat::Raster(f) => decode_raster(path, bytes, f, ColorSpace::Srgb).map(|i| (i, None)),
    }
}
