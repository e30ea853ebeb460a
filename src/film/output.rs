//! Reading and writing rendered images.
//!
//! Renders are kept as linear-light `f32` RGB. Two output formats are
//! supported: OpenEXR keeps the exact floats plus provenance metadata (so
//! partial renders can be merged later), PNG is a tone-clamped 8-bit sRGB
//! preview. Reading additionally accepts JPEG and Radiance HDR so reference
//! images from other tools can be compared against.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Cursor, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use exr::prelude::{self as ex, ReadChannels, ReadLayers, WritableImage};

/// Linear-light RGB image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
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
    pub spp: u32,
    pub sample_offset: u64,
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

/// Output formats `write_image` can produce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
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

/// What `read_image` accepts; wider than [`ImageFormat`] because references
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
pub(crate) fn label(path: Option<&Path>, fallback: &str) -> String {
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

/// Settings for the 8-bit PNG preview.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PngOptions {
    /// Exposure in stops: pixels are multiplied by `2^exposure` before
    /// clamping.
    pub exposure: f32,
}

/// sRGB opto-electronic transfer function (IEC 61966-2-1), linear → encoded.
///
/// Values at or below the 0.0031308 breakpoint (including negatives) take
/// the linear segment, so the result is never NaN for finite input.
pub fn srgb_encode(linear: f32) -> f32 {
    // Branch on the f32 value so an input of exactly `0.0031308_f32` is on
    // the linear segment (widened to f64 it is slightly larger); evaluate in
    // f64 to keep the round trip with `srgb_decode` well inside 1e-6.
    let l = f64::from(linear);
    let e = if linear <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    e as f32
}

/// Inverse of [`srgb_encode`], encoded → linear, breakpoint 0.04045.
pub fn srgb_decode(encoded: f32) -> f32 {
    let e = f64::from(encoded);
    let l = if encoded <= 0.040_45 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    };
    l as f32
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
        ImageFormat::Png => encode_png(path, img, png)?,
        ImageFormat::Exr => encode_exr(path, img, meta)?,
    };
    write_atomic(path, &bytes)
}

