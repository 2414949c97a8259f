//! Rendering a scene for the golden test: the render job takes its passes batch by batch
//! ([`super::batch_means::batch_ranges`]) and each batch's block means are recorded between
//! them. The finished film is the one a plain render gives, byte for byte (a job's image never
//! depends on how its samples were split into passes).

use super::batch_means::{BatchBlocks, BatchRecorder, batch_ranges};
use crate::render::{RenderError, RenderJob, RenderOptions, RenderOutput};
use crate::render_scene::RenderScene;

/// A render with its batches.
#[derive(Debug)]
pub struct GoldenRender {
    /// The finished render (the same bytes as [`crate::render::render`]).
    pub output: RenderOutput,
    /// Each batch's block means.
    pub batches: BatchBlocks,
    /// The photon-map radius shrink parameter α of a progressive integrator (its per-pass
    /// noise grows as the radius shrinks, which the samples-per-pixel advice accounts for);
    /// `None` for the others.
    pub progressive_alpha: Option<f64>,
}

/// Renders the whole image of `scene` (`options.region` and `options.samples` are ignored)
/// in batches of passes, recording each batch's means over blocks of `block` pixels.
///
/// # Errors
/// As [`RenderJob::new`] and [`RenderJob::render_pass`].
pub fn render_batches(
    scene: &RenderScene,
    options: &RenderOptions,
    block: u32,
) -> Result<GoldenRender, RenderError> {
    let options = RenderOptions {
        region: None,
        samples: None,
        ..options.clone()
    };
    let mut job = RenderJob::new(scene, &options)?;
    let progressive_alpha = job
        .integrator()
        .is_progressive()
        .then_some(f64::from(scene.params.photons.alpha));
    let (w, h) = (scene.params.width, scene.params.height);
    let mut recorder = BatchRecorder::new(w, h, block);
    for range in batch_ranges(scene.params.samples_per_pixel) {
        job.render_pass(range.end - range.start)?;
        recorder.record(job.sums(), job.samples_done());
    }
    Ok(GoldenRender {
        output: job.into_output(),
        batches: recorder.finish(),
        progressive_alpha,
    })
}
