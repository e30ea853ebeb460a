//! Chi-square goodness-of-fit harness for sampling routines.
//!
//! Samples are histogrammed over a 2-D parameter rectangle; each bin's
//! expected count is `n ×` the pdf integrated over it by adaptive Simpson.
//! Sampling failures (`None`) and samples outside the rectangle share one
//! extra cell whose expected count is `n × (1 − ∫pdf)`, so a pdf whose mass
//! is wrong overall is caught as well as a mis-shaped one. Cells expecting
//! fewer than [`Chi2::min_expected`] samples are pooled, and the statistic's
//! p-value comes from the regularized upper incomplete gamma function.
//!
//! The integration is adaptive, so pdfs with edges inside bins (a disk's
//! rim on a Cartesian grid) are handled, but a pdf whose jumps fall on bin
//! edges (a hemisphere's horizon, a cone's rim in (1 − cos θ, φ)) is
//! integrated exactly and cheaply: prefer such domains.
//!
//! Directions are binned in (1 − cos θ, φ) about +z, where the solid-angle
//! element is exactly d(1 − cos θ) dφ; 1 − cos θ is computed without
//! cancellation, so narrow cones near +z are resolved finely.

use std::f64::consts::TAU;

use glam::{DVec3, Vec2, Vec3};
use rand::Rng;
use rand_pcg::Pcg32;

/// Significance level of a single test.
pub const SIGNIFICANCE: f64 = 0.01;

/// Test configuration; see the module docs.
#[derive(Clone, Copy, Debug)]
pub struct Chi2 {
    /// Bins along the two parameter axes (a 1-D test uses `res[0]`).
    pub res: [usize; 2],
    /// Number of samples drawn.
    pub samples: usize,
    /// Seed of the uniform numbers fed to the sampling routine.
    pub seed: u64,
    /// Rejection level before the Šidák correction.
    pub significance: f64,
    /// Number of tests sharing `significance` (Šidák correction).
    pub tests: usize,
    /// Levels of adaptive quadtree refinement allowed per bin when
    /// integrating the pdf (each level halves the cell size).
    pub max_depth: u32,
    /// Cells expecting fewer samples than this are pooled.
    pub min_expected: f64,
}

/// Result of a test that ran to completion.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// Per-test rejection threshold after the Šidák correction.
    pub threshold: f64,
    /// Numerical integral of the pdf over the domain.
    pub integral: f64,
}

impl Outcome {
    pub fn passed(&self) -> bool {
        self.p_value >= self.threshold
    }
}

impl Chi2 {
    pub fn new(samples: usize, seed: u64) -> Self {
        Self {
            res: [32, 64],
            samples,
            seed,
            significance: SIGNIFICANCE,
            tests: 1,
            max_depth: 6,
            min_expected: 5.0,
        }
    }

    pub fn res(mut self, a: usize, b: usize) -> Self {
        self.res = [a, b];
        self
    }

    /// Declares that `tests` tests run at the same significance, tightening
    /// each one's threshold so the family-wise false rejection rate stays at
    /// `significance`.
    pub fn tests(mut self, tests: usize) -> Self {
        self.tests = tests.max(1);
        self
    }

    pub fn max_depth(mut self, max_depth: u32) -> Self {
        self.max_depth = max_depth;
        self
    }

    /// Directions about +z, with 1 − cos θ restricted to `one_minus_cos`
    /// (use `[0, 2]` for the whole sphere). `pdf` is per solid angle.
    pub fn directions(
        &self,
        one_minus_cos: [f64; 2],
        mut sample: impl FnMut(Vec2) -> Option<Vec3>,
        pdf: impl Fn(Vec3) -> f32,
    ) -> Result<Outcome, String> {
        self.run(
            [one_minus_cos[0], 0.0],
            [one_minus_cos[1], TAU],
            |rng| match sample(uniform_2d(rng)) {
                None => Ok(None),
                Some(d) => direction_to_param(d).map(Some),
            },
            |s, phi| f64::from(pdf(param_to_direction(s, phi))),
        )
    }

