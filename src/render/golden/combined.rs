//! The whole golden check: the block means at every scale ([`super::batch_means`]) and, when
//! both renders have enough batches, the structure test over small cells
//! ([`super::structure`]), with α split equally between the two (Bonferroni: the chance that an
//! unchanged scene is called changed by either is at most α). Without the structure test
//! (fewer than [`MIN_BATCHES`] batches, or a check at other samples per pixel than its golden)
//! the block means get all of α, as before it existed.

use super::batch_means::{BatchBlocks, BatchTest, BatchTestError, BatchVerdict};
use super::structure::{MIN_BATCHES, StructureSkip, StructureTest, StructureVerdict};

/// The false-alarm rate left to the block means of a golden whose cells are `cells`: α/2 when
/// the structure test can run (its cells have at least [`MIN_BATCHES`] batches), else α.
#[must_use]
pub fn block_alpha(alpha: f64, cells: &BatchBlocks) -> f64 {
    if cells.batches() >= MIN_BATCHES {
        0.5 * alpha
    } else {
        alpha
    }
}

/// The outcome of [`GoldenTest::compare`].
#[derive(Debug, Clone, PartialEq)]
pub struct GoldenVerdict {
    /// The block means at every scale.
    pub blocks: BatchVerdict,
    /// The structure test, or why it did not run.
    pub structure: Result<StructureVerdict, StructureSkip>,
}

impl GoldenVerdict {
    /// Whether either test found a change beyond the noise.
    #[must_use]
    pub fn changed(&self) -> bool {
        self.blocks.changed() || self.structure.as_ref().is_ok_and(StructureVerdict::changed)
    }
}

/// The golden check at false-alarm rate `alpha` per scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoldenTest {
    /// The largest chance that an unchanged scene is called changed.
    pub alpha: f64,
}

impl Default for GoldenTest {
    fn default() -> Self {
        Self { alpha: 0.01 }
    }
}

impl GoldenTest {
    /// Compares a render (its blocks and cells) with the golden's.
    ///
    /// # Errors
    /// As [`BatchTest::compare`].
    pub fn compare(
        &self,
        golden: (&BatchBlocks, &BatchBlocks),
        now: (&BatchBlocks, &BatchBlocks),
    ) -> Result<GoldenVerdict, BatchTestError> {
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(BatchTestError::Alpha(self.alpha));
        }
        let structure = StructureTest {
            alpha: 0.5 * self.alpha,
        }
        .compare(golden.1, now.1);
        let blocks_alpha = if structure.is_ok() {
            0.5 * self.alpha
        } else {
            self.alpha
        };
        let blocks = BatchTest {
            alpha: blocks_alpha,
        }
        .compare(golden.0, now.0)?;
        Ok(GoldenVerdict { blocks, structure })
    }
}
