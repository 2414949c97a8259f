//! Rendering a scene for the golden test: the render job takes its passes batch by batch
//! ([`super::batch_means::batch_ranges`]) and each batch's block means are recorded between
//! them. The finished film is the one a plain render gives, byte for byte (a job's image never
//! depends on how its samples were split into passes).
//!
//! The one exception is the `photon` integrator, whose maps are traced once per render: every
//! pass reads the same maps, so passes are not independent estimates and their spread would
//! miss the maps' noise. Its batches are therefore **replications**: batch j is a render of
//! its own samples with its own seed (so its own maps), and the film is their sum — a render
//! of the same settings, but not the bytes of a one-seed render. Each replication traces the
//! full maps, so there are at most [`MAX_REPLICATIONS`] of them, the samples per pixel spread
//! over them (golden and check alike: both render here; [`super::noise_scaling`]).

use super::batch_means::{BatchBlocks, BatchRecorder, batch_ranges, split_ranges};
use super::noise_scaling::{MAX_REPLICATIONS, NoiseScaling};
use super::structure::{CELL, MAX_CELL_BATCHES, merge_batches};
use crate::render::{PixelSums, RenderError, RenderJob, RenderOptions, RenderOutput};
use crate::render_scene::RenderScene;
use crate::settings::IntegratorKind;

/// A render with its batches.
#[derive(Debug)]
pub struct GoldenRender {
    /// The finished render (the same bytes as [`crate::render::render`]).
    pub output: RenderOutput,
    /// Each batch's block means.
    pub batches: BatchBlocks,
    /// Each batch's means over cells of [`CELL`] pixels, consecutive batches merged to at most
    /// [`MAX_CELL_BATCHES`] (for the structure test, [`super::structure`]).
    pub cells: BatchBlocks,
    /// The photon-map radius shrink parameter α of a progressive integrator (its per-pass
    /// noise grows as the radius shrinks, which the samples-per-pixel advice accounts for);
    /// `None` for the others.
    pub progressive_alpha: Option<f64>,
    /// How the noise falls with the samples per pixel (for the `--detect` advice): passes, or
    /// `photon` replications (the split of their noise between maps and camera samples is
    /// measured by the `--detect` search from two renders).
    pub noise: NoiseScaling,
}

/// The seed of replication `j` of a render seeded `seed` (`photon` integrator): distinct for
/// every (seed, j), and never a neighbouring seed's (a check renders with the golden's + 1).
#[must_use]
pub fn replication_seed(seed: u64, j: u32) -> u64 {
    seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .rotate_left(17)
        .wrapping_add(u64::from(j) + 1)
}

/// Renders the whole image of `scene` (`options.region` and `options.samples` are ignored)
/// in batches of passes, recording each batch's means over blocks of `block` pixels. The
/// scene's seed and sample count are changed while a `photon` render's replications run and
/// restored before returning.
///
/// # Errors
/// As [`RenderJob::new`] and [`RenderJob::render_pass`].
pub fn render_batches(
    scene: &mut RenderScene,
    options: &RenderOptions,
    block: u32,
) -> Result<GoldenRender, RenderError> {
    let options = RenderOptions {
        region: None,
        samples: None,
        ..options.clone()
    };
    match scene.params.integrator {
        IntegratorKind::Photon => replications(scene, &options, block),
        IntegratorKind::Whitted
        | IntegratorKind::Path
        | IntegratorKind::Ppm
        | IntegratorKind::PathPpm => passes(scene, &options, block),
    }
}

fn passes(
    scene: &RenderScene,
    options: &RenderOptions,
    block: u32,
) -> Result<GoldenRender, RenderError> {
    let mut job = RenderJob::new(scene, options)?;
    let progressive_alpha = job
        .integrator()
        .is_progressive()
        .then_some(f64::from(scene.params.photons.alpha));
    let (w, h) = (scene.params.width, scene.params.height);
    let mut recorder = BatchRecorder::new(w, h, block);
    let mut cells = BatchRecorder::new(w, h, CELL);
    for range in batch_ranges(scene.params.samples_per_pixel) {
        job.render_pass(range.end - range.start)?;
        recorder.record(job.sums(), job.samples_done());
        cells.record(job.sums(), job.samples_done());
    }
    Ok(GoldenRender {
        output: job.into_output(),
        batches: recorder.finish(),
        cells: merge_batches(&cells.finish(), MAX_CELL_BATCHES),
        progressive_alpha,
        noise: NoiseScaling::Passes,
    })
}

fn replications(
    scene: &mut RenderScene,
    options: &RenderOptions,
    block: u32,
) -> Result<GoldenRender, RenderError> {
    let (seed, spp) = (scene.params.seed, scene.params.samples_per_pixel);
    let (w, h) = (scene.params.width, scene.params.height);
    let mut batches = BatchBlocks::new(w, h, block);
    let mut cells = BatchBlocks::new(w, h, CELL);
    let mut total: Option<RenderOutput> = None;
    let mut result = Ok(());
    for (j, range) in split_ranges(spp, MAX_REPLICATIONS).into_iter().enumerate() {
        scene.params.seed = replication_seed(seed, j as u32);
        scene.params.samples_per_pixel = range.end - range.start;
        let out = match RenderJob::new(scene, options).and_then(RenderJob::finish) {
            Ok(o) => o,
            Err(e) => {
                result = Err(e);
                break;
            }
        };
        let sums: Vec<glam::DVec3> = (0..(w * h) as usize).map(|i| out.sums.sum(i)).collect();
        batches.push_batch(&sums, range.end - range.start);
        cells.push_batch(&sums, range.end - range.start);
        total = Some(match total {
            None => out,
            Some(mut t) => {
                merge_into(&mut t.sums, &out.sums);
                t.stats.rays += out.stats.rays;
                t.stats.samples += out.stats.samples;
                t.stats.nan_samples += out.stats.nan_samples;
                t.stats.elapsed += out.stats.elapsed;
                t
            }
        });
    }
    scene.params.seed = seed;
    scene.params.samples_per_pixel = spp;
    result?;
    let mut output = total.ok_or(RenderError::SampleRange(0, 0, spp))?;
    output.film = output.sums.to_film();
    Ok(GoldenRender {
        output,
        batches,
        cells: merge_batches(&cells, MAX_CELL_BATCHES),
        progressive_alpha: None,
        noise: NoiseScaling::Replications(None),
    })
}

/// Adds `from` into `into` (the replications are all of the whole image: same size).
fn merge_into(into: &mut PixelSums, from: &PixelSums) {
    let merged = into.merge(from);
    debug_assert!(merged.is_ok(), "replications share the image size");
}
