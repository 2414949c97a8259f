//! Pearson's χ² goodness-of-fit test of a direction sampler against the density it claims, for
//! BSDF, light and emission samplers (test-only).
//!
//! Samples are histogrammed over the sphere (or a cap of it) in `(1 − cos θ, φ)` of a frame; the
//! expected count of each bin is the sample count times the integral of the pdf over it,
//! integrated numerically (nested adaptive Simpson, so discontinuities such as a cone's rim or
//! the horizon are resolved); bins with expected counts below 5 are pooled; the p-value comes
//! from the χ² distribution's upper tail, the regularised incomplete gamma function `Q(k/2, χ²/2)`
//! (series and continued fraction, as in Press et al., "Numerical Recipes", §6.2). The design
//! follows the BSDF tests of pbrt-v4 and Mitsuba 3; the code is our own.
//!
//! Bins are uniform in `1 − cos θ` and φ, so they have equal solid angle `Δ(1 − cos θ) · Δφ`,
//! and `dω = d(1 − cos θ) dφ` makes the pdf's integral over a bin a plain 2-D integral.

use super::special::gamma_q;
use glam::{DVec3, Vec3};
use std::f64::consts::TAU;

use crate::geometry::Frame;
use crate::sampling::Rng;

/// Absolute quadrature tolerance of one cell's probability (× 10⁵ samples: 0.01 counts, far
/// below the Poisson noise a χ² test measures).
const CELL_TOLERANCE: f64 = 1e-7;

/// Smallest expected count a bin may have before it is pooled with other small bins.
const MIN_EXPECTED: f64 = 5.0;

/// The histogram's layout: `theta_bins × phi_bins` cells over the directions whose
/// `1 − cos θ` (θ measured from `frame.n`) is at most `max_one_minus_cos` (2 for the whole
/// sphere; smaller to zoom in on a narrow cone). Directions beyond it fall in one extra
/// "outside" cell, whose expected count is whatever probability the pdf leaves outside the cap.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SphereBins {
    /// Orientation: θ is measured from `frame.n`, φ from `frame.s` towards `frame.t`.
    pub frame: Frame,
    /// Cells in `1 − cos θ`.
    pub theta_bins: usize,
    /// Cells in φ.
    pub phi_bins: usize,
    /// Extent of the binned cap in `1 − cos θ`, in `(0, 2]`.
    pub max_one_minus_cos: f64,
}

impl SphereBins {
    /// The whole sphere around `n` (unit), in `theta_bins × phi_bins` cells.
    pub(crate) fn sphere(n: Vec3, theta_bins: usize, phi_bins: usize) -> Self {
        Self::cap(n, theta_bins, phi_bins, 2.0)
    }

    /// The cap `1 − cos θ ≤ max_one_minus_cos` around `n` (unit).
    pub(crate) fn cap(n: Vec3, theta_bins: usize, phi_bins: usize, max_one_minus_cos: f64) -> Self {
        Self {
            frame: Frame::from_normal(n),
            theta_bins,
            phi_bins,
            max_one_minus_cos: max_one_minus_cos.min(2.0),
        }
    }

    fn cells(&self) -> usize {
        self.theta_bins * self.phi_bins
    }

    fn frame64(&self) -> [DVec3; 3] {
        [
            self.frame.s.as_dvec3(),
            self.frame.t.as_dvec3(),
            self.frame.n.as_dvec3(),
        ]
    }

    /// The cell of direction `w`, `cells()` for the outside cell, `None` for a direction that
    /// is not a unit vector (NaN, zero).
    fn cell_of(&self, w: Vec3) -> Option<usize> {
        let [s, t, n] = self.frame64();
        let w = w.as_dvec3();
        let len = w.length();
        if !(len > 0.5 && len < 2.0) {
            return None;
        }
        let l = DVec3::new(w.dot(s), w.dot(t), w.dot(n)) / len;
        // 1 − cos θ = |w − n|² / 2: accurate even for directions hugging n.
        let one_minus_cos = (l - DVec3::Z).length_squared() / 2.0;
        if one_minus_cos > self.max_one_minus_cos {
            return Some(self.cells());
        }
        let phi = l.y.atan2(l.x).rem_euclid(TAU);
        let ti = ((one_minus_cos / self.max_one_minus_cos * self.theta_bins as f64) as usize)
            .min(self.theta_bins - 1);
        let pi = ((phi / TAU * self.phi_bins as f64) as usize).min(self.phi_bins - 1);
        Some(ti * self.phi_bins + pi)
    }

