//! Image textures: decoding once into linear `f32` RGB, filtered lookups, and a cache so
//! entities that name the same file share one copy.

use std::collections::HashMap;
use std::fmt;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

pub use crate::imageio::ColorSpace;
use crate::imageio::{FilmError, decode_raster, read_image};
use crate::simd::{Float, UInt, V3};

/// How texture coordinates outside [0, 1] are folded back onto the image.
///
/// Folding happens per texel index, so with bilinear filtering the edges behave as:
/// - `Repeat`: the image tiles; exactly at u = 0 or u = 1 the result is the mean of the
///   first and last column (they are neighbours across the seam).
/// - `Clamp`: the edge texel extends outwards; u ≤ 1/(2·width) gives the first column.
/// - `Mirror`: every other tile is flipped, so the edge texel is its own neighbour and u = 0
///   or u = 1 gives the edge column, with no seam.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// The edge texels extend outwards.
    Clamp,
    /// The image tiles with every other copy flipped.
    Mirror,
}

/// Extensions [`TexImage::load`] accepts.
pub const TEXTURE_EXTENSIONS: &str = ".png, .jpg, .jpeg, .hdr, .exr";

/// Why a texture could not be loaded. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    /// The file does not exist.
    #[error("texture '{}' not found", .path.display())]
    Missing {
        /// The texture file.
        path: PathBuf,
    },
    /// The file exists but could not be read.
    #[error("cannot read texture '{}': {}", .path.display(), io_reason(.error))]
    Unreadable {
        /// The texture file.
        path: PathBuf,
        /// The I/O error.
        error: io::Error,
    },
    /// The file's extension is not one of [`TEXTURE_EXTENSIONS`].
    #[error(
        "texture '{}': unsupported image format ({found}); supported extensions: {}",
        .path.display(), TEXTURE_EXTENSIONS
    )]
    UnsupportedFormat {
        /// The texture file.
        path: PathBuf,
        /// The extension found, quoted, or `no extension`.
        found: String,
    },
    /// The file was read but its contents are not a valid image.
    #[error("cannot decode texture '{}': {message}", .path.display())]
    Decode {
        /// The texture file.
        path: PathBuf,
        /// What the decoder reported.
        message: String,
    },
}

impl TextureError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            Self::Missing { path }
            | Self::Unreadable { path, .. }
            | Self::UnsupportedFormat { path, .. }
            | Self::Decode { path, .. } => path,
        }
    }

    fn from_io(path: &Path, error: io::Error) -> Self {
        if error.kind() == io::ErrorKind::NotFound {
            Self::Missing {
                path: path.to_path_buf(),
            }
        } else {
            Self::Unreadable {
                path: path.to_path_buf(),
                error,
            }
        }
    }
}

use crate::imageio::io_reason;

/// A decoded texture: linear RGB, row-major, top row of the file first.
///
/// Lookups use the OpenGL convention: v = 0 is the bottom row, v = 1 the top, and texel
/// (x, y) (y counted from the top, as in the file) has its centre at
/// u = (x + ½) / width, v = 1 − (y + ½) / height.
#[derive(Clone, PartialEq)]
pub struct TexImage {
    width: u32,
    height: u32,
    pixels: Vec<[f32; 3]>,
    /// The file it was read from, for `prism info`; `None` when built in memory.
    source: Option<PathBuf>,
}

impl fmt::Debug for TexImage {
    // The pixel buffer would drown any message that prints a texture.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TexImage")
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

impl TexImage {
    /// An in-memory texture from linear RGB pixels, top row first.
    ///
    /// # Panics
    /// If a side is zero or `pixels.len() != width * height`.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<[f32; 3]>) -> Self {
        assert!(width > 0 && height > 0, "texture must be non-empty");
        assert_eq!(
            pixels.len(),
            width as usize * height as usize,
            "pixel buffer does not match {width}×{height}"
        );
        Self {
            width,
            height,
            pixels,
            source: None,
        }
    }

