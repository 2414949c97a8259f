//! The per-pixel-variance block test: are two images the same within noise? Used to compare
//! two estimators' renders of one scene (path against path-ppm, in the estimator-agreement
//! tests) and for the error image's per-pixel |z|; `caustic golden` itself uses the batch
//! means of [`super::batch_means`], because this test's noise model does not hold for the
//! progressive integrators (see below and docs/golden.md).
//!
//! Both images carry each pixel's mean and the variance of that mean (from the film's
//! per-pixel sums of squares). The image is cut into blocks of `block`×`block` pixels (smaller
//! at the right and bottom edges). For block *b* and channel *c*, with *n* pixels,
//!
//! ```text
//! d  = (1/n) Σ_p (test_p − golden_p)                 mean difference
//! se = sqrt( (1/n²) Σ_p (var_golden_p + var_test_p) )  its standard error
//! z  = d / se
//! ```
//!
//! For the same scene rendered with independent random numbers, each z is close to a standard
//! normal variable (a block mean averages n · spp samples) and blocks are independent. The
//! verdict is **changed** when any of three tests rejects, each at a third of the false-alarm
//! rate α:
//!
//! - *local* (Bonferroni): some |z| over all blocks × 3 channels exceeds z* with
//!   P(|Z| > z*) = (α/3)/(3 · blocks), which catches a change in a few blocks (a moved object);
//! - *spread* (χ²): for some channel, Σ_b z² exceeds the χ² quantile with `blocks` degrees of
//!   freedom at tail (α/3)/3, which catches a change over many blocks that no single block
//!   shows (a wall's colour). Per channel, because the channels of one block are correlated
//!   (the same samples), which would widen a χ² over all three;
//! - *global*: for some channel, the z of the whole image's mean exceeds the two-sided limit
//!   at (α/3)/3, the most sensitive test for a change of the same sign everywhere (a dimmer
//!   light).
//!
//! By the union bound the false-alarm rate is at most α whatever the correlation between
//! channels, as long as the z are normal: the Gaussian approximation of block means and the
//! estimated variances are the assumptions. Owen-scrambled Sobol samples have a smaller
//! variance of the mean than the independent-sample estimate s²/n the film gives, so with the
//! Sobol sampler the test is conservative (fewer false alarms, a little less power). Noise that
//! pixels share is not in the per-pixel variances: photon maps traced once per render (the
//! `Photon` integrator) make neighbouring pixels err together, so the test over-reports changes
//! there; so do the progressive integrators, whose pixels share each pass's maps (measured on
//! a user's pool scene, issue #42: block |z| up to 10 between two seeds of the same scene), and
//! pixels lit by rare paths, whose variance estimate from a few samples is itself noise.

use glam::Vec3;

use super::PixelEstimates;
use super::quantile::{chi2_upper_quantile, normal_upper_quantile};

/// The test's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockTest {
    /// Block side in pixels.
    pub block: u32,
    /// False-alarm rate: the largest probability that two renders of the same scene are called
    /// changed.
    pub alpha: f64,
}

impl Default for BlockTest {
    fn default() -> Self {
        Self {
            block: 8,
            alpha: 0.01,
        }
    }
}

/// Why two images could not be compared.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BlockTestError {
    /// The images differ in size.
    #[error("the golden image is {0}×{1} but the render is {2}×{3}")]
    Size(u32, u32, u32, u32),
    /// A parameter is out of range.
    #[error("{0}")]
    Parameter(String),
}

/// One block's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockZ {
    /// Left column of the block in pixels.
    pub x: u32,
    /// Top row of the block in pixels.
    pub y: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The golden's block mean per channel.
    pub golden: [f64; 3],
    /// The render's block mean per channel.
    pub test: [f64; 3],
    /// (test − golden) over its standard error, per channel (the error floored at 10⁻⁶ of the
    /// means, so a difference where neither image has noise is very large); NaN where either
    /// mean is not a number.
    pub z: [f64; 3],
}

impl BlockZ {
    /// The largest |z| of the three channels (∞ for NaN).
    #[must_use]
    pub fn max_abs_z(&self) -> f64 {
        self.z
            .iter()
            .map(|z| if z.is_nan() { f64::INFINITY } else { z.abs() })
            .fold(0.0, f64::max)
    }
}

/// The outcome of [`BlockTest::compare`].
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// The test that was run.
    pub test: BlockTest,
    /// Every block, row-major.
    pub blocks: Vec<BlockZ>,
    /// The local test's limit z*: a block moved when some channel's |z| exceeds it.
    pub z_limit: f64,
    /// Σ z² over the blocks per channel.
    pub chi2: [f64; 3],
    /// Blocks with noise or a difference per channel (the χ² degrees of freedom).
    pub dof: [u32; 3],
    /// The spread test's limit per channel.
    pub chi2_limit: [f64; 3],
    /// z of the whole image's mean difference per channel.
    pub image_z: [f64; 3],
    /// The global test's limit on |image z|.
    pub image_z_limit: f64,
}

