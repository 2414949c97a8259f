//! How the noise of a golden's block means falls as its samples per pixel grow, for the
//! `--detect` advice ([`super::floor`]), and the cap on the `photon` integrator's
//! replications.
//!
//! **Passes** (every integrator but `photon`): the batches are groups of passes of one render,
//! independent estimates whose cost is their samples; the variance of the mean falls as 1/spp
//! and there are `min(spp, MAX_BATCHES)` batches.
//!
//! **Replications** (`photon`, [`super::record`]): its maps are traced once per render, so each
//! batch is a render of its own with its own maps, and each costs a full photon tracing (and
//! the irradiance precomputation) besides its camera samples. At most [`MAX_REPLICATIONS`] are
//! rendered, the samples per pixel spread over them. A replication's block mean then has
//! variance σ_M² + σ_P²/n: σ_M² from its maps (fixed whatever its samples), σ_P²/n from its n
//! camera samples per pixel given the maps (the one-way random-effects model: Searle, Casella &
//! McCulloch, *Variance Components*, 1992, §3.2). The mean of R(s) = min(s, 16) replications of
//! s samples in all has variance v(s) = σ_M²/R(s) + σ_P²/s, so
//!
//! ```text
//! v(s′) / v(s) = (1 − q)·R(s)/R(s′) + q·s/s′,   q = (σ_P²/s) / v(s)
//! ```
//!
//! q, the share of the golden's noise that comes from its camera samples, is measured from two
//! goldens at different samples per pixel ([`fit_share`]: the model through the two measured
//! variances), which the `--detect` search renders anyway; from one golden it is unknown and
//! taken as 1 (the passes' scaling: what the next render measures). Beyond 16 samples per pixel
//! only the camera samples' part falls: a floor below the maps' part is out of reach by samples
//! per pixel, and the search stops where more samples buy little ([`NoiseScaling::knee`])
//! instead of rendering at `--detect-limit`. The spread of a replication's own passes would
//! not do as the estimate of σ_P²: Owen-scrambled Sobol points (the default sampler) make a
//! render's sample indices negatively correlated, so that spread is many times the variance
//! of the replication's mean (on `scenes/water.ron` at 32×32 it put all the noise of the 8×8
//! blocks in the camera samples while 89 to 395 spp left their floor at 3.9 %). With Sobol
//! points σ_P²/s falls faster than 1/s, so the fit's prediction beyond its two renders errs
//! towards too many samples, never too few.

use super::batch_means::MAX_BATCHES;

/// Most replications of a `photon` golden: each traces the scene's photon maps, which is most
/// of a `photon` render's cost at a golden's small sizes, so they are capped and the samples
/// per pixel spread over them. 16 is above the structure test's minimum of
/// [`super::structure::MIN_BATCHES`] (its 2¹⁵ distinct sign flips are far more than its
/// α/2 = 0.005 needs) and gives Welch's t up to 30 degrees of freedom (the block limits are
/// about 10 % wider than with 64 batches; docs/golden.md has the numbers).
pub const MAX_REPLICATIONS: u32 = 16;

/// How a golden's noise scales with its samples per pixel.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum NoiseScaling {
    /// Batches of passes of one render: variance ∝ 1/spp, `min(spp, MAX_BATCHES)` batches.
    #[default]
    Passes,
    /// `photon` replications with their own maps (at most [`MAX_REPLICATIONS`]), with the
    /// camera samples' share of the noise where measured ([`fit_share`]; `None`: taken as 1).
    Replications(Option<SampleShare>),
}

/// q, the share of a `photon` golden's variance that its camera samples make (0 to 1; the
/// rest is its replications' maps').
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleShare {
    /// At the block scale the `--detect` advice aims at.
    pub blocks: f64,
    /// Over the structure test's cells.
    pub cells: f64,
}

impl NoiseScaling {
    /// Batches of a golden at `spp` samples per pixel.
    #[must_use]
    pub fn batches(&self, spp: u32) -> u32 {
        match self {
            Self::Passes => spp.min(MAX_BATCHES),
            Self::Replications(_) => spp.min(MAX_REPLICATIONS),
        }
    }

    /// The share q for the blocks (`cells` false) or the cells; 1 for passes or unmeasured.
    #[must_use]
    pub fn sample_share(&self, cells: bool) -> f64 {
        match self {
            Self::Passes | Self::Replications(None) => 1.0,
            Self::Replications(Some(q)) => {
                if cells {
                    q.cells
                } else {
                    q.blocks
                }
            }
        }
    }

    /// v(spp)/v(golden_spp), the variance of a block mean (`cells`: a cell's) at `spp`
    /// samples per pixel relative to the golden's at `golden_spp` (module doc).
    #[must_use]
    pub fn variance_ratio(&self, cells: bool, golden_spp: u32, spp: u32) -> f64 {
        let (s0, s1) = (f64::from(golden_spp.max(1)), f64::from(spp.max(1)));
        let q = self.sample_share(cells);
        let r0 = f64::from(self.batches(golden_spp).max(1));
        let r1 = f64::from(self.batches(spp).max(1));
        match self {
            Self::Passes => s0 / s1,
            Self::Replications(_) => (1.0 - q) * r0 / r1 + q * s0 / s1,
        }
    }

