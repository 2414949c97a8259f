//! Piecewise-constant 1-D and 2-D distributions sampled by continuous inversion of their CDF,
//! for importance-sampling environment maps (and anything else tabulated on a grid).
//!
//! The 2-D distribution is the marginal/conditional construction (Pharr, Jakob & Humphreys,
//! "Physically Based Rendering", 4th ed., §A.5, `PiecewiseConstant2D`): a marginal distribution
//! over rows picks `y`, then that row's conditional distribution picks `x`. Both are over
//! `[0, 1)`; densities are with respect to the area of the unit square. CDFs are accumulated in
//! `f64` so long rows of tiny values keep their resolution. Our own code.

/// A piecewise-constant density over `[0, 1)` with `n` equal cells proportional to `func`.
///
/// Negative and non-finite values count as 0. A function that is 0 everywhere becomes the
/// uniform density (so a row of black pixels still maps `u` to a valid `x`; the marginal then
/// gives that row probability 0, and the 2-D density stays consistent).
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution1D {
    func: Vec<f32>,
    /// `n + 1` entries, `cdf[0] = 0`, `cdf[n] = 1`, non-decreasing.
    cdf: Vec<f32>,
    /// `∫₀¹ func` (the mean of the cleaned `func`); 0 if it was all zero.
    integral: f64,
}

/// The result of [`Distribution1D::sample_continuous`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample1D {
    /// The sampled point in `[0, 1)`.
    pub x: f32,
    /// Its density (with respect to length on `[0, 1)`).
    pub pdf: f32,
    /// The cell it fell in.
    pub cell: usize,
}

impl Distribution1D {
    /// The distribution proportional to `func` (at least one cell; an empty slice gives one
    /// cell of value 0, i.e. the uniform density).
    #[must_use]
    pub fn new(func: &[f32]) -> Self {
        let clean = |v: f32| if v.is_finite() && v > 0.0 { v } else { 0.0 };
        let mut func: Vec<f32> = func.iter().map(|&v| clean(v)).collect();
        if func.is_empty() {
            func.push(0.0);
        }
        let n = func.len();
        let mut sums = Vec::with_capacity(n + 1);
        let mut acc = 0.0f64;
        sums.push(0.0);
        for &v in &func {
            acc += f64::from(v);
            sums.push(acc);
        }
        let integral = acc / n as f64;
        let cdf = if acc > 0.0 {
            let mut c: Vec<f32> = sums.iter().map(|&s| (s / acc) as f32).collect();
            c[n] = 1.0;
            c
        } else {
            (0..=n).map(|i| (i as f64 / n as f64) as f32).collect()
        };
        Self {
            func,
            cdf,
            integral,
        }
    }

    /// Number of cells.
    #[must_use]
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// Always false (a distribution has at least one cell).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// `∫₀¹ func(x) dx` of the cleaned function (0 when it was all zero).
    #[must_use]
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The cleaned value of cell `i` (0 out of range).
    #[must_use]
    pub fn func(&self, i: usize) -> f32 {
        self.func.get(i).copied().unwrap_or(0.0)
    }

    /// Density at `x ∈ [0, 1)` (values outside are clamped to the end cells).
    #[inline]
    #[must_use]
    pub fn pdf(&self, x: f32) -> f32 {
        self.pdf_cell(self.cell_of(x))
    }

    /// Density of cell `i`: `func[i] / ∫func` (1 for the all-zero, uniform case).
    #[inline]
    #[must_use]
    pub fn pdf_cell(&self, i: usize) -> f32 {
        if self.integral > 0.0 {
            (f64::from(self.func(i)) / self.integral) as f32
        } else {
            1.0
        }
    }

    /// Probability of cell `i`: `pdf_cell(i) / n`.
    #[inline]
    #[must_use]
    pub fn pmf(&self, i: usize) -> f32 {
        match (self.cdf.get(i), self.cdf.get(i + 1)) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }

    /// The cell containing `x` (clamped into `0..n`).
    #[inline]
    #[must_use]
    pub fn cell_of(&self, x: f32) -> usize {
        let n = self.func.len();
        if !(x > 0.0) {
            return 0;
        }
        ((x * n as f32) as usize).min(n - 1)
    }

