//! Adaptive sampling across passes (`--adaptive`, `render.adaptive`; issue #43): after a few
//! uniform passes, each pixel's further samples follow its own estimated error.
//!
//! The rule is the noise-threshold sampling of Cycles (its "adaptive sampling": a pixel stops
//! once its error estimate is below a threshold, the samples per pixel only cap it) and of
//! LuxCore's noise-driven sampling, with the per-pixel error of Rousselle, Knaus & Zwicker
//! (2011) that `--target-error` already estimates ([`super::error_estimate`]): the relative
//! squared error of the pixel's mean, `e = (s² / n) / (m² + 0.01)`. Since `e` falls as `1/n`, a
//! pixel with `n` samples needs about `n · e / τ` of them in all to reach a threshold `τ`.
//!
//! Rounds:
//! 1. **Warm-up**: every pixel takes samples `0..W` (the bytes of a uniform render at that
//!    many samples per pixel), `W` a quarter of the samples per pixel within 8..=64.
//! 2. **Each later round** gives pixel `i` `clamp(⌈n · e / τ⌉ − n, 1, taken)` more samples if
//!    `e > τ`, none otherwise: at most as many as it has (the estimate from few samples is
//!    itself noisy, so a pixel at most doubles before it is looked at again), never past the
//!    samples per pixel. The render ends when a round gives no pixel a sample.
//!
//! The decision for a pixel reads only that pixel's statistics after the previous round, in
//! fixed-point sums that are the same for any thread count, and a pixel's `s`-th sample is the
//! sampler's sample `s` of that pixel whichever round takes it. So the image is the same for
//! any thread count, a crop (`--region`) is the same pixels as the full render, and a render
//! continued from a saved state equals one that never stopped. No neighbourhood is read
//! (Cycles dilates the active pixels over a window): a crop would not have its neighbours.
//!
//! **Progressive photon passes** (`path-ppm`, `ppm`, and so the default estimator): a pixel's
//! sample `s` reads the photon maps of pass `s` (fresh maps, radius shrunk by Knaus & Zwicker's
//! schedule for pass `s`), exactly as in a uniform render. A round traces the passes of the
//! sample indices some pixel takes in it, in increasing order, each once per round, and in
//! pass `s` the pixels whose next sample is `s` take it. A pixel that skips passes simply has
//! fewer samples: with `n` of them it is, bit for bit, the pixel of the uniform render at `n`
//! samples per pixel, with that render's bias and variance, and consistent like it. (The
//! alternative, a sample reading the maps of the round's pass whatever its index, would number
//! passes by how many the *other* pixels needed, and a crop would differ.) The cost: passes are
//! traced up to the most samples any pixel takes, and a pass index taken in two rounds by
//! different pixels is traced twice (`--integrator path` has no passes).
//!
//! **The mean**: the film keeps each pixel's count, so every pixel is the mean of its own
//! samples. Stopping on a pixel's own samples is not exactly unbiased (Kirk & Arvo 1991: a
//! pixel whose first samples happen to miss a rare bright path has a low variance estimate,
//! stops early and keeps a low mean: the mean of such renders is low). The warm-up keeps that
//! small: measured on the Cornell box with a 64×48 image, a cap of 256 and a threshold of
//! 0.02, the mean over the image of (adaptive − reference) was −0.035 with a warm-up of 8,
//! −0.013 with 32 and −0.0055 with 64 (the quarter of 256 chosen here), where the uniform render at the same mean
//! samples per pixel is within ±0.001 (docs/convergence.md). `tests/it/adaptive.rs` checks
//! the mean on a scene with a closed form.
//!
//! **Shards and merge**: a shard's samples would depend on every earlier shard's film, so an
//! adaptive render cannot be split into sample ranges: `--shard`, `--samples` and a `.part`
//! output refuse `--adaptive` (docs/farm.md).

use super::PixelSums;
use super::error_estimate::pixel_rel_mse;

/// The fewest uniform samples per pixel before the first adaptive round.
pub const WARMUP_MIN: u32 = 8;
/// The most uniform samples per pixel before the first adaptive round (a quarter of the
/// samples per pixel up to this).
pub const WARMUP_MAX: u32 = 64;
/// The per-pixel threshold without a `--target-error`: an estimated relMSE of 0.002 (a
/// relative standard error of about 4.5 %) for each pixel's mean.
pub const DEFAULT_PIXEL_TARGET: f64 = 0.002;

