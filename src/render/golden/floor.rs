//! The detection floor of a golden: the smallest change that a check catches in 95 % of its
//! runs, per block scale, and the samples per pixel that reach a floor the user asks for.
//!
//! A block whose golden mean is m with batch-means variance v is compared with a render whose
//! noise is assumed the same (same settings, another seed): the difference has standard error
//! √(2v) with ν = 2(K − 1) degrees of freedom for K batches a side. A relative change δ of the
//! block is caught with probability ≥ 95 % when δ·m ≥ (t* + t₀.₀₅)·√(2v), t* the scale's
//! Bonferroni limit and t₀.₀₅ the 95 % quantile of Student's t (the usual normal approximation
//! of the noncentral t's power, Cohen 1988 §2.3, with t quantiles for the few-batch case). A
//! block's floor is the smallest over its channels (a change of every channel by δ); a scale's
//! floor is the median over its lit blocks (black blocks have no relative change), so "caught
//! in 95 % of checks" holds for at least half the blocks of that size.

use super::batch_means::{BatchBlocks, scale_spans};
use super::noise_scaling::{NoiseScaling, SampleShare, fit_share};
use super::quantile::student_upper_quantile;
use crate::integrators::photon::RadiusSchedule;

pub use super::batch_means::POWER;

/// Fraction of the image the `--detect` advice aims at: a change over a square this share of
/// the image (the scale whose blocks are closest to it in area).
pub const DETECT_AREA: f64 = 0.05;

/// The floor of one block scale.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleFloor {
    /// Side of this scale's blocks in pixels.
    pub side: u32,
    /// Blocks of this scale (the last scale has one: the whole image).
    pub blocks: usize,
    /// The median over lit blocks of the smallest relative change caught in 95 % of checks
    /// (0.03: 3 %); infinite when no block is lit.
    pub median: f64,
}

/// The detection floor of a golden at every scale, finest first, and of its structure test.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectionFloor {
    /// Batches of the golden.
    pub batches: usize,
    /// Per scale, finest first; the last is the whole image.
    pub scales: Vec<ScaleFloor>,
    /// The structure test's floor ([`super::structure::structure_floor`]): the smallest
    /// change of every lit cell by ±δ of its light caught in 95 % of checks (infinite when
    /// not measured).
    pub structure: f64,
    /// Side in pixels of the cells of [`DetectionFloor::structure`].
    pub cell: u32,
    /// Whether the structure test runs at these samples per pixel (enough batches).
    pub structure_active: bool,
    /// How the noise falls with more samples per pixel (for the predictions of the
    /// `--detect` advice): [`NoiseScaling::Passes`] unless set by [`DetectionFloor::with_noise`].
    pub noise: NoiseScaling,
}

/// (t* + t₀.₀₅) for a scale of `blocks` blocks at false-alarm rate `alpha` split over
/// `scales` scales, with `k` batches a side.
fn critical(alpha: f64, scales: usize, blocks: usize, k: usize) -> f64 {
    let nu = 2.0 * (k as f64 - 1.0);
    let p = alpha / scales as f64 / (3.0 * blocks as f64);
    student_upper_quantile(0.5 * p, nu) + student_upper_quantile(1.0 - POWER, nu)
}

impl DetectionFloor {
    /// The floor of a golden's blocks and cells for checks at false-alarm rate `alpha` (split
    /// between the two tests as [`super::combined::GoldenTest`] does).
    #[must_use]
    pub fn of(golden: &BatchBlocks, cells: &BatchBlocks, alpha: f64) -> Self {
        let structure_active = cells.batches() >= super::structure::MIN_BATCHES;
        let mut f = Self::of_blocks(golden, super::combined::block_alpha(alpha, cells));
        f.structure = super::structure::structure_floor(cells, 0.5 * alpha);
        f.cell = cells.block;
        f.structure_active = structure_active;
        f
    }

