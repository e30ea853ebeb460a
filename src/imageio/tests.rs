//! Round trips, error messages and atomicity of image files.

use super::exr::{decode_exr, encode_exr, exr_header_attributes};
use super::*;
use ::exr::prelude::{self as ex, WritableImage};
use std::fs;
use std::io;
use std::path::Path;

const META: ImageMeta = ImageMeta {
    spp: 4096,
    sample_offset: 1 << 40,
    scene_hash: 0xfedc_ba98_7654_3210,
    simd: Some(16),
    complete: true,
    settings: Some(0x0123_4567_89ab_cdef),
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
fn headers_of_both_formats_give_size_and_provenance() {
    let dir = tempfile::tempdir().unwrap();
    let incomplete = ImageMeta {
        complete: false,
        ..META
    };
    for name in ["h.exr", "h.png"] {
        let path = dir.path().join(name);
        for meta in [META, incomplete] {
            write_image(&path, &hdr_image(), &meta, &PngOptions::default()).unwrap();
            let h = read_header(&path).unwrap();
            let img = hdr_image();
            assert_eq!((h.width, h.height), (img.width, img.height), "{name}");
            assert_eq!(h.meta, Some(meta), "{name}");
        }
    }
    // Files from other tools (or from before the attributes existed) have no provenance;
    // a file without `prism:complete` counts as complete.
    let plain = dir.path().join("plain.png");
    image::RgbImage::new(3, 2).save(&plain).unwrap();
    let h = read_header(&plain).unwrap();
    assert_eq!((h.width, h.height, h.meta), (3, 2, None));
    let m = ImageMeta::from_attributes(|k| match k {
        ATTR_SPP => Some("8".into()),
        ATTR_SAMPLE_OFFSET => Some("0".into()),
        ATTR_SCENE_HASH => Some("0x1f".into()),
        _ => None,
    });
    assert_eq!(
        m,
        Some(ImageMeta {
            spp: 8,
            sample_offset: 0,
            scene_hash: 0x1f,
            simd: None,
            complete: true,
            settings: None,
        })
    );
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
            complete: false,
            settings: None,
        },
        ImageMeta {
            spp: u32::MAX,
            sample_offset: u64::MAX,
            scene_hash: u64::MAX,
            simd: Some(u32::MAX),
            complete: true,
            settings: Some(u64::MAX),
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
    let val = |x: usize, y: usize, c: usize| f16::from_f32((y * w + x) as f32 + c as f32 * 0.25);
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

/// CRC-32 (IEEE) of a PNG chunk's type and data.
fn png_crc(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// Small files whose headers claim huge images are refused before any pixel is decoded:
/// an EXR whose data window is 200000 × 200000 (a 1 × 1 file with its window edited) and a
/// 45-byte PNG claiming 30000 × 30000 (a header and an empty data chunk). Both fit the pixel cap at their real sizes.
#[test]
fn files_claiming_huge_images_are_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("huge.exr");
    write_image(
        &exr,
        &Image::filled(1, 1, [0.5; 3]),
        &META,
        &PngOptions::default(),
    )
    .unwrap();
    let mut bytes = fs::read(&exr).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .expect("a dataWindow attribute")
        + key.len()
        + 4;
    for k in [2, 3] {
        bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&199_999i32.to_le_bytes());
    }
    fs::write(&exr, &bytes).unwrap();
    let msg = read_image(&exr).unwrap_err().to_string();
    assert!(
        msg.contains("huge.exr") && msg.contains("200000×200000"),
        "{msg}"
    );

    let png = dir.path().join("huge.png");
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(30_000u32.to_be_bytes());
    ihdr.extend(30_000u32.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    let mut file = b"\x89PNG\r\n\x1a\n".to_vec();
    file.extend(13u32.to_be_bytes());
    file.extend(&ihdr);
    file.extend(png_crc(&ihdr).to_be_bytes());
    // An empty IDAT: the decoder reads the header up to the first data chunk.
    file.extend(0u32.to_be_bytes());
    file.extend(b"IDAT");
    file.extend(png_crc(b"IDAT").to_be_bytes());
    fs::write(&png, &file).unwrap();
    let msg = read_image(&png).unwrap_err().to_string();
    assert!(
        msg.contains("huge.png") && msg.contains("30000×30000"),
        "{msg}"
    );
    // The same header at a size within the cap gets past the check to the decoder.
    assert!(check_read_size(&png, 16_384, 16_384).is_ok());
    assert!(check_read_size(&png, 32_768, 8_192).is_ok());
    assert!(check_read_size(&png, 16_385, 16_384).is_err());
    assert!(check_read_size(&png, 32_769, 1).is_err());
    assert!(check_read_size(&png, u64::MAX, 2).is_err());
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
        msg.contains("bad.png") && msg.contains("2×2 needs 4 pixels") && msg.contains("holds 3"),
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
