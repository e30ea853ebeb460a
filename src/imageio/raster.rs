//! 8-bit and Radiance formats through the `image` crate: the PNG preview written from a render,
//! and PNG, JPEG (sRGB) and HDR (linear) read as linear RGB.

use std::io::Cursor;
use std::path::Path;

use super::{FilmError, Image, srgb_decode, srgb_encode};

/// Settings for the 8-bit PNG preview.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PngOptions {
    /// Exposure in stops: pixels are multiplied by `2^exposure` before
    /// clamping.
    pub exposure: f32,
}

pub(super) fn encode_png(
    path: &Path,
    img: &Image,
    opts: &PngOptions,
) -> Result<Vec<u8>, FilmError> {
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

pub(super) fn decode_with_image(
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
