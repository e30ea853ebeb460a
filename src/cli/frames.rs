//! Frame series: `--frames A..B` renders a camera path (and moving objects) frame by frame,
//! each frame written atomically so `--resume` can skip the finished ones.

use super::CliError;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The most frames one series may have (a frame list is built before rendering).
pub const MAX_FRAMES: u32 = 1_000_000;

/// Parses Rust-style ranges: `A..B` is A to B − 1, `A..=B` is A to B, at most
/// [`MAX_FRAMES`] frames.
pub fn parse_range(s: &str) -> Result<Range<u32>, String> {
    let r = parse_unbounded(s)?;
    if r.len() > MAX_FRAMES as usize {
        return Err(format!(
            "frame range '{s}' has {} frames; a series may have at most {MAX_FRAMES}",
            r.len()
        ));
    }
    Ok(r)
}

fn parse_unbounded(s: &str) -> Result<Range<u32>, String> {
    let bad = || format!("expected a frame, or a range like 0..24 or 0..=23, got '{s}'");
    let num = |v: &str| v.trim().parse::<u32>().map_err(|_| bad());
    if !s.contains("..") {
        // One frame.
        let f = num(s)?;
        let end = f
            .checked_add(1)
            .ok_or_else(|| format!("frame {f} is out of range"))?;
        return Ok(f..end);
    }
    if let Some((a, b)) = s.split_once("..=") {
        let (a, b) = (num(a)?, num(b)?);
        if b < a {
            return Err(format!("frame range '{s}' is empty"));
        }
        let end = b
            .checked_add(1)
            .ok_or_else(|| format!("frame {b} is out of range"))?;
        return Ok(a..end);
    }
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let (a, b) = (num(a)?, num(b)?);
    if b <= a {
        return Err(format!("frame range '{s}' is empty"));
    }
    Ok(a..b)
}

/// Replaces each run of `#` in the file name with the zero-padded frame number (as wide as
/// the run, wider if the number needs it).
pub fn frame_path(template: &Path, frame: u32) -> PathBuf {
    let s = template.to_string_lossy();
    let mut out = String::with_capacity(s.len() + 4);
    let mut chars = s.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '#' {
            let mut width = 1;
            while chars.peek() == Some(&'#') {
                chars.next();
                width += 1;
            }
            out.push_str(&format!("{frame:0width$}"));
        } else {
            out.push(c);
        }
    }
    PathBuf::from(out)
}

/// Checks that a frame template names each frame differently.
pub fn check_template(template: &Path) -> Result<(), CliError> {
    let name = template
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    if !name.contains('#') {
        return Err(CliError::FrameTemplate(template.to_path_buf()));
    }
    Ok(())
}

/// The sampler seed of frame `f`: frame 0 keeps the scene's seed (a still render and frame 0
/// of a series are the same image); other frames hash it, so every frame's noise is
/// independent and depends on nothing but (seed, frame).
pub fn frame_seed(seed: u64, frame: u32) -> u64 {
    if frame == 0 {
        return seed;
    }
    let mut z = seed ^ (frame as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Assembles the frames into an animated GIF at `fps`, written atomically.
pub fn write_gif(frames: &[PathBuf], fps: u32, out: &Path) -> Result<(), CliError> {
    use image::codecs::gif::{GifEncoder, Repeat};
    use image::{Delay, Frame, RgbaImage};
    let mut bytes = Vec::new();
    {
        let mut enc = GifEncoder::new_with_speed(&mut bytes, 10);
        enc.set_repeat(Repeat::Infinite)
            .map_err(|error| CliError::Gif {
                path: out.to_path_buf(),
                error,
            })?;
        for f in frames {
            let (img, _) = crate::film::read_image(f)?;
            let mut rgba = RgbaImage::new(img.width, img.height);
            for (px, c) in rgba.pixels_mut().zip(&img.pixels) {
                let q =
                    |v: f32| (crate::film::srgb_encode(v.clamp(0.0, 1.0)) * 255.0).round() as u8;
                *px = image::Rgba([q(c[0]), q(c[1]), q(c[2]), 255]);
            }
            let delay = Delay::from_numer_denom_ms(1000, fps.max(1));
            enc.encode_frame(Frame::from_parts(rgba, 0, 0, delay))
                .map_err(|error| CliError::Gif {
                    path: out.to_path_buf(),
                    error,
                })?;
        }
    }
    crate::film::write_atomic(out, &bytes)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_follow_rust() {
        assert_eq!(parse_range("0..24").unwrap(), 0..24);
        assert_eq!(parse_range("0..=23").unwrap(), 0..24);
        assert_eq!(parse_range("5..=5").unwrap(), 5..6);
        assert!(parse_range("3..3").is_err());
        assert!(parse_range("a..3").is_err());
        assert_eq!(parse_range("3").unwrap(), 3..4, "one frame");
        assert!(parse_range(&u32::MAX.to_string()).is_err());
        assert!(parse_range("-1").is_err());
        // No wrap to an empty range, and no list of four billion frames.
        let e = parse_range("0..=4294967295").unwrap_err();
        assert!(e.contains("out of range"), "{e}");
        let e = parse_range("0..4294967295").unwrap_err();
        assert!(e.contains("at most 1000000"), "{e}");
        assert_eq!(parse_range("7..1000007").unwrap().len(), 1_000_000);
        assert!(parse_range("7..=1000007").is_err());
    }

    #[test]
    fn hashes_become_padded_frames() {
        assert_eq!(
            frame_path(Path::new("out/f_####.png"), 7),
            PathBuf::from("out/f_0007.png")
        );
        assert_eq!(
            frame_path(Path::new("a#b##.exr"), 12345),
            PathBuf::from("a12345b12345.exr")
        );
    }

    #[test]
    fn frame_seeds_are_distinct() {
        let s: std::collections::HashSet<u64> = (0..1000).map(|f| frame_seed(1, f)).collect();
        assert_eq!(s.len(), 1000);
        assert_eq!(frame_seed(9, 0), 9);
    }
}
