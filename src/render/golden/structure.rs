//! The golden test's **structure** statistic: a change of the pattern of light at the scale of
//! a few pixels — a caustic network redrawn, a refracted image shifted by a fraction of a pixel
//! — which moves light within a block without changing the block's mean, so that the block
//! means of [`super::batch_means`] cannot see it.
//!
//! The golden keeps, besides its blocks, the batch means of every `CELL`×`CELL`-pixel cell
//! (at most [`MAX_CELL_BATCHES`] batches: consecutive batches merged). A check pairs its batch
//! j with the golden's batch j (the same passes, so the same radius and the same sample
//! count) and forms, per cell i and channel, the differences dᵢⱼ = nowᵢⱼ − goldenᵢⱼ, their
//! weighted mean d̄ᵢ and its batch-means variance vᵢ, and the image-wide statistic
//!
//! ```text
//! Q = Σᵢ d̄ᵢ² / vᵢ        over every cell and channel (a χ²-like sum of squared paired t)
//! ```
//!
//! after taking out of each batch's differences the common proportional change of each group
//! of cells [`GROUP`] pixels square (rᵢⱼ = dᵢⱼ − sᵢ Σₖ dₖⱼ / Σₖ sₖ over the group, sᵢ the cell's
//! mean light over both renders): a pass with a few more photons in a region brightens all its
//! cells together, and a change of a block's mean is the block test's to find; what is left is
//! light moved between cells.
//!
//! at two cell sizes (2×2 and 4×4 px; coarser where the image has more than [`MAX_CELLS`]
//! cells). Q grows with any change, however its signs are spread, where a block mean sums
//! positive and negative moves to nothing.
//!
//! Its null distribution is not a χ² law — the cells of a progressive pass share photons, so
//! their errors are correlated, and single batches are heavy-tailed — so it is measured, by a
//! **sign-flip randomization test** (Fisher 1935 §21; Good, *Permutation, Parametric and
//! Bootstrap Tests of Hypotheses*, 2005, §3.1): when the scene is unchanged, golden batch j and
//! check batch j are independent draws of one distribution, so dⱼ is symmetric about 0 and the
//! joint law of (d₁, …, d_K) is unchanged by flipping the sign of any dⱼ (all cells of a batch
//! flip together, which keeps their correlation). Q is recomputed for [`FLIPS`] random sign
//! vectors; the two sizes' statistics are standardized over the flips and their maximum
//! compared (Westfall & Young 1993's max-statistic, so the two sizes cost no Bonferroni split);
//! the p-value (1 + #{flips at least as extreme}) / (1 + FLIPS) is exact for any correlation
//! between cells and any batch distribution. It needs golden and check to have the same batch
//! sizes (the same samples per pixel) and at least [`MIN_BATCHES`] batches (with K batches
//! there are 2^(K−1) distinct values of Q).

use glam::DVec3;

use super::batch_means::BatchBlocks;
use super::quantile::normal_upper_quantile;
use crate::sampling::Rng;

/// Side of the golden's cells in pixels.
pub const CELL: u32 = 2;
/// Most cell batches a golden keeps (consecutive batches merged beyond).
pub const MAX_CELL_BATCHES: u32 = 32;
/// Fewest batches for the structure test: 2^(K−1) sign patterns must allow p-values well below
/// α/2 (2 048 at 12).
pub const MIN_BATCHES: usize = 12;
/// Random sign vectors drawn (the p-value's resolution is 1/(1 + FLIPS)).
pub const FLIPS: usize = 1999;
/// Most cells a statistic sums (its cost is cells × batches × flips); beyond, cells are larger.
pub const MAX_CELLS: usize = 4096;
/// Key of the sign vectors' random stream (the verdict is a function of the two renders only).
const FLIP_STREAM: u64 = 0x5349_474E_464C_4950;