/// How an adaptive render spends its samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptivePlan {
    /// A pixel takes samples while its estimated relMSE is above this.
    pub pixel_target: f64,
    /// Uniform samples per pixel first.
    pub warmup: u32,
}

impl AdaptivePlan {
    /// The plan for a render of `cap` samples per pixel at most with this `--target-error`
    /// (each pixel then aims at the target, so the image and its worst 1 % both reach it),
    /// else [`DEFAULT_PIXEL_TARGET`]; the warm-up is a quarter of `cap`, within
    /// [`WARMUP_MIN`]..=[`WARMUP_MAX`].
    #[must_use]
    pub fn new(target_error: Option<f64>, cap: u32) -> Self {
        Self {
            pixel_target: target_error
                .filter(|t| t.is_finite() && *t > 0.0)
                .unwrap_or(DEFAULT_PIXEL_TARGET),
            warmup: (cap / 4).clamp(WARMUP_MIN, WARMUP_MAX).min(cap),
        }
    }

    /// The next round's samples for each pixel of `sums` (row-major), given the sample
    /// indices each has taken (`taken(i)`) and the samples per pixel `cap`.
    #[must_use]
    pub fn counts(&self, sums: &PixelSums, taken: impl Fn(usize) -> u32, cap: u32) -> Vec<u32> {
        let n = sums.width as usize * sums.height as usize;
        (0..n)
            .map(|i| self.pixel_count(sums, i, taken(i), cap))
            .collect()
    }

    /// The next round's samples for pixel `i` that has taken `taken` sample indices.
    fn pixel_count(&self, sums: &PixelSums, i: usize, taken: u32, cap: u32) -> u32 {
        if taken >= cap {
            return 0;
        }
        let left = cap - taken;
        if taken < self.warmup {
            return (self.warmup - taken).min(left);
        }
        let n = f64::from(sums.count(i));
        let e = pixel_rel_mse(sums, i);
        if e <= self.pixel_target {
            return 0;
        }
        // The estimate falls as 1/n: n · e / τ samples in all reach τ. `as` saturates.
        let more = (n * e / self.pixel_target - n).ceil();
        (more as u32).clamp(1, taken.max(1)).min(left)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Pixel 0 is flat (estimate 0), pixel 1 alternates 0 and 2 (mean 1, s² = 8/7 over 8
    /// samples, e = (8/7 / 8) / 1.01 = 0.14144), pixel 2 has too few samples to trust.
    #[test]
    fn counts_follow_the_hand_computed_need() {
        let mut s = PixelSums::new(3, 1);
        for k in 0..8 {
            s.add(0, Vec3::splat(0.5));
            s.add(1, Vec3::splat(if k % 2 == 0 { 0.0 } else { 2.0 }));
        }
        s.add(2, Vec3::ONE);
        let plan = AdaptivePlan {
            pixel_target: 0.01,
            warmup: 8,
        };
        let taken = [8, 8, 1];
        let c = plan.counts(&s, |i| taken[i], 64);
        // Pixel 1 needs 8 · 0.14144 / 0.01 ≈ 113 in all, 105 more: capped at doubling (8).
        assert_eq!(c, vec![0, 8, 7]);
        // A looser target: 8 · 0.14144 / 0.1 = 11.3 → 4 more.
        let loose = AdaptivePlan {
            pixel_target: 0.1,
            warmup: 8,
        };
        assert_eq!(loose.counts(&s, |i| taken[i], 64), vec![0, 4, 7]);
        // The cap: pixel 1 at 60 of 64 takes at most 4 more, at 64 none.
        assert_eq!(plan.counts(&s, |i| [8, 60, 64][i], 64), vec![0, 4, 0]);
    }

    #[test]
    fn the_default_threshold_is_used_without_a_target() {
        assert_eq!(
            AdaptivePlan::new(None, 64).pixel_target,
            DEFAULT_PIXEL_TARGET
        );
        assert_eq!(AdaptivePlan::new(Some(0.05), 64).pixel_target, 0.05);
        assert_eq!(
            AdaptivePlan::new(Some(f64::NAN), 64).pixel_target,
            DEFAULT_PIXEL_TARGET
        );
        // The warm-up: a quarter of the cap within 8..=64, never past the cap.
        let w = |cap| AdaptivePlan::new(None, cap).warmup;
        assert_eq!([w(4), w(16), w(64), w(256), w(1 << 20)], [4, 8, 16, 64, 64]);
    }
}
