//! The estimated error of an image still being rendered, from its own samples: what
//! `--target-error` stops on (issue #43).
//!
//! For each pixel and channel the variance of the mean is the unbiased sample variance over the
//! count, `s² / n` ([`PixelSums::variance`]); divided by `m² + 0.01` (`m` the pixel's mean) it
//! estimates the pixel's relative squared error in the form of Rousselle, Knaus & Zwicker
//! (2011) that `caustic compare` scores against a reference (`analysis::metrics`, relMSE with the
//! same 0.01). The image's estimate is the mean over pixels and channels; the worst 1 % is the
//! mean over the 1 % of pixels with the largest estimate.
//!
//! What it does and does not see:
//! - **Independent samples.** Each sample of a pixel is one path, and for the progressive
//!   estimators (`path-ppm`, `ppm`) each sample index is one pass with photon maps of its own,
//!   so a pixel's samples are independent and `s² / n` holds for the photon noise too: the
//!   correlation of photon noise *between neighbouring pixels* (a blotch spans many pixels)
//!   leaves each pixel's variance, and so the mean over pixels, unchanged.
//! - **Stratified samples** (the Sobol sampler) converge faster than `s² / n` says: the estimate
//!   is then pessimistic and the render stops later than it needs to.
//! - **Bias** is not seen: the progressive estimators' shrinking radius blurs caustics by an
//!   amount no sample variance shows. `docs/convergence.md` measures the estimate against
//!   reference renders.

use super::PixelSums;

/// The ε of the relative error's denominator `m² + ε` (Rousselle et al. 2011; the same as
/// `caustic compare`'s relMSE).
pub const REL_EPSILON: f64 = 0.01;
/// The fewest samples per pixel an estimate is trusted from (a variance from one or two
/// samples is mostly noise, and zero when they agree by chance).
pub const MIN_SAMPLES: u32 = 4;
/// The share of pixels the worst-pixels figure averages.
pub const WORST_FRACTION: f64 = 0.01;

/// The estimated relative mean squared error of an image, from its per-pixel statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEstimate {
    /// Mean over pixels and channels of `(s² / n) / (m² + ε)`.
    pub image: f64,
    /// The same averaged over the worst [`WORST_FRACTION`] of the pixels (at least one).
    pub worst: f64,
    /// The fewest samples any pixel has (the estimate is trusted from [`MIN_SAMPLES`]).
    pub min_samples: u32,
}

impl ErrorEstimate {
    /// The estimate of the image `sums` holds (fixed-order sums: the same for any thread
    /// count). An empty film estimates 0.
    #[must_use]
    pub fn of_sums(sums: &PixelSums) -> Self {
        let n = sums.width as usize * sums.height as usize;
        let mut per_pixel: Vec<f64> = (0..n).map(|i| pixel_rel_mse(sums, i)).collect();
        let min_samples = (0..n).map(|i| sums.count(i)).min().unwrap_or(0);
        if n == 0 {
            return Self {
                image: 0.0,
                worst: 0.0,
                min_samples,
            };
        }
        let image = per_pixel.iter().sum::<f64>() / n as f64;
        let k = ((n as f64 * WORST_FRACTION).ceil() as usize).clamp(1, n);
        // The k largest, in a fixed order (a full sort: deterministic and O(n log n), a
        // fraction of a pass's cost).
        per_pixel.sort_unstable_by(|a, b| b.total_cmp(a));
        let worst = per_pixel[..k].iter().sum::<f64>() / k as f64;
        Self {
            image,
            worst,
            min_samples,
        }
    }

    /// Whether the estimate is trusted (every pixel has [`MIN_SAMPLES`]) and the image's is at
    /// most `target`.
    #[must_use]
    pub fn reached(&self, target: f64) -> bool {
        self.min_samples >= MIN_SAMPLES && self.image <= target
    }

    /// Whether the estimate is trusted and both the image's and its worst 1 %'s are at most
    /// `target` (what an adaptive render stops on: each pixel aims at the target itself).
    #[must_use]
    pub fn reached_everywhere(&self, target: f64) -> bool {
        self.reached(target) && self.worst <= target
    }
}

/// `(s² / n) / (m² + ε)` averaged over the channels of pixel `i`; a pixel with fewer than two
/// samples counts as unconverged (1).
pub(super) fn pixel_rel_mse(sums: &PixelSums, i: usize) -> f64 {
    let n = sums.count(i);
    if n < 2 {
        return 1.0;
    }
    let (m, v) = (sums.mean(i).as_dvec3(), sums.variance(i).as_dvec3());
    let rel = |c: usize| v[c] / f64::from(n) / (m[c] * m[c] + REL_EPSILON);
    (rel(0) + rel(1) + rel(2)) / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Two pixels with samples written out by hand: pixel 0 takes 1, 3 (mean 2, s² = 2), pixel
    /// 1 takes 0, 0 (mean 0, s² = 0). relMSE: pixel 0 (2 / 2) / (4 + 0.01) = 0.249377, pixel 1 0.
    #[test]
    fn the_estimate_matches_a_hand_computation() {
        let mut s = PixelSums::new(2, 1);
        for v in [1.0, 3.0] {
            s.add(0, Vec3::splat(v));
            s.add(1, Vec3::ZERO);
        }
        let e = ErrorEstimate::of_sums(&s);
        assert!((e.image - 0.249_377 / 2.0).abs() < 1e-6, "{e:?}");
        assert!((e.worst - 0.249_377).abs() < 1e-6, "{e:?}");
        assert_eq!(e.min_samples, 2);
        assert!(!e.reached(1.0), "two samples are too few to trust");
    }

    /// Independent samples of known variance: the estimate falls as 1/n and matches
    /// σ² / n / (μ² + ε) within the noise of a sample variance.
    #[test]
    fn the_estimate_falls_as_one_over_n_for_independent_samples() {
        let mut rng = crate::sampling::Rng::new(7, 0);
        let (mu, sigma) = (0.5f64, 0.2f64);
        let pixels = 400;
        for n in [16u32, 64] {
            let mut s = PixelSums::new(pixels, 1);
            for i in 0..pixels as usize {
                for _ in 0..n {
                    // Uniform on [μ − √3σ, μ + √3σ]: variance σ².
                    let u = f64::from(rng.next_f32());
                    let x = mu + (2.0 * u - 1.0) * 3f64.sqrt() * sigma;
                    s.add(i, Vec3::splat(x as f32));
                }
            }
            let e = ErrorEstimate::of_sums(&s);
            let expected = sigma * sigma / f64::from(n) / (mu * mu + REL_EPSILON);
            assert!(
                (e.image / expected - 1.0).abs() < 0.05,
                "n = {n}: {} vs {expected}",
                e.image
            );
            assert!(e.reached(expected * 1.1) && !e.reached(expected * 0.9));
        }
    }
}