    /// The samples per pixel beyond which more buy less than a tenth of the maps' part of the
    /// variance (the camera samples' part q·s/s′ ≤ 0.1 × the maps' part at
    /// [`MAX_REPLICATIONS`]), from a golden at `golden_spp`: where `--detect` stops when its
    /// target is out of reach. `None` for passes or when the maps make no noise (more samples
    /// always help).
    #[must_use]
    pub fn knee(&self, cells: bool, golden_spp: u32) -> Option<u32> {
        let Self::Replications(_) = self else {
            return None;
        };
        let q = self.sample_share(cells);
        let r0 = f64::from(self.batches(golden_spp).max(1));
        let map = (1.0 - q) * r0 / f64::from(MAX_REPLICATIONS);
        if map <= 0.0 {
            return None;
        }
        // q·s0/s ≤ 0.1·map  ⇔  s ≥ 10·q·s0/map (less a rounding hair, so that an exact
        // integer stays one).
        let s = (10.0 * q * f64::from(golden_spp.max(1)) / map * (1.0 - 1e-12)).ceil();
        Some(if s >= f64::from(u32::MAX) {
            u32::MAX
        } else {
            (s as u32).max(MAX_REPLICATIONS)
        })
    }
}

/// The camera samples' share q at `at` samples per pixel of a `photon` golden's variance, from
/// the variances `a.1` and `b.1` (in one unit) measured at `a.0` and `b.0` samples per pixel:
/// the model v(s) = M/R(s) + P/s (module doc) through the two points, M and P kept ≥ 0. `None`
/// when the two points carry no information on the split (R(s)/s the same at both: both at
/// most [`MAX_REPLICATIONS`], where every replication has one sample per pixel) or a variance
/// is not positive and finite.
#[must_use]
pub fn fit_share(a: (u32, f64), b: (u32, f64), at: u32) -> Option<f64> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if !ok(a.1) || !ok(b.1) {
        return None;
    }
    let r = |s: u32| f64::from(s.clamp(1, MAX_REPLICATIONS));
    let (xa, za) = (1.0 / r(a.0), 1.0 / f64::from(a.0.max(1)));
    let (xb, zb) = (1.0 / r(b.0), 1.0 / f64::from(b.0.max(1)));
    let det = xa * zb - xb * za;
    if det.abs() <= 1e-9 * (xa * zb).abs().max((xb * za).abs()) {
        return None;
    }
    let m = (a.1 * zb - b.1 * za) / det;
    let p = (xa * b.1 - xb * a.1) / det;
    let (m, p) = (m.max(0.0), p.max(0.0));
    let (x, z) = (1.0 / r(at), 1.0 / f64::from(at.max(1)));
    let v = m * x + p * z;
    if v > 0.0 { Some(p * z / v) } else { None }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn replications(blocks: f64) -> NoiseScaling {
        NoiseScaling::Replications(Some(SampleShare {
            blocks,
            cells: blocks,
        }))
    }

    #[test]
    fn the_variance_ratio_is_the_hand_computed_one() {
        // Passes: 1/spp.
        assert!((NoiseScaling::Passes.variance_ratio(false, 16, 64) - 0.25).abs() < 1e-15);
        assert_eq!(NoiseScaling::Passes.batches(100), 64);
        // Replications, q = 0.25 at 32 spp (16 replications of 2): at 128 spp the maps' part
        // stays 0.75 (16 replications either way), the samples' part falls to 0.25·32/128:
        // 0.8125. At 8 spp (8 replications): 0.75·16/8 + 0.25·32/8 = 2.5.
        let r = replications(0.25);
        assert_eq!(r.batches(100), 16);
        assert_eq!(r.batches(9), 9);
        assert!((r.variance_ratio(false, 32, 128) - 0.8125).abs() < 1e-12);
        assert!((r.variance_ratio(false, 32, 8) - 2.5).abs() < 1e-12);
        assert!((r.variance_ratio(false, 32, 32) - 1.0).abs() < 1e-12);
        // The knee: 0.25·32/s ≤ 0.075 ⇔ s ≥ 106.7.
        assert_eq!(r.knee(false, 32), Some(107));
        // Unmeasured: the passes' scaling, and no maps' part to stop at.
        let unknown = NoiseScaling::Replications(None);
        assert!((unknown.variance_ratio(false, 32, 64) - 0.5).abs() < 1e-12);
        assert_eq!(unknown.knee(false, 32), None);
        assert_eq!(NoiseScaling::Passes.knee(false, 32), None);
    }

    #[test]
    fn the_fit_recovers_the_split_of_an_exact_model_and_refuses_no_information() {
        // v(s) = M/R(s) + P/s with M = 0.16, P = 0.64: at 16 spp 0.01 + 0.04 = 0.05, at 64 spp
        // 0.01 + 0.01 = 0.02. q at 64 spp is 0.01/0.02 = 0.5; at 256 spp 0.0025/0.0125 = 0.2.
        let v = |s: u32| 0.16 / f64::from(s.min(16)) + 0.64 / f64::from(s);
        let q64 = fit_share((16, v(16)), (64, v(64)), 64).unwrap();
        assert!((q64 - 0.5).abs() < 1e-12, "{q64}");
        let q256 = fit_share((64, v(64)), (16, v(16)), 256).unwrap();
        assert!((q256 - 0.2).abs() < 1e-12, "{q256}");
        // The ratio it predicts from 64 to 256 spp is the model's: 0.0125/0.02.
        let r = replications(q64);
        assert!((r.variance_ratio(false, 64, 256) - 0.625).abs() < 1e-12);
        // Both at most 16 spp (one sample per replication): no information on the split.
        assert_eq!(fit_share((8, v(8)), (16, v(16)), 16), None);
        // A noisy pair whose variance did not fall: all maps (q = 0), not a negative share.
        assert_eq!(fit_share((32, 0.02), (128, 0.021), 128), Some(0.0));
        // More than 1/s fall (possible with Sobol points): all samples.
        assert_eq!(fit_share((32, 0.02), (128, 0.004), 128), Some(1.0));
        assert_eq!(fit_share((32, 0.0), (128, 0.004), 128), None);
    }
}
