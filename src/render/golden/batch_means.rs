//! The golden test's noise model: **batch means** over the passes of a render.
//!
//! A render takes its samples in passes over sample indices; each group of consecutive passes
//! (a *batch*) is an estimate of the whole image made with its own random numbers — for the
//! progressive integrators (`ppm`, `path-ppm`, the default) with its own photon maps, since
//! every pass traces fresh ones (Knaus & Zwicker 2011). The image is cut into blocks of
//! `block`×`block` pixels, and for every batch we keep each block's mean radiance. The spread
//! of a block's batch means measures the noise of the block's mean directly, whatever the
//! correlation between the block's pixels (all pixels of a progressive pass read the same
//! photons) and however heavy-tailed single pixels are (a pixel lit by rare paths): this is
//! the batch-means method of simulation output analysis (Law & Kelton, *Simulation Modeling
//! and Analysis*, §9.5.3; Schmeiser 1982).
//!
//! Two renders — the golden and the check — are compared block by block with **Welch's t
//! test** on their batch means (Welch 1947): the difference of the block means over its
//! standard error, against Student's t with the Welch–Satterthwaite degrees of freedom, so that
//! a noise estimate from few batches is not trusted more than it deserves. Blocks are tested at
//! every scale: the base blocks, squares of 2×2, 4×4, … base blocks, up to the whole image
//! (one block); α is split equally between the scales and, within a scale, between its blocks
//! and the three channels (Bonferroni), so the chance that an unchanged scene is called changed
//! is at most α whatever the correlation between blocks, channels and scales. The coarse scales
//! find a small change spread over a large area, the fine ones a large change in a small one.

use glam::DVec3;

use super::quantile::{student_upper_quantile, student_upper_tail};
use crate::render::PixelSums;

/// Probability of catching a change at the detection floor (the floors of the block means,
/// `floor.rs`, and of the structure test, `structure.rs`).
pub const POWER: f64 = 0.95;

/// Most batches a golden keeps: beyond about 60 degrees of freedom Student's t is within 2 % of
/// the normal law at the test's quantiles, and more batches only grow the file.
pub const MAX_BATCHES: u32 = 64;

/// The batches of `spp` samples per pixel: `min(spp, MAX_BATCHES)` consecutive ranges of
/// sample indices whose sizes differ by at most one.
#[must_use]
pub fn batch_ranges(spp: u32) -> Vec<std::ops::Range<u32>> {
    split_ranges(spp, MAX_BATCHES)
}

/// `min(spp, max)` consecutive ranges of the sample indices `0..spp` whose sizes differ by at
/// most one (the batches of [`batch_ranges`], the replications of a `photon` render).
#[must_use]
pub fn split_ranges(spp: u32, max: u32) -> Vec<std::ops::Range<u32>> {
    let k = spp.min(max);
    (0..k)
        .map(|j| {
            let at = |j: u32| (u64::from(j) * u64::from(spp) / u64::from(k)) as u32;
            at(j)..at(j + 1)
        })
        .collect()
}

/// Each block's mean radiance in each batch of a render.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchBlocks {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Side of a base block in pixels (blocks at the right and bottom edges are smaller).
    pub block: u32,
    /// Samples per pixel of each batch.
    pub samples: Vec<u32>,
    /// Mean radiance of base block `b` in batch `j` at `j * blocks() + b` (blocks row-major).
    pub means: Vec<[f64; 3]>,
}

impl BatchBlocks {
    /// No batch yet, for an image of `width`×`height` cut into blocks of `block` pixels
    /// (`block` ≥ 1).
    #[must_use]
    pub fn new(width: u32, height: u32, block: u32) -> Self {
        Self {
            width,
            height,
            block: block.max(1),
            samples: Vec::new(),
            means: Vec::new(),
        }
    }

    /// Blocks per row.
    #[must_use]
    pub fn blocks_x(&self) -> u32 {
        self.width.div_ceil(self.block)
    }

    /// Blocks per column.
    #[must_use]
    pub fn blocks_y(&self) -> u32 {
        self.height.div_ceil(self.block)
    }