fn encode_png(path: &Path, img: &Image, opts: &PngOptions) -> Result<Vec<u8>, FilmError> {
    use image::ImageEncoder;

    let scale = opts.exposure.exp2();
    let to_byte = |v: f32| -> u8 {
        if !v.is_finite() {
            return 0;
        }
        let scaled = v * scale;
        // NaN can still appear (0 × ∞ for absurd exposures); treat as black.
        if scaled.is_nan() {
            return 0;
        }
        (srgb_encode(scaled.clamp(0.0, 1.0)) * 255.0).round() as u8
    };
    let raw: Vec<u8> = img.pixels.iter().flat_map(|p| p.map(to_byte)).collect();

    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&raw, img.width, img.height, image::ExtendedColorType::Rgb8)
        .map_err(|e| FilmError::Encode {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    Ok(out)
}

fn encode_exr(path: &Path, img: &Image, meta: &ImageMeta) -> Result<Vec<u8>, FilmError> {
    let width = img.width as usize;
    let size = (width, img.height as usize);
    let pixels = &img.pixels;
    let channels = ex::SpecificChannels::rgb(move |pos: ex::Vec2<usize>| {
        let [r, g, b] = pixels[pos.y() * width + pos.x()];
        (r, g, b)
    });

    let mut attributes = ex::LayerAttributes::default();
    for (name, value) in [
        (ATTR_SPP, meta.spp.to_string()),
        (ATTR_SAMPLE_OFFSET, meta.sample_offset.to_string()),
        (ATTR_SCENE_HASH, format!("{:#018x}", meta.scene_hash)),
    ]
    .into_iter()
    .chain(meta.simd.map(|w| (ATTR_SIMD, w.to_string())))
    {
        attributes.other.insert(
            ex::Text::from(name),
            ex::AttributeValue::Text(ex::Text::from(value.as_str())),
        );
    }

    // ZIP over 16-line blocks: lossless, compact, and readable everywhere.
    let layer = ex::Layer::new(size, attributes, ex::Encoding::SMALL_LOSSLESS, channels);
    let mut out = Cursor::new(Vec::new());
    ex::Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .map_err(|e| FilmError::Encode {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let mut bytes = out.into_inner();
    sort_exr_header(&mut bytes);
    Ok(bytes)
}

/// Puts the attributes of a single-part EXR header in name order, as OpenEXR writes them. The
/// `exr` crate writes custom attributes from a `HashMap`, in an order that changes from run to
/// run, so the same image came out as different bytes. The attributes only move within the
/// header, whose length stays the same, so the offsets after it still hold. Anything that does
/// not parse as expected (multi-part or deep files) is left as it is.
fn sort_exr_header(bytes: &mut [u8]) {
    let Some(mut attrs) = exr_header_attributes(bytes) else {
        return;
    };
    let (Some(first), Some(last)) = (attrs.first(), attrs.last()) else {
        return;
    };
    let (header_start, header_end) = (first.start, last.end);
    attrs.sort_by(|a, b| bytes[a.start..a.name_end].cmp(&bytes[b.start..b.name_end]));
    let header: Vec<u8> = attrs
        .iter()
        .flat_map(|a| bytes[a.start..a.end].iter().copied())
        .collect();
    bytes[header_start..header_end].copy_from_slice(&header);
}

/// Where an attribute of an EXR header lies: its name is `start..name_end`, the whole
/// attribute (name, type, size, value) `start..end`.
struct ExrAttribute {
    start: usize,
    name_end: usize,
    end: usize,
}

/// The attributes of a single-part EXR header in file order; `None` for multi-part or deep
/// files, or bytes that do not parse as a header.
fn exr_header_attributes(bytes: &[u8]) -> Option<Vec<ExrAttribute>> {
    const MULTIPART_OR_DEEP: u32 = (1 << 11) | (1 << 12);
    let word = |at: usize| -> Option<[u8; 4]> { bytes.get(at..at + 4)?.try_into().ok() };
    if u32::from_le_bytes(word(4)?) & MULTIPART_OR_DEEP != 0 {
        return None;
    }
    let nul = |from: usize| Some(from + bytes.get(from..)?.iter().position(|&b| b == 0)?);
    // Each attribute: name, NUL, type, NUL, a 4-byte little-endian size, the value; a NUL
    // where the next name would start ends the header.
    let mut attrs = Vec::new();
    let mut at = 8;
    while *bytes.get(at)? != 0 {
        let name_end = nul(at)?;
        let type_end = nul(name_end + 1)?;
        let size = usize::try_from(i32::from_le_bytes(word(type_end + 1)?)).ok()?;
        let end = type_end + 5 + size;
        if end > bytes.len() {
            return None;
        }
        attrs.push(ExrAttribute {
            start: at,
            name_end,
            end,
        });
        at = end;
    }
    Some(attrs)
}

/// Distinguishes temporary files of concurrent writes from one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`: a reader
/// never sees a partial file, and an interrupted write leaves no file with the final name.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FilmError> {
    let write_err = |error| FilmError::Write {
        path: path.to_path_buf(),
        error,
    };
    let Some(file_name) = path.file_name() else {
        return Err(write_err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "path has no file name",
        )));
    };
    // `Path::parent` of a bare file name is "", which means the cwd.
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    fs::create_dir_all(dir).map_err(|error| FilmError::CreateDir {
        dir: dir.to_path_buf(),
        path: path.to_path_buf(),
        error,
    })?;

    // Same directory as the target so the rename stays on one filesystem
    // (and is therefore atomic); hidden so it does not look like output.
    // `create_new` never clobbers a file we did not create.
    let (tmp_path, file) = loop {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let name = format!(
            ".{}.tmp-{}-{n}",
            file_name.to_string_lossy(),
            std::process::id()
        );
        let candidate = dir.join(name);
        match OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&candidate)
        {
            Ok(f) => break (candidate, f),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(write_err(e)),
        }
    };

    let result = finish_temp(file, bytes, &tmp_path, path);
    if let Err(error) = result {
        // Best effort: the original error is what matters to the caller.
        let _ = fs::remove_file(&tmp_path);
        return Err(write_err(error));
    }
    sync_dir(dir);
    Ok(())
}

fn finish_temp(mut file: File, bytes: &[u8], tmp: &Path, target: &Path) -> io::Result<()> {
    file.write_all(bytes)?;
    // Data must be on disk before the rename makes it visible, or a crash
    // could leave a complete-looking but empty target.
    file.sync_all()?;
    drop(file);
    fs::rename(tmp, target)
}