    /// Points in the rectangle `[lo, hi]`; `pdf` is per unit area.
    pub fn planar(
        &self,
        lo: Vec2,
        hi: Vec2,
        mut sample: impl FnMut(Vec2) -> Option<Vec2>,
        pdf: impl Fn(Vec2) -> f32,
    ) -> Result<Outcome, String> {
        self.run(
            [f64::from(lo.x), f64::from(lo.y)],
            [f64::from(hi.x), f64::from(hi.y)],
            |rng| match sample(uniform_2d(rng)) {
                None => Ok(None),
                Some(p) if p.is_finite() => Ok(Some([f64::from(p.x), f64::from(p.y)])),
                Some(p) => Err(format!("non-finite sample {p}")),
            },
            |x, y| f64::from(pdf(Vec2::new(x as f32, y as f32))),
        )
    }

    /// Points on the interval `[lo, hi]` in `res[0]` bins; `pdf` is per
    /// unit length.
    pub fn linear(
        &self,
        lo: f32,
        hi: f32,
        mut sample: impl FnMut(f32) -> Option<f32>,
        pdf: impl Fn(f32) -> f32,
    ) -> Result<Outcome, String> {
        let one_d = Self {
            res: [self.res[0], 1],
            ..*self
        };
        one_d.run(
            [f64::from(lo), 0.0],
            [f64::from(hi), 1.0],
            |rng| match sample(uniform_1d(rng)) {
                None => Ok(None),
                Some(x) if x.is_finite() => Ok(Some([f64::from(x), 0.5])),
                Some(x) => Err(format!("non-finite sample {x}")),
            },
            |x, _| f64::from(pdf(x as f32)),
        )
    }

    /// Core: `draw` yields parameter-space points (None: failed sample),
    /// `density` is the pdf in parameter space.
    fn run(
        &self,
        lo: [f64; 2],
        hi: [f64; 2],
        mut draw: impl FnMut(&mut Pcg32) -> Result<Option<[f64; 2]>, String>,
        density: impl Fn(f64, f64) -> f64,
    ) -> Result<Outcome, String> {
        let [rx, ry] = self.res;
        assert!(
            rx > 0 && ry > 0 && self.samples > 0,
            "empty chi-square test"
        );
        let n = self.samples as f64;

        let mut observed = vec![0.0f64; rx * ry + 1];
        let outside = rx * ry;
        let mut rng = Pcg32::new(self.seed, 0x6a09_e667_f3bc_c909);
        for _ in 0..self.samples {
            let cell = match draw(&mut rng)? {
                None => outside,
                Some(p) => match (
                    bin_of(p[0], lo[0], hi[0], rx),
                    bin_of(p[1], lo[1], hi[1], ry),
                ) {
                    (Some(i), Some(j)) => j * rx + i,
                    _ => outside,
                },
            };
            observed[cell] += 1.0;
        }

        let bins = integrate_bins(lo, hi, self.res, self.max_depth, &density);
        let describe = |cell: usize| {
            if cell == outside {
                "the failed/outside cell".to_string()
            } else {
                let (i, j) = (cell % rx, cell / rx);
                let at = |k: usize, a: usize| {
                    lo[a] + (hi[a] - lo[a]) * (k as f64 + 0.5) / self.res[a] as f64
                };
                format!(
                    "bin ({i}, {j}) centred at ({:.6}, {:.6})",
                    at(i, 0),
                    at(j, 1)
                )
            }
        };
        if let Some(c) = bins.iter().position(|b| !b.is_finite() || *b < 0.0) {
            return Err(format!("pdf is negative or not finite in {}", describe(c)));
        }
        let integral: f64 = bins.iter().sum();
        // Simpson's error on a smooth, normalized pdf is far below this; more
        // than this is a pdf with too much mass, not noise.
        if integral > 1.0 + 1e-3 {
            return Err(format!("pdf integrates to {integral} > 1 over the domain"));
        }
        let mut expected: Vec<f64> = bins.iter().map(|b| b * n).collect();
        expected.push(((1.0 - integral) * n).max(0.0));
        judge(
            &observed,
            &expected,
            self.min_expected,
            self.significance,
            self.tests,
            integral,
            describe,
        )
    }
}