/// Merges consecutive batches of `b` into at most `max` batches (sizes differing by at most
/// one batch), each the sample-weighted mean of those it replaces.
#[must_use]
pub fn merge_batches(b: &BatchBlocks, max: u32) -> BatchBlocks {
    let k = b.batches();
    let mut out = BatchBlocks::new(b.width, b.height, b.block);
    let n = b.blocks();
    let groups = (k as u32).min(max.max(1));
    if groups == 0 {
        return out;
    }
    for g in 0..groups {
        let at = |g: u32| (u64::from(g) * k as u64 / u64::from(groups)) as usize;
        let (lo, hi) = (at(g), at(g + 1));
        let samples: u32 = b.samples[lo..hi].iter().sum();
        for i in 0..n {
            let mut m = [0.0; 3];
            for j in lo..hi {
                let w = f64::from(b.samples[j]) / f64::from(samples.max(1));
                for (c, v) in m.iter_mut().enumerate() {
                    *v += w * b.means[j * n + i][c];
                }
            }
            out.means.push(m);
        }
        out.samples.push(samples);
    }
    out
}

/// Why two renders' cells cannot be compared by the structure test (the check then relies on
/// the block means alone, and says why).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StructureSkip {
    /// Different image or cell sizes.
    #[error("the golden's cells are not the render's (another size)")]
    Shape,
    /// The batches hold different samples (another `--spp` than the golden's).
    #[error("the render's batches are not the golden's (another number of samples per pixel)")]
    Batches,
    /// Too few batches for the randomization to reach α.
    #[error(
        "{0} batches; the structure test needs at least {MIN_BATCHES} (at least {MIN_BATCHES} samples per pixel)"
    )]
    TooFewBatches(usize),
}

/// One cell size's statistic.
#[derive(Debug, Clone, PartialEq)]
pub struct CellScale {
    /// Side of its cells in pixels.
    pub side: u32,
    /// Cell-channels summed (those where either render has light).
    pub terms: usize,
    /// The observed Q.
    pub q: f64,
    /// Q's median over the sign flips (what an unchanged scene gives).
    pub null_median: f64,
    /// Q's (1 − α) quantile over the sign flips.
    pub null_limit: f64,
    /// The cells that moved most, as (x, y, side in pixels, channel, relative change, d̄/√v),
    /// largest |d̄/√v| first (at most 5).
    pub largest: Vec<CellMove>,
}

/// A cell that moved, for the report.
#[derive(Debug, Clone, PartialEq)]
pub struct CellMove {
    /// Left column in pixels.
    pub x: u32,
    /// Top row in pixels.
    pub y: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Channel (0 red, 1 green, 2 blue).
    pub channel: usize,
    /// The golden's mean there.
    pub golden: f64,
    /// The render's mean there.
    pub now: f64,
    /// The difference over its noise.
    pub t: f64,
}

/// The outcome of [`StructureTest::compare`].
#[derive(Debug, Clone, PartialEq)]
pub struct StructureVerdict {
    /// The false-alarm rate of this test.
    pub alpha: f64,
    /// The randomization p-value of the largest standardized statistic.
    pub p: f64,
    /// Batches paired.
    pub batches: usize,
    /// The statistic at each cell size, finest first.
    pub scales: Vec<CellScale>,
}

impl StructureVerdict {
    /// Whether the pattern of light differs beyond its noise.
    #[must_use]
    pub fn changed(&self) -> bool {
        self.p <= self.alpha
    }
}

/// The structure test at false-alarm rate `alpha` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StructureTest {
    /// The largest chance that an unchanged scene is called changed by this test.
    pub alpha: f64,
}

/// The cells of one statistic: per cell, its pixel-weighted share of the stored cells.
struct Grid {
    side: u32,
    nx: u32,
    /// Per coarse cell: the stored cells and their weights (pixels).
    members: Vec<Vec<(usize, f64)>>,
    /// The coarse cells of each group (about [`GROUP`] pixels square) whose common
    /// proportional change is removed.
    groups: Vec<Vec<usize>>,
}