    /// Reads and decodes `path` (chosen by extension: PNG, JPEG, Radiance HDR, OpenEXR).
    ///
    /// 8- and 16-bit samples are decoded according to `space`; float sources are linear
    /// already. Alpha is dropped, grey is replicated to RGB.
    pub fn load(path: &Path, space: ColorSpace) -> Result<Self, TextureError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let format = match ext.as_deref() {
            Some("png") => image::ImageFormat::Png,
            Some("jpg" | "jpeg") => image::ImageFormat::Jpeg,
            Some("hdr") => image::ImageFormat::Hdr,
            Some("exr") => return Self::load_exr(path),
            _ => {
                return Err(TextureError::UnsupportedFormat {
                    path: path.to_path_buf(),
                    found: match path.extension() {
                        Some(e) => format!("'.{}'", e.to_string_lossy()),
                        None => "no extension".to_owned(),
                    },
                });
            }
        };
        let bytes = crate::files::read_bounded(path, crate::files::MAX_IMAGE_BYTES)
            .map_err(|e| TextureError::from_io(path, e))?;
        Self::decode_raster(path, bytes, format, space)
    }

    /// EXR is always linear, so the film reader (which handles f16/f32/u32 channels and
    /// finds the RGB layer) does exactly what is needed.
    fn load_exr(path: &Path) -> Result<Self, TextureError> {
        let decode = |message: String| TextureError::Decode {
            path: path.to_path_buf(),
            message,
        };
        let (img, _) = read_image(path).map_err(|e| match e {
            FilmError::Read { error, .. } => TextureError::from_io(path, error),
            FilmError::Decode { message, .. } => decode(message),
            FilmError::MissingChannel {
                channel, present, ..
            } => decode(format!(
                "no '{channel}' channel (channels present: {present})"
            )),
            other => decode(other.to_string()),
        })?;
        Self::checked(path, img.width, img.height, img.pixels)
    }

    fn decode_raster(
        path: &Path,
        bytes: Vec<u8>,
        format: image::ImageFormat,
        space: ColorSpace,
    ) -> Result<Self, TextureError> {
        let img = decode_raster(path, bytes, format, space).map_err(|e| match e {
            FilmError::Decode { message, .. } => TextureError::Decode {
                path: path.to_path_buf(),
                message,
            },
            other => TextureError::Decode {
                path: path.to_path_buf(),
                message: other.to_string(),
            },
        })?;
        Self::checked(path, img.width, img.height, img.pixels)
    }

    fn checked(
        path: &Path,
        width: u32,
        height: u32,
        pixels: Vec<[f32; 3]>,
    ) -> Result<Self, TextureError> {
        if width == 0 || height == 0 || pixels.len() != width as usize * height as usize {
            return Err(TextureError::Decode {
                path: path.to_path_buf(),
                message: format!("image is {width}×{height}; both sides must be non-zero"),
            });
        }
        Ok(Self {
            width,
            height,
            pixels,
            source: Some(path.to_path_buf()),
        })
    }

    /// The file the texels were read from (`None` for an in-memory texture).
    pub fn source(&self) -> Option<&Path> {
        self.source.as_deref()
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Texel `(x, y)` with y counted from the top row, as stored in the file.
    ///
    /// # Panics
    /// If the coordinates are outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        assert!(
            x < self.width && y < self.height,
            "texel ({x}, {y}) outside image"
        );
        Vec3::from_array(self.pixels[y as usize * self.width as usize + x as usize])
    }

    /// Bilinearly filtered linear RGB at `uv` (v = 0 at the bottom row).
    ///
    /// Allocates nothing and never panics: NaN or infinite coordinates are treated as 0, and
    /// huge finite ones are folded into range before they are scaled to texels.
    #[inline]
    pub fn bilinear(&self, uv: Vec2, wrap: Wrap) -> Vec3 {
        let (x0, x1, fx) = axis(uv.x, self.width, wrap);
        let (y0, y1, fy) = axis(uv.y, self.height, wrap);
        let w = self.width as usize;
        // Axis indices count from the bottom; storage rows from the top.
        let row = |j: u32| (self.height - 1 - j) as usize * w;
        let at = |i: u32, r: usize| Vec3::from_array(self.pixels[r + i as usize]);
        let (r0, r1) = (row(y0), row(y1));
        let bottom = at(x0, r0).lerp(at(x1, r0), fx);
        let top = at(x0, r1).lerp(at(x1, r1), fx);
        bottom.lerp(top, fy)
    }

    /// [`bilinear`](Self::bilinear) for every lane at once, bit for bit: the texel indices
    /// are folded in lanes and the twelve texel values gathered, so a packet's lookups share
    /// their instructions. Every lane is looked up (inactive ones too: any coordinate gives
    /// an index inside the image).
    #[inline(always)]
    pub fn bilinear_lanes<F: Float>(&self, u: F, v: F, wrap: Wrap) -> V3<F> {
        let (x0, x1, fx) = axis_lanes(u, self.width, wrap);
        let (y0, y1, fy) = axis_lanes(v, self.height, wrap);
        let w = F::U32::splat(self.width);
        // Axis indices count from the bottom; storage rows from the top. Indices stay below
        // 3·2²⁸ (the size bound of decoded images), so u32 arithmetic cannot wrap.
        let last = F::U32::splat(self.height - 1);
        let (r0, r1) = (
            last.wrapping_sub(y0).wrapping_mul(w),
            last.wrapping_sub(y1).wrapping_mul(w),
        );
        let flat = self.pixels.as_flattened();
        let bottom = lerp_lanes(texel_lanes(flat, x0, r0), texel_lanes(flat, x1, r0), fx);
        let top = lerp_lanes(texel_lanes(flat, x0, r1), texel_lanes(flat, x1, r1), fx);
        lerp_lanes(bottom, top, fy)
    }

    /// Rec. 709 luminance of the filtered colour.
    #[inline]
    pub fn luminance(&self, uv: Vec2, wrap: Wrap) -> f32 {
        self.bilinear(uv, wrap)
            .dot(Vec3::new(0.2126, 0.7152, 0.0722))
    }
}