    /// The floor of the block means alone at false-alarm rate `alpha` (no structure floor).
    #[must_use]
    pub fn of_blocks(golden: &BatchBlocks, alpha: f64) -> Self {
        let k = golden.batches();
        let spans = scale_spans(golden.blocks_x(), golden.blocks_y());
        let scales = spans
            .iter()
            .map(|&span| {
                let (nx, ny) = (
                    golden.blocks_x().div_ceil(span),
                    golden.blocks_y().div_ceil(span),
                );
                let blocks = (nx * ny) as usize;
                let c = if k >= 2 {
                    critical(alpha, spans.len(), blocks, k)
                } else {
                    f64::INFINITY
                };
                let mut floors: Vec<f64> = (0..ny)
                    .flat_map(|y| (0..nx).map(move |x| (x, y)))
                    .filter_map(|(x, y)| {
                        let (m, v) = golden.block_mean_variance(x * span, y * span, span);
                        (0..3)
                            .filter(|&c| m[c] > 0.0)
                            .map(|ch| c * (2.0 * v[ch]).sqrt() / m[ch])
                            .min_by(f64::total_cmp)
                    })
                    .collect();
                floors.sort_by(f64::total_cmp);
                let median = if floors.is_empty() {
                    f64::INFINITY
                } else {
                    floors[floors.len() / 2]
                };
                ScaleFloor {
                    side: span * golden.block,
                    blocks,
                    median,
                }
            })
            .collect();
        Self {
            batches: k,
            scales,
            structure: f64::INFINITY,
            cell: 0,
            structure_active: false,
            noise: NoiseScaling::Passes,
        }
    }

    /// This floor with the render's noise scaling (`GoldenRender::noise`), which the
    /// predictions for other samples per pixel follow.
    #[must_use]
    pub fn with_noise(self, noise: NoiseScaling) -> Self {
        Self { noise, ..self }
    }

    /// The scale the `--detect` advice aims at: blocks closest in area to [`DETECT_AREA`] of
    /// a `width`×`height` image.
    #[must_use]
    pub fn detect_scale(&self, width: u32, height: u32) -> usize {
        let target = DETECT_AREA * f64::from(width) * f64::from(height);
        let mut best = 0;
        for (i, s) in self.scales.iter().enumerate() {
            let d = |s: &ScaleFloor| (f64::from(s.side).powi(2) / target).ln().abs();
            if d(s) < d(&self.scales[best]) {
                best = i;
            }
        }
        best
    }
}

/// The mean over the first `n` passes of the per-pass variance relative to the first pass:
/// 1 for estimators whose passes are alike; for a progressive one the radius of pass i is
/// sᵢ·R, a density estimate's variance grows as 1/sᵢ², so the mean of 1/sᵢ² (an upper bound
/// for `path-ppm`, whose path-traced part does not grow).
#[must_use]
pub fn variance_growth(progressive_alpha: Option<f64>, n: u32) -> f64 {
    let Some(alpha) = progressive_alpha else {
        return 1.0;
    };
    let schedule = RadiusSchedule { alpha };
    let n = n.max(1);
    (0..n)
        .map(|i| 1.0 / f64::from(schedule.scale(i)).powi(2))
        .sum::<f64>()
        / f64::from(n)
}

/// The floor at scale `scale` predicted for `spp` samples per pixel from a golden's `floor`
/// rendered at `golden_spp`: the standard error scales as the square root of the floor's
/// [`NoiseScaling::variance_ratio`] (1/spp for passes, times the progressive growth when
/// `progressive_alpha` is given; the maps' part fixed beyond 16 `photon` replications), and
/// the critical value follows the batch count ([`NoiseScaling::batches`]).
#[must_use]
pub fn predicted_floor(
    floor: &DetectionFloor,
    scale: usize,
    golden_spp: u32,
    spp: u32,
    alpha: f64,
    progressive_alpha: Option<f64>,
) -> f64 {
    let s = &floor.scales[scale];
    let k0 = floor.batches;
    let k1 = floor.noise.batches(spp) as usize;
    if k0 < 2 || k1 < 2 {
        return f64::INFINITY;
    }
    let n = floor.scales.len();
    let c0 = critical(alpha, n, s.blocks, k0);
    let c1 = critical(alpha, n, s.blocks, k1);
    s.median * c1 / c0 * variance_ratio(floor, false, golden_spp, spp, progressive_alpha).sqrt()
}

