//! Constant-time sampling of a discrete distribution (Walker's alias method,
//! built with Vose's numerically stable construction).

/// One bin of the table: keep `index` when the remapped uniform falls below
/// `threshold`, otherwise take `alias`.
#[derive(Clone, Copy, Debug)]
struct Bin {
    threshold: f32,
    alias: u32,
}

/// Discrete distribution over `0..len()` proportional to the given weights.
#[derive(Clone, Debug, Default)]
pub struct AliasTable {
    bins: Vec<Bin>,
    pmf: Vec<f32>,
}

impl AliasTable {
    /// Builds the table in O(n).
    ///
    /// Weights should be finite and non-negative; anything else (negative,
    /// NaN, infinite) is treated as zero so one bad value cannot poison the
    /// whole table. If every weight is zero the distribution is uniform;
    /// an empty slice gives an empty table.
    pub fn new(weights: &[f32]) -> Self {
        let n = weights.len();
        assert!(n <= u32::MAX as usize, "AliasTable: too many entries ({n})");
        let clean = |w: f32| {
            if w.is_finite() && w > 0.0 {
                f64::from(w)
            } else {
                0.0
            }
        };
        // f64 accumulation: sums of many f32 weights lose mass in f32.
        let total: f64 = weights.iter().map(|&w| clean(w)).sum();
        let pmf64: Vec<f64> = if total > 0.0 {
            weights.iter().map(|&w| clean(w) / total).collect()
        } else {
            vec![1.0 / n as f64; n]
        };

        // Probabilities scaled so the mean bin holds exactly 1.
        let mut scaled: Vec<f64> = pmf64.iter().map(|p| p * n as f64).collect();
        let mut bins = vec![
            Bin {
                threshold: 1.0,
                alias: 0,
            };
            n
        ];
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            bins[s] = Bin {
                threshold: scaled[s] as f32,
                alias: l as u32,
            };
            // Written as (a + b) - 1 rather than a - (1 - b) to lose less
            // precision when the large entry is drained slowly.
            scaled[l] = (scaled[l] + scaled[s]) - 1.0;
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // Leftovers are ~1 up to rounding: they keep themselves. A zero-weight
        // entry can only be left over through rounding, and must still never
        // be returned, so it forwards everything to a positive entry instead
        // (entries that ever sat in `large` always have positive weight).
        let fallback = (0..n).find(|&i| pmf64[i] > 0.0).unwrap_or(0);
        for i in large.into_iter().chain(small) {
            bins[i] = if pmf64[i] > 0.0 {
                Bin {
                    threshold: 1.0,
                    alias: i as u32,
                }
            } else {
                Bin {
                    threshold: 0.0,
                    alias: fallback as u32,
                }
            };
        }
        Self {
            bins,
            pmf: pmf64.iter().map(|&p| p as f32).collect(),
        }
    }

    /// Draws an index from `u` in [0, 1), returning it with its probability.
    ///
    /// One uniform number picks both the bin and the coin flip inside it, so
    /// the flip has about 24 − log2(len) bits of resolution.
    ///
    /// # Panics
    /// If the table is empty.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let n = self.bins.len();
        assert!(n > 0, "AliasTable::sample on an empty table");
        // f64 keeps u * n exact, so `frac` is the true remainder.
        let scaled = f64::from(u) * n as f64;
        let i = (scaled as usize).min(n - 1);
        let frac = scaled - i as f64;
        let bin = self.bins[i];
        let k = if frac < f64::from(bin.threshold) {
            i
        } else {
            bin.alias as usize
        };
        (k, self.pmf[k])
    }

    /// Probability of drawing `i` (0 for out-of-range indices).
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf.get(i).copied().unwrap_or(0.0)
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Whether the table has no entries (and so cannot be sampled).
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }
}