    /// Base blocks in the image.
    #[must_use]
    pub fn blocks(&self) -> usize {
        self.blocks_x() as usize * self.blocks_y() as usize
    }

    /// Batches recorded.
    #[must_use]
    pub fn batches(&self) -> usize {
        self.samples.len()
    }

    /// Pixels in base block (`bx`, `by`).
    #[must_use]
    pub fn pixels(&self, bx: u32, by: u32) -> u32 {
        let w = self.block.min(self.width - bx * self.block);
        let h = self.block.min(self.height - by * self.block);
        w * h
    }

    /// The mean and the estimated variance of that mean per channel of the block of
    /// `span`×`span` base blocks whose top-left base block is (`x0`, `y0`), from the batches.
    #[must_use]
    pub fn block_mean_variance(&self, x0: u32, y0: u32, span: u32) -> ([f64; 3], [f64; 3]) {
        mean_and_variance(&coarse_batches(self, x0, y0, span), &self.samples)
    }

    /// Appends a batch from per-pixel sums of its samples (`sums[i]`: Σ over the batch's
    /// `samples` samples of pixel `i`, row-major).
    pub fn push_batch(&mut self, sums: &[DVec3], samples: u32) {
        let (bx, s) = (self.blocks_x() as usize, self.block as usize);
        let mut acc = vec![DVec3::ZERO; self.blocks()];
        for (i, v) in sums.iter().enumerate() {
            let (x, y) = (i % self.width as usize, i / self.width as usize);
            acc[(y / s) * bx + x / s] += *v;
        }
        for (b, a) in acc.iter().enumerate() {
            let n = f64::from(self.pixels((b % bx) as u32, (b / bx) as u32)) * f64::from(samples);
            let m = if n > 0.0 { *a / n } else { DVec3::ZERO };
            self.means.push(m.to_array());
        }
        self.samples.push(samples);
    }
}

/// Records batches from a render's cumulative sums: after each batch's passes, the difference
/// of each pixel's sum since the previous batch is the batch's own sum.
#[derive(Debug, Clone)]
pub struct BatchRecorder {
    batches: BatchBlocks,
    previous: Vec<DVec3>,
    previous_samples: u32,
}

impl BatchRecorder {
    /// A recorder for a `width`×`height` render cut into blocks of `block` pixels.
    #[must_use]
    pub fn new(width: u32, height: u32, block: u32) -> Self {
        Self {
            batches: BatchBlocks::new(width, height, block),
            previous: vec![DVec3::ZERO; width as usize * height as usize],
            previous_samples: 0,
        }
    }

    /// Records the batch that ends with `sums` (the render's sums after `samples_done` samples
    /// per pixel; the sizes must be the recorder's).
    pub fn record(&mut self, sums: &PixelSums, samples_done: u32) {
        let delta: Vec<DVec3> = self
            .previous
            .iter_mut()
            .enumerate()
            .map(|(i, p)| {
                let now = sums.sum(i);
                let d = now - *p;
                *p = now;
                d
            })
            .collect();
        let n = samples_done.saturating_sub(self.previous_samples);
        self.previous_samples = samples_done;
        self.batches.push_batch(&delta, n);
    }

    /// The batches recorded.
    #[must_use]
    pub fn finish(self) -> BatchBlocks {
        self.batches
    }
}

/// Why two renders' batches cannot be compared.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BatchTestError {
    /// Different image sizes or block sizes.
    #[error(
        "the golden is {0}×{1} pixels in blocks of {2} but the render is {3}×{4} in blocks of {5}"
    )]
    Shape(u32, u32, u32, u32, u32, u32),
    /// Fewer than two batches on a side: the noise cannot be measured.
    #[error(
        "a render has {0} batch(es); at least 2 samples per pixel are needed to measure the noise"
    )]
    TooFewBatches(usize),
    /// α outside (0, 1).
    #[error("the false-alarm rate must be between 0 and 1 (e.g. 0.01), found {0}")]
    Alpha(f64),
}