/// v(spp)/v(golden_spp) of the blocks (`cells`: the structure cells): the floor's noise
/// scaling, times the progressive growth of passes when `progressive_alpha` is given.
fn variance_ratio(
    floor: &DetectionFloor,
    cells: bool,
    golden_spp: u32,
    spp: u32,
    progressive_alpha: Option<f64>,
) -> f64 {
    let growth = variance_growth(progressive_alpha, spp.max(1))
        / variance_growth(progressive_alpha, golden_spp.max(1));
    floor.noise.variance_ratio(cells, golden_spp, spp) * growth
}

/// The structure floor predicted for `spp` samples per pixel from a golden's `floor` rendered
/// at `golden_spp`: δ scales as the standard error, the square root of the cells'
/// [`NoiseScaling::variance_ratio`] (its critical value does not depend on the batch count).
#[must_use]
pub fn predicted_structure_floor(
    floor: &DetectionFloor,
    golden_spp: u32,
    spp: u32,
    progressive_alpha: Option<f64>,
) -> f64 {
    floor.structure * variance_ratio(floor, true, golden_spp, spp, progressive_alpha).sqrt()
}

/// The fewest samples per pixel (at least [`super::structure::MIN_BATCHES`], at most
/// `limit`) whose predicted structure floor is at most `target`; `None` when even `limit`
/// does not reach it.
#[must_use]
pub fn recommend_structure_spp(
    floor: &DetectionFloor,
    golden_spp: u32,
    target: f64,
    progressive_alpha: Option<f64>,
    limit: u32,
) -> Option<u32> {
    let min = super::structure::MIN_BATCHES as u32;
    let reaches =
        |spp: u32| predicted_structure_floor(floor, golden_spp, spp, progressive_alpha) <= target;
    fewest_spp(min, limit, reaches)
}

/// The fewest samples per pixel (at least 2, at most `limit`) whose predicted floor at `scale`
/// is at most `target` (0.02 for 2 %); `None` when even `limit` does not reach it.
#[must_use]
pub fn recommend_spp(
    floor: &DetectionFloor,
    scale: usize,
    golden_spp: u32,
    target: f64,
    alpha: f64,
    progressive_alpha: Option<f64>,
    limit: u32,
) -> Option<u32> {
    let reaches = |spp: u32| {
        predicted_floor(floor, scale, golden_spp, spp, alpha, progressive_alpha) <= target
    };
    // The predicted floor falls with spp (fewer-batch t quantiles and 1/√spp both help).
    fewest_spp(2, limit, reaches)
}

/// The fewest samples per pixel from `start` to `limit` for which `reaches` holds, assuming it
/// stays true above (doubling, then bisection); `None` when even `limit` does not reach.
fn fewest_spp(start: u32, limit: u32, reaches: impl Fn(u32) -> bool) -> Option<u32> {
    let (mut lo, mut hi) = (start, start);
    while !reaches(hi) {
        if hi >= limit {
            return None;
        }
        lo = hi;
        hi = hi.saturating_mul(2).min(limit);
    }
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if reaches(mid) { hi = mid } else { lo = mid + 1 }
    }
    Some(hi)
}

/// Renders `--detect` may take to find the samples per pixel.
pub const DETECT_ROUNDS: usize = 4;
/// The prediction aims this far below the requested floor, so that the measured floor (itself
/// an estimate) usually reaches it at the first try.
pub const DETECT_AIM: f64 = 0.9;

/// The search for the samples per pixel that reach a requested floor (`golden update
/// --detect`): predict from the floor measured (noise ∝ 1/√spp, limits from the batch count),
/// render there, measure again, at most [`DETECT_ROUNDS`] times. The prediction is only
/// approximate for the progressive integrators, whose per-pass noise grows as the radius
/// shrinks, hence the renders: the floor a golden states is always the measured one.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectSearch {
    /// The requested floor (0.02 for 2 %).
    pub target: f64,
    /// The checks' false-alarm rate.
    pub alpha: f64,
    /// Most samples per pixel to try.
    pub limit: u32,
    rounds: usize,
    /// The previous floor's samples per pixel and its variances (blocks at the detect scale,
    /// in units of the squared critical value; cells), for the fit of a `photon` golden's
    /// noise split ([`fit_share`]).
    previous: Option<(u32, f64, f64)>,
}