    /// Inverts the CDF at `u ∈ [0, 1)`: the cell whose CDF interval holds `u`, then linearly
    /// within it. Cells of probability 0 are never returned.
    #[inline]
    #[must_use]
    pub fn sample_continuous(&self, u: f32) -> Sample1D {
        let (cell, du) = self.invert(u);
        let n = self.func.len();
        let x = ((cell as f32 + du) / n as f32).min(ONE_MINUS_EPSILON);
        Sample1D {
            x,
            pdf: self.pdf_cell(cell),
            cell,
        }
    }

    /// Picks a cell with `u ∈ [0, 1)`: the cell, its probability, and `u` remapped to a fresh
    /// uniform in `[0, 1)` (the position of `u` within the cell's CDF interval).
    #[inline]
    #[must_use]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let (cell, du) = self.invert(u);
        (cell, self.pmf(cell), du.min(ONE_MINUS_EPSILON))
    }

    /// The cell `i` with `cdf[i] ≤ u < cdf[i+1]` (never a zero-width cell) and the offset of `u`
    /// in it, in `[0, 1]`.
    #[inline]
    fn invert(&self, u: f32) -> (usize, f32) {
        let n = self.func.len();
        let u = u.clamp(0.0, ONE_MINUS_EPSILON);
        // First index whose cdf exceeds u, minus one: the last cell starting at or before u.
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .saturating_sub(1)
            .min(n - 1);
        let (a, b) = (self.cdf[i], self.cdf[i + 1]);
        let du = if b > a {
            ((u - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (i, du)
    }
}

/// The largest `f32` below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A piecewise-constant density over the unit square on a `width × height` grid, proportional
/// to `func` (row-major, row 0 at `y ∈ [0, 1/height)`), sampled by marginal (rows) then
/// conditional (columns) inversion.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution2D {
    conditional: Vec<Distribution1D>,
    marginal: Distribution1D,
}

/// The result of [`Distribution2D::sample`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample2D {
    /// The sampled point in `[0, 1)²` (`x` along a row, `y` across rows).
    pub x: f32,
    /// See `x`.
    pub y: f32,
    /// Its density with respect to area on the unit square.
    pub pdf: f32,
}

impl Distribution2D {
    /// The distribution proportional to `func` (`width · height` values, row-major). A missing
    /// tail counts as 0; `width` and `height` are raised to at least 1.
    #[must_use]
    pub fn new(func: &[f32], width: usize, height: usize) -> Self {
        let (w, h) = (width.max(1), height.max(1));
        let conditional: Vec<Distribution1D> = (0..h)
            .map(|y| {
                let row: Vec<f32> = (0..w)
                    .map(|x| func.get(y * w + x).copied().unwrap_or(0.0))
                    .collect();
                Distribution1D::new(&row)
            })
            .collect();
        let row_integrals: Vec<f32> = conditional.iter().map(|c| c.integral() as f32).collect();
        Self {
            marginal: Distribution1D::new(&row_integrals),
            conditional,
        }
    }

    /// `∫∫ func` over the unit square (0 for an all-zero function).
    #[must_use]
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// Samples a point with `u ∈ [0, 1)²`: `u.1` picks the row, `u.0` the position in it.
    #[inline]
    #[must_use]
    pub fn sample(&self, u: (f32, f32)) -> Sample2D {
        let row = self.marginal.sample_continuous(u.1);
        let col = self.conditional[row.cell].sample_continuous(u.0);
        Sample2D {
            x: col.x,
            y: row.x,
            pdf: row.pdf * col.pdf,
        }
    }