/// Pools, computes the statistic and its p-value, and accepts or rejects.
fn judge(
    observed: &[f64],
    expected: &[f64],
    min_expected: f64,
    significance: f64,
    tests: usize,
    integral: f64,
    describe: impl Fn(usize) -> String,
) -> Result<Outcome, String> {
    let (statistic, dof, worst) =
        pooled_statistic(observed, expected, min_expected).map_err(|cell| {
            format!(
                "{} samples in {} whose expected count is 0",
                observed[cell],
                describe(cell)
            )
        })?;
    if dof == 0 {
        return Err("too few cells with enough expected samples for a chi-square test".into());
    }
    let p_value = chi2_p_value(statistic, dof);
    let threshold = 1.0 - (1.0 - significance).powf(1.0 / tests.max(1) as f64);
    let outcome = Outcome {
        statistic,
        dof,
        p_value,
        threshold,
        integral,
    };
    if outcome.passed() {
        Ok(outcome)
    } else {
        Err(format!(
            "rejected: chi² = {statistic:.1} with {dof} dof, p = {p_value:.3e} < {threshold:.3e}; \
             pdf integral {integral:.6}; worst cell: {} observed {} expected {:.1}",
            describe(worst),
            observed[worst],
            expected[worst]
        ))
    }
}

/// Goodness of fit of observed `counts` of a discrete distribution to `pmf`
/// (one test at [`SIGNIFICANCE`], Šidák-corrected for `tests` tests).
pub fn chi2_test_discrete(counts: &[u64], pmf: &[f64], tests: usize) -> Result<Outcome, String> {
    assert_eq!(counts.len(), pmf.len(), "one count per pmf entry");
    let total: f64 = pmf.iter().sum();
    if !total.is_finite() || (total - 1.0).abs() > 1e-4 {
        return Err(format!("pmf sums to {total}, not 1"));
    }
    let n = counts.iter().sum::<u64>() as f64;
    let observed: Vec<f64> = counts.iter().map(|&c| c as f64).collect();
    let expected: Vec<f64> = pmf.iter().map(|&p| p * n).collect();
    judge(&observed, &expected, 5.0, SIGNIFICANCE, tests, total, |i| {
        format!("entry {i}")
    })
}

/// Whole-sphere direction test with the default configuration.
pub fn chi2_test_directions(
    sample: impl FnMut(Vec2) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
    n: usize,
    seed: u64,
) -> Result<(), String> {
    Chi2::new(n, seed)
        .directions([0.0, 2.0], sample, pdf)
        .map(|_| ())
}

/// Planar test over `[lo, hi]` on a 32 × 32 grid.
pub fn chi2_test_planar(
    sample: impl FnMut(Vec2) -> Option<Vec2>,
    pdf: impl Fn(Vec2) -> f32,
    lo: Vec2,
    hi: Vec2,
    n: usize,
    seed: u64,
) -> Result<(), String> {
    Chi2::new(n, seed)
        .res(32, 32)
        .planar(lo, hi, sample, pdf)
        .map(|_| ())
}

/// ∫ pdf dω over the directions with 1 − cos θ in `one_minus_cos`.
pub fn integrate_directions(
    pdf: impl Fn(Vec3) -> f32,
    one_minus_cos: [f64; 2],
    res: [usize; 2],
) -> f64 {
    integrate_bins(
        [one_minus_cos[0], 0.0],
        [one_minus_cos[1], TAU],
        res,
        6,
        &|s, phi| f64::from(pdf(param_to_direction(s, phi))),
    )
    .iter()
    .sum()
}

/// ∫ pdf dA over the rectangle `[lo, hi]`.
pub fn integrate_planar(pdf: impl Fn(Vec2) -> f32, lo: Vec2, hi: Vec2, res: [usize; 2]) -> f64 {
    integrate_bins(
        [f64::from(lo.x), f64::from(lo.y)],
        [f64::from(hi.x), f64::from(hi.y)],
        res,
        6,
        &|x, y| f64::from(pdf(Vec2::new(x as f32, y as f32))),
    )
    .iter()
    .sum()
}

/// Uniform f32 in [0, 1) with 24 random bits, like the renderer's samplers.
pub fn uniform_1d(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
}

pub fn uniform_2d(rng: &mut Pcg32) -> Vec2 {
    let x = uniform_1d(rng);
    Vec2::new(x, uniform_1d(rng))
}

/// Direction with the given 1 − cos θ and φ about +z.
pub fn param_to_direction(one_minus_cos: f64, phi: f64) -> Vec3 {
    let s = one_minus_cos;
    let sin_theta = (s * (2.0 - s)).max(0.0).sqrt();
    DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), 1.0 - s).as_vec3()
}