impl Verdict {
    /// Whether the local or the global test rejects "same scene within noise".
    #[must_use]
    pub fn changed(&self) -> bool {
        self.max_abs_z() > self.z_limit || self.chi2_rejects() || self.global_rejects()
    }

    /// Whether some channel's whole-image z is beyond its limit.
    #[must_use]
    pub fn global_rejects(&self) -> bool {
        self.image_z
            .iter()
            .any(|z| !(z.abs() <= self.image_z_limit))
    }

    /// Whether some channel's Σ z² is above its χ² limit.
    #[must_use]
    pub fn chi2_rejects(&self) -> bool {
        (0..3).any(|c| !(self.chi2[c] <= self.chi2_limit[c]))
    }

    /// The largest |z| over blocks and channels.
    #[must_use]
    pub fn max_abs_z(&self) -> f64 {
        self.blocks
            .iter()
            .map(BlockZ::max_abs_z)
            .fold(0.0, f64::max)
    }

    /// The blocks whose |z| is above the local limit, largest first.
    #[must_use]
    pub fn moved(&self) -> Vec<&BlockZ> {
        let mut v: Vec<&BlockZ> = self
            .blocks
            .iter()
            .filter(|b| b.max_abs_z() > self.z_limit)
            .collect();
        v.sort_by(|a, b| b.max_abs_z().total_cmp(&a.max_abs_z()));
        v
    }

    /// The `n` blocks of largest |z|, largest first.
    #[must_use]
    pub fn largest(&self, n: usize) -> Vec<&BlockZ> {
        let mut v: Vec<&BlockZ> = self.blocks.iter().collect();
        v.sort_by(|a, b| b.max_abs_z().total_cmp(&a.max_abs_z()));
        v.truncate(n);
        v
    }
}

/// Relative floor of a block's standard error: absorbs the `f32` rounding of the means, so
/// that noiseless blocks (a constant background) compare equal rather than infinitely apart.
const SE_FLOOR: f64 = 1e-6;

impl BlockTest {
    /// Compares a render's estimates with the golden's (same size).
    ///
    /// # Errors
    /// [`BlockTestError::Size`] when the sizes differ, [`BlockTestError::Parameter`] for a
    /// block of 0 pixels or an α outside (0, 1).
    pub fn compare(
        &self,
        golden: &PixelEstimates,
        test: &PixelEstimates,
    ) -> Result<Verdict, BlockTestError> {
        if (golden.width, golden.height) != (test.width, test.height) {
            return Err(BlockTestError::Size(
                golden.width,
                golden.height,
                test.width,
                test.height,
            ));
        }
        if self.block == 0 {
            return Err(BlockTestError::Parameter(
                "the block size must be at least 1 pixel".into(),
            ));
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(BlockTestError::Parameter(format!(
                "the false-alarm rate must be between 0 and 1 (e.g. 0.01), found {}",
                self.alpha
            )));
        }
        let (w, h, s) = (golden.width, golden.height, self.block);
        let mut blocks = Vec::new();
        for y in (0..h).step_by(s as usize) {
            for x in (0..w).step_by(s as usize) {
                blocks.push(block_z(golden, test, x, y, s.min(w - x), s.min(h - y)));
            }
        }
        let mut chi2 = [0.0; 3];
        let mut dof = [0u32; 3];
        for b in &blocks {
            for c in 0..3 {
                if b.z[c] != 0.0 {
                    dof[c] += 1;
                    chi2[c] += if b.z[c].is_nan() {
                        f64::INFINITY
                    } else {
                        b.z[c] * b.z[c]
                    };
                }
            }
        }
        let share = self.alpha / 3.0;
        let tests = 3.0 * blocks.len().max(1) as f64;
        let z_limit = normal_upper_quantile(share / 2.0 / tests);
        let chi2_limit = dof.map(|k| {
            if k == 0 {
                0.0
            } else {
                chi2_upper_quantile(share / 3.0, k)
            }
        });
        let image_z = block_z(golden, test, 0, 0, w, h).z;
        let image_z_limit = normal_upper_quantile(share / 6.0);
        Ok(Verdict {
            test: *self,
            blocks,
            z_limit,
            chi2,
            dof,
            chi2_limit,
            image_z,
            image_z_limit,
        })
    }
}

fn block_z(g: &PixelEstimates, t: &PixelEstimates, x0: u32, y0: u32, w: u32, h: u32) -> BlockZ {
    let (mut mg, mut mt, mut var) = ([0.0f64; 3], [0.0f64; 3], [0.0f64; 3]);
    for y in y0..y0 + h {
        for x in x0..x0 + w {
            let i = y as usize * g.width as usize + x as usize;
            let (a, b) = (g.mean[i].as_dvec3(), t.mean[i].as_dvec3());
            let v = (g.variance[i] + t.variance[i]).as_dvec3();
            for c in 0..3 {
                mg[c] += a[c];
                mt[c] += b[c];
                var[c] += v[c];
            }
        }
    }
    let n = f64::from(w * h);
    let mut z = [0.0; 3];
    for c in 0..3 {
        mg[c] /= n;
        mt[c] /= n;
        let floor = SE_FLOOR * 0.5 * (mg[c].abs() + mt[c].abs());
        let se = (var[c] / (n * n) + floor * floor).sqrt();
        let d = mt[c] - mg[c];
        z[c] = if d == 0.0 { 0.0 } else { d / se };
    }
    BlockZ {
        x: x0,
        y: y0,
        width: w,
        height: h,
        golden: mg,
        test: mt,
        z,
    }
}

