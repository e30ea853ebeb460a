//! Structural similarity (Wang et al. 2004) on display luminance: a perceptual error that
//! noise and bias move differently from RMSE.

use crate::film::{Image, srgb_encode};

/// Mean SSIM of `a` against `b` over 7×7 windows of the sRGB-encoded, clamped luminance (what
/// a viewer of the PNG sees). 1 means identical.
pub fn ssim(a: &Image, b: &Image) -> f64 {
    let lum = |img: &Image| -> Vec<f64> {
        img.pixels
            .iter()
            .map(|p| {
                let y = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                srgb_encode(if y.is_finite() {
                    y.clamp(0.0, 1.0)
                } else {
                    0.0
                }) as f64
            })
            .collect()
    };
    let (la, lb) = (lum(a), lum(b));
    let (w, h) = (a.width as usize, a.height as usize);
    const R: usize = 3;
    let (c1, c2) = (0.01f64.powi(2), 0.03f64.powi(2));
    if w < 2 * R + 1 || h < 2 * R + 1 {
        return 1.0 - crate::film::compare(a, b).map_or(1.0, |m| m.rmse.min(1.0));
    }
    let (mut total, mut n) = (0.0, 0usize);
    for y in R..h - R {
        for x in R..w - R {
            let (mut sa, mut sb, mut saa, mut sbb, mut sab) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for yy in y - R..=y + R {
                for xx in x - R..=x + R {
                    let (p, q) = (la[yy * w + xx], lb[yy * w + xx]);
                    sa += p;
                    sb += q;
                    saa += p * p;
                    sbb += q * q;
                    sab += p * q;
                }
            }
            let k = ((2 * R + 1) * (2 * R + 1)) as f64;
            let (ma, mb) = (sa / k, sb / k);
            let (va, vb, cov) = (saa / k - ma * ma, sbb / k - mb * mb, sab / k - ma * mb);
            total += ((2.0 * ma * mb + c1) * (2.0 * cov + c2))
                / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            n += 1;
        }
    }
    total / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_is_one_and_noise_lowers_it() {
        let w = 32;
        let a = Image {
            width: w,
            height: w,
            pixels: (0..w * w).map(|i| [(i % w) as f32 / w as f32; 3]).collect(),
        };
        assert!((ssim(&a, &a) - 1.0).abs() < 1e-12);
        let mut b = a.clone();
        for (i, p) in b.pixels.iter_mut().enumerate() {
            let n = if i % 2 == 0 { 0.1 } else { -0.1 };
            *p = [p[0] + n, p[1] + n, p[2] + n];
        }
        assert!(ssim(&b, &a) < 0.9);
    }
}