/// What to do after a render in a [`DetectSearch`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DetectStep {
    /// Render at these samples per pixel and call [`DetectSearch::next`] with the result.
    Render(u32),
    /// Keep the current render.
    Done,
}

impl DetectSearch {
    /// A search for `target` at false-alarm rate `alpha`, trying at most `limit` spp.
    #[must_use]
    pub fn new(target: f64, alpha: f64, limit: u32) -> Self {
        Self {
            target,
            alpha,
            limit,
            rounds: 0,
            previous: None,
        }
    }

    /// Whether `floor` (of a `width`×`height` golden) reaches the target at the detect scale
    /// and, with the structure test running, the structure floor reaches it too.
    #[must_use]
    pub fn reached(&self, floor: &DetectionFloor, width: u32, height: u32) -> bool {
        let structure =
            floor.cell == 0 || (floor.structure_active && floor.structure <= self.target);
        floor.scales[floor.detect_scale(width, height)].median <= self.target && structure
    }

    /// The next step from the kept render (`floor` at `spp`).
    pub fn next(
        &mut self,
        floor: &DetectionFloor,
        spp: u32,
        width: u32,
        height: u32,
    ) -> DetectStep {
        if self.rounds >= DETECT_ROUNDS {
            return DetectStep::Done;
        }
        self.rounds += 1;
        let scale = floor.detect_scale(width, height);
        let reached = self.reached(floor, width, height);
        let block_alpha = if floor.cell == 0 {
            self.alpha
        } else {
            0.5 * self.alpha
        };
        let fitted = self.fit(floor, scale, spp, block_alpha);
        let floor = &fitted;
        let blocks = recommend_spp(
            floor,
            scale,
            spp,
            DETECT_AIM * self.target,
            block_alpha,
            None,
            self.limit,
        );
        // The blocks get half of α once the structure test runs (at the spp aimed at).
        let structure = if floor.cell == 0 {
            Some(2)
        } else {
            recommend_structure_spp(floor, spp, DETECT_AIM * self.target, None, self.limit)
        };
        let advice = match (blocks, structure) {
            (Some(a), Some(b)) => Some(a.max(b)),
            _ => None,
        };
        // Out of reach: passes render at the limit once; `photon` replications, whose maps'
        // noise more samples do not lower, at most where more buy little (the knee).
        let knee = floor.noise.knee(blocks.is_some(), spp);
        let out_of_reach = knee.map_or(self.limit, |k| k.min(self.limit));
        match advice {
            None if spp >= out_of_reach => DetectStep::Done,
            None => DetectStep::Render(out_of_reach),
            Some(next) if next == spp || (reached && next > spp) => DetectStep::Done,
            Some(next) => DetectStep::Render(next),
        }
    }

    /// `floor` (at `spp`) with a `photon` golden's noise split fitted from it and the previous
    /// floor given to [`DetectSearch::next`] (unchanged for passes, or without a previous
    /// floor at other samples per pixel); remembers this floor for the next fit.
    fn fit(
        &mut self,
        floor: &DetectionFloor,
        scale: usize,
        spp: u32,
        alpha: f64,
    ) -> DetectionFloor {
        let s = &floor.scales[scale];
        let k = floor.batches;
        let blocks = if k >= 2 {
            (s.median / critical(alpha, floor.scales.len(), s.blocks, k)).powi(2)
        } else {
            f64::NAN
        };
        let cells = floor.structure.powi(2);
        let previous = self.previous.replace((spp, blocks, cells));
        let NoiseScaling::Replications(_) = floor.noise else {
            return floor.clone();
        };
        let Some((p_spp, p_blocks, p_cells)) = previous else {
            return floor.clone();
        };
        let blocks = fit_share((p_spp, p_blocks), (spp, blocks), spp);
        let cells = fit_share((p_spp, p_cells), (spp, cells), spp);
        match (blocks, cells) {
            (None, None) => floor.clone(),
            (b, c) => floor
                .clone()
                .with_noise(NoiseScaling::Replications(Some(SampleShare {
                    blocks: b.unwrap_or(1.0),
                    cells: c.unwrap_or(1.0),
                }))),
        }
    }

