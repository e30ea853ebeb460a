//! 8-bit and Radiance formats through the `image` crate: the PNG preview written from a render,
//! and PNG, JPEG (sRGB) and HDR (linear) read as linear RGB.

use std::io::Cursor;
use std::path::Path;

use super::{FilmError, Image, ImageMeta, srgb_decode, srgb_encode};

/// Settings for the 8-bit PNG preview.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PngOptions {
    /// Exposure in stops: pixels are multiplied by `2^exposure` before
    /// clamping.
    pub exposure: f32,
}

/// The 8-bit sRGB preview of `img`, with `meta` as `tEXt` chunks before the pixels (so a
/// header read finds them without decoding the image).
pub(super) fn encode_png(
    path: &Path,
    img: &Image,
    meta: &ImageMeta,
    opts: &PngOptions,
) -> Result<Vec<u8>, FilmError> {
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

    let encode_err = |e: png::EncodingError| FilmError::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, img.width, img.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    for (name, value) in meta.attributes() {
        enc.add_text_chunk(name.to_owned(), value)
            .map_err(encode_err)?;
    }
    let mut writer = enc.write_header().map_err(encode_err)?;
    writer.write_image_data(&raw).map_err(encode_err)?;
    writer.finish().map_err(encode_err)?;
    Ok(out)
}

/// The size and provenance (`prism:*` text chunks) of a PNG file, from the chunks before its
/// pixels.
pub(super) fn png_header(
    path: &Path,
    bytes: &[u8],
) -> Result<(u32, u32, Option<ImageMeta>), FilmError> {
    let reader = png::Decoder::new(Cursor::new(bytes))
        .read_info()
        .map_err(|e| FilmError::Decode {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let info = reader.info();
    let text = |name: &str| {
        info.uncompressed_latin1_text
            .iter()
            .find(|c| c.keyword == name)
            .map(|c| c.text.clone())
    };
    Ok((info.width, info.height, ImageMeta::from_attributes(text)))
}

/// How the integer samples of a file encode light.
///
/// Only 8- and 16-bit sources are affected: EXR and Radiance HDR store linear floats and are
/// never decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    /// Colour images (photos, albedo): samples are sRGB-encoded and decoded with
    /// [`srgb_decode`].
    Srgb,
    /// Data images (normal maps): samples are used as stored, scaled to [0, 1]. Decoding a
    /// normal map as sRGB would bend every normal.
    Linear,
}

/// Decodes PNG, JPEG or Radiance HDR `bytes` (the content decides if it disagrees with
/// `format`) into linear RGB: 8- and 16-bit samples through `space`, float samples as they
/// are; alpha dropped, grey replicated. `path` only labels errors.
pub fn decode_raster(
    path: &Path,
    bytes: Vec<u8>,
    format: image::ImageFormat,
    space: ColorSpace,
) -> Result<Image, FilmError> {
    let decode_err = |message: String| FilmError::Decode {
        path: path.to_path_buf(),
        message,
    };
    // The header first: its size decides what decoding allocates (and a 12-byte-per-pixel
    // f32 RGB image follows).
    let (w, h) = image::ImageReader::with_format(Cursor::new(&bytes[..]), format)
        .with_guessed_format()
        .map_err(|e| decode_err(e.to_string()))?
        .into_dimensions()
        .map_err(|e| decode_err(e.to_string()))?;
    super::check_read_size(path, u64::from(w), u64::from(h))?;
    let decoded = image::ImageReader::with_format(Cursor::new(bytes), format)
        .with_guessed_format()
        .map_err(|e| decode_err(e.to_string()))?
        .decode()
        .map_err(|e| decode_err(e.to_string()))?;
    let to_linear = |x: f32| match space {
        ColorSpace::Srgb => srgb_decode(x),
        ColorSpace::Linear => x,
    };
    let color = decoded.color();
    let bytes_per_sample = color.bytes_per_pixel() / color.channel_count();
    let (width, height) = (decoded.width(), decoded.height());
    let pixels: Vec<[f32; 3]> = match bytes_per_sample {
        1 => {
            // A table keeps decoding a large photo cheap: 256 powf calls, not millions.
            let lut: Vec<f32> = (0..=255u8).map(|b| to_linear(b as f32 / 255.0)).collect();
            decoded
                .into_rgb8()
                .pixels()
                .map(|p| p.0.map(|c| lut[c as usize]))
                .collect()
        }
        2 => {
            let lut: Vec<f32> = (0..=u16::MAX)
                .map(|s| to_linear(s as f32 / 65535.0))
                .collect();
            decoded
                .into_rgb16()
                .pixels()
                .map(|p| p.0.map(|c| lut[c as usize]))
                .collect()
        }
        // Float sources (Radiance HDR) hold linear radiance already.
        _ => decoded.into_rgb32f().pixels().map(|p| p.0).collect(),
    };
    Ok(Image {
        width,
        height,
        pixels,
    })
}
