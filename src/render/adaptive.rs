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
//! 2. **Each later round** covers the sample indices `start..2·start` (so rounds double, up to
//!    the samples per pixel, the same for every pixel and crop), and pixel `i` takes the
//!    first `clamp(⌈n · e / τ⌉ − n, 1, start)` of them if `e > τ`, none otherwise (the
//!    estimate from few samples is itself noisy, so a pixel at most doubles before it is
//!    looked at again). The indices a pixel skips in a round are never taken: its samples are
//!    the warm-up and a prefix of each round it took part in. The render ends when a round
//!    gives no pixel a sample.
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
//! schedule for pass `s`), as in a uniform render; a round traces each of its passes once, for
//! every pixel whose prefix of the round reaches it, so passes are traced up to the most
//! samples any pixel reached, never twice. A pixel that skipped the end of a round has samples
//! of later passes than its count: their radii shrank further than a uniform render's at
//! that count (less bias, more variance per sample), and every radius still goes to zero, so
//! it stays consistent. Each sample reads its own maps: a pixel's samples are independent and
//! its variance estimate holds. (Numbering passes by how many a round needed instead would
//! depend on the other pixels, and a crop would differ.)
//!
//! **The mean**: the film keeps each pixel's count, so every pixel is the mean of its own
//! samples. Stopping on a pixel's own samples is not exactly unbiased (Kirk & Arvo 1991: a
//! pixel whose first samples happen to miss a rare bright path has a low variance estimate,
//! stops early and keeps a low mean: the mean of such renders is low). The warm-up keeps that
//! small: measured on the Cornell box with a 64×48 image, a cap of 256 and a threshold of
//! 0.02, the mean over the image of (adaptive − reference) was −0.035 with a warm-up of 8,
//! −0.013 with 32 and −0.0055 with 64 (the quarter of 256 chosen here), where the uniform
//! render at the same mean samples per pixel is within ±0.003 (docs/convergence.md). `tests/it/adaptive.rs` checks
//! the mean on a scene with a closed form.
//!
//! **Shards and merge**: a shard's samples would depend on every earlier shard's film, so an
//! adaptive render cannot be split into sample ranges: `--shard`, `--samples` and a `.part`
//! output refuse `--adaptive` (docs/farm.md).

use std::ops::Range;

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

    /// The sample indices of the round that starts at `start` (the first index no pixel has
    /// taken) in a render of `cap` samples per pixel: the warm-up `0..warmup`, then rounds
    /// that double, `start..2·start`; empty at the cap. The same for every pixel and region.
    #[must_use]
    pub fn round(&self, start: u32, cap: u32) -> Range<u32> {
        let end = if start < self.warmup {
            self.warmup
        } else {
            start.saturating_mul(2)
        };
        start.min(cap)..end.min(cap)
    }

    /// How many of `round`'s sample indices ([`AdaptivePlan::round`]) each pixel of `sums`
    /// (row-major) takes.
    #[must_use]
    pub fn counts(&self, sums: &PixelSums, round: &Range<u32>) -> Vec<u32> {
        let n = sums.width as usize * sums.height as usize;
        (0..n).map(|i| self.pixel_count(sums, i, round)).collect()
    }

    /// How many of `round`'s sample indices pixel `i` takes: all of the warm-up; later, none
    /// once its estimate is at most the threshold, else what the 1/n fall predicts it needs.
    fn pixel_count(&self, sums: &PixelSums, i: usize, round: &Range<u32>) -> u32 {
        let len = round.end.saturating_sub(round.start);
        if round.start < self.warmup {
            return len;
        }
        let n = f64::from(sums.count(i));
        let e = pixel_rel_mse(sums, i);
        if e <= self.pixel_target {
            return 0;
        }
        // The estimate falls as 1/n: n · e / τ samples in all reach τ. `as` saturates.
        let more = (n * e / self.pixel_target - n).ceil();
        (more as u32).clamp(1, len.max(1)).min(len)
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
        // After the warm-up of 8 the round is 8..16.
        assert_eq!(plan.round(8, 64), 8..16);
        let c = plan.counts(&s, &(8..16));
        // Pixel 1 needs 8 · 0.14144 / 0.01 ≈ 113 in all, 106 more: the round's 8. Pixel 2's
        // single sample says nothing (estimate 1): the whole round.
        assert_eq!(c, vec![0, 8, 8]);
        // A looser target: 8 · 0.14144 / 0.1 = 11.3 → 4 more.
        let loose = AdaptivePlan {
            pixel_target: 0.1,
            warmup: 8,
        };
        assert_eq!(loose.counts(&s, &(8..16)), vec![0, 4, 8]);
        // The warm-up round gives every pixel all of it; rounds double up to the cap.
        assert_eq!(plan.counts(&s, &(0..8)), vec![8, 8, 8]);
        assert_eq!(
            [
                plan.round(0, 64),
                plan.round(16, 64),
                plan.round(32, 48),
                plan.round(64, 64)
            ],
            [0..8, 16..32, 32..48, 64..64]
        );
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