/// A block (at any scale) compared between the golden and the render.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockDiff {
    /// Left column in pixels.
    pub x: u32,
    /// Top row in pixels.
    pub y: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The golden's block mean per channel.
    pub golden: [f64; 3],
    /// The render's block mean per channel.
    pub now: [f64; 3],
    /// Standard error of the difference `now − golden` per channel (from both renders'
    /// batches).
    pub se: [f64; 3],
    /// Welch's t: the difference over its standard error (0 when both are 0).
    pub t: [f64; 3],
    /// Welch–Satterthwaite degrees of freedom of each t.
    pub dof: [f64; 3],
    /// The two-sided p-value of each t.
    pub p: [f64; 3],
}

impl BlockDiff {
    /// The smallest p-value over the channels (NaN counts as 0: an impossible difference).
    #[must_use]
    pub fn min_p(&self) -> f64 {
        self.p
            .iter()
            .map(|p| if p.is_nan() { 0.0 } else { *p })
            .fold(1.0, f64::min)
    }

    /// The channel of the smallest p-value.
    #[must_use]
    pub fn worst_channel(&self) -> usize {
        let mut c = 0;
        for k in 1..3 {
            if self.p[k] < self.p[c] || self.p[k].is_nan() {
                c = k;
            }
        }
        c
    }
}

/// The blocks of one scale.
#[derive(Debug, Clone, PartialEq)]
pub struct Scale {
    /// Side of this scale's blocks in base blocks (1, 2, 4, …).
    pub span: u32,
    /// Side in pixels.
    pub side: u32,
    /// The per-test two-sided p-value below which a block of this scale has changed.
    pub p_limit: f64,
    /// Every block of this scale, row-major.
    pub blocks: Vec<BlockDiff>,
}

impl Scale {
    /// Whether this scale covers the whole image with one block.
    #[must_use]
    pub fn is_whole_image(&self) -> bool {
        self.blocks.len() == 1
    }

    /// |t| a block with `dof` degrees of freedom must exceed to count as changed here.
    #[must_use]
    pub fn t_limit(&self, dof: f64) -> f64 {
        student_upper_quantile(0.5 * self.p_limit, dof)
    }
}

/// The outcome of [`BatchTest::compare`].
#[derive(Debug, Clone, PartialEq)]
pub struct BatchVerdict {
    /// The test that was run.
    pub test: BatchTest,
    /// Batches of the golden and of the render.
    pub batches: (usize, usize),
    /// Every scale, finest first; the last is the whole image.
    pub scales: Vec<Scale>,
}

impl BatchVerdict {
    /// Whether some block at some scale differs beyond its noise.
    #[must_use]
    pub fn changed(&self) -> bool {
        self.scales
            .iter()
            .any(|s| s.blocks.iter().any(|b| b.min_p() < s.p_limit))
    }

    /// The blocks that differ beyond their noise, as (scale index, block), the most
    /// significant (smallest p relative to its scale's limit) first.
    #[must_use]
    pub fn changed_blocks(&self) -> Vec<(usize, &BlockDiff)> {
        let mut v: Vec<(usize, &BlockDiff)> = self
            .scales
            .iter()
            .enumerate()
            .flat_map(|(i, s)| {
                s.blocks
                    .iter()
                    .filter(|b| b.min_p() < s.p_limit)
                    .map(move |b| (i, b))
            })
            .collect();
        v.sort_by(|a, b| {
            let ra = a.1.min_p() / self.scales[a.0].p_limit;
            let rb = b.1.min_p() / self.scales[b.0].p_limit;
            ra.total_cmp(&rb)
        });
        v
    }

    /// The `n` blocks of the finest scale with the smallest p-values (for a report when no
    /// block changed).
    #[must_use]
    pub fn closest(&self, n: usize) -> Vec<(usize, &BlockDiff)> {
        let mut v: Vec<(usize, &BlockDiff)> = self
            .scales
            .iter()
            .enumerate()
            .flat_map(|(i, s)| s.blocks.iter().map(move |b| (i, b)))
            .collect();
        v.sort_by(|a, b| {
            let ra = a.1.min_p() / self.scales[a.0].p_limit;
            let rb = b.1.min_p() / self.scales[b.0].p_limit;
            ra.total_cmp(&rb)
        });
        v.truncate(n);
        v
    }