/// Side in pixels of the groups of cells whose common change (all cells of the group brighter
/// or darker in proportion: what a progressive pass with a few more photons there gives, and
/// what the block means test) is taken out of the structure statistic.
pub const GROUP: u32 = 8;

fn grid(b: &BatchBlocks, span: u32) -> Grid {
    let (bx, by) = (b.blocks_x(), b.blocks_y());
    let (nx, ny) = (bx.div_ceil(span), by.div_ceil(span));
    let mut members = Vec::with_capacity((nx * ny) as usize);
    for cy in 0..ny {
        for cx in 0..nx {
            let mut m = Vec::new();
            for y in cy * span..((cy + 1) * span).min(by) {
                for x in cx * span..((cx + 1) * span).min(bx) {
                    m.push(((y * bx + x) as usize, f64::from(b.pixels(x, y))));
                }
            }
            let total: f64 = m.iter().map(|c| c.1).sum();
            for c in &mut m {
                c.1 /= total;
            }
            members.push(m);
        }
    }
    let side = span * b.block;
    let g = (GROUP / side).max(2);
    let mut groups = Vec::new();
    for gy in 0..ny.div_ceil(g) {
        for gx in 0..nx.div_ceil(g) {
            let mut m = Vec::new();
            for y in gy * g..((gy + 1) * g).min(ny) {
                for x in gx * g..((gx + 1) * g).min(nx) {
                    m.push((y * nx + x) as usize);
                }
            }
            groups.push(m);
        }
    }
    Grid {
        side,
        nx,
        members,
        groups,
    }
}

/// The spans (in stored cells) of the two statistics: the finest whose cell count is at most
/// [`MAX_CELLS`], and twice it.
fn spans(b: &BatchBlocks) -> [u32; 2] {
    let mut s = 1u32;
    while (b.blocks_x().div_ceil(s) as usize) * (b.blocks_y().div_ceil(s) as usize) > MAX_CELLS {
        s *= 2;
    }
    [s, 2 * s]
}

/// One cell-channel's paired differences, pre-weighted: aⱼ = wⱼdⱼ/W, bⱼ = wⱼ²dⱼ/W².
struct Term {
    a: Vec<f64>,
    b: Vec<f64>,
    /// Σ wⱼ²dⱼ² / W².
    sq: f64,
    /// Square of the standard-error floor.
    floor2: f64,
    /// Index of the coarse cell and channel (for the report).
    cell: usize,
    channel: usize,
    golden: f64,
    now: f64,
}

/// Relative floor of a difference's standard error, as [`super::batch_means`]'s.
const SE_FLOOR: f64 = 1e-9;

impl Term {
    /// d̄²/v for the sign vector `signs` (±1 per batch); `sum_w2` is Σwⱼ²/W², `kk` K/(K−1).
    fn value(&self, signs: &[f64], sum_w2: f64, kk: f64) -> f64 {
        let (mut s1, mut s2) = (0.0, 0.0);
        for ((a, b), e) in self.a.iter().zip(&self.b).zip(signs) {
            s1 += e * a;
            s2 += e * b;
        }
        let v = (self.sq - 2.0 * s1 * s2 + s1 * s1 * sum_w2) * kk;
        s1 * s1 / (v.max(0.0) + self.floor2)
    }
}

