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
pub mod signals;
mod srgb;
#[cfg(test)]
mod tests;

use std::path::Path;

pub use atomic::{STALE_AFTER, sweep, write_atomic};
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
    /// Whether the render finished as asked (`prism:complete`, 1 or 0): every sample, or as
    /// many as its time limit allowed. A render stopped by a signal writes what it has with
    /// its true `spp` and 0 here. Files without the attribute count as complete.
    pub complete: bool,
    /// Hash of the command-line settings that change pixels but are not part of the scene
    /// (`prism:settings`: forced effects, PNG exposure), so `--resume` can tell a frame
    /// rendered otherwise. `None` when unknown.
    pub settings: Option<u64>,
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
/// `1` for a finished render, `0` for one stopped by a signal (optional; absent means 1).
pub const ATTR_COMPLETE: &str = "prism:complete";
/// [`ImageMeta::settings`] as `0x` and 16 hex digits (optional).
pub const ATTR_SETTINGS: &str = "prism:settings";

impl ImageMeta {
    /// The header attributes of `self`, in the order they are written: names and text values,
    /// the same in EXR headers and PNG text chunks.
    pub fn attributes(&self) -> Vec<(&'static str, String)> {
        let mut v = vec![
            (ATTR_SPP, self.spp.to_string()),
            (ATTR_SAMPLE_OFFSET, self.sample_offset.to_string()),
            (ATTR_SCENE_HASH, format!("{:#018x}", self.scene_hash)),
            (ATTR_COMPLETE, u8::from(self.complete).to_string()),
        ];
        if let Some(w) = self.simd {
            v.push((ATTR_SIMD, w.to_string()));
        }
        if let Some(h) = self.settings {
            v.push((ATTR_SETTINGS, format!("{h:#018x}")));
        }
        v
    }

    /// Metadata from header attributes looked up by `text`: `None` unless `prism:spp`,
    /// `prism:sample_offset` and `prism:scene_hash` are present and parse.
    pub fn from_attributes(text: impl Fn(&str) -> Option<String>) -> Option<ImageMeta> {
        let hash = |t: String| parse_hash(&t);
        Some(ImageMeta {
            spp: text(ATTR_SPP)?.trim().parse().ok()?,
            sample_offset: text(ATTR_SAMPLE_OFFSET)?.trim().parse().ok()?,
            scene_hash: hash(text(ATTR_SCENE_HASH)?)?,
            simd: text(ATTR_SIMD).and_then(|t| t.trim().parse().ok()),
            complete: text(ATTR_COMPLETE).is_none_or(|t| t.trim() != "0"),
            settings: text(ATTR_SETTINGS).and_then(hash),
        })
    }
}

/// A hash written as hex digits, with or without `0x`.
fn parse_hash(s: &str) -> Option<u64> {
    let s = s.trim();
    let digits = s
        .strip_prefix("0x")
        .or_else(|| s.strip_prefix("0X"))
        .unwrap_or(s);
    u64::from_str_radix(digits, 16).ok()
}

/// Output formats [`write_image`] can produce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit sRGB preview, clamped after [`PngOptions::exposure`]; [`ImageMeta`] as text
    /// chunks.
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
/// EXR stores the exact floats and `meta` as header attributes; PNG stores the 8-bit preview
/// after `png`'s exposure, with `meta` as text chunks. The file is encoded in memory, written
/// to a hidden temporary file in the target directory and renamed over `path`, so readers see
/// either the old file or the complete new one, and a failure leaves neither a partial target
/// nor a temporary file. A missing parent directory is created (as `mkdir -p` would), since
/// output paths like `out/run1/x.exr` are routinely fresh.
pub fn write_image(
    path: &Path,
    img: &Image,
    meta: &ImageMeta,
    png: &PngOptions,
) -> Result<(), FilmError> {
    write_image_aux(path, img, meta, png, &AuxChannels::default())
}

/// The EXR channel of an adaptive render's per-pixel sample counts (u32).
pub const CHANNEL_COUNT: &str = "count";
/// The EXR channel of an adaptive render's per-pixel estimated relMSE (f32).
pub const CHANNEL_ERROR: &str = "error";

/// Per-pixel channels an EXR carries besides R, G and B (a PNG has no room for them).
#[derive(Clone, Copy, Debug, Default)]
pub struct AuxChannels<'a> {
    /// Samples in each pixel ([`CHANNEL_COUNT`]).
    pub count: Option<&'a [u32]>,
    /// Each pixel's estimated relMSE ([`CHANNEL_ERROR`]).
    pub error: Option<&'a [f32]>,
}

/// The [`AuxChannels`] read back from a file (`None` where absent).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Aux {
    /// Samples in each pixel.
    pub count: Option<Vec<u32>>,
    /// Each pixel's estimated relMSE.
    pub error: Option<Vec<f32>>,
}

/// [`write_image`] with extra per-pixel channels, written to EXR files only.
pub fn write_image_aux(
    path: &Path,
    img: &Image,
    meta: &ImageMeta,
    png: &PngOptions,
    aux: &AuxChannels,
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
        ImageFormat::Png => raster::encode_png(path, img, meta, png)?,
        ImageFormat::Exr => exr::encode_exr_aux(path, img, meta, aux)?,
    };
    write_atomic(path, &bytes)
}

/// An image file's size and provenance, read from its header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageHeader {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The `prism:*` attributes (EXR) or text chunks (PNG), if the file has them.
    pub meta: Option<ImageMeta>,
}

/// The size and provenance of a PNG or EXR file written by [`write_image`], without decoding
/// its pixels: what `--resume` checks before it keeps a frame.
pub fn read_header(path: &Path) -> Result<ImageHeader, FilmError> {
    let format = ImageFormat::from_path(path)?;
    // Both formats put what is read here first (the PNG text chunks before the pixels).
    let bytes = crate::files::read_prefix(path, 1 << 20).map_err(|error| FilmError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    let (width, height, meta) = match format {
        ImageFormat::Png => raster::png_header(path, &bytes)?,
        ImageFormat::Exr => exr::exr_header(path, &bytes)?,
    };
    Ok(ImageHeader {
        width,
        height,
        meta,
    })
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
    read_image_aux(path).map(|(i, m, _)| (i, m))
}

/// [`read_image`], with an EXR's [`Aux`] channels (empty for other formats).
pub fn read_image_aux(path: &Path) -> Result<(Image, Option<ImageMeta>, Aux), FilmError> {
    let format = ReadFormat::from_path(path)?;
    let bytes =
        crate::files::read_bounded(path, crate::files::MAX_IMAGE_BYTES).map_err(|error| {
            FilmError::Read {
                path: path.to_path_buf(),
                error,
            }
        })?;
    match format {
        ReadFormat::Exr => exr::decode_exr_aux(path, bytes),
        ReadFormat::Raster(f) => {
            decode_raster(path, bytes, f, ColorSpace::Srgb).map(|i| (i, None, Aux::default()))
        }
    }
}