/// The two texel indices along one axis that straddle `t` (counted from the start of the
/// axis) and the weight of the second one.
#[inline]
fn axis(t: f32, n: u32, wrap: Wrap) -> (u32, u32, f32) {
    let t = if t.is_finite() { t } else { 0.0 };
    // Fold into one period first so `t * n` cannot overflow; `rem_euclid` is exact here, so
    // in-range coordinates are unchanged.
    let t = match wrap {
        Wrap::Repeat => t.rem_euclid(1.0),
        Wrap::Mirror => t.rem_euclid(2.0),
        Wrap::Clamp => t.clamp(0.0, 1.0),
    };
    // Texel i covers [i, i + 1) in texel units, so its centre is at i + ½.
    let x = t * n as f32 - 0.5;
    let base = x.floor();
    let frac = x - base;
    let i = base as i64;
    (fold(i, n, wrap), fold(i + 1, n, wrap), frac)
}

/// The texels at column `i` of storage row offset `r` (a row's first pixel) in every lane.
// Helpers here are functions, not closures: a closure is not reliably inlined into the
// lane kernel's entry point and would then run its lane operations outside it.
#[inline(always)]
fn texel_lanes<F: Float>(flat: &[f32], i: F::U32, r: F::U32) -> V3<F> {
    let k = r.wrapping_add(i).wrapping_mul(F::U32::splat(3));
    V3::new(
        F::gather(flat, k),
        F::gather(flat, k.wrapping_add(F::U32::splat(1))),
        F::gather(flat, k.wrapping_add(F::U32::splat(2))),
    )
}

/// glam's `lerp`, `a·(1 − s) + b·s`, unfused like the scalar lookup.
#[inline(always)]
fn lerp_lanes<F: Float>(a: V3<F>, b: V3<F>, s: F) -> V3<F> {
    let t = F::one() - s;
    V3::new(a.x * t + b.x * s, a.y * t + b.y * s, a.z * t + b.z * s)
}

/// `t.rem_euclid(m)` for `m` = 1 or 2 in every lane, bit for bit up to the sign of a zero
/// result (which no caller can see: it is scaled and offset next).
#[inline(always)]
pub(crate) fn rem_euclid_lanes<F: Float>(t: F, m: f32) -> F {
    let r = t - F::splat(m) * (t * F::splat(1.0 / m)).floor();
    // A negative subnormal whose half rounds to −0 is left negative; `rem_euclid` adds m.
    F::select(r.lt(F::zero()), r + F::splat(m), r)
}

/// [`axis`] in lanes: the same arithmetic, with the texel indices folded by [`fold_lanes`].
#[inline(always)]
fn axis_lanes<F: Float>(t: F, n: u32, wrap: Wrap) -> (F::U32, F::U32, F) {
    let t = F::select(t.is_finite(), t, F::zero());
    let t = match wrap {
        Wrap::Repeat => rem_euclid_lanes(t, 1.0),
        Wrap::Mirror => rem_euclid_lanes(t, 2.0),
        Wrap::Clamp => t.clamp(F::zero(), F::one()),
    };
    let x = t * F::splat(n as f32) - F::splat(0.5);
    let base = x.floor();
    let frac = x - base;
    // t ∈ [0, 2] and n ≤ 2²⁴, so base ∈ [−1, 2n − 1] is an exact integer.
    let i = base.to_i32_bits();
    let i1 = i.wrapping_add(F::U32::splat(1));
    (
        fold_lanes::<F>(i, n, wrap),
        fold_lanes::<F>(i1, n, wrap),
        frac,
    )
}

