//! The error of a render estimated from its own samples, and the adaptive allocation of
//! samples that spends them where that error is.
//!
//! **Model.** A pixel's samples alternate between two halves, A and B, drawn from two
//! independently scrambled sequences (the sampler keys half B apart, [`super::HALF_B`]). Their
//! means `a` and `b` are then independent estimates of the pixel with equal variance, and the
//! variance of the pixel's mean `x = (a + b) / 2` is estimated without bias by
//! `(a − b)² / 4`. Splitting the two halves by sample parity within one sequence would not do:
//! an Owen-scrambled Sobol sequence puts its even and odd samples in complementary halves of
//! every stratum, so `a − b` would measure the pixel's structure, not its noise. Each
//! channel's estimate is divided by `r² + 0.01`, the denominator of `prism compare`'s relMSE,
//! with `r²` estimated from two sources. The pixel's own `a·b` is unbiased (`E[ab] = E[a]E[b]`
//! for independent halves; it is `x² − (a − b)²/4`), clamped at 0, but with few samples it
//! is often near 0 (a half that drew only dark samples), and the estimate then divides by
//! 0.01: 12× the true error of the Cornell box at 2 spp, 1.45× at 8. The mean `a·b` of the
//! eight neighbours is steady, being drawn from other samples, but wrong at an edge, above
//! all next to a light seen directly; capped by the pixel's own `x²` (which exceeds its `r²`
//! only by its variance) it stays near the pixel's brightness. The two are blended by the
//! pixel's samples per half `h`: `r² ≈ w·ab + (1 − w)·min(N, x²)`, `w = h / (h + 4)`, so
//! the neighbours weigh little once a pixel has a few dozen samples. Measured against the
//! true error over independent renders (0.77 to 1.25× at 2 spp, within 0.84–1.08× from 8 spp
//! on the Cornell box, the textured scene and a haze; docs/accuracy.md). With `x²` alone, a
//! pixel whose one half drew a rare bright sample would never count for more than about 1,
//! where its true error (against a dark reference) is far larger.
//! The image's estimated relMSE is the mean over pixels and channels, as `compare` averages.

use super::compare::RELMSE_EPSILON;

/// A pixel's half means `(a, b)` per channel from the sums of all its `n` samples and of
/// half B's `n / 2`.
#[inline]
fn halves(sum: [f64; 3], half: [f64; 3], n: u32) -> [(f64, f64); 3] {
    let h = f64::from(n / 2);
    std::array::from_fn(|c| ((sum[c] - half[c]) / h, half[c] / h))
}

/// How much a pixel with `h` samples per half trusts its own `a·b` as `r²` over its
/// neighbours' (see the module's notes).
const OWN_WEIGHT_HALF_SAMPLES: f64 = 4.0;

/// The estimated relMSE of one pixel's mean (averaged over its channels) from the sums of all
/// its `n` samples and of half B's `n / 2`, and `near`, the mean `max(a·b, 0)` of its
/// neighbours per channel (`None`: the pixel's own is used). `n` must be even; below 2
/// nothing is known and the estimate is infinite.
#[inline]
pub fn pixel_error(sum: [f64; 3], half: [f64; 3], n: u32, near: Option<[f64; 3]>) -> f64 {
    if n < 2 {
        return f64::INFINITY;
    }
    let h = f64::from(n / 2);
    let w = h / (h + OWN_WEIGHT_HALF_SAMPLES);
    let mut e = 0.0;
    for (c, (a, b)) in halves(sum, half, n).into_iter().enumerate() {
        let ab = (a * b).max(0.0);
        let x = 0.5 * (a + b);
        let r2 = match near {
            Some(nb) => w * ab + (1.0 - w) * nb[c].min(x * x),
            None => ab,
        };
        e += 0.25 * (a - b) * (a - b) / (r2 + RELMSE_EPSILON);
    }
    e / 3.0
}

/// Per-pixel estimated relMSE of a `width` × `height` film with halves, each pixel with its
/// own sample count: [`pixel_error`] of each, with the mean `max(a·b, 0)` of its (up to
/// eight) neighbours that have samples.
pub fn pixel_errors(
    sums: &[[f64; 3]],
    half: &[[f64; 3]],
    counts: &[u32],
    width: u32,
    height: u32,
) -> Vec<f64> {
    let (w, h) = (width as usize, height as usize);
    debug_assert_eq!(sums.len(), w * h);
    let ab: Vec<Option<[f64; 3]>> = (0..sums.len())
        .map(|p| {
            (counts[p] >= 2)
                .then(|| halves(sums[p], half[p], counts[p]).map(|(a, b)| (a * b).max(0.0)))
        })
        .collect();
    (0..sums.len())
        .map(|p| {
            let (x, y) = (p % w.max(1), p / w.max(1));
            let (mut s, mut k) = ([0.0; 3], 0.0);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    if (xx, yy) != (x, y)
                        && let Some(v) = ab[yy * w + xx]
                    {
                        for c in 0..3 {
                            s[c] += v[c];
                        }
                        k += 1.0;
                    }
                }
            }
            let near = (k > 0.0).then(|| s.map(|v| v / k));
            pixel_error(sums[p], half[p], counts[p], near)
        })
        .collect()
}

