//! Scaling out without a network layer of our own: frame shards for batch schedulers (Slurm
//! arrays, Kubernetes Indexed Jobs, GNU parallel) and merging of sample batches.

use super::CliError;
use crate::film::{self, Image, ImageMeta, PngOptions};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Shard `i` of `n`: which of the frames in `range` it renders. Frames are dealt round-robin,
/// so shard sizes differ by at most one and neighbouring frames (often of similar cost) spread
/// over all shards; the union over i is exactly the range, each frame once.
pub fn shard_frames(range: Range<u32>, i: u32, n: u32) -> Vec<u32> {
    range.filter(|f| f % n == i).collect()
}

/// Parses `I/N` with 0 <= I < N.
pub fn parse_shard(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("expected --shard I/N with 0 <= I < N, e.g. 0/4, got '{s}'");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (u32, u32) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// Reads the shard index from the environment variable `var` (as batch schedulers set it).
pub fn shard_from_env(var: &str, count: Option<u32>) -> Result<(u32, u32), CliError> {
    let n = count.ok_or_else(|| {
        CliError(format!(
            "--shard-from-env {var} needs --shard-count N (the number of shards)"
        ))
    })?;
    let v = std::env::var(var).map_err(|_| {
        CliError(format!(
            "--shard-from-env: environment variable {var} is not set"
        ))
    })?;
    let i: u32 = v.trim().parse().map_err(|_| {
        CliError(format!(
            "--shard-from-env: {var}='{v}' is not a shard index (a whole number)"
        ))
    })?;
    if n == 0 || i >= n {
        return Err(CliError(format!(
            "--shard-from-env: {var}={i} is outside 0..{n} (--shard-count {n})"
        )));
    }
    Ok((i, n))
}

/// Combines sample batches of one image, weighted by their sample counts. The parts must come
/// from the same scene and settings (`prism:scene_hash`), have the same size, and cover
/// disjoint sample ranges that together form one contiguous range.
pub fn merge(parts: &[PathBuf], out: &Path) -> Result<(u32, u64), CliError> {
    if parts.is_empty() {
        return Err(CliError("merge needs at least one part".into()));
    }
    let mut loaded: Vec<(PathBuf, Image, ImageMeta)> = Vec::with_capacity(parts.len());
    for p in parts {
        let (img, meta) = film::read_image(p)?;
        let meta = meta.ok_or_else(|| {
            CliError(format!(
                "'{}' has no prism:spp / prism:sample_offset / prism:scene_hash header: only EXR files rendered by prism can be merged",
                p.display()
            ))
        })?;
        if let Some((p0, i0, m0)) = loaded.first() {
            if m0.scene_hash != meta.scene_hash {
                return Err(CliError(format!(
                    "'{}' and '{}' come from different scenes or settings (scene hash {:#018x} vs {:#018x})",
                    p0.display(),
                    p.display(),
                    m0.scene_hash,
                    meta.scene_hash
                )));
            }
            if let (Some(w0), Some(w)) = (m0.simd, meta.simd)
                && w0 != w
            {
                return Err(CliError(format!(
                    "'{}' was rendered at lane width {w0} but '{}' at {w}: widths round differently, so render every part with the same --simd",
                    p0.display(),
                    p.display(),
                )));
            }
            if (i0.width, i0.height) != (img.width, img.height) {
                return Err(CliError(format!(
                    "'{}' is {}x{} but '{}' is {}x{}",
                    p0.display(),
                    i0.width,
                    i0.height,
                    p.display(),
                    img.width,
                    img.height
                )));
            }
        }
        loaded.push((p.clone(), img, meta));
    }
    let mut ranges: Vec<(u64, u64, &Path)> = loaded
        .iter()
        .map(|(p, _, m)| (m.sample_offset, m.sample_offset + m.spp as u64, p.as_path()))
        .collect();
    ranges.sort();
    for w in ranges.windows(2) {
        let ((a0, a1, pa), (b0, b1, pb)) = (w[0], w[1]);
        if b0 < a1 {
            return Err(CliError(format!(
                "'{}' (samples {a0}..{a1}) and '{}' (samples {b0}..{b1}) overlap: they would count the same samples twice",
                pa.display(),
                pb.display()
            )));
        }
        if b0 > a1 {
            return Err(CliError(format!(
                "samples {a1}..{b0} are missing between '{}' and '{}'",
                pa.display(),
                pb.display()
            )));
        }
    }
    let total: u64 = loaded.iter().map(|(_, _, m)| m.spp as u64).sum();
    let total_u32 = u32::try_from(total)
        .map_err(|_| CliError(format!("merged sample count {total} is too large")))?;
    let (w, h) = (loaded[0].1.width, loaded[0].1.height);
    let mut sums = vec![[0.0f64; 3]; (w * h) as usize];
    for (_, img, m) in &loaded {
        let k = m.spp as f64;
        for (s, p) in sums.iter_mut().zip(&img.pixels) {
            for c in 0..3 {
                s[c] += p[c] as f64 * k;
            }
        }
    }
    let inv = 1.0 / total as f64;
    let merged = Image {
        width: w,
        height: h,
        pixels: sums
            .iter()
            .map(|s| {
                [
                    (s[0] * inv) as f32,
                    (s[1] * inv) as f32,
                    (s[2] * inv) as f32,
                ]
            })
            .collect(),
    };
    let meta = ImageMeta {
        spp: total_u32,
        sample_offset: ranges[0].0,
        scene_hash: loaded[0].2.scene_hash,
        simd: loaded[0].2.simd,
    };
    film::write_image(out, &merged, &meta, &PngOptions::default())?;
    Ok((total_u32, ranges[0].0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_cover_each_frame_once() {
        for (range, n) in [
            (0..24u32, 4u32),
            (5..6, 3),
            (3..100, 7),
            (0..1, 1),
            (10..13, 5),
        ] {
            let mut all: Vec<u32> = (0..n)
                .flat_map(|i| shard_frames(range.clone(), i, n))
                .collect();
            all.sort();
            assert_eq!(all, range.clone().collect::<Vec<_>>(), "{range:?} / {n}");
            let sizes: Vec<usize> = (0..n)
                .map(|i| shard_frames(range.clone(), i, n).len())
                .collect();
            assert!(
                sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1,
                "{sizes:?}"
            );
        }
    }

    #[test]
    fn shard_syntax() {
        assert_eq!(parse_shard("0/4").unwrap(), (0, 4));
        assert_eq!(parse_shard("3/4").unwrap(), (3, 4));
        assert!(parse_shard("4/4").is_err());
        assert!(parse_shard("1/0").is_err());
        assert!(parse_shard("x").is_err());
    }
}