impl StructureTest {
    /// Compares the cells of a render with the golden's.
    ///
    /// # Errors
    /// [`StructureSkip`] when the shapes or batch sizes differ or there are too few batches.
    pub fn compare(
        &self,
        golden: &BatchBlocks,
        now: &BatchBlocks,
    ) -> Result<StructureVerdict, StructureSkip> {
        if (golden.width, golden.height, golden.block) != (now.width, now.height, now.block) {
            return Err(StructureSkip::Shape);
        }
        if golden.samples != now.samples {
            return Err(StructureSkip::Batches);
        }
        let k = golden.batches();
        if k < MIN_BATCHES {
            return Err(StructureSkip::TooFewBatches(k));
        }
        let total: f64 = golden.samples.iter().map(|s| f64::from(*s)).sum();
        let w: Vec<f64> = golden
            .samples
            .iter()
            .map(|s| f64::from(*s) / total)
            .collect();
        let sum_w2: f64 = w.iter().map(|x| x * x).sum();
        let kk = k as f64 / (k as f64 - 1.0);
        let n = golden.blocks();
        let grids: Vec<Grid> = spans(golden).iter().map(|&s| grid(golden, s)).collect();
        let terms: Vec<Vec<Term>> = grids
            .iter()
            .map(|g| {
                // Per cell: its batch means on both sides.
                let sides: Vec<(Vec<DVec3>, Vec<DVec3>)> = g
                    .members
                    .iter()
                    .map(|members| {
                        let (mut dg, mut dt) = (vec![DVec3::ZERO; k], vec![DVec3::ZERO; k]);
                        for j in 0..k {
                            for &(i, share) in members {
                                dg[j] += DVec3::from_array(golden.means[j * n + i]) * share;
                                dt[j] += DVec3::from_array(now.means[j * n + i]) * share;
                            }
                        }
                        (dg, dt)
                    })
                    .collect();
                let mean = |v: &[DVec3], c: usize| (0..k).map(|j| w[j] * v[j][c]).sum::<f64>();
                let mut out = Vec::new();
                for group in &g.groups {
                    for c in 0..3 {
                        // The group's proportional common mode: each cell's share of the
                        // group's difference in batch j, by its light (the same on both
                        // sides, so a sign flip flips it with the difference).
                        let share: Vec<f64> = group
                            .iter()
                            .map(|&ci| 0.5 * (mean(&sides[ci].0, c) + mean(&sides[ci].1, c)))
                            .collect();
                        let total: f64 = share.iter().sum();
                        let common: Vec<f64> = (0..k)
                            .map(|j| {
                                group
                                    .iter()
                                    .map(|&ci| sides[ci].1[j][c] - sides[ci].0[j][c])
                                    .sum::<f64>()
                            })
                            .collect();
                        for (&ci, sh) in group.iter().zip(&share) {
                            let (dg, dt) = &sides[ci];
                            let d: Vec<f64> = (0..k)
                                .map(|j| {
                                    let own = dt[j][c] - dg[j][c];
                                    if total > 0.0 {
                                        own - sh / total * common[j]
                                    } else {
                                        own
                                    }
                                })
                                .collect();
                            if d.iter().all(|x| *x == 0.0) {
                                continue;
                            }
                            let (mg, mt) = (mean(dg, c), mean(dt, c));
                            let floor = SE_FLOOR * 0.5 * (mg.abs() + mt.abs());
                            out.push(Term {
                                a: d.iter().zip(&w).map(|(d, w)| w * d).collect(),
                                b: d.iter().zip(&w).map(|(d, w)| w * w * d).collect(),
                                sq: d.iter().zip(&w).map(|(d, w)| (w * d).powi(2)).sum(),
                                floor2: (floor * floor).max(f64::MIN_POSITIVE),
                                cell: ci,
                                channel: c,
                                golden: mg,
                                now: mt,
                            });
                        }
                    }
                }
                out
            })
            .collect();
        // Row 0: the observed signs; then FLIPS random sign vectors.
        let mut rng = Rng::new(FLIP_STREAM, k as u64);
        let mut signs = vec![1.0; k];
        let mut q = vec![vec![0.0; FLIPS + 1]; grids.len()];
        for f in 0..=FLIPS {
            if f > 0 {
                for s in &mut signs {
                    *s = if rng.next_u32() & 1 == 0 { 1.0 } else { -1.0 };
                }
            }
            for (qs, ts) in q.iter_mut().zip(&terms) {
                qs[f] = ts.iter().map(|t| t.value(&signs, sum_w2, kk)).sum();
            }
        }
        // Standardize each size's statistic over all rows and take the largest.
        let z: Vec<Vec<f64>> = q
            .iter()
            .map(|qs| {
                let m = qs.iter().sum::<f64>() / qs.len() as f64;
                let sd = (qs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / qs.len() as f64).sqrt();
                qs.iter()
                    .map(|x| if sd > 0.0 { (x - m) / sd } else { 0.0 })
                    .collect()
            })
            .collect();
        let max_z = |f: usize| z.iter().map(|zs| zs[f]).fold(f64::NEG_INFINITY, f64::max);
        let observed = max_z(0);
        let as_extreme = (1..=FLIPS).filter(|&f| max_z(f) >= observed).count();
        let p = (1 + as_extreme) as f64 / (1 + FLIPS) as f64;
        let ones = vec![1.0; k];
        let scales = grids
            .iter()
            .zip(&terms)
            .zip(&q)
            .map(|((g, ts), qs)| {
                let mut null: Vec<f64> = qs[1..].to_vec();
                null.sort_by(f64::total_cmp);
                let at = |p: f64| null[((p * null.len() as f64) as usize).min(null.len() - 1)];
                let mut moves: Vec<CellMove> = ts
                    .iter()
                    .map(|t| {
                        let (cx, cy) = (t.cell as u32 % g.nx, t.cell as u32 / g.nx);
                        let (x, y) = (cx * g.side, cy * g.side);
                        CellMove {
                            x,
                            y,
                            width: g.side.min(golden.width - x),
                            height: g.side.min(golden.height - y),
                            channel: t.channel,
                            golden: t.golden,
                            now: t.now,
                            t: (t.now - t.golden).signum() * t.value(&ones, sum_w2, kk).sqrt(),
                        }
                    })
                    .collect();
                moves.sort_by(|a, b| b.t.abs().total_cmp(&a.t.abs()));
                moves.truncate(5);
                CellScale {
                    side: g.side,
                    terms: ts.len(),
                    q: qs[0],
                    null_median: at(0.5),
                    null_limit: at(1.0 - self.alpha),
                    largest: moves,
                }
            })
            .collect();
        Ok(StructureVerdict {
            alpha: self.alpha,
            p,
            batches: k,
            scales,
        })
    }
}

