//! Error metrics between a render and a reference image.

use std::path::Path;

use crate::imageio::{FilmError, Image, read_image};

/// Per-channel error statistics of an image against a reference.
///
/// Non-finite pixels propagate (a NaN anywhere makes every metric NaN), so a
/// threshold test such as `m.rmse < tol` fails rather than passing silently.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// √(mean over pixels and channels of (a − b)²).
    pub rmse: f64,
    /// Mean over pixels and channels of (a − b)² / (b² + 0.01).
    pub relmse: f64,
    /// Largest |a − b| over pixels and channels.
    pub max_abs: f64,
}

/// Keeps relMSE finite where the reference is black; 0.01 is the usual
/// choice in the rendering literature.
pub const RELMSE_EPSILON: f64 = 0.01;

/// Compares `a` against the reference `b`. relMSE = mean over pixels and
/// channels of (a − b)² / (b² + 0.01). Images with no pixels give all-zero
/// metrics.
pub fn compare(a: &Image, b: &Image) -> Result<Metrics, FilmError> {
    compare_labelled(a, None, b, None)
}

/// Reads both files and compares `a` against the reference `b`; errors name
/// the files.
pub fn compare_files(a: &Path, b: &Path) -> Result<Metrics, FilmError> {
    let (img_a, _) = read_image(a)?;
    let (img_b, _) = read_image(b)?;
    compare_labelled(&img_a, Some(a), &img_b, Some(b))
}

fn compare_labelled(
    a: &Image,
    a_path: Option<&Path>,
    b: &Image,
    b_path: Option<&Path>,
) -> Result<Metrics, FilmError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(FilmError::SizeMismatch {
            a: a_path.map(Path::to_path_buf),
            a_size: (a.width, a.height),
            b: b_path.map(Path::to_path_buf),
            b_size: (b.width, b.height),
        });
    }
    a.validate(a_path)?;
    b.validate(b_path)?;

    let samples = a.pixels.len() * 3;
    if samples == 0 {
        return Ok(Metrics {
            rmse: 0.0,
            relmse: 0.0,
            max_abs: 0.0,
        });
    }

    // f64 accumulation: a 4K image has ~25M terms, enough to lose digits
    // in f32.
    let (mut sq, mut rel, mut max_abs) = (0.0f64, 0.0f64, 0.0f64);
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        for (&ca, &cb) in pa.iter().zip(pb) {
            let (ca, cb) = (f64::from(ca), f64::from(cb));
            let d = ca - cb;
            sq += d * d;
            rel += d * d / (cb * cb + RELMSE_EPSILON);
            // `f64::max` would drop NaN; once seen, keep it visible.
            let ad = d.abs();
            if !max_abs.is_nan() && (ad.is_nan() || ad > max_abs) {
                max_abs = ad;
            }
        }
    }
    let n = samples as f64;
    Ok(Metrics {
        rmse: (sq / n).sqrt(),
        relmse: rel / n,
        max_abs,
    })
}

