//! Constant-time sampling of a discrete distribution: Walker's alias method with Vose's
//! numerically stable construction (M. D. Vose, "A linear algorithm for generating random numbers
//! with a given distribution", IEEE TSE 17(9), 1991).

/// One column of the alias table: keep the column's own index with probability `keep`, else
/// take `alias`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bin {
    keep: f32,
    alias: u32,
    pmf: f32,
}

/// A discrete distribution over `0..len()` proportional to non-negative weights, sampled in O(1)
/// from one uniform number.
///
/// Weights that are negative, NaN or infinite count as 0; entries of weight 0 are never chosen.
/// If every weight is 0 (or there are none) the table is empty of mass and `sample` returns
/// `None`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AliasTable {
    bins: Vec<Bin>,
    total: f64,
}

impl AliasTable {
    /// Builds the table for `weights` (any positive scale; normalised here), in O(n).
    #[must_use]
    pub fn new(weights: &[f32]) -> Self {
        let clean = |w: f32| {
            if w.is_finite() && w > 0.0 {
                f64::from(w)
            } else {
                0.0
            }
        };
        let total: f64 = weights.iter().map(|&w| clean(w)).sum();
        if weights.is_empty() || !(total > 0.0) || weights.len() > u32::MAX as usize {
            return Self {
                bins: Vec::new(),
                total: 0.0,
            };
        }
        let n = weights.len();
        // Scaled probabilities: a column of height 1 per entry holds n · pmf of mass.
        let mut scaled: Vec<f64> = weights
            .iter()
            .map(|&w| clean(w) / total * n as f64)
            .collect();
        let mut bins: Vec<Bin> = weights
            .iter()
            .enumerate()
            .map(|(i, &w)| Bin {
                keep: 1.0,
                alias: i as u32,
                pmf: (clean(w) / total) as f32,
            })
            .collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| scaled[i] < 1.0);
        // The heaviest entry: where leftover columns of weight-0 entries point.
        let heaviest = (0..n)
            .max_by(|&a, &b| scaled[a].total_cmp(&scaled[b]))
            .unwrap_or(0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            bins[s].keep = scaled[s] as f32;
            bins[s].alias = l as u32;
            // The large entry gives 1 − scaled[s] of its mass to column s.
            scaled[l] = (scaled[l] + scaled[s]) - 1.0;
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // Whatever is left is 1 up to rounding; a weight-0 entry keeps nothing.
        for i in small.into_iter().chain(large) {
            if bins[i].pmf > 0.0 {
                bins[i].keep = 1.0;
                bins[i].alias = i as u32;
            } else {
                bins[i].keep = 0.0;
                bins[i].alias = heaviest as u32;
            }
        }
        Self { bins, total }
    }