    /// Density at `(x, y) ∈ [0, 1)²` (clamped into the square): `func(cell) / ∫∫func`, or 1
    /// everywhere for an all-zero function.
    #[inline]
    #[must_use]
    pub fn pdf(&self, x: f32, y: f32) -> f32 {
        let row = self.marginal.cell_of(y);
        self.marginal.pdf_cell(row) * self.conditional[row].pdf(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::sampling::chi2::pearson;

    #[test]
    fn one_d_pdf_integrates_to_one_and_inversion_is_exact() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0, 4.0]);
        assert!((d.integral() - 2.0).abs() < 1e-12);
        let total: f32 = (0..4).map(|i| d.pdf_cell(i) / 4.0).sum();
        assert!((total - 1.0).abs() < 1e-6);
        // CDF = [0, 1/8, 1/8, 4/8, 1]: u = 0.3 lies in cell 2 at (0.3 − 0.125)/0.375.
        let s = d.sample_continuous(0.3);
        assert_eq!(s.cell, 2);
        let want = (2.0 + (0.3 - 0.125) / 0.375) / 4.0;
        assert!((s.x - want).abs() < 1e-6, "{s:?}");
        assert!((s.pdf - 1.5).abs() < 1e-6 && d.pdf(s.x) == s.pdf);
        // The zero cell is skipped even at its CDF boundary.
        assert_eq!(d.sample_continuous(0.125).cell, 2);
        let (cell, pmf, rest) = d.sample_discrete(0.75);
        assert_eq!(cell, 3);
        assert!((pmf - 0.5).abs() < 1e-6 && (rest - 0.5).abs() < 1e-6);
        // Extremes stay in [0, 1).
        assert!(d.sample_continuous(0.0).x >= 0.0);
        assert!(d.sample_continuous(1.0).x < 1.0);
    }

    #[test]
    fn all_zero_and_bad_values_give_the_uniform_density() {
        let d = Distribution1D::new(&[0.0, f32::NAN, -1.0]);
        assert_eq!(d.integral(), 0.0);
        let s = d.sample_continuous(0.5);
        assert!((s.x - 0.5).abs() < 1e-6 && s.pdf == 1.0);
        let e = Distribution1D::new(&[]);
        assert_eq!(e.len(), 1);
        assert_eq!(e.sample_continuous(0.25).x, 0.25);
    }

    #[test]
    fn two_d_samples_follow_the_tabulated_function() {
        // A 6 × 4 grid with a zero row and a zero cell: χ² of sampled cell counts.
        let (w, h) = (6, 4);
        let func: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if y == 1 || (x, y) == (3, 2) {
                    0.0
                } else {
                    1.0 + (x * (y + 1)) as f32
                }
            })
            .collect();
        let d = Distribution2D::new(&func, w, h);
        let total: f64 = func.iter().map(|&v| f64::from(v)).sum();
        assert!((d.integral() / (total / (w * h) as f64) - 1.0).abs() < 1e-6);
        let n = 200_000;
        let mut counts = vec![0u64; w * h];
        let mut rng = Rng::new(7, 0);
        for _ in 0..n {
            let s = d.sample(rng.next_2d());
            assert!((0.0..1.0).contains(&s.x) && (0.0..1.0).contains(&s.y));
            let pdf = d.pdf(s.x, s.y);
            assert!((pdf / s.pdf - 1.0).abs() < 1e-5, "{s:?} vs {pdf}");
            let (cx, cy) = ((s.x * w as f32) as usize, (s.y * h as f32) as usize);
            counts[cy * w + cx] += 1;
        }
        let expected: Vec<f64> = func
            .iter()
            .map(|&v| f64::from(v) / total * n as f64)
            .collect();
        let r = pearson(&counts, &expected);
        eprintln!("Distribution2D cell χ²: {r:?}");
        assert!(r.p_value > 0.01 && r.impossible == 0, "{r:?}");
        // A wrong claim (uniform) is rejected.
        let wrong = vec![n as f64 / (w * h) as f64; w * h];
        assert!(pearson(&counts, &wrong).p_value < 1e-6);
        // The density integrates to one (midpoint rule is exact for a piecewise constant).
        let sum: f64 = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
                f64::from(d.pdf(x / w as f32, y / h as f32))
            })
            .sum::<f64>()
            / (w * h) as f64;
        assert!((sum - 1.0).abs() < 1e-6, "{sum}");
    }

    #[test]
    fn within_cell_positions_are_uniform() {
        // One cell of a 1-D distribution: x − cell start is uniform (inversion is linear).
        let d = Distribution1D::new(&[1.0, 5.0]);
        let mut rng = Rng::new(3, 1);
        let mut counts = vec![0u64; 10];
        let mut hits = 0;
        for _ in 0..50_000 {
            let s = d.sample_continuous(rng.next_f32());
            if s.cell == 1 {
                hits += 1;
                counts[(((s.x - 0.5) * 2.0 * 10.0) as usize).min(9)] += 1;
            }
        }
        let expected = vec![f64::from(hits) / 10.0; 10];
        let r = pearson(&counts, &expected);
        assert!(r.p_value > 0.01, "{r:?}");
    }
}