/// The mean of per-pixel errors: the image's estimated relMSE.
pub fn image_error(errors: &[f64]) -> f64 {
    if errors.is_empty() {
        return 0.0;
    }
    errors.iter().sum::<f64>() / errors.len() as f64
}

/// How the next adaptive pass is sized.
#[derive(Clone, Copy, Debug)]
pub struct Allocation {
    /// The image's target relMSE.
    pub target: f64,
    /// The pass aims at this share of the target, so that the estimate's noise seldom
    /// leaves the image just above it (which would cost another pass).
    pub aim: f64,
    /// The most samples a pixel may reach.
    pub cap: u32,
    /// The most the image's total sample count may grow in one pass (a factor).
    pub growth: f64,
}

/// The samples each pixel adds in the next pass: an even number (so both halves stay equal),
/// zero for pixels that are done.
///
/// A pixel's per-sample relative variance `v = n · e` is taken as the mean over its eight
/// neighbours, leaving the pixel itself out: its own estimate has only one degree of freedom
/// per channel, and a pixel whose count followed its own samples would stop when they happened
/// to look converged, leaving its estimate (and the image's) too low. Neighbours' samples are
/// independent of the pixel's, so its mean and estimate stay unbiased. For a fixed total, the image's
/// mean of `v / n` is smallest with `n ∝ √v` (Lagrange), so pixels are raised to
/// `max(n, α √v)`, with `α` the least that brings the predicted error down by `E / (aim · T)`
/// (the prediction is scaled to the measured `E`, so a pass always adds samples while
/// `E > T`), and no more than the growth limit allows. The plan depends only on the film, so
/// it is the same on any number of threads.
pub fn allocate(
    errors: &[f64],
    counts: &[u32],
    width: u32,
    height: u32,
    plan: &Allocation,
) -> Vec<u32> {
    let (w, h) = (width as usize, height as usize);
    let v: Vec<f64> = errors
        .iter()
        .zip(counts)
        .map(|(&e, &n)| if e.is_finite() { e * f64::from(n) } else { 0.0 })
        .collect();
    // The mean over the 3×3 neighbourhood without its centre, clamped at the borders (a
    // one-pixel image has only itself).
    let mut vs = vec![0.0; v.len()];
    for y in 0..h {
        for x in 0..w {
            let (mut s, mut k) = (0.0, 0.0);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    if (xx, yy) != (x, y) {
                        s += v[yy * w + xx];
                        k += 1.0;
                    }
                }
            }
            vs[y * w + x] = if k > 0.0 { s / k } else { v[y * w + x] };
        }
    }
    let root: Vec<f64> = vs.iter().map(|x| x.sqrt()).collect();
    let cap = f64::from(plan.cap);
    let raised = |alpha: f64, p: usize| -> f64 {
        let n = f64::from(counts[p]);
        (alpha * root[p]).max(n).min(cap.max(n))
    };
    let predicted = |alpha: f64| -> f64 {
        (0..v.len())
            .map(|p| {
                let n = raised(alpha, p);
                if n > 0.0 { vs[p] / n } else { 0.0 }
            })
            .sum::<f64>()
    };
    let total = |alpha: f64| -> f64 { (0..v.len()).map(|p| raised(alpha, p)).sum() };
    let measured = image_error(errors) * v.len() as f64;
    let now = predicted(0.0);
    if !(now > 0.0 && measured > 0.0) {
        return vec![0; v.len()];
    }
    let want = now * (plan.aim * plan.target * v.len() as f64 / measured).min(1.0);
    let budget = total(0.0) * plan.growth;
    // Both conditions are monotone in α: bisect in log space for the least α meeting the
    // error aim, then for the largest within the budget.
    let bisect = |ok: &dyn Fn(f64) -> bool, grows: bool| -> f64 {
        let (mut lo, mut hi) = (1e-12f64, 1e12f64);
        for _ in 0..100 {
            let mid = (lo * hi).sqrt();
            if ok(mid) == grows {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        if grows { hi } else { lo }
    };
    let a_err = bisect(&|a| predicted(a) <= want, true);
    let a_budget = bisect(&|a| total(a) <= budget, false);
    let alpha = a_err.min(a_budget);
    (0..v.len())
        .map(|p| {
            let add = (raised(alpha, p) - f64::from(counts[p])).max(0.0).ceil() as u32;
            let add = add + (add & 1);
            add.min(plan.cap.saturating_sub(counts[p]) & !1)
        })
        .collect()
}

/// The estimated relMSE of the mean of independent parts of one pixel, each given as (its
/// sample count, its mean, its estimated relMSE): variances add with weights `(nᵢ / n)²`, and
/// are re-expressed against the combined mean.
pub fn combine_error(parts: &[(f64, [f64; 3], f64)]) -> f64 {
    let n: f64 = parts.iter().map(|p| p.0).sum();
    if n <= 0.0 {
        return f64::INFINITY;
    }
    let mut mean = [0.0; 3];
    for (k, m, _) in parts {
        for c in 0..3 {
            mean[c] += k * m[c] / n;
        }
    }
    let mut e = 0.0;
    for c in 0..3 {
        // A part's relMSE is per-channel averaged; spread it back over channels in proportion
        // to each channel's denominator, which is exact when the channels' relative errors are
        // equal and close otherwise.
        let var: f64 = parts
            .iter()
            .map(|(k, m, err)| {
                let w = k / n;
                w * w * err * (m[c] * m[c] + RELMSE_EPSILON)
            })
            .sum();
        e += var / (mean[c] * mean[c] + RELMSE_EPSILON);
    }
    e / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_halves_have_no_error_and_unequal_ones_the_formula() {
        assert_eq!(pixel_error([4.0; 3], [2.0; 3], 4, None), 0.0);
        // a = 1, b = 3 per channel: Var = 1, r² ≈ ab = 3, relMSE = 1 / 3.01.
        let e = pixel_error([8.0; 3], [6.0; 3], 4, None);
        assert!((e - 1.0 / 3.01).abs() < 1e-12);
        // One bright half over a dark pixel: r² ≈ 0, the error is the variance over 0.01.
        let e = pixel_error([200.0; 3], [0.0; 3], 4, None);
        assert!((e - 100.0f64.powi(2) / 4.0 / 0.01).abs() < 1e-6, "{e}");
        assert!(pixel_error([1.0; 3], [0.0; 3], 1, None).is_infinite());
    }

    #[test]
    fn a_dark_half_borrows_its_neighbours_brightness() {
        // 3×3 pixels of one sample per half: a = b = 1 around, a = 2 and b = 0 in the middle.
        let mut sums = vec![[2.0; 3]; 9];
        let mut half = vec![[1.0; 3]; 9];
        (sums[4], half[4]) = ([2.0; 3], [0.0; 3]);
        let e = pixel_errors(&sums, &half, &[2; 9], 3, 3);
        assert!(e.iter().enumerate().all(|(p, &e)| p == 4 || e == 0.0));
        // Own a·b = 0, neighbours' 1, x² = 1; w = 1/5: r² = 0.8, Var = 1.
        assert!((e[4] - 1.0 / 0.81).abs() < 1e-12, "{}", e[4]);
        // The pixel alone divides by 0.01.
        assert!((pixel_error(sums[4], half[4], 2, None) - 100.0).abs() < 1e-9);
        // With many samples its own a·b dominates: h = 96, w = 0.96, r² = 0.04.
        let mut counts = [2; 9];
        (counts[4], sums[4]) = (192, [192.0; 3]);
        let e = pixel_errors(&sums, &half, &counts, 3, 3);
        assert!((e[4] - 1.0 / 0.05).abs() < 1e-9, "{}", e[4]);
    }

    #[test]
    fn allocation_follows_the_noise_and_stops_converged_pixels() {
        // A 4×4 image: the left half ten times noisier per sample than the right.
        let (w, h) = (8u32, 4u32);
        let counts = vec![32u32; 32];
        let errors: Vec<f64> = (0..32)
            .map(|p| if p % 8 < 4 { 0.1 } else { 0.001 })
            .collect();
        let plan = Allocation {
            target: 0.01,
            aim: 1.0,
            cap: 1 << 20,
            growth: 100.0,
        };
        let add = allocate(&errors, &counts, w, h, &plan);
        assert!(add.iter().all(|a| a % 2 == 0));
        let noisy: u32 = (0..32).filter(|p| p % 8 == 0).map(|p| add[p]).sum();
        let quiet: u32 = (0..32).filter(|p| p % 8 == 7).map(|p| add[p]).sum();
        assert!(noisy > 0 && quiet == 0, "{add:?}");
        // The predicted error after the pass meets the target.
        let after: f64 = (0..32)
            .map(|p| errors[p] * 32.0 / f64::from(32 + add[p]))
            .sum::<f64>()
            / 32.0;
        assert!(after <= 0.0105, "{after}");
        // A growth limit of 1.25 holds the total.
        let slow = allocate(
            &errors,
            &counts,
            w,
            h,
            &Allocation {
                growth: 1.25,
                ..plan
            },
        );
        let total: u32 = slow.iter().sum();
        assert!(total as f64 <= 0.25 * 32.0 * 32.0 + 2.0 * 32.0, "{total}");
        // At the target, nothing more.
        let done: Vec<f64> = vec![0.005; 32];
        assert!(
            allocate(&done, &counts, w, h, &plan)
                .iter()
                .all(|&a| a == 0)
        );
    }

    #[test]
    fn combining_two_equal_parts_halves_the_error() {
        let e = combine_error(&[(10.0, [1.0; 3], 0.02), (10.0, [1.0; 3], 0.02)]);
        assert!((e - 0.01).abs() < 1e-12, "{e}");
    }
}