/// Persists the rename itself; failure only weakens crash durability, so it
/// is ignored.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
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
    let bytes = fs::read(path).map_err(|error| FilmError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    match format {
        ReadFormat::Exr => decode_exr(path, bytes),
        ReadFormat::Raster(f) => decode_with_image(path, bytes, f).map(|i| (i, None)),
    }
}

fn decode_with_image(
    path: &Path,
    bytes: Vec<u8>,
    format: image::ImageFormat,
) -> Result<Image, FilmError> {
    let decode_err = |message: String| FilmError::Decode {
        path: path.to_path_buf(),
        message,
    };
    // Trust the content over the extension if they disagree.
    let reader = image::ImageReader::with_format(Cursor::new(bytes), format)
        .with_guessed_format()
        .map_err(|e| decode_err(e.to_string()))?;
    let decoded = reader.decode().map_err(|e| decode_err(e.to_string()))?;
    // Decide by what was decoded, not by the extension: float sources (HDR)
    // are linear already, integer ones (PNG, JPEG) are sRGB-encoded.
    let decode = !matches!(
        decoded.color(),
        image::ColorType::Rgb32F | image::ColorType::Rgba32F
    );
    let rgb = decoded.into_rgb32f();
    let (width, height) = rgb.dimensions();
    let pixels = rgb
        .pixels()
        .map(|p| if decode { p.0.map(srgb_decode) } else { p.0 })
        .collect();
    Ok(Image {
        width,
        height,
        pixels,
    })
}

fn decode_exr(path: &Path, bytes: Vec<u8>) -> Result<(Image, Option<ImageMeta>), FilmError> {
    let exr_image = ex::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| match e {
            ex::Error::Io(error) => FilmError::Read {
                path: path.to_path_buf(),
                error,
            },
            other => FilmError::Decode {
                path: path.to_path_buf(),
                message: other.to_string(),
            },
        })?;

    let find = |layer: &ex::Layer<ex::AnyChannels<ex::FlatSamples>>, name: &str| {
        layer.channel_data.list.iter().position(|c| c.name.eq(name))
    };
    let chosen = exr_image.layer_data.iter().find_map(|layer| {
        match (find(layer, "R"), find(layer, "G"), find(layer, "B")) {
            (Some(r), Some(g), Some(b)) => Some((layer, [r, g, b])),
            _ => None,
        }
    });
    let Some((layer, [r, g, b])) = chosen else {
        return Err(missing_channel(path, &exr_image.layer_data));
    };

    let list = &layer.channel_data.list;
    let (width, height) = (layer.size.width(), layer.size.height());
    let too_big = || FilmError::Decode {
        path: path.to_path_buf(),
        message: format!("{width}×{height} exceeds the supported image size"),
    };
    let w = u32::try_from(width).map_err(|_| too_big())?;
    let h = u32::try_from(height).map_err(|_| too_big())?;
    let pixels = list[r]
        .sample_data
        .values_as_f32()
        .zip(list[g].sample_data.values_as_f32())
        .zip(list[b].sample_data.values_as_f32())
        .map(|((r, g), b)| [r, g, b])
        .collect::<Vec<_>>();
    // Subsampled channels hold fewer samples than pixels; refuse rather than
    // misplace them.
    if pixels.len() != width * height {
        return Err(FilmError::Decode {
            path: path.to_path_buf(),
            message: "subsampled R, G or B channels are not supported".to_owned(),
        });
    }

    let attrs = [&layer.attributes.other, &exr_image.attributes.other];
    let text = |name: &str| {
        attrs.iter().find_map(|map| match map.get(name.as_bytes()) {
            Some(ex::AttributeValue::Text(t)) => Some(t.to_string()),
            _ => None,
        })
    };
    let meta = (|| {
        Some(ImageMeta {
            spp: text(ATTR_SPP)?.trim().parse().ok()?,
            sample_offset: text(ATTR_SAMPLE_OFFSET)?.trim().parse().ok()?,
            scene_hash: parse_hash(&text(ATTR_SCENE_HASH)?)?,
            simd: text(ATTR_SIMD).and_then(|t| t.trim().parse().ok()),
        })
    })();

    Ok((
        Image {
            width: w,
            height: h,
            pixels,
        },
        meta,
    ))
}