    /// The world direction at `(1 − cos θ, φ)`.
    fn direction(&self, one_minus_cos: f64, phi: f64) -> Vec3 {
        let [s, t, n] = self.frame64();
        let sin_t = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
        let w = s * (sin_t * phi.cos()) + t * (sin_t * phi.sin()) + n * (1.0 - one_minus_cos);
        w.normalize().as_vec3()
    }

    /// The integral of `pdf` over every cell (the outside cell excluded), in cell order.
    fn integrate_cells(&self, pdf: &impl Fn(Vec3) -> f32) -> Vec<f64> {
        let dt = self.max_one_minus_cos / self.theta_bins as f64;
        let dphi = TAU / self.phi_bins as f64;
        let mut out = Vec::with_capacity(self.cells());
        for ti in 0..self.theta_bins {
            for pi in 0..self.phi_bins {
                let (t0, p0) = (ti as f64 * dt, pi as f64 * dphi);
                // Absolute tolerances: the cell's integral is a probability (≤ 1), and an
                // error δ in the inner integral moves the outer one by about δ · dt.
                let mut over_t = |t: f64| {
                    let mut f = |phi: f64| f64::from(pdf(self.direction(t, phi)));
                    adaptive_simpson(&mut f, p0, p0 + dphi, CELL_TOLERANCE / dt, 10)
                };
                out.push(adaptive_simpson(
                    &mut over_t,
                    t0,
                    t0 + dt,
                    CELL_TOLERANCE,
                    14,
                ));
            }
        }
        out
    }
}

/// The integral of a density over the cells of `bins` (the sphere, or the cap it covers):
/// 1 for a normalised density over the sphere. Accurate to ~1e-8 for piecewise-smooth pdfs.
pub(crate) fn integrate(bins: &SphereBins, pdf: impl Fn(Vec3) -> f32) -> f64 {
    bins.integrate_cells(&pdf).iter().sum()
}

/// The integral of a density over the whole sphere, in a 40 × 80 grid around `n`.
pub(crate) fn integrate_sphere(n: Vec3, pdf: impl Fn(Vec3) -> f32) -> f64 {
    integrate(&SphereBins::sphere(n, 40, 80), pdf)
}

/// Outcome of a χ² test.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Chi2Result {
    /// Pearson's statistic Σ (observed − expected)² / expected over the pooled cells.
    pub statistic: f64,
    /// Degrees of freedom: pooled cells − 1.
    pub dof: usize,
    /// Probability of a statistic at least this large if the sampler follows the pdf
    /// (0 when a sample landed where the pdf is exactly 0).
    pub p_value: f64,
    /// Samples drawn (including ones the sampler rejected).
    pub samples: usize,
    /// Samples the sampler returned `None` for (counted in the outside cell).
    pub rejected: usize,
    /// Samples in cells whose expected count is exactly 0 (each is proof of a mismatch).
    pub impossible: usize,
}

impl Chi2Result {
    /// True when the test does not reject at significance `alpha`.
    pub(crate) fn passes(&self, alpha: f64) -> bool {
        self.p_value >= alpha
    }
}

/// Draws `n_samples` directions with `sample` (from the stream `Rng::new(seed, 0)`) and tests
/// them against `pdf` (solid-angle density) over `bins`. A sampler that may fail (`None`) is
/// consistent with a pdf that integrates to the success probability: failures go to the
/// outside cell.
pub(crate) fn chi2_test(
    n_samples: usize,
    seed: u64,
    bins: &SphereBins,
    mut sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
) -> Chi2Result {
    let cells = bins.cells();
    let mut observed = vec![0u64; cells + 1];
    let mut rng = Rng::new(seed, 0);
    let mut rejected = 0;
    for _ in 0..n_samples {
        match sample(&mut rng).and_then(|w| bins.cell_of(w)) {
            Some(c) => observed[c] += 1,
            None => {
                rejected += 1;
                observed[cells] += 1;
            }
        }
    }
    let n = n_samples as f64;
    let mut expected: Vec<f64> = bins.integrate_cells(&pdf).iter().map(|p| p * n).collect();
    let inside: f64 = expected.iter().sum();
    expected.push((n - inside).max(0.0));
    let mut result = pearson(&observed, &expected);
    result.samples = n_samples;
    result.rejected = rejected;
    result
}