/// (1 − cos θ, φ ∈ [0, 2π)) of a unit direction, renormalized in f64 first
/// so f32 length error does not bias the binning.
pub fn direction_to_param(d: Vec3) -> Result<[f64; 2], String> {
    let len = d.length();
    if !d.is_finite() || (len - 1.0).abs() > 1e-3 {
        return Err(format!(
            "sampled direction {d} is not a unit vector (length {len})"
        ));
    }
    let d = d.as_dvec3().normalize();
    // Near +z, 1 − z cancels; (x² + y²)/(1 + z) is the same quantity
    // computed from the small components at full relative precision.
    let s = if d.z > 0.0 {
        (d.x * d.x + d.y * d.y) / (1.0 + d.z)
    } else {
        1.0 - d.z
    };
    let phi = d.y.atan2(d.x);
    Ok([s, if phi < 0.0 { phi + TAU } else { phi }])
}

/// Bin of `x` among `res` equal bins over [lo, hi]; values within a hair of
/// the ends (rounding in the sampler) count as inside.
fn bin_of(x: f64, lo: f64, hi: f64, res: usize) -> Option<usize> {
    let t = (x - lo) / (hi - lo);
    if !(-1e-6..=1.0 + 1e-6).contains(&t) {
        return None;
    }
    Some(((t * res as f64).max(0.0) as usize).min(res - 1))
}

/// Integral of `density` over each bin (row-major, x fastest).
///
/// Each bin is integrated by adaptive 2-D Simpson: a cell's 4 × 4-interval
/// Simpson estimate is compared with the sum over its four quadrants, and
/// only cells where they disagree (a discontinuity or kink inside) are split
/// further, up to `max_depth` levels. Every cell's outermost nodes sit a hair
/// inside it, so a pdf that jumps exactly on a bin edge is integrated from
/// the correct side on both.
fn integrate_bins(
    lo: [f64; 2],
    hi: [f64; 2],
    res: [usize; 2],
    max_depth: u32,
    density: &dyn Fn(f64, f64) -> f64,
) -> Vec<f64> {
    let [rx, ry] = res;
    let (wx, wy) = ((hi[0] - lo[0]) / rx as f64, (hi[1] - lo[1]) / ry as f64);
    let mut bins = Vec::with_capacity(rx * ry);
    for j in 0..ry {
        for i in 0..rx {
            let x0 = lo[0] + wx * i as f64;
            let y0 = lo[1] + wy * j as f64;
            // Each bin starts as 4 × 4 sub-cells: a pdf that is zero at every node of one
            // Simpson cell (a thin corner of an emitter crossing the bin) would otherwise
            // look empty to the adaptive refinement.
            const SPLIT: usize = 4;
            let (sx, sy) = (wx / SPLIT as f64, wy / SPLIT as f64);
            let mut sum = 0.0;
            for b in 0..SPLIT {
                for a in 0..SPLIT {
                    let (cx, cy) = (x0 + sx * a as f64, y0 + sy * b as f64);
                    let cell = [cx, cy, cx + sx, cy + sy];
                    let whole = simpson_cell(cell, density);
                    sum += adaptive_cell(cell, whole, max_depth, density);
                }
            }
            bins.push(sum);
        }
    }
    bins
}

fn quadrants([x0, y0, x1, y1]: [f64; 4]) -> [[f64; 4]; 4] {
    let (xm, ym) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    [
        [x0, y0, xm, ym],
        [xm, y0, x1, ym],
        [x0, ym, xm, y1],
        [xm, ym, x1, y1],
    ]
}

fn adaptive_cell(cell: [f64; 4], whole: f64, depth: u32, density: &dyn Fn(f64, f64) -> f64) -> f64 {
    let parts = quadrants(cell).map(|q| (q, simpson_cell(q, density)));
    let refined: f64 = parts.iter().map(|p| p.1).sum();
    // Smooth integrands agree to O(h⁴) here; a 1e-6 relative gap (far below
    // what a million samples can resolve) means something is inside the cell.
    // A gap below 1e-10 of probability is not worth resolving: even 10⁵ such
    // cells move the expected counts of 10⁶ samples by 10 in all, against a
    // noise of about 30 in one busy bin, and splitting the tails of narrow
    // lobes down to f32 rounding cost minutes.
    if depth == 0 || (refined - whole).abs() <= 1e-6 * refined.abs() + 1e-10 {
        refined
    } else {
        parts
            .iter()
            .map(|&(q, s)| adaptive_cell(q, s, depth - 1, density))
            .sum()
    }
}