/// Hex with optional `0x`, the form `write_image` produces.
fn parse_hash(s: &str) -> Option<u64> {
    let s = s.trim();
    let digits = s
        .strip_prefix("0x")
        .or_else(|| s.strip_prefix("0X"))
        .unwrap_or(s);
    u64::from_str_radix(digits, 16).ok()
}

/// Reports the first of R, G, B that the first layer lacks, listing what it
/// does have so a mislabelled file (e.g. `Y`, or `beauty.R`) is obvious.
fn missing_channel(
    path: &Path,
    layers: &[ex::Layer<ex::AnyChannels<ex::FlatSamples>>],
) -> FilmError {
    let names: Vec<String> = layers
        .first()
        .map(|l| {
            l.channel_data
                .list
                .iter()
                .map(|c| c.name.to_string())
                .collect()
        })
        .unwrap_or_default();
    let channel = ["R", "G", "B"]
        .into_iter()
        .find(|c| !names.iter().any(|n| n == c))
        .unwrap_or("R");
    FilmError::MissingChannel {
        path: path.to_path_buf(),
        channel,
        present: if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(", ")
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const META: ImageMeta = ImageMeta {
        spp: 4096,
        sample_offset: 1 << 40,
        scene_hash: 0xfedc_ba98_7654_3210,
        simd: Some(16),
    };

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    /// Deterministic values spanning zero, denormal-ish, ordinary and huge.
    fn hdr_image() -> Image {
        let specials = [
            0.0, -0.0, 1e-38, 1.5e-45, 1e-7, 0.5, 1.0, 3.25, 65504.0, 1e20, 3.4e38,
        ];
        let (w, h) = (7, 5);
        let pixels = (0..w * h)
            .map(|i| {
                let f = |k: usize| {
                    specials[(i * 3 + k) % specials.len()] * if i % 4 == 1 { -1.0 } else { 1.0 }
                };
                [f(0), f(1), f(2) + i as f32 * 0.125]
            })
            .collect();
        Image {
            width: w as u32,
            height: h as u32,
            pixels,
        }
    }

    #[test]
    fn format_from_path_is_case_insensitive() {
        assert_eq!(
            ImageFormat::from_path(Path::new("a/b.png")).unwrap(),
            ImageFormat::Png
        );
        assert_eq!(
            ImageFormat::from_path(Path::new("B.PnG")).unwrap(),
            ImageFormat::Png
        );
        assert_eq!(
            ImageFormat::from_path(Path::new("x.EXR")).unwrap(),
            ImageFormat::Exr
        );
    }

    #[test]
    fn format_from_path_error_names_path_and_extensions() {
        let msg = ImageFormat::from_path(Path::new("out/x.tiff"))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("'out/x.tiff'"), "{msg}");
        assert!(
            msg.contains("'.tiff'") && msg.contains(".png") && msg.contains(".exr"),
            "{msg}"
        );
        let msg = ImageFormat::from_path(Path::new("noext"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("'noext'") && msg.contains("no extension"),
            "{msg}"
        );
    }

    #[test]
    fn srgb_matches_standard_breakpoints_and_values() {
        // Linear segment up to and including the breakpoints.
        assert!((srgb_encode(0.003_130_8) - 12.92 * 0.003_130_8).abs() < 1e-9);
        assert!((srgb_decode(0.040_45) - 0.040_45 / 12.92).abs() < 1e-9);
        assert_eq!(srgb_encode(0.0), 0.0);
        assert_eq!(srgb_decode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-7);
        assert!((srgb_decode(1.0) - 1.0).abs() < 1e-7);
        // Reference values from the closed-form curve.
        assert!((srgb_encode(0.18) - 0.461_356_13).abs() < 1e-6);
        assert!((srgb_encode(0.5) - 0.735_357).abs() < 1e-6);
        assert!((srgb_decode(0.5) - 0.214_041_14).abs() < 1e-6);
        // Both segments meet at the breakpoint (the curve is continuous).
        let below = srgb_encode(0.003_130_8);
        let above = srgb_encode(0.003_130_81);
        assert!(above > below && above - below < 1e-6);
        // Negative input stays on the linear segment instead of NaN.
        assert_eq!(srgb_encode(-0.5), -0.5 * 12.92);
    }

    #[test]
    fn srgb_encode_decode_are_inverse() {
        for i in 0..=10_000 {
            let x = i as f32 / 10_000.0;
            assert!((srgb_decode(srgb_encode(x)) - x).abs() <= 1e-6, "{x}");
            assert!((srgb_encode(srgb_decode(x)) - x).abs() <= 1e-6, "{x}");
        }
    }

    #[test]
    fn exr_round_trip_is_bit_exact_with_meta() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.exr");
        let img = hdr_image();
        write_image(&path, &img, &META, &PngOptions::default()).unwrap();
        let (back, meta) = read_image(&path).unwrap();
        assert_eq!((back.width, back.height), (img.width, img.height));
        for (a, b) in img.pixels.iter().zip(&back.pixels) {
            assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits));
        }
        assert_eq!(meta, Some(META));
    }

    #[test]
    fn exr_files_of_one_image_are_identical_bytes() {
        // Each encode fills a fresh hash map of attributes, whose order is random: unsorted,
        // eight encodes agree only by chance (odds about 1 in 6^7).
        let path = Path::new("same.exr");
        let first = encode_exr(path, &hdr_image(), &META).unwrap();
        for _ in 0..7 {
            assert_eq!(encode_exr(path, &hdr_image(), &META).unwrap(), first);
        }
        // The header is in name order and still reads back whole.
        let attrs = exr_header_attributes(&first).unwrap();
        let names: Vec<&[u8]> = attrs.iter().map(|a| &first[a.start..a.name_end]).collect();
        assert!(names.len() >= 6 && names.is_sorted(), "{names:?}");
        let (_, meta) = decode_exr(path, first).unwrap();
        assert_eq!(meta, Some(META));
    }

    #[test]
    fn exr_meta_extremes_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.exr");
        for meta in [
            ImageMeta {
                spp: 0,
                sample_offset: 0,
                scene_hash: 0,
                simd: None,
            },
            ImageMeta {
                spp: u32::MAX,
                sample_offset: u64::MAX,
                scene_hash: u64::MAX,
                simd: Some(u32::MAX),
            },
        ] {
            write_image(
                &path,
                &Image::filled(1, 1, [1.0; 3]),
                &meta,
                &PngOptions::default(),
            )
            .unwrap();
            assert_eq!(read_image(&path).unwrap().1, Some(meta));
        }
    }

    #[test]
    fn exr_meta_is_stored_as_text_attributes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.exr");
        write_image(
            &path,
            &Image::filled(2, 1, [0.0; 3]),
            &META,
            &PngOptions::default(),
        )
        .unwrap();
        let meta = ex::MetaData::read_from_file(&path, false).unwrap();
        let other = &meta.headers[0].own_attributes.other;
        let text = |n: &str| match other.get(n.as_bytes()) {
            Some(ex::AttributeValue::Text(t)) => t.to_string(),
            v => panic!("{n}: {v:?}"),
        };
        assert_eq!(text(ATTR_SPP), "4096");
        assert_eq!(text(ATTR_SAMPLE_OFFSET), "1099511627776");
        assert_eq!(text(ATTR_SCENE_HASH), "0xfedcba9876543210");
        assert_eq!(meta.headers[0].compression, ex::Compression::ZIP16);
    }

    /// Writes an EXR with the exr crate directly: f16 RGBA, no prism
    /// attributes, as another tool would.
    fn write_foreign_exr(path: &Path, with_blue: bool) {
        use ex::f16;
        let (w, h) = (3usize, 2usize);
        let val =
            |x: usize, y: usize, c: usize| f16::from_f32((y * w + x) as f32 + c as f32 * 0.25);
        let chan = |name: &str, c: usize| {
            let samples: Vec<f16> = (0..w * h).map(|i| val(i % w, i / w, c)).collect();
            ex::AnyChannel::new(name, ex::FlatSamples::F16(samples))
        };
        let mut list = ex::SmallVec::new();
        list.push(chan("R", 0));
        list.push(chan("G", 1));
        if with_blue {
            list.push(chan("B", 2));
        }
        list.push(chan("A", 3));
        let layer = ex::Layer::new(
            (w, h),
            ex::LayerAttributes::default(),
            ex::Encoding::FAST_LOSSLESS,
            ex::AnyChannels::sort(list),
        );
        ex::Image::from_layer(layer).write().to_file(path).unwrap();
    }

    #[test]
    fn exr_without_prism_attributes_reads_meta_none() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("foreign.exr");
        write_foreign_exr(&path, true);
        let (img, meta) = read_image(&path).unwrap();
        assert_eq!(meta, None);
        assert_eq!((img.width, img.height), (3, 2));
        // f16 → f32 is exact for these values; alpha is ignored.
        assert_eq!(img.pixels[0], [0.0, 0.25, 0.5]);
        assert_eq!(img.pixels[4], [4.0, 4.25, 4.5]);
    }

    #[test]
    fn exr_missing_channel_is_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rg.exr");
        write_foreign_exr(&path, false);
        let err = read_image(&path).unwrap_err();
        assert!(
            matches!(err, FilmError::MissingChannel { channel: "B", .. }),
            "{err:?}"
        );
        let msg = err.to_string();
        assert!(
            msg.contains("rg.exr") && msg.contains("'B'") && msg.contains("A, G, R"),
            "{msg}"
        );
    }

    #[test]
    fn corrupt_exr_is_decode_error_naming_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.exr");
        fs::write(&path, b"not an exr at all").unwrap();
        let msg = read_image(&path).unwrap_err().to_string();
        assert!(
            msg.starts_with("cannot decode '") && msg.contains("bad.exr"),
            "{msg}"
        );
    }

    #[test]
    fn png_round_trip_within_quantisation() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("q.png");
        let (w, h) = (16u32, 16u32);
        let pixels: Vec<[f32; 3]> = (0..w * h)
            .map(|i| {
                let t = i as f32 / (w * h - 1) as f32;
                [t, t * t, 1.0 - t]
            })
            .collect();
        let img = Image {
            width: w,
            height: h,
            pixels,
        };
        write_image(&path, &img, &META, &PngOptions::default()).unwrap();
        let (back, meta) = read_image(&path).unwrap();
        assert_eq!(meta, None);
        assert_eq!((back.width, back.height), (w, h));
        for (a, b) in img.pixels.iter().zip(&back.pixels) {
            for c in 0..3 {
                let d = (srgb_encode(a[c]) - srgb_encode(b[c])).abs();
                assert!(d <= 0.5 / 255.0 + 1e-6, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn png_applies_exposure_clamp_and_zeroes_non_finite() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("e.png");
        let img = Image {
            width: 3,
            height: 2,
            pixels: vec![
                [0.25, 2.0, -1.0],
                [f32::NAN, f32::INFINITY, f32::NEG_INFINITY],
                [0.0, 0.5, 1e30],
                [0.125, 0.001, 0.5],
                [1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
        };
        write_image(&path, &img, &META, &PngOptions { exposure: 1.0 }).unwrap();
        let raw = image::open(&path).unwrap().to_rgb8();
        assert_eq!(raw.dimensions(), (3, 2));
        let px: Vec<[u8; 3]> = raw.pixels().map(|p| p.0).collect();
        // 0.25·2 = 0.5 → 0.7354 → 188; 0.125·2 = 0.25 → 0.5371 → 137;
        // 0.001·2 → 12.92·0.002 = 0.02584 → 7.
        assert_eq!(px[0], [188, 255, 0]);
        assert_eq!(px[1], [0, 0, 0]);
        assert_eq!(px[2], [0, 255, 255]);
        assert_eq!(px[3], [137, 7, 255]);
        assert_eq!(px[4], [255, 0, 0]);
        assert_eq!(px[5], [0, 0, 255]);
    }

    #[test]
    fn jpeg_read_decodes_srgb() {
        use image::ImageEncoder;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("flat.JPG");
        let raw = [188u8; 8 * 8 * 3];
        let mut bytes = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 100)
            .write_image(&raw, 8, 8, image::ExtendedColorType::Rgb8)
            .unwrap();
        fs::write(&path, bytes).unwrap();
        let (img, meta) = read_image(&path).unwrap();
        assert_eq!(meta, None);
        assert_eq!((img.width, img.height), (8, 8));
        for p in &img.pixels {
            for &c in p {
                assert!((srgb_encode(c) - 188.0 / 255.0).abs() <= 1.5 / 255.0, "{c}");
            }
        }
    }

    #[test]
    fn hdr_read_is_linear() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("l.hdr");
        let pixels = vec![image::Rgb([2.0f32, 0.5, 0.25]); 4];
        let mut bytes = Vec::new();
        image::codecs::hdr::HdrEncoder::new(&mut bytes)
            .encode(&pixels, 2, 2)
            .unwrap();
        fs::write(&path, bytes).unwrap();
        let (img, _) = read_image(&path).unwrap();
        // Powers of two are exact in RGBE.
        assert_eq!(img.pixels, vec![[2.0, 0.5, 0.25]; 4]);
    }

    #[test]
    fn atomic_write_leaves_no_stray_files_on_success() {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("a.exr");
        let png = dir.path().join("a.png");
        write_image(&exr, &hdr_image(), &META, &PngOptions::default()).unwrap();
        write_image(&png, &hdr_image(), &META, &PngOptions::default()).unwrap();
        // Overwriting replaces the file in place.
        let other = Image::filled(2, 2, [0.5; 3]);
        write_image(&exr, &other, &META, &PngOptions::default()).unwrap();
        assert_eq!(read_image(&exr).unwrap().0, other);
        assert_eq!(entries(dir.path()), ["a.exr", "a.png"]);
    }

    #[test]
    fn unsupported_extension_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.tiff");
        let err = write_image(&path, &hdr_image(), &META, &PngOptions::default()).unwrap_err();
        assert!(
            matches!(err, FilmError::UnsupportedFormat { .. }),
            "{err:?}"
        );
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn parent_is_a_file_fails_naming_it_and_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let blocker = dir.path().join("blocker");
        fs::write(&blocker, b"x").unwrap();
        let path = blocker.join("out.exr");
        let err = write_image(&path, &hdr_image(), &META, &PngOptions::default()).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.starts_with("cannot create directory '")
                && msg.contains("blocker")
                && msg.contains("out.exr"),
            "{msg}"
        );
        assert_eq!(entries(dir.path()), ["blocker"]);
    }

    #[test]
    fn failed_rename_removes_temp_file() {
        // The target exists as a directory, so everything up to the final
        // rename succeeds; the temporary file must still be cleaned up.
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("taken.png");
        fs::create_dir(&target).unwrap();
        let err = write_image(&target, &hdr_image(), &META, &PngOptions::default()).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.starts_with("cannot write '") && msg.contains("taken.png"),
            "{msg}"
        );
        assert_eq!(entries(dir.path()), ["taken.png"]);
        assert!(entries(&target).is_empty());
    }

    #[test]
    fn missing_parent_directories_are_created() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a/b/c.exr");
        write_image(&path, &hdr_image(), &META, &PngOptions::default()).unwrap();
        assert_eq!(entries(&dir.path().join("a/b")), ["c.exr"]);
    }

    #[test]
    fn bad_buffer_and_empty_image_are_refused_without_writing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.png");
        let bad = Image {
            width: 2,
            height: 2,
            pixels: vec![[0.0; 3]; 3],
        };
        let msg = write_image(&path, &bad, &META, &PngOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("bad.png")
                && msg.contains("2×2 needs 4 pixels")
                && msg.contains("holds 3"),
            "{msg}"
        );
        let empty = Image {
            width: 0,
            height: 5,
            pixels: vec![],
        };
        let msg = write_image(&path, &empty, &META, &PngOptions::default())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("bad.png") && msg.contains("0×5"), "{msg}");
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn read_missing_file_names_path() {
        let msg = read_image(Path::new("/nonexistent/dir/x.exr"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            msg,
            "cannot read '/nonexistent/dir/x.exr': no such file or directory"
        );
        let msg = read_image(Path::new("x.bmp")).unwrap_err().to_string();
        assert!(msg.contains("'x.bmp'") && msg.contains(".jpeg"), "{msg}");
    }

    #[test]
    fn io_reason_is_short_and_lowercase() {
        let e = io::Error::from_raw_os_error(13);
        assert_eq!(io_reason(&e), "permission denied");
        let e = io::Error::other("Custom thing");
        assert_eq!(io_reason(&e), "custom thing");
    }
}