/// Each pixel's largest |golden − test| over its standard error across the channels (for the
/// error image; single pixels are far noisier than blocks, so expect values of 3 or 4 by
/// chance).
#[must_use]
pub fn pixel_z(golden: &PixelEstimates, test: &PixelEstimates) -> Vec<f32> {
    golden
        .mean
        .iter()
        .zip(&test.mean)
        .zip(golden.variance.iter().zip(&test.variance))
        .map(|((a, b), (va, vb))| {
            let d = (*a - *b).abs();
            let se = (*va + *vb).max(Vec3::splat(1e-30)).powf(0.5);
            let z = d / se;
            if z.is_nan() {
                f32::NAN
            } else {
                z.max_element()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// A `size`² image whose pixel p has `spp` samples of a skewed (exponential) variable of
    /// mean `mean(p)`, summarized as the film would.
    fn synthetic(size: u32, spp: u32, rng: &mut Rng, mean: impl Fn(u32) -> f32) -> PixelEstimates {
        let n = (size * size) as usize;
        let mut sums = crate::render::PixelSums::new(size, size);
        for i in 0..n {
            let m = mean(i as u32);
            for _ in 0..spp {
                let x = -(1.0 - rng.next_f32()).ln() * m;
                let y = -(1.0 - rng.next_f32()).ln() * m;
                sums.add(i, Vec3::new(x, 0.5 * x, y));
            }
        }
        PixelEstimates::from_sums(&sums)
    }

    fn base(i: u32) -> f32 {
        0.2 + 0.6 * ((i % 7) as f32 / 7.0)
    }

    #[test]
    fn the_false_alarm_rate_is_at_most_alpha_and_not_far_below() {
        // 400 pairs of independent renders of the same image: the count of "changed" is
        // binomial(400, rate ≤ 0.05), mean ≤ 20 and standard deviation ≤ 4.4.
        let test = BlockTest {
            block: 8,
            alpha: 0.05,
        };
        let mut rng = Rng::new(11, 3);
        let mut alarms = 0;
        for _ in 0..400 {
            let g = synthetic(32, 8, &mut rng, base);
            let t = synthetic(32, 8, &mut rng, base);
            if test.compare(&g, &t).unwrap().changed() {
                alarms += 1;
            }
        }
        eprintln!(
            "block test, synthetic exponential samples: {alarms} false alarms of 400 at α 0.05"
        );
        assert!((3..=33).contains(&alarms), "{alarms} false alarms of 400");
    }

    #[test]
    fn a_spread_change_and_a_local_change_are_caught() {
        let test = BlockTest::default();
        let mut rng = Rng::new(12, 3);
        let g = synthetic(32, 8, &mut rng, base);
        // 15 % brighter everywhere: a block mean of 512 exponential samples has a standard
        // error of m/√512, the difference √2 times that, so each block's z is about 2.4 and
        // Σ z² over 16 blocks about 16 · (1 + 5.8) = 108 against a limit of about 39; the
        // whole image's z is about 4 · 2.4 = 9.6 against a limit of about 3.3.
        let t = synthetic(32, 8, &mut rng, |i| base(i) * 1.15);
        let v = test.compare(&g, &t).unwrap();
        assert!(
            v.changed() && v.chi2_rejects(),
            "{:?} {:?}",
            v.chi2,
            v.chi2_limit
        );
        assert!(v.global_rejects(), "{:?} {}", v.image_z, v.image_z_limit);
        // One 4×4 patch four times as bright: only the block holding it moves (z about 7).
        let patch = |i: u32| {
            let (x, y) = (i % 32, i / 32);
            base(i)
                * if (9..13).contains(&x) && (18..22).contains(&y) {
                    4.0
                } else {
                    1.0
                }
        };
        let t = synthetic(32, 8, &mut rng, patch);
        let v = test.compare(&g, &t).unwrap();
        let moved = v.moved();
        assert!(v.changed() && !moved.is_empty());
        assert!(moved.iter().all(|b| (b.x, b.y) == (8, 16)), "{moved:?}");
        // The same image is not changed, and a noiseless difference is very far.
        assert!(!test.compare(&g, &g).unwrap().changed());
        let mut flat = g.clone();
        flat.variance.iter_mut().for_each(|v| *v = Vec3::ZERO);
        let mut other = flat.clone();
        other.mean[0].x += 0.5;
        let v = test.compare(&flat, &other).unwrap();
        assert!(v.blocks[0].z[0] > 1e3 && v.changed(), "{:?}", v.blocks[0].z);
        let small = synthetic(8, 2, &mut rng, base);
        assert_eq!(
            test.compare(&g, &small).unwrap_err(),
            BlockTestError::Size(32, 32, 8, 8)
        );
    }
}