/// Composite Simpson with 4 intervals per axis over a cell whose edge nodes
/// are pulled inward by 10⁻⁵ of its size (a negligible bias, and large
/// enough to survive rounding the coordinates to f32).
fn simpson_cell([x0, y0, x1, y1]: [f64; 4], density: &dyn Fn(f64, f64) -> f64) -> f64 {
    const W: [f64; 5] = [1.0, 4.0, 2.0, 4.0, 1.0];
    let (ex, ey) = (1e-5 * (x1 - x0), 1e-5 * (y1 - y0));
    let (hx, hy) = ((x1 - x0 - 2.0 * ex) / 4.0, (y1 - y0 - 2.0 * ey) / 4.0);
    let mut acc = 0.0;
    for (j, wj) in W.iter().enumerate() {
        let y = y0 + ey + hy * j as f64;
        for (i, wi) in W.iter().enumerate() {
            acc += wi * wj * density(x0 + ex + hx * i as f64, y);
        }
    }
    // Rescale from the shrunken cell to the true one.
    acc * hx * hy / 9.0 * ((x1 - x0) * (y1 - y0)) / ((x1 - x0 - 2.0 * ex) * (y1 - y0 - 2.0 * ey))
}

/// Pearson's statistic with cells expecting fewer than `min_expected`
/// samples merged into one, smallest first (as Mitsuba does). Returns
/// (statistic, degrees of freedom, cell contributing the most), or the index
/// of a cell that received samples although none were expected.
fn pooled_statistic(
    observed: &[f64],
    expected: &[f64],
    min_expected: f64,
) -> Result<(f64, usize, usize), usize> {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut stat, mut cells) = (0.0, 0usize);
    let (mut pool_obs, mut pool_exp) = (0.0, 0.0);
    let (mut worst, mut worst_term) = (order[0], -1.0);
    for &c in &order {
        let (o, e) = (observed[c], expected[c]);
        if e.is_nan() {
            // A non-finite pdf value poisons its bin; report it as such.
            return Err(c);
        }
        if e <= 0.0 {
            if o > 0.0 {
                return Err(c);
            }
        } else if e < min_expected || (pool_exp > 0.0 && pool_exp < min_expected) {
            pool_obs += o;
            pool_exp += e;
        } else {
            let term = (o - e) * (o - e) / e;
            if term > worst_term {
                (worst, worst_term) = (c, term);
            }
            stat += term;
            cells += 1;
        }
    }
    if pool_exp > 0.0 {
        stat += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
        cells += 1;
    }
    // The total count is fixed, which removes one degree of freedom.
    Ok((stat, cells.saturating_sub(1), worst))
}

/// P(X ≥ statistic) for X ~ χ²(dof).
pub fn chi2_p_value(statistic: f64, dof: usize) -> f64 {
    gamma_q(dof as f64 / 2.0, statistic / 2.0)
}

/// Regularized upper incomplete gamma function Q(a, x) = Γ(a, x) / Γ(a).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0, "gamma_q needs a > 0");
    if x <= 0.0 {
        return 1.0;
    }
    // Common factor e^{−x} x^a / Γ(a), in logs to avoid overflow.
    let log_front = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        // Series for the lower function P converges fast here:
        // P = front · Σₙ xⁿ / (a (a+1) … (a+n)).
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * log_front.exp()).clamp(0.0, 1.0)
    } else {
        // Continued fraction for Q, evaluated with the modified Lentz method:
        // Q = front / (x + 1 − a − 1(1 − a) / (x + 3 − a − 2(2 − a) / …)).
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (h * log_front.exp()).clamp(0.0, 1.0)
    }
}

/// ln Γ(x) for x > 0: shift up with Γ(x + 1) = x Γ(x) until Stirling's
/// series is accurate to ~1e-13, then apply it.
pub fn ln_gamma(x: f64) -> f64 {
    let (mut z, mut shift) = (x, 0.0);
    while z < 10.0 {
        shift += z.ln();
        z += 1.0;
    }
    let inv = 1.0 / z;
    let inv2 = inv * inv;
    // Terms B₂ₖ / (2k (2k − 1) z^{2k−1}) for k = 1..4.
    let series = inv * (1.0 / 12.0 - inv2 * (1.0 / 360.0 - inv2 * (1.0 / 1260.0 - inv2 / 1680.0)));
    (z - 0.5) * z.ln() - z + 0.5 * TAU.ln() + series - shift
}