    /// The smallest p-value over all blocks relative to its scale's limit (below 1: changed).
    #[must_use]
    pub fn worst_ratio(&self) -> f64 {
        self.scales
            .iter()
            .flat_map(|s| s.blocks.iter().map(move |b| b.min_p() / s.p_limit))
            .fold(f64::INFINITY, f64::min)
    }
}

/// The batch-means comparison of two renders (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BatchTest {
    /// The largest chance that an unchanged scene is called changed.
    pub alpha: f64,
}

impl Default for BatchTest {
    fn default() -> Self {
        Self { alpha: 0.01 }
    }
}

/// Relative floor of a difference's standard error: the means are exact sums, so this only
/// keeps a noiseless block (a constant background) from dividing by zero.
const SE_FLOOR: f64 = 1e-9;

/// The batch means of one block (any scale) per channel: pixel-weighted means of base blocks.
fn coarse_batches(b: &BatchBlocks, x0: u32, y0: u32, span: u32) -> Vec<[f64; 3]> {
    let (bx, by) = (b.blocks_x(), b.blocks_y());
    let nb = b.blocks();
    let cells: Vec<(usize, f64)> = (y0..(y0 + span).min(by))
        .flat_map(|y| (x0..(x0 + span).min(bx)).map(move |x| (x, y)))
        .map(|(x, y)| ((y * bx + x) as usize, f64::from(b.pixels(x, y))))
        .collect();
    let total: f64 = cells.iter().map(|c| c.1).sum();
    (0..b.batches())
        .map(|j| {
            let mut m = [0.0; 3];
            for &(i, w) in &cells {
                let v = b.means[j * nb + i];
                for c in 0..3 {
                    m[c] += v[c] * w / total;
                }
            }
            m
        })
        .collect()
}

/// The mean of a block's batch means weighted by the batches' samples, and the estimated
/// variance of that mean: Σ wⱼ² (mⱼ − m̄)² / (Σ w)² · K/(K − 1) (s²/K for equal batches).
pub(crate) fn mean_and_variance(values: &[[f64; 3]], weights: &[u32]) -> ([f64; 3], [f64; 3]) {
    let k = values.len() as f64;
    let total: f64 = weights.iter().map(|w| f64::from(*w)).sum();
    let mut mean = [0.0; 3];
    let mut var = [0.0; 3];
    for c in 0..3 {
        mean[c] = values
            .iter()
            .zip(weights)
            .map(|(v, w)| v[c] * f64::from(*w))
            .sum::<f64>()
            / total;
        var[c] = values
            .iter()
            .zip(weights)
            .map(|(v, w)| (f64::from(*w) * (v[c] - mean[c])).powi(2))
            .sum::<f64>()
            / (total * total)
            * k
            / (k - 1.0);
    }
    (mean, var)
}

impl BatchTest {
    /// Compares a render's batches with the golden's (same size and block size).
    ///
    /// # Errors
    /// [`BatchTestError`] when the shapes differ, a side has fewer than 2 batches, or α is
    /// outside (0, 1).
    pub fn compare(
        &self,
        golden: &BatchBlocks,
        now: &BatchBlocks,
    ) -> Result<BatchVerdict, BatchTestError> {
        if (golden.width, golden.height, golden.block) != (now.width, now.height, now.block) {
            return Err(BatchTestError::Shape(
                golden.width,
                golden.height,
                golden.block,
                now.width,
                now.height,
                now.block,
            ));
        }
        let k = golden.batches().min(now.batches());
        if k < 2 {
            return Err(BatchTestError::TooFewBatches(k));
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(BatchTestError::Alpha(self.alpha));
        }
        let spans = scale_spans(golden.blocks_x(), golden.blocks_y());
        let per_scale = self.alpha / spans.len() as f64;
        let scales = spans
            .iter()
            .map(|&span| {
                let (nx, ny) = (
                    golden.blocks_x().div_ceil(span),
                    golden.blocks_y().div_ceil(span),
                );
                let mut blocks = Vec::with_capacity((nx * ny) as usize);
                for cy in 0..ny {
                    for cx in 0..nx {
                        blocks.push(block_diff(golden, now, cx * span, cy * span, span));
                    }
                }
                Scale {
                    span,
                    side: span * golden.block,
                    p_limit: per_scale / (3.0 * blocks.len() as f64),
                    blocks,
                }
            })
            .collect();
        Ok(BatchVerdict {
            test: *self,
            batches: (golden.batches(), now.batches()),
            scales,
        })
    }
}

