//! OpenEXR: exact floats with the render's provenance as text attributes, written with a
//! deterministic header order; read from any single-part file with R, G and B channels.

use std::io::Cursor;
use std::path::Path;

use exr::prelude::{self as ex, ReadChannels, ReadLayers, WritableImage};

use super::{Aux, AuxChannels, CHANNEL_COUNT, CHANNEL_ERROR, FilmError, Image, ImageMeta};

#[cfg(test)]
pub(super) fn encode_exr(path: &Path, img: &Image, meta: &ImageMeta) -> Result<Vec<u8>, FilmError> {
    encode_exr_aux(path, img, meta, &AuxChannels::default())
}

/// [`encode_exr`] with the per-pixel `count` (u32) and `error` (f32) channels of an adaptive
/// render, where given.
pub(super) fn encode_exr_aux(
    path: &Path,
    img: &Image,
    meta: &ImageMeta,
    aux: &AuxChannels,
) -> Result<Vec<u8>, FilmError> {
    let width = img.width as usize;
    let size = (width, img.height as usize);
    let mut attributes = ex::LayerAttributes::default();
    for (name, value) in meta.attributes() {
        attributes.other.insert(
            ex::Text::from(name),
            ex::AttributeValue::Text(ex::Text::from(value.as_str())),
        );
    }
    let encode_error = |e: ex::Error| FilmError::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut out = Cursor::new(Vec::new());
    // ZIP over 16-line blocks: lossless, compact, and readable everywhere.
    let enc = ex::Encoding::SMALL_LOSSLESS;
    if aux.count.is_none() && aux.error.is_none() {
        let pixels = &img.pixels;
        let channels = ex::SpecificChannels::rgb(move |pos: ex::Vec2<usize>| {
            let [r, g, b] = pixels[pos.y() * width + pos.x()];
            (r, g, b)
        });
        ex::Image::from_layer(ex::Layer::new(size, attributes, enc, channels))
            .write()
            .to_buffered(&mut out)
            .map_err(encode_error)?;
    } else {
        let n = img.pixels.len();
        let check = |len: usize| -> Result<(), FilmError> {
            if len == n {
                Ok(())
            } else {
                Err(FilmError::Encode {
                    path: path.to_path_buf(),
                    message: format!("an extra channel has {len} values for {n} pixels"),
                })
            }
        };
        let channel = |c: usize| img.pixels.iter().map(|p| p[c]).collect::<Vec<f32>>();
        let mut list = vec![
            ex::AnyChannel::new("R", ex::FlatSamples::F32(channel(0))),
            ex::AnyChannel::new("G", ex::FlatSamples::F32(channel(1))),
            ex::AnyChannel::new("B", ex::FlatSamples::F32(channel(2))),
        ];
        if let Some(c) = aux.count {
            check(c.len())?;
            list.push(ex::AnyChannel::new(
                CHANNEL_COUNT,
                ex::FlatSamples::U32(c.to_vec()),
            ));
        }
        if let Some(e) = aux.error {
            check(e.len())?;
            list.push(ex::AnyChannel::new(
                CHANNEL_ERROR,
                ex::FlatSamples::F32(e.to_vec()),
            ));
        }
        let channels = ex::AnyChannels::sort(ex::SmallVec::from_vec(list));
        ex::Image::from_layer(ex::Layer::new(size, attributes, enc, channels))
            .write()
            .to_buffered(&mut out)
            .map_err(encode_error)?;
    }
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
pub(super) struct ExrAttribute {
    pub(super) start: usize,
    pub(super) name_end: usize,
    pub(super) end: usize,
}

/// The attributes of a single-part EXR header in file order; `None` for multi-part or deep
/// files, or bytes that do not parse as a header.
pub(super) fn exr_header_attributes(bytes: &[u8]) -> Option<Vec<ExrAttribute>> {
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

/// The size and provenance of an EXR file from its header alone (its first part).
pub(super) fn exr_header(
    path: &Path,
    bytes: &[u8],
) -> Result<(u32, u32, Option<ImageMeta>), FilmError> {
    let decode = |message: String| FilmError::Decode {
        path: path.to_path_buf(),
        message,
    };
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| decode(e.to_string()))?;
    let h = meta
        .headers
        .first()
        .ok_or_else(|| decode("the file has no parts".to_owned()))?;
    let (w, hgt) = (h.layer_size.0, h.layer_size.1);
    let too_big = || decode(format!("its header claims {w}×{hgt} pixels"));
    let attrs = [&h.own_attributes.other, &h.shared_attributes.other];
    let text = |name: &str| {
        attrs.iter().find_map(|map| match map.get(name.as_bytes()) {
            Some(ex::AttributeValue::Text(t)) => Some(t.to_string()),
            _ => None,
        })
    };
    Ok((
        u32::try_from(w).map_err(|_| too_big())?,
        u32::try_from(hgt).map_err(|_| too_big())?,
        ImageMeta::from_attributes(text),
    ))
}

#[cfg(test)]
pub(super) fn decode_exr(
    path: &Path,
    bytes: Vec<u8>,
) -> Result<(Image, Option<ImageMeta>), FilmError> {
    decode_exr_aux(path, bytes).map(|(i, m, _)| (i, m))
}

/// [`decode_exr`], with the `count` and `error` channels of the chosen layer when it has
/// them (full resolution, one value per pixel).
pub(super) fn decode_exr_aux(
    path: &Path,
    bytes: Vec<u8>,
) -> Result<(Image, Option<ImageMeta>, Aux), FilmError> {
    // The headers first: their data windows decide what the decoder allocates. (Headers
    // that do not parse are left to the decoder, whose error names the fault.)
    if let Ok(meta) = exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes[..]), false) {
        for h in &meta.headers {
            super::check_read_size(path, h.layer_size.0 as u64, h.layer_size.1 as u64)?;
        }
    }
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
    let meta = ImageMeta::from_attributes(text);
    let extra = |name: &str| {
        find(layer, name)
            .map(|i| &list[i].sample_data)
            .filter(|d| d.len() == pixels.len())
    };
    let aux = Aux {
        count: extra(CHANNEL_COUNT).map(|d| match d {
            ex::FlatSamples::U32(v) => v.clone(),
            // Written by other tools as floats: whole, non-negative counts only.
            other => other
                .values_as_f32()
                .map(|x| {
                    if x.is_finite() && x >= 0.0 {
                        x as u32
                    } else {
                        0
                    }
                })
                .collect(),
        }),
        error: extra(CHANNEL_ERROR).map(|d| d.values_as_f32().collect()),
    };

    Ok((
        Image {
            width: w,
            height: h,
            pixels,
        },
        meta,
        aux,
    ))
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