/// relMSE with the pixels of the largest errors left out: each pixel's relMSE (mean over its
/// channels), the `drop` fraction of pixels with the largest ones discarded, the rest
/// averaged. Rare very bright samples (caustic paths found by chance) dominate the plain
/// mean for thousands of samples, hiding how the rest of the image converges; dropping the
/// worst 0.1 % is the usual remedy in the rendering literature. Sizes must match (callers
/// compare the images first); NaN sorts last and so is dropped first, but [`compare`]
/// still reports it.
pub fn relmse_trimmed(a: &Image, b: &Image, drop: f64) -> f64 {
    let mut e: Vec<f64> = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(pa, pb)| {
            pa.iter()
                .zip(pb)
                .map(|(&ca, &cb)| {
                    let (ca, cb) = (f64::from(ca), f64::from(cb));
                    (ca - cb) * (ca - cb) / (cb * cb + RELMSE_EPSILON)
                })
                .sum::<f64>()
                / 3.0
        })
        .collect();
    if e.is_empty() {
        return 0.0;
    }
    let keep = e.len() - ((e.len() as f64 * drop).ceil() as usize).min(e.len() - 1);
    e.select_nth_unstable_by(keep - 1, f64::total_cmp);
    e[..keep].iter().sum::<f64>() / keep as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::imageio::{ImageMeta, PngOptions, write_image};

    #[test]
    fn trimmed_relmse_drops_only_the_worst_pixels() {
        // 2000 pixels: one outlier of error 1e6 and 1999 of relMSE (0.1)²/(1 + 0.01).
        let r = Image {
            width: 2000,
            height: 1,
            pixels: vec![[1.0; 3]; 2000],
        };
        let mut a = r.clone();
        for p in &mut a.pixels {
            *p = [1.1; 3];
        }
        a.pixels[7] = [1001.0; 3];
        let each = 0.1f64 * 0.1 / 1.01;
        // 0.1 % of 2000 is 2 pixels: the outlier and one ordinary pixel go.
        let t = relmse_trimmed(&a, &r, 0.001);
        assert!((t / each - 1.0).abs() < 1e-5, "{t} vs {each}");
        // Dropping nothing keeps the outlier's weight.
        assert!(relmse_trimmed(&a, &r, 0.0) > 100.0);
        assert!(compare(&a, &r).unwrap().relmse > 100.0);
    }

    fn row(pixels: &[[f32; 3]]) -> Image {
        Image {
            width: pixels.len() as u32,
            height: 1,
            pixels: pixels.to_vec(),
        }
    }

    fn reference() -> Image {
        row(&[[0.0; 3], [1.0; 3], [2.0; 3]])
    }

    fn close(x: f64, y: f64) -> bool {
        (x - y).abs() <= 1e-12 * y.abs().max(1.0)
    }

    #[test]
    fn identical_images_have_zero_error() {
        let m = compare(&reference(), &reference()).unwrap();
        assert_eq!(
            m,
            Metrics {
                rmse: 0.0,
                relmse: 0.0,
                max_abs: 0.0
            }
        );
    }

    #[test]
    fn known_images_give_exact_metrics() {
        // Differences 1 (ref 0), 2 (ref 1) and −2 (ref 2); other channels
        // agree. Σd² = 9 over 9 samples.
        let a = row(&[[1.0, 0.0, 0.0], [1.0, 3.0, 1.0], [2.0, 2.0, 0.0]]);
        let m = compare(&a, &reference()).unwrap();
        assert_eq!(m.rmse, 1.0);
        assert_eq!(m.max_abs, 2.0);
        // (1/0.01 + 4/1.01 + 4/4.01) / 9
        let expected = (100.0 + 4.0 / 1.01 + 4.0 / 4.01) / 9.0;
        assert!(close(m.relmse, expected), "{}", m.relmse);
        assert!(close(m.relmse, 11.661_989_141_557_548), "{}", m.relmse);
    }

    #[test]
    fn relmse_is_relative_to_the_reference() {
        // Swapping the roles changes only the relative metric.
        let (x, y) = (row(&[[0.0; 3]]), row(&[[1.0; 3]]));
        let xy = compare(&x, &y).unwrap();
        let yx = compare(&y, &x).unwrap();
        assert_eq!((xy.rmse, xy.max_abs), (yx.rmse, yx.max_abs));
        assert!(close(xy.relmse, 1.0 / 1.01));
        assert!(close(yx.relmse, 100.0));
    }

    #[test]
    fn non_finite_pixels_poison_the_metrics() {
        let a = row(&[[f32::NAN, 0.0, 0.0], [1.0; 3], [2.0; 3]]);
        let m = compare(&a, &reference()).unwrap();
        assert!(
            m.rmse.is_nan() && m.relmse.is_nan() && m.max_abs.is_nan(),
            "{m:?}"
        );
    }

    #[test]
    fn empty_images_compare_as_zero() {
        let e = Image {
            width: 0,
            height: 0,
            pixels: vec![],
        };
        assert_eq!(compare(&e, &e).unwrap().rmse, 0.0);
    }

    #[test]
    fn size_mismatch_names_both_sizes() {
        let a = Image::filled(64, 64, [0.0; 3]);
        let b = Image::filled(32, 16, [0.0; 3]);
        let err = compare(&a, &b).unwrap_err();
        assert_eq!(err.to_string(), "image is 64×64 but reference is 32×16");
    }

    #[test]
    fn bad_buffer_is_an_error() {
        let mut a = reference();
        a.pixels.pop();
        let msg = compare(&a, &reference()).unwrap_err().to_string();
        assert_eq!(msg, "image: 3×1 needs 3 pixels but the buffer holds 2");
    }

    #[test]
    fn compare_files_names_both_paths() {
        let dir = tempfile::tempdir().unwrap();
        let (pa, pb) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
        let meta = ImageMeta {
            spp: 1,
            sample_offset: 0,
            scene_hash: 0,
            simd: None,
            complete: true,
            settings: None,
        };
        let opts = PngOptions::default();
        write_image(&pa, &Image::filled(64, 64, [0.0; 3]), &meta, &opts).unwrap();
        write_image(&pb, &Image::filled(32, 32, [0.0; 3]), &meta, &opts).unwrap();
        let msg = compare_files(&pa, &pb).unwrap_err().to_string();
        assert_eq!(
            msg,
            format!(
                "'{}' is 64×64 but '{}' is 32×32",
                pa.display(),
                pb.display()
            )
        );

        write_image(&pb, &Image::filled(64, 64, [0.5; 3]), &meta, &opts).unwrap();
        let m = compare_files(&pa, &pb).unwrap();
        assert_eq!((m.rmse, m.max_abs), (0.5, 0.5));
    }
}