/// The spans of the scales for a grid of `bx`×`by` base blocks: 1, 2, 4, … up to the first
/// that covers the grid with one block.
#[must_use]
pub fn scale_spans(bx: u32, by: u32) -> Vec<u32> {
    let mut spans = vec![1u32];
    while spans[spans.len() - 1] < bx.max(by) {
        let s = spans[spans.len() - 1] * 2;
        spans.push(s);
    }
    spans
}

fn block_diff(g: &BatchBlocks, t: &BatchBlocks, x0: u32, y0: u32, span: u32) -> BlockDiff {
    let (gm, gv) = g.block_mean_variance(x0, y0, span);
    let (tm, tv) = t.block_mean_variance(x0, y0, span);
    let (kg, kt) = (g.batches() as f64, t.batches() as f64);
    let (mut se, mut tt, mut dof, mut p) = ([0.0; 3], [0.0; 3], [0.0; 3], [1.0; 3]);
    for c in 0..3 {
        let floor = SE_FLOOR * 0.5 * (gm[c].abs() + tm[c].abs());
        let v = gv[c] + tv[c];
        se[c] = (v + floor * floor).sqrt();
        let d = tm[c] - gm[c];
        // Welch–Satterthwaite; a side without noise contributes no uncertainty.
        let denom = gv[c] * gv[c] / (kg - 1.0) + tv[c] * tv[c] / (kt - 1.0);
        dof[c] = if denom > 0.0 {
            (v * v / denom).max(1.0)
        } else {
            kg + kt - 2.0
        };
        tt[c] = if d == 0.0 { 0.0 } else { d / se[c] };
        p[c] = if tt[c].is_nan() {
            f64::NAN
        } else {
            2.0 * student_upper_tail(tt[c].abs(), dof[c])
        };
    }
    let (x, y) = (x0 * g.block, y0 * g.block);
    BlockDiff {
        x,
        y,
        width: (span * g.block).min(g.width - x),
        height: (span * g.block).min(g.height - y),
        golden: gm,
        now: tm,
        se,
        t: tt,
        dof,
        p,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::golden::BlockTest;
    use crate::render::golden::PixelEstimates;
    use crate::sampling::Rng;

    /// A 32×32 render of `k` passes of one sample per pixel, in which every pixel of a pass
    /// reads the same "photon map": each 8×8 region of a pass is scaled by a common factor
    /// (exponential, mean 1: a few bright passes), each pixel adds its own exponential noise.
    /// Returns its batches and its per-pixel estimates.
    fn progressive_like(
        k: u32,
        rng: &mut Rng,
        scale: impl Fn(u32) -> f64,
    ) -> (BatchBlocks, PixelEstimates) {
        let mut batches = BatchBlocks::new(32, 32, 8);
        let mut sums = PixelSums::new(32, 32);
        for _ in 0..k {
            let shared: Vec<f64> = (0..16)
                .map(|_| -(1.0 - f64::from(rng.next_f32())).ln())
                .collect();
            let mut pass = vec![DVec3::ZERO; 1024];
            for (i, p) in pass.iter_mut().enumerate() {
                let (x, y) = (i % 32, i / 32);
                let own = -(1.0 - f64::from(rng.next_f32())).ln();
                let v = scale(i as u32) * (0.5 + 0.4 * shared[(y / 8) * 4 + x / 8] + 0.1 * own);
                *p = DVec3::new(v, 0.5 * v, 0.25 * v);
                sums.add(i, p.as_vec3());
            }
            batches.push_batch(&pass, 1);
        }
        (batches, PixelEstimates::from_sums(&sums))
    }

    #[test]
    fn batch_means_stay_calibrated_where_pixel_variances_do_not() {
        // 300 pairs of unchanged renders with pass-shared noise, 8 passes each, α = 0.05: the
        // count of "changed" is binomial(300, rate ≤ 0.05), mean ≤ 15, standard deviation 3.8;
        // 30 is 4 standard deviations above. The per-pixel-variance test sees one 64th of the
        // shared noise and calls most pairs changed.
        let (test, old) = (
            BatchTest { alpha: 0.05 },
            BlockTest {
                block: 8,
                alpha: 0.05,
            },
        );
        let mut rng = Rng::new(21, 4);
        let (mut alarms, mut old_alarms) = (0, 0);
        for _ in 0..300 {
            let (g, ge) = progressive_like(8, &mut rng, |_| 1.0);
            let (t, te) = progressive_like(8, &mut rng, |_| 1.0);
            alarms += usize::from(test.compare(&g, &t).unwrap().changed());
            old_alarms += usize::from(old.compare(&ge, &te).unwrap().changed());
        }
        eprintln!(
            "pass-shared noise: batch means {alarms} / 300, per-pixel variances {old_alarms} / 300 false alarms at α 0.05"
        );
        assert!(alarms <= 30, "{alarms} false alarms of 300");
        assert!(old_alarms > 150, "{old_alarms}");
    }

    #[test]
    fn a_large_local_change_and_a_small_spread_change_are_caught_at_their_scales() {
        let test = BatchTest::default();
        let mut rng = Rng::new(22, 4);
        let (g, _) = progressive_like(32, &mut rng, |_| 1.0);
        // One 8×8 block twice as bright: the finest scale names it.
        let (t, _) = progressive_like(32, &mut rng, |i| {
            if (8..16).contains(&(i % 32)) && (16..24).contains(&(i / 32)) {
                2.0
            } else {
                1.0
            }
        });
        let v = test.compare(&g, &t).unwrap();
        assert!(v.changed());
        let (scale, b) = v.changed_blocks()[0];
        assert_eq!((scale, b.x, b.y, b.width), (0, 8, 16, 8), "{b:?}");
        // Everything 20 % brighter: each 8×8 block's batch spread (shared factor of standard
        // deviation 0.4 over 32 passes: a standard error of about 0.1 of the difference) hides
        // it, the whole image (16 regions averaged) does not.
        let (t, _) = progressive_like(32, &mut rng, |_| 1.2);
        let v = test.compare(&g, &t).unwrap();
        assert!(v.changed());
        let whole = v.scales.last().unwrap();
        assert!(whole.is_whole_image() && whole.blocks[0].min_p() < whole.p_limit);
        // The same render is the same; shapes and batch counts are checked.
        assert!(!test.compare(&g, &g).unwrap().changed());
        let (few, _) = progressive_like(1, &mut rng, |_| 1.0);
        assert_eq!(
            test.compare(&g, &few).unwrap_err(),
            BatchTestError::TooFewBatches(1)
        );
        let other = BatchBlocks::new(32, 32, 4);
        assert!(matches!(
            test.compare(&g, &other),
            Err(BatchTestError::Shape(..))
        ));
        assert_eq!(batch_ranges(3), vec![0..1, 1..2, 2..3]);
        assert_eq!(batch_ranges(130).len(), 64);
        assert_eq!(
            batch_ranges(130)
                .iter()
                .map(|r| r.end - r.start)
                .sum::<u32>(),
            130
        );
    }

    #[test]
    fn the_recorder_keeps_each_batch_s_own_sums() {
        let mut sums = PixelSums::new(2, 1);
        let mut rec = BatchRecorder::new(2, 1, 1);
        sums.add(0, glam::Vec3::splat(1.0));
        sums.add(1, glam::Vec3::splat(3.0));
        rec.record(&sums, 1);
        sums.add(0, glam::Vec3::splat(5.0));
        sums.add(1, glam::Vec3::splat(7.0));
        sums.add(0, glam::Vec3::splat(0.0));
        sums.add(1, glam::Vec3::splat(2.0));
        rec.record(&sums, 3);
        let b = rec.finish();
        assert_eq!(b.samples, vec![1, 2]);
        assert_eq!(b.means, vec![[1.0; 3], [3.0; 3], [2.5; 3], [4.5; 3]]);
    }
}