/// The structure test's floor: the smallest change of every lit cell of the finest statistic
/// by ±δ of its light (random signs: a pattern change with no change of the mean) that a check
/// catches in 95 % of its runs, approximately — taking the cells as independent and each as
/// noisy as the median lit cell-channel, so that Q is a noncentral χ²-like sum of N terms with
/// mean N + λ and variance 2N + 4λ, λ = δ² N median(mᵢ²/(2vᵢ)) (the golden's mean mᵢ and batch
/// variance vᵢ of each lit cell-channel; 2vᵢ for the difference of two renders). Infinite when
/// no cell is lit or there are fewer than 2 batches.
#[must_use]
pub fn structure_floor(cells: &BatchBlocks, alpha: f64) -> f64 {
    let k = cells.batches();
    if k < 2 {
        return f64::INFINITY;
    }
    let g = grid(cells, spans(cells)[0]);
    let mut ratios: Vec<f64> = Vec::new();
    let n_blocks = cells.blocks();
    for members in &g.members {
        let vals: Vec<[f64; 3]> = (0..k)
            .map(|j| {
                let mut m = [0.0; 3];
                for &(i, share) in members {
                    for (c, v) in m.iter_mut().enumerate() {
                        *v += cells.means[j * n_blocks + i][c] * share;
                    }
                }
                m
            })
            .collect();
        let (mean, var) = super::batch_means::mean_and_variance(&vals, &cells.samples);
        for c in 0..3 {
            if mean[c] > 0.0 {
                ratios.push(mean[c] * mean[c] / (2.0 * var[c]));
            }
        }
    }
    if ratios.is_empty() {
        return f64::INFINITY;
    }
    ratios.sort_by(f64::total_cmp);
    let n = ratios.len() as f64;
    // Every cell as noisy as the median lit cell (noiseless cells would make any change of
    // theirs certain to be caught, and say nothing of the others).
    let sum = n * ratios[ratios.len() / 2];
    if sum.is_nan() || sum <= 0.0 {
        return f64::INFINITY;
    }
    // λ − z₀.₀₅·√(2N + 4λ) = z_α·√(2N): solve for λ by iteration (increasing in λ).
    let (za, zb) = (
        normal_upper_quantile(alpha),
        normal_upper_quantile(1.0 - super::batch_means::POWER),
    );
    let c = za * (2.0 * n).sqrt();
    let mut lambda = c;
    for _ in 0..100 {
        lambda = c + zb * (2.0 * n + 4.0 * lambda).sqrt();
    }
    (lambda / sum).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 16×16 render of `k` one-sample passes over 2×2 cells in which each pass's pixels
    /// share a factor (as a progressive pass's photons) and `pattern(i)` scales pixel i.
    fn render(k: u32, rng: &mut Rng, pattern: impl Fn(usize) -> f64) -> BatchBlocks {
        let mut cells = BatchBlocks::new(16, 16, CELL);
        for _ in 0..k {
            let shared = -(1.0 - f64::from(rng.next_f32())).ln();
            let pass: Vec<DVec3> = (0..256)
                .map(|i| {
                    let own = -(1.0 - f64::from(rng.next_f32())).ln();
                    DVec3::splat(pattern(i) * (0.5 + 0.4 * shared + 0.1 * own))
                })
                .collect();
            cells.push_batch(&pass, 1);
        }
        cells
    }

    #[test]
    fn unchanged_renders_stay_within_alpha_and_a_redistribution_is_caught() {
        // 200 unchanged pairs at α = 0.05 with a shared factor per pass (every cell errs
        // together, so Q is far from a χ² law): binomial(200, ≤ 0.05) false alarms, mean ≤ 10,
        // sd 3.1; 22 is 4 sd above.
        let test = StructureTest { alpha: 0.05 };
        let mut rng = Rng::new(31, 2);
        let mut alarms = 0;
        for _ in 0..200 {
            let g = render(16, &mut rng, |_| 1.0);
            let t = render(16, &mut rng, |_| 1.0);
            alarms += usize::from(test.compare(&g, &t).unwrap().changed());
        }
        assert!(alarms <= 22, "{alarms} false alarms of 200");
        // A checkerboard of ±10 % over 2×2 cells: every 8×8 block's mean is unchanged.
        let board = |i: usize| {
            let (x, y) = (i % 16 / 2, i / 16 / 2);
            if (x + y) % 2 == 0 { 1.1 } else { 0.9 }
        };
        let g = render(32, &mut rng, |_| 1.0);
        let t = render(32, &mut rng, board);
        let v = StructureTest { alpha: 0.01 }.compare(&g, &t).unwrap();
        assert!(v.changed(), "{v:?}");
        assert_eq!(v.scales[0].side, 2);
        // Shapes, batch sizes and counts are checked.
        let few = render(8, &mut rng, |_| 1.0);
        assert_eq!(
            test.compare(&few, &few).unwrap_err(),
            StructureSkip::TooFewBatches(8)
        );
        assert_eq!(test.compare(&g, &few).unwrap_err(), StructureSkip::Batches);
    }

    #[test]
    fn merging_keeps_the_sample_weighted_means() {
        let mut b = BatchBlocks::new(2, 1, 2);
        for (v, s) in [(1.0, 1), (3.0, 3), (5.0, 1)] {
            b.push_batch(&[DVec3::splat(v * f64::from(s)); 2], s);
        }
        let m = merge_batches(&b, 2);
        // Groups {0} and {1, 2}: means 1 and (3·3 + 5·1)/4 = 3.5.
        assert_eq!(m.samples, vec![1, 4]);
        assert_eq!(m.means, vec![[1.0; 3], [3.5; 3]]);
        assert_eq!(merge_batches(&b, 8), b);
    }
}