    /// Whether a render at `tried` spp replaces the kept one at `kept` spp: more samples
    /// always do (closer to the target); fewer only when they still reach it.
    #[must_use]
    pub fn keep_new(&self, tried: u32, kept: u32, new_reaches: bool) -> bool {
        new_reaches || tried > kept
    }

    /// Whether to stop after trying `tried` spp: the target was just reached from above, or
    /// fewer samples than the kept render's failed it.
    #[must_use]
    pub fn stop_after(&self, tried: u32, kept: u32, was_reached: bool, new_reaches: bool) -> bool {
        (new_reaches && !was_reached) || (!new_reaches && tried < kept)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn the_floor_is_the_hand_computed_one_and_the_advice_reaches_it() {
        // One 4×4 block, K = 2 batches with block means 1 and 3: mean 2, variance of the mean
        // ((1−2)² + (3−2)²)/4 · 2/1 = 1, so the difference's standard error is √2. One scale,
        // one block: t* is Student's t (ν = 2) at (0.01/3)/2, t₀.₀₅ at 0.05.
        let mut b = BatchBlocks::new(4, 4, 4);
        b.push_batch(&[DVec3::splat(1.0); 16], 1);
        b.push_batch(&[DVec3::splat(3.0); 16], 1);
        let f = DetectionFloor::of_blocks(&b, 0.01);
        assert_eq!(f.scales.len(), 1);
        let c = student_upper_quantile(0.01 / 3.0 / 2.0, 2.0) + student_upper_quantile(0.05, 2.0);
        let want = c * 2f64.sqrt() / 2.0;
        assert!(
            (f.scales[0].median - want).abs() < 1e-9,
            "{:?} {want}",
            f.scales
        );
        // Without progressive growth the floor falls as 1/√spp times the ratio of quantiles.
        let at8 = predicted_floor(&f, 0, 2, 8, 0.01, None);
        let c8 =
            student_upper_quantile(0.01 / 3.0 / 2.0, 14.0) + student_upper_quantile(0.05, 14.0);
        assert!((at8 - want * c8 / c * 0.5).abs() < 1e-9);
        let spp = recommend_spp(&f, 0, 2, at8, 0.01, None, 1 << 20).unwrap();
        assert_eq!(spp, 8);
        assert!(predicted_floor(&f, 0, 2, 7, 0.01, None) > at8);
        assert_eq!(recommend_spp(&f, 0, 2, 1e-9, 0.01, None, 64), None);
    }

    #[test]
    fn the_detect_search_renders_more_until_the_floor_is_reached_and_no_more() {
        // The floor of the first test (K = 2 batches): far above 1 %, so render more.
        let mut b = BatchBlocks::new(4, 4, 4);
        b.push_batch(&[DVec3::splat(1.0); 16], 1);
        b.push_batch(&[DVec3::splat(3.0); 16], 1);
        let f = DetectionFloor::of_blocks(&b, 0.01);
        let mut search = DetectSearch::new(0.5, 0.01, 1 << 16);
        assert!(!search.reached(&f, 4, 4));
        let DetectStep::Render(spp) = search.next(&f, 2, 4, 4) else {
            panic!("should render more")
        };
        assert!(predicted_floor(&f, 0, 2, spp, 0.01, None) <= 0.45);
        assert!(predicted_floor(&f, 0, 2, spp - 1, 0.01, None) > 0.45);
        assert!(search.keep_new(spp, 2, false) && search.stop_after(spp, 2, false, true));
        // Fewer samples that fail are not kept and end the search.
        assert!(!search.keep_new(3, 8, false) && search.stop_after(3, 8, true, false));
        // A target out of reach renders at the limit once, then stops.
        let mut far = DetectSearch::new(1e-9, 0.01, 64);
        assert_eq!(far.next(&f, 2, 4, 4), DetectStep::Render(64));
        assert_eq!(far.next(&f, 64, 4, 4), DetectStep::Done);
    }

    #[test]
    fn photon_replications_predict_a_floor_that_stops_falling_and_the_search_stops_there() {
        // The floor of the first test, as if from a `photon` golden of 32 spp (16 replications
        // of 2) whose camera samples make q = 0.2 of its noise (the maps 0.8). At 128 spp the
        // variance is 0.8 + 0.2·32/128 = 0.85 of the golden's (16 replications either way) and
        // the batch count stays 16: the floor falls by √0.85 only, where passes would halve it.
        let mut b = BatchBlocks::new(4, 4, 4);
        b.push_batch(&[DVec3::splat(1.0); 16], 1);
        b.push_batch(&[DVec3::splat(3.0); 16], 1);
        let passes = DetectionFloor::of_blocks(&b, 0.01);
        let share = |q: f64| {
            NoiseScaling::Replications(Some(SampleShare {
                blocks: q,
                cells: q,
            }))
        };
        let f = passes.clone().with_noise(share(0.2));
        let c = |k: f64| {
            student_upper_quantile(0.01 / 3.0 / 2.0, 2.0 * (k - 1.0))
                + student_upper_quantile(0.05, 2.0 * (k - 1.0))
        };
        let want = f.scales[0].median * c(16.0) / c(2.0) * 0.85f64.sqrt();
        assert!((predicted_floor(&f, 0, 32, 128, 0.01, None) - want).abs() < 1e-12);
        let halved = passes.scales[0].median * c(64.0) / c(2.0) * 0.5;
        assert!((predicted_floor(&passes, 0, 32, 128, 0.01, None) - halved).abs() < 1e-12);
        // A reachable target: the fewest spp whose predicted floor reaches it, with the maps'
        // part fixed: 0.8 + 0.2·32/s ≤ 1.05²·0.8 ⇔ s ≥ 6.4/0.082 = 78.05: 79 spp.
        let floor_16 = f.scales[0].median * c(16.0) / c(2.0);
        let reachable = 1.05 * floor_16 * 0.8f64.sqrt();
        let spp = recommend_spp(&f, 0, 32, reachable, 0.01, None, 1 << 20).unwrap();
        assert_eq!(spp, 79);
        assert!(predicted_floor(&f, 0, 32, spp - 1, 0.01, None) > reachable);
        // Below the maps' part (√0.8 of the floor at 16 replications) no spp reaches: the
        // passes' search would render at the limit (4096); this one renders at the knee, where
        // the samples' part is a tenth of the maps' (0.2·32/s ≤ 0.08: 80 spp) ...
        let target = 0.85 * floor_16 * 0.8f64.sqrt() / DETECT_AIM;
        let mut search = DetectSearch::new(target, 0.01, 4096);
        assert_eq!(search.next(&f, 32, 4, 4), DetectStep::Render(80));
        let mut passes_search = DetectSearch::new(target, 0.01, 4096);
        assert!(matches!(passes_search.next(&passes, 32, 4, 4), DetectStep::Render(n) if n < 4096));
        // ... and measures there a floor √0.88 of the first (the same model: σ_M²/16 = 0.8,
        // σ_P²/80 = 0.08 in units of the 32-spp variance; same batch count in this synthetic
        // golden). The fit through the two floors finds q = 0.08/0.88 at 80 spp, whose knee is
        // 80: it stops, out of reach, instead of rendering more.
        let mut at80 =
            DetectionFloor::of_blocks(&b, 0.01).with_noise(NoiseScaling::Replications(None));
        at80.scales[0].median *= 0.88f64.sqrt();
        assert_eq!(search.next(&at80, 80, 4, 4), DetectStep::Done);
        // Without the fit (an unmeasured split, taken as all samples) the same floor would ask
        // for more samples.
        let mut blind = DetectSearch::new(target, 0.01, 4096);
        assert!(matches!(blind.next(&at80, 80, 4, 4), DetectStep::Render(n) if n > 80));
    }

    #[test]
    fn progressive_variance_grows_as_the_radius_shrinks() {
        assert_eq!(variance_growth(None, 100), 1.0);
        // One pass: radius R, no growth; α → 1 keeps the radius.
        assert_eq!(variance_growth(Some(0.7), 1), 1.0);
        assert!((variance_growth(Some(1.0), 50) - 1.0).abs() < 1e-12);
        // Two passes at α: r₂²/r₁² = (1 + α)/2, so the mean of 1/s² is (1 + 2/(1 + α))/2.
        let a = 0.7;
        let want = 0.5 * (1.0 + 2.0 / (1.0 + a));
        assert!((variance_growth(Some(a), 2) - want).abs() < 1e-6);
    }
}