/// Pearson's test of observed against expected counts (same length), pooling cells whose
/// expected count is below 5. Also usable for discrete distributions.
pub(crate) fn pearson(observed: &[u64], expected: &[f64]) -> Chi2Result {
    let impossible: u64 = observed
        .iter()
        .zip(expected)
        .filter(|&(_, &e)| e <= 0.0)
        .map(|(&o, _)| o)
        .sum();
    let mut cells: Vec<(f64, f64)> = observed
        .iter()
        .zip(expected)
        .filter(|&(_, &e)| e > 0.0)
        .map(|(&o, &e)| (o as f64, e))
        .collect();
    cells.sort_by(|a, b| a.1.total_cmp(&b.1));
    // Pool the smallest cells together until the pool reaches the minimum; if the pool ends
    // up too small on its own, fold it into the next cell.
    let mut pooled: Vec<(f64, f64)> = Vec::with_capacity(cells.len());
    let mut pool = (0.0, 0.0);
    for (o, e) in cells {
        if e < MIN_EXPECTED || (pool.1 > 0.0 && pool.1 < MIN_EXPECTED) {
            pool = (pool.0 + o, pool.1 + e);
            if pool.1 >= MIN_EXPECTED {
                pooled.push(pool);
                pool = (0.0, 0.0);
            }
        } else {
            pooled.push((o, e));
        }
    }
    if pool.1 > 0.0 {
        match pooled.first_mut() {
            Some(first) => *first = (first.0 + pool.0, first.1 + pool.1),
            None => pooled.push(pool),
        }
    }
    let statistic: f64 = pooled.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum();
    let dof = pooled.len().saturating_sub(1);
    let p_value = if impossible > 0 {
        0.0
    } else {
        chi2_p_value(statistic, dof)
    };
    Chi2Result {
        statistic,
        dof,
        p_value,
        samples: observed.iter().sum::<u64>() as usize,
        rejected: 0,
        impossible: impossible as usize,
    }
}

/// The significance each of `tests` independent tests must use so that the chance of any
/// false rejection is `alpha` overall (Šidák's correction): `1 − (1 − alpha)^(1/tests)`.
pub(crate) fn sidak_alpha(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64)
}

/// Upper tail `P(X ≥ statistic)` of the χ² distribution with `dof` degrees of freedom
/// (1 for `dof = 0`).
pub(crate) fn chi2_p_value(statistic: f64, dof: usize) -> f64 {
    if dof == 0 {
        return 1.0;
    }
    if !(statistic > 0.0) {
        return if statistic.is_nan() { 0.0 } else { 1.0 };
    }
    gamma_q(dof as f64 / 2.0, statistic / 2.0)
}

/// Adaptive Simpson quadrature of `f` over `[a, b]` to absolute tolerance `eps`, subdividing at
/// most `depth` times (always at least twice, so narrow features between the first five nodes
/// are still found).
fn adaptive_simpson(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, eps: f64, depth: u32) -> f64 {
    let (fa, fm, fb) = (f(a), f((a + b) / 2.0), f(b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    simpson_step(f, [a, b], [fa, fm, fb], whole, eps, depth, 2)
}

fn simpson_step(
    f: &mut impl FnMut(f64) -> f64,
    [a, b]: [f64; 2],
    [fa, fm, fb]: [f64; 3],
    whole: f64,
    eps: f64,
    depth: u32,
    min_depth: u32,
) -> f64 {
    let m = (a + b) / 2.0;
    let (flm, frm) = (f((a + m) / 2.0), f((m + b) / 2.0));
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if depth == 0 || (min_depth == 0 && delta.abs() <= 15.0 * eps) {
        return left + right + delta / 15.0;
    }
    let next = min_depth.saturating_sub(1);
    simpson_step(f, [a, m], [fa, flm, fm], left, eps / 2.0, depth - 1, next)
        + simpson_step(f, [m, b], [fm, frm, fb], right, eps / 2.0, depth - 1, next)
}

#[cfg(test)]
mod tests;