    /// Number of entries (including weight-0 ones); 0 when the table has no mass.
    #[must_use]
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// True when nothing can be sampled.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// Sum of the (clean) weights the table was built from.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Picks an entry with `u ∈ [0, 1)`; returns it and its probability. `None` when empty.
    #[inline]
    #[must_use]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        let n = self.bins.len();
        if n == 0 {
            return None;
        }
        let scaled = f64::from(u.clamp(0.0, 1.0)) * n as f64;
        let column = (scaled as usize).min(n - 1);
        let within = (scaled - column as f64) as f32;
        let bin = self.bins[column];
        let i = if within < bin.keep {
            column
        } else {
            bin.alias as usize
        };
        Some((i, self.bins[i].pmf))
    }

    /// Like [`AliasTable::sample`], and also returns `u` remapped to a fresh uniform in
    /// `[0, 1)`, independent of the choice (the position of `u` within the part of the column
    /// that chose the entry), so one number can pick an entry and then drive a second warp.
    #[inline]
    #[must_use]
    pub fn sample_remapped(&self, u: f32) -> Option<(usize, f32, f32)> {
        let n = self.bins.len();
        if n == 0 {
            return None;
        }
        let scaled = f64::from(u.clamp(0.0, 1.0)) * n as f64;
        let column = (scaled as usize).min(n - 1);
        let within = (scaled - column as f64).clamp(0.0, 1.0);
        let bin = self.bins[column];
        let keep = f64::from(bin.keep);
        let (i, rest) = if within < keep {
            (column, within / keep)
        } else {
            (bin.alias as usize, (within - keep) / (1.0 - keep))
        };
        let rest = (rest as f32).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        Some((i, self.bins[i].pmf, rest))
    }

    /// Probability of entry `i` (0 out of range).
    #[inline]
    #[must_use]
    pub fn pmf(&self, i: usize) -> f32 {
        self.bins.get(i).map_or(0.0, |b| b.pmf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// The probability the table actually assigns to each entry, read off its columns: column j
    /// gives `keep_j / n` to j and `(1 − keep_j) / n` to its alias.
    fn implied(t: &AliasTable) -> Vec<f64> {
        let n = t.bins.len();
        let mut p = vec![0.0; n];
        for (j, b) in t.bins.iter().enumerate() {
            p[j] += f64::from(b.keep) / n as f64;
            p[b.alias as usize] += (1.0 - f64::from(b.keep)) / n as f64;
        }
        p
    }

    #[test]
    fn columns_reproduce_the_weights() {
        let cases: [&[f32]; 5] = [
            &[1.0],
            &[1.0, 2.0, 3.0, 4.0],
            &[0.0, 5.0, 0.0, 1e-6, 7.0, f32::NAN, -3.0, f32::INFINITY],
            &[1e-30, 1e30],
            &[0.3; 17],
        ];
        for weights in cases {
            let t = AliasTable::new(weights);
            let total: f64 = weights
                .iter()
                .filter(|w| w.is_finite() && **w > 0.0)
                .map(|&w| f64::from(w))
                .sum();
            let p = implied(&t);
            for (i, &w) in weights.iter().enumerate() {
                let want = if w.is_finite() && w > 0.0 {
                    f64::from(w) / total
                } else {
                    0.0
                };
                assert!(
                    (p[i] - want).abs() < 1e-6,
                    "{weights:?}[{i}]: {} vs {want}",
                    p[i]
                );
                assert!((f64::from(t.pmf(i)) - want).abs() <= 1e-6 * want + 1e-12);
                if want == 0.0 {
                    assert_eq!(p[i], 0.0, "weight-0 entry {i} reachable in {weights:?}");
                }
            }
        }
    }

    #[test]
    fn sampled_frequencies_match_and_zero_weights_never_come_up() {
        let weights = [3.0, 0.0, 1.0, 6.0, 0.0];
        let t = AliasTable::new(&weights);
        let mut r = Rng::new(2, 3);
        let n = 100_000;
        let mut counts = [0u32; 5];
        for _ in 0..n {
            let (i, pmf) = t.sample(r.next_f32()).unwrap();
            assert_eq!(pmf, t.pmf(i));
            counts[i] += 1;
        }
        assert_eq!(counts[1] + counts[4], 0);
        for (i, w) in weights.iter().enumerate() {
            let want = w / 10.0 * n as f32;
            // 5σ of a binomial count.
            let sigma = (want * (1.0 - w / 10.0)).sqrt();
            assert!(
                (counts[i] as f32 - want).abs() <= 5.0 * sigma + 1e-3,
                "{counts:?}"
            );
        }
        // The extreme uniforms stay in range.
        assert!(t.sample(0.0).is_some() && t.sample(1.0 - f32::EPSILON / 2.0).is_some());
    }

    #[test]
    fn remapped_uniform_is_uniform_within_each_choice() {
        use crate::sampling::chi2::pearson;
        let t = AliasTable::new(&[3.0, 1.0, 6.0]);
        let mut r = Rng::new(4, 4);
        let mut counts = vec![0u64; 30];
        let mut per = [0u64; 3];
        for _ in 0..90_000 {
            let (i, pmf, rest) = t.sample_remapped(r.next_f32()).unwrap();
            assert_eq!(pmf, t.pmf(i));
            assert!((0.0..1.0).contains(&rest));
            per[i] += 1;
            counts[i * 10 + ((rest * 10.0) as usize).min(9)] += 1;
        }
        // Each entry's remapped uniforms fill its 10 bins evenly, and entries keep their pmf.
        let expected: Vec<f64> = (0..30)
            .map(|k| 90_000.0 * f64::from(t.pmf(k / 10)) / 10.0)
            .collect();
        let res = pearson(&counts, &expected);
        assert!(res.p_value > 0.001, "{res:?} {per:?}");
    }

    #[test]
    fn empty_or_massless_tables_sample_nothing() {
        for weights in [&[][..], &[0.0, 0.0][..], &[f32::NAN][..]] {
            let t = AliasTable::new(weights);
            assert!(t.is_empty());
            assert_eq!(t.sample(0.5), None);
            assert_eq!(t.pmf(0), 0.0);
        }
    }
}
