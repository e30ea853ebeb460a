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
    let n = count.ok_or_else(|| CliError::ShardCountMissing { var: var.into() })?;
    let v = std::env::var(var).map_err(|error| CliError::ShardEnvUnset {
        var: var.into(),
        error,
    })?;
    let i: u32 = v.trim().parse().map_err(|error| CliError::ShardIndex {
        var: var.into(),
        value: v.clone(),
        error,
    })?;
    if n == 0 || i >= n {
        return Err(CliError::ShardOutOfRange {
            var: var.into(),
            index: i,
            count: n,
        });
    }
    Ok((i, n))
}

/// Combines sample batches of one image, weighted by their sample counts. The parts must come
/// from the same scene and settings (`prism:scene_hash`), have the same size, and cover
/// disjoint sample ranges that together form one contiguous range.
pub fn merge(parts: &[PathBuf], out: &Path) -> Result<(u32, u64), CliError> {
    if parts.is_empty() {
        return Err(CliError::MergeNoParts);
    }
    let mut loaded: Vec<(PathBuf, Image, ImageMeta)> = Vec::with_capacity(parts.len());
    let mut aux: Vec<film::Aux> = Vec::with_capacity(parts.len());
    for p in parts {
        let (img, meta, a) = film::read_image_aux(p)?;
        aux.push(a);
        let meta = meta.ok_or_else(|| CliError::MergeNoHeader(p.clone()))?;
        if meta.spp == 0 {
            return Err(CliError::MergeEmptyPart(p.clone()));
        }
        if let Some((p0, i0, m0)) = loaded.first() {
            if m0.scene_hash != meta.scene_hash {
                return Err(CliError::MergeScenes {
                    first: p0.clone(),
                    other: p.clone(),
                    first_hash: m0.scene_hash,
                    other_hash: meta.scene_hash,
                });
            }
            if let (Some(w0), Some(w)) = (m0.simd, meta.simd)
                && w0 != w
            {
                return Err(CliError::MergeWidths {
                    first: p0.clone(),
                    other: p.clone(),
                    first_width: w0,
                    other_width: w,
                });
            }
            if let (Some(s0), Some(s)) = (m0.settings, meta.settings)
                && s0 != s
            {
                return Err(CliError::MergeSettings {
                    first: p0.clone(),
                    other: p.clone(),
                });
            }
            if (i0.width, i0.height) != (img.width, img.height) {
                return Err(CliError::MergeSizes {
                    first: p0.clone(),
                    first_size: (i0.width, i0.height),
                    other: p.clone(),
                    other_size: (img.width, img.height),
                });
            }
        }
        loaded.push((p.clone(), img, meta));
    }
    // An adaptive part (one with a count channel) draws indices `offset ..` up to half its
    // largest count in each of its two halves; its pixels stop at different counts, so the
    // ranges of adaptive parts leave gaps by design.
    let adaptive = aux.iter().any(|a| a.count.is_some());
    let mut ranges: Vec<(u64, u64, &Path)> = loaded
        .iter()
        .zip(&aux)
        .map(|((p, _, m), a)| {
            let used = match a.count {
                Some(_) => u64::from(m.spp).div_ceil(2),
                None => u64::from(m.spp),
            };
            (m.sample_offset, m.sample_offset + used, p.as_path())
        })
        .collect();
    ranges.sort();
    for w in ranges.windows(2) {
        let ((a0, a1, pa), (b0, b1, pb)) = (w[0], w[1]);
        if b0 < a1 {
            return Err(CliError::MergeOverlap {
                first: pa.to_path_buf(),
                first_samples: (a0, a1),
                second: pb.to_path_buf(),
                second_samples: (b0, b1),
            });
        }
        if b0 > a1 && !adaptive {
            return Err(CliError::MergeGap {
                missing: (a1, b0),
                before: pa.to_path_buf(),
                after: pb.to_path_buf(),
            });
        }
    }
    let (w, h) = (loaded[0].1.width, loaded[0].1.height);
    let n = w as usize * h as usize;
    // Each pixel is weighted by its own sample count in each part.
    let count = |k: usize, i: usize| -> u64 {
        aux[k]
            .count
            .as_ref()
            .map_or(u64::from(loaded[k].2.spp), |c| u64::from(c[i]))
    };
    let counts: Vec<u64> = (0..n)
        .map(|i| (0..loaded.len()).map(|k| count(k, i)).sum())
        .collect();
    let total = if adaptive {
        counts.iter().copied().max().unwrap_or(0)
    } else {
        loaded.iter().map(|(_, _, m)| m.spp as u64).sum()
    };
    let total_u32 = u32::try_from(total).map_err(|_| CliError::MergeTooLarge(total))?;
    let mut sums = vec![[0.0f64; 3]; n];
    for (k, (_, img, _)) in loaded.iter().enumerate() {
        for (i, (s, p)) in sums.iter_mut().zip(&img.pixels).enumerate() {
            let c = count(k, i) as f64;
            for ch in 0..3 {
                s[ch] += p[ch] as f64 * c;
            }
        }
    }
    let merged = Image {
        width: w,
        height: h,
        pixels: sums
            .iter()
            .zip(&counts)
            .map(|(s, &c)| {
                let inv = 1.0 / c.max(1) as f64;
                [
                    (s[0] * inv) as f32,
                    (s[1] * inv) as f32,
                    (s[2] * inv) as f32,
                ]
            })
            .collect(),
    };
    // The merged error where every part has one: independent parts' variances add.
    let errors: Option<Vec<f32>> = aux.iter().all(|a| a.error.is_some()).then(|| {
        (0..n)
            .map(|i| {
                let parts: Vec<(f64, [f64; 3], f64)> = (0..loaded.len())
                    .map(|k| {
                        let p = loaded[k].1.pixels[i];
                        let e = aux[k].error.as_ref().map_or(0.0, |e| f64::from(e[i]));
                        (count(k, i) as f64, p.map(f64::from), e)
                    })
                    .collect();
                film::estimate::combine_error(&parts) as f32
            })
            .collect()
    });
    let counts_u32: Option<Vec<u32>> = adaptive.then(|| {
        counts
            .iter()
            .map(|&c| u32::try_from(c).unwrap_or(u32::MAX))
            .collect()
    });
    let meta = ImageMeta {
        spp: total_u32,
        sample_offset: ranges[0].0,
        scene_hash: loaded[0].2.scene_hash,
        simd: loaded[0].2.simd,
        complete: loaded.iter().all(|(_, _, m)| m.complete),
        settings: loaded[0].2.settings,
    };
    film::write_image_aux(
        out,
        &merged,
        &meta,
        &PngOptions::default(),
        &film::AuxChannels {
            count: counts_u32.as_deref(),
            error: errors.as_deref(),
        },
    )?;
    Ok((total_u32, ranges[0].0))
}

/// `prism merge`: [`merge`], then a line on stderr naming the result.
pub(super) fn run_merge(parts: &[PathBuf], output: &Path) -> Result<(), CliError> {
    let (spp, offset) = merge(parts, output)?;
    eprintln!(
        "wrote {} ({} parts, samples {}..{})",
        output.display(),
        parts.len(),
        offset,
        offset + spp as u64
    );
    Ok(())
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