/// [`fold`] for indices in [−1, 2n] (all [`axis_lanes`] produces), as i32 lanes.
#[inline(always)]
fn fold_lanes<F: Float>(i: F::U32, n: u32, wrap: Wrap) -> F::U32 {
    let zero = F::U32::splat(0);
    let nn = F::U32::splat(n);
    let negative = i.lt_i32(zero);
    match wrap {
        Wrap::Repeat => {
            let j = F::U32::select(negative, i.wrapping_add(nn), i);
            F::U32::select(j.lt_i32(nn), j, j.wrapping_sub(nn))
        }
        Wrap::Clamp => {
            let j = F::U32::select(negative, zero, i);
            F::U32::select(j.lt_i32(nn), j, F::U32::splat(n - 1))
        }
        Wrap::Mirror => {
            let two = F::U32::splat(2 * n);
            let m = F::U32::select(negative, i.wrapping_add(two), i);
            let m = F::U32::select(m.lt_i32(two), m, m.wrapping_sub(two));
            F::U32::select(m.lt_i32(nn), m, F::U32::splat(2 * n - 1).wrapping_sub(m))
        }
    }
}

#[inline]
fn fold(i: i64, n: u32, wrap: Wrap) -> u32 {
    let n = i64::from(n);
    let j = match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m < n { m } else { 2 * n - 1 - m }
        }
    };
    j as u32
}

/// Loads each (file, colour space) once and hands out shared images.
///
/// Paths are compared after canonicalisation when the file exists, so `a/../t.png` and
/// `t.png` share one image. The same file in two colour spaces is two different images.
#[derive(Debug, Default)]
pub struct TextureCache {
    images: HashMap<(PathBuf, ColorSpace), Arc<TexImage>>,
}

impl TextureCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The image at `path` decoded for `space`, loading it on first use. Errors name `path`
    /// as given.
    pub fn get(&mut self, path: &Path, space: ColorSpace) -> Result<Arc<TexImage>, TextureError> {
        let key = (
            std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
            space,
        );
        if let Some(img) = self.images.get(&key) {
            return Ok(Arc::clone(img));
        }
        let img = Arc::new(TexImage::load(path, space)?);
        self.images.insert(key, Arc::clone(&img));
        Ok(img)
    }

    /// Number of distinct images loaded.
    pub fn len(&self) -> usize {
        self.images.len()
    }

    /// Whether no image has been loaded.
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fold_matches_documented_modes() {
        let n = 4;
        let r: Vec<u32> = (-5..9).map(|i| fold(i, n, Wrap::Repeat)).collect();
        assert_eq!(r, [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]);
        let c: Vec<u32> = (-2..6).map(|i| fold(i, n, Wrap::Clamp)).collect();
        assert_eq!(c, [0, 0, 0, 1, 2, 3, 3, 3]);
        let m: Vec<u32> = (-5..13).map(|i| fold(i, n, Wrap::Mirror)).collect();
        assert_eq!(m, [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0, 1, 2, 3, 3]);
    }

    #[test]
    fn axis_handles_extremes_without_overflow() {
        for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror] {
            for t in [f32::MAX, f32::MIN, 1e30, -1e30, f32::NAN, f32::INFINITY] {
                let (a, b, f) = axis(t, 7, wrap);
                assert!(a < 7 && b < 7 && (0.0..=1.0).contains(&f), "{wrap:?} {t}");
            }
        }
    }

    #[test]
    fn bottom_row_is_v_zero() {
        // 1×2: top texel red, bottom texel blue.
        let img = TexImage::from_pixels(1, 2, vec![[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        assert_eq!(img.bilinear(Vec2::new(0.5, 0.25), Wrap::Clamp), Vec3::Z);
        assert_eq!(img.bilinear(Vec2::new(0.5, 0.75), Wrap::Clamp), Vec3::X);
    }

    #[test]
    fn io_reason_is_short_and_lowercase() {
        assert_eq!(
            io_reason(&io::Error::from_raw_os_error(13)),
            "permission denied"
        );
    }
}
