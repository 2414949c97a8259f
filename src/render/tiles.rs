//! The tile scheduler: rayon over 16×16 tiles, each pixel's samples drawn from its own random
//! stream, so the image is identical for any thread count and tile order.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::Vec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use super::Film;
use super::pixel_sums::PixelSums;
use crate::geometry::Ray;
use crate::integrators::photon::PassTotals;
use crate::integrators::{Counters, Integrator, LightPath, TraceLog};
use crate::render_scene::RenderScene;
use crate::sampling::Sampler;

const TILE: u32 = 16;

/// A rectangle of the image, in pixels from the top-left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Region {
    /// Left edge.
    pub x: u32,
    /// Top edge.
    pub y: u32,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

/// How to run a render.
#[derive(Debug, Clone, Default)]
pub struct RenderOptions {
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// Render only this crop; its pixels equal the same pixels of the full image.
    pub region: Option<Region>,
    /// Show a progress bar on stderr (only when it is a terminal).
    pub progress: bool,
    /// Raised by another thread to stop the render early: workers look at it before each pixel
    /// and between passes, and the render then returns [`RenderError::Cancelled`].
    pub cancel: Option<Arc<AtomicBool>>,
    /// Take only these sample indices of every pixel (`None`: `0..samples_per_pixel`). Renders
    /// of disjoint ranges merge ([`crate::render::PixelSums::merge`]) into exactly the render
    /// of their union.
    pub samples: Option<Range<u32>>,
    /// Also keep the radiance of each kind of light path ([`LightPath`]) per pixel, for EXR
    /// layers (`--layers`).
    pub light_paths: bool,
    /// Folder of the photon-map cache (`--photon-cache`): the photon integrator reads its maps
    /// from there when they were saved for this scene, and saves them there otherwise.
    pub photon_cache: Option<std::path::PathBuf>,
}

/// What a render did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RenderStats {
    /// Rays traced.
    pub rays: u64,
    /// Camera samples taken.
    pub samples: u64,
    /// Samples whose radiance was NaN or infinite (dropped from the pixel, counted here).
    pub nan_samples: u64,
    /// Photon-map density estimates made (photon integrator).
    pub photon_estimates: u64,
    /// Estimates whose k-nearest search the largest radius cut short.
    pub photon_radius_cut: u64,
    /// Progressive integrators: the passes' photon maps.
    pub progressive: Option<ProgressiveStats>,
    /// Worker threads used.
    pub threads: usize,
    /// Wall-clock time of the render (excluding scene loading).
    pub elapsed: Duration,
}

/// What the passes of a progressive integrator traced.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ProgressiveStats {
    /// Photon maps built, photons emitted and stored over all passes, and the time it took.
    pub totals: PassTotals,
    /// The fraction of the k-nearest radius the last pass taken read (1 for the first pass;
    /// it shrinks by Knaus & Zwicker's schedule).
    pub last_shrink: f32,
}

/// A rendered film with its statistics.
#[derive(Debug, Clone)]
pub struct RenderOutput {
    /// The (possibly cropped) image: each pixel's mean.
    pub film: Film,
    /// The per-pixel sums, squares and counts the image was made from (mergeable).
    pub sums: PixelSums,
    /// With [`RenderOptions::light_paths`]: the same sums for each kind of light path, in
    /// [`LightPath::ALL`] order (they add up to `sums`' means).
    pub parts: Option<Vec<PixelSums>>,
    /// Counters and timing.
    pub stats: RenderStats,
}

/// Why a render could not start or finish.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The region lies (partly) outside the image.
    #[error("region {x},{y},{w},{h} does not fit in the {iw}×{ih} image", x = .0.x, y = .0.y, w = .0.width, h = .0.height, iw = .1, ih = .2)]
    RegionOutside(Region, u32, u32),
    /// The region is empty.
    #[error("region width and height must be at least 1")]
    EmptyRegion,
    /// The pixel is outside the image.
    #[error("pixel ({0}, {1}) is outside the {2}×{3} image")]
    PixelOutside(u32, u32, u32, u32),
    /// The worker pool could not be created.
    #[error("cannot start {0} render threads: {1}")]
    Threads(usize, String),
    /// The sample range is empty-ended or beyond the scene's samples per pixel.
    #[error("sample range {0}..{1} is not within the scene's {2} samples per pixel")]
    SampleRange(u32, u32, u32),
    /// The cancel flag of [`RenderOptions`] was raised; no image is returned.
    #[error("the render was cancelled")]
    Cancelled,
}

/// Renders `scene` (or a region of it) in one pass of all its samples per pixel.
///
/// # Errors
/// [`RenderError::Cancelled`] when `options.cancel` is raised before the last tile is done; the
/// other variants when the region or thread count is unusable.
pub fn render(scene: &RenderScene, options: &RenderOptions) -> Result<RenderOutput, RenderError> {
    RenderJob::new(scene, options)?.finish()
}

/// Checks that `region` is non-empty and inside a `w` × `h` image.
fn check_region(region: Region, w: u32, h: u32) -> Result<(), RenderError> {
    if region.width == 0 || region.height == 0 {
        return Err(RenderError::EmptyRegion);
    }
    if u64::from(region.x) + u64::from(region.width) > u64::from(w)
        || u64::from(region.y) + u64::from(region.height) > u64::from(h)
    {
        return Err(RenderError::RegionOutside(region, w, h));
    }
    Ok(())
}

/// A render done in passes over sample indices: pass after pass adds samples `[done, done + n)`
/// to every pixel, in ascending sample order, so the finished film is bit-identical to the
/// one-pass [`render`] whatever the pass sizes. Between passes the image so far can be read
/// (for checkpoints), and a cancelled pass leaves the job as it was after the previous one.
pub struct RenderJob<'a> {
    scene: &'a RenderScene,
    integrator: Integrator<'a>,
    region: Region,
    tiles: Vec<Region>,
    pool: rayon::ThreadPool,
    cancel: Option<Arc<AtomicBool>>,
    progress: ProgressBar,
    /// Per-pixel sample statistics over the samples done, row-major over the region.
    sums: PixelSums,
    /// The same per kind of light path, when kept.
    parts: Option<Vec<PixelSums>>,
    /// First sample index this job takes.
    first: u32,
    /// Samples `first..done` are in `sums`.
    done: u32,
    /// One past the last sample index this job takes.
    end: u32,
    stats: RenderStats,
    start: Instant,
}

impl std::fmt::Debug for RenderJob<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RenderJob")
            .field("region", &self.region)
            .field("samples_done", &self.done)
            .field("samples_per_pixel", &self.samples_per_pixel())
            .finish_non_exhaustive()
    }
}

impl<'a> RenderJob<'a> {
    /// Checks the options and sets up the worker pool; no samples are taken yet.
    ///
    /// # Errors
    /// When the region is empty or outside the image, or the worker pool cannot start.
    pub fn new(scene: &'a RenderScene, options: &RenderOptions) -> Result<Self, RenderError> {
        let (w, h) = (scene.params.width, scene.params.height);
        let region = options.region.unwrap_or(Region {
            x: 0,
            y: 0,
            width: w,
            height: h,
        });
        check_region(region, w, h)?;
        let threads = options
            .threads
            .unwrap_or_else(rayon::current_num_threads)
            .max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| RenderError::Threads(threads, e.to_string()))?;
        let tiles = tile_grid(region);
        let range = options
            .samples
            .clone()
            .unwrap_or(0..scene.params.samples_per_pixel);
        // Shared state (photon maps; a progressive integrator's first pass) is built on the
        // job's own workers.
        let integrator = pool.install(|| {
            let mut i = Integrator::prepare_cancellable(
                scene,
                options.photon_cache.as_deref(),
                options.cancel.clone(),
            );
            i.begin_pass(range.start);
            i
        });
        // A signal during photon tracing left the maps incomplete.
        if options
            .cancel
            .as_deref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
        {
            return Err(RenderError::Cancelled);
        }
        if range.end > scene.params.samples_per_pixel || range.start > range.end {
            return Err(RenderError::SampleRange(
                range.start,
                range.end,
                scene.params.samples_per_pixel,
            ));
        }
        let spp = u64::from(range.end - range.start);
        let progress = progress_bar(options.progress, tiles.len() as u64 * spp);
        Ok(Self {
            scene,
            integrator,
            region,
            tiles,
            pool,
            cancel: options.cancel.clone(),
            progress,
            sums: PixelSums::new(region.width, region.height),
            parts: options
                .light_paths
                .then(|| new_parts(region.width, region.height)),
            first: range.start,
            done: range.start,
            end: range.end,
            stats: RenderStats {
                threads,
                ..Default::default()
            },
            start: Instant::now(),
        })
    }

    /// The prepared integrator (e.g. to report how its photon maps were built).
    #[must_use]
    pub fn integrator(&self) -> &Integrator<'a> {
        &self.integrator
    }

    /// One past the last sample index of the finished render (its samples per pixel when it
    /// starts at 0).
    #[must_use]
    pub fn samples_per_pixel(&self) -> u32 {
        self.end
    }

    /// One past the last sample index taken so far (by complete passes).
    #[must_use]
    pub fn samples_done(&self) -> u32 {
        self.done
    }

    /// Takes the next `n` samples of every pixel (fewer if fewer remain; none is a no-op). A
    /// progressive integrator takes them one sample index (one pass) at a time, setting up
    /// each pass's shared state first.
    ///
    /// # Errors
    /// [`RenderError::Cancelled`] when the cancel flag is raised before the pass ends; the job
    /// then still holds the image of the samples it completed before (whole sample indices).
    pub fn render_pass(&mut self, n: u32) -> Result<(), RenderError> {
        let end = self.done + n.min(self.samples_per_pixel() - self.done);
        if self.is_cancelled() {
            return Err(RenderError::Cancelled);
        }
        if !self.integrator.is_progressive() {
            return self.sweep(end);
        }
        while self.done < end {
            let integrator = &mut self.integrator;
            let sample = self.done;
            self.pool.install(|| integrator.begin_pass(sample));
            self.sweep(sample + 1)?;
        }
        Ok(())
    }

    /// Takes samples `done..end` of every pixel in one sweep over the tiles.
    fn sweep(&mut self, end: u32) -> Result<(), RenderError> {
        if end == self.done {
            return Ok(());
        }
        let (integrator, region, samples) = (&self.integrator, self.region, self.done..end);
        let (progress, cancel) = (&self.progress, self.cancel.as_deref());
        let results: Option<Vec<TileResult>> = self.pool.install(|| {
            self.tiles
                .par_iter()
                .map(|t| {
                    let samples = samples.clone();
                    let parts = self.parts.is_some();
                    render_tile(self.scene, integrator, t, samples, parts, cancel, progress)
                })
                .collect()
        });
        let Some(results) = results else {
            return Err(RenderError::Cancelled);
        };
        for (tile, r) in self.tiles.iter().zip(results) {
            for i in 0..(tile.width * tile.height) as usize {
                let at = pixel_index(region, tile, i);
                self.sums.add_pixel(at, &r.sums, i);
                if let (Some(mine), Some(theirs)) = (self.parts.as_mut(), r.parts.as_ref()) {
                    for (m, t) in mine.iter_mut().zip(theirs) {
                        m.add_pixel(at, t, i);
                    }
                }
            }
            self.stats.rays += r.counters.rays;
            self.stats.photon_estimates += r.counters.photon_estimates;
            self.stats.photon_radius_cut += r.counters.photon_radius_cut;
            self.stats.nan_samples += r.nan;
        }
        self.done = end;
        Ok(())
    }

    /// The image so far: each pixel's mean over the samples done (black before the first
    /// pass).
    #[must_use]
    pub fn snapshot(&self) -> Film {
        self.sums.to_film()
    }

    /// The per-pixel statistics so far.
    #[must_use]
    pub fn sums(&self) -> &PixelSums {
        &self.sums
    }

    /// Renders every sample of another `region` of the same image with this job's prepared
    /// integrator (its photon maps are built once, by [`RenderJob::new`]) and returns that
    /// region's output; the job can then render further regions. For tools that render many
    /// crops of one image, such as the doc-image test's row strips.
    ///
    /// # Errors
    /// When the region is empty or outside the image, or as [`RenderJob::render_pass`].
    pub fn render_region(&mut self, region: Region) -> Result<RenderOutput, RenderError> {
        check_region(region, self.scene.params.width, self.scene.params.height)?;
        self.region = region;
        self.tiles = tile_grid(region);
        self.sums = PixelSums::new(region.width, region.height);
        if self.parts.is_some() {
            self.parts = Some(new_parts(region.width, region.height));
        }
        self.done = self.first;
        self.stats = RenderStats {
            threads: self.stats.threads,
            ..Default::default()
        };
        self.start = Instant::now();
        self.render_pass(self.end - self.done)?;
        Ok(self.take_output())
    }

    /// Takes the remaining samples in one pass and returns the finished film.
    ///
    /// # Errors
    /// As [`RenderJob::render_pass`].
    pub fn finish(mut self) -> Result<RenderOutput, RenderError> {
        self.render_pass(self.samples_per_pixel() - self.done)?;
        Ok(self.into_output())
    }

    /// The image and statistics of the samples done so far (for a render stopped early by a
    /// time budget: every pixel has the same number of samples). Ends the job; its sums move
    /// into the output (no copy of the film's statistics).
    #[must_use]
    pub fn into_output(mut self) -> RenderOutput {
        self.progress.finish_and_clear();
        self.take_output()
    }

    /// The output of the samples done so far, moving the sums out (the job keeps empty ones).
    fn take_output(&mut self) -> RenderOutput {
        let mut stats = self.stats;
        stats.samples = u64::from(self.region.width)
            * u64::from(self.region.height)
            * u64::from(self.done - self.first);
        stats.elapsed = self.start.elapsed();
        stats.progressive = self.integrator.progressive().map(|p| ProgressiveStats {
            totals: p.totals(),
            last_shrink: p.shrink(self.done.saturating_sub(1)),
        });
        let sums = std::mem::replace(&mut self.sums, PixelSums::new(0, 0));
        let parts = self
            .parts
            .as_mut()
            .map(|p| std::mem::replace(p, new_parts(0, 0)));
        RenderOutput {
            film: sums.to_film(),
            sums,
            parts,
            stats,
        }
    }

    fn is_cancelled(&self) -> bool {
        self.cancel
            .as_deref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }
}

impl Drop for RenderJob<'_> {
    fn drop(&mut self) {
        self.progress.finish_and_clear();
    }
}

/// Empty sums for each kind of light path.
fn new_parts(width: u32, height: u32) -> Vec<PixelSums> {
    LightPath::ALL
        .iter()
        .map(|_| PixelSums::new(width, height))
        .collect()
}

/// Index in the region-sized buffer of pixel `i` (row-major) of `tile`.
fn pixel_index(region: Region, tile: &Region, i: usize) -> usize {
    let (x, y) = (
        tile.x + i as u32 % tile.width,
        tile.y + i as u32 / tile.width,
    );
    ((y - region.y) * region.width + (x - region.x)) as usize
}

fn tile_grid(r: Region) -> Vec<Region> {
    let mut tiles = Vec::new();
    let mut y = r.y;
    while y < r.y + r.height {
        let th = TILE.min(r.y + r.height - y);
        let mut x = r.x;
        while x < r.x + r.width {
            let tw = TILE.min(r.x + r.width - x);
            tiles.push(Region {
                x,
                y,
                width: tw,
                height: th,
            });
            x += tw;
        }
        y += th;
    }
    tiles
}

fn progress_bar(enabled: bool, tiles: u64) -> ProgressBar {
    if !enabled {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(tiles), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} rendering [{bar:40}] {percent:>3}% {elapsed} eta {eta}",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// One tile's share of a pass: its pixels' statistics over the pass (row-major in the tile) and
/// counters.
struct TileResult {
    sums: PixelSums,
    parts: Option<Vec<PixelSums>>,
    counters: Counters,
    nan: u64,
}

/// Takes samples `samples` of each pixel of `tile`. `None` when `cancel` is raised: it is
/// checked before each pixel, never per ray.
fn render_tile(
    scene: &RenderScene,
    integrator: &Integrator,
    tile: &Region,
    samples: Range<u32>,
    keep_parts: bool,
    cancel: Option<&AtomicBool>,
    progress: &ProgressBar,
) -> Option<TileResult> {
    let mut sampler = Sampler::new(
        scene.params.sampler,
        scene.params.seed,
        scene.params.samples_per_pixel,
    );
    let mut counters = Counters::default();
    let mut nan = 0u64;
    let mut out = PixelSums::new(tile.width, tile.height);
    let mut parts = keep_parts.then(|| new_parts(tile.width, tile.height));
    for i in 0..(tile.width * tile.height) as usize {
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return None;
        }
        let (x, y) = (
            tile.x + i as u32 % tile.width,
            tile.y + i as u32 / tile.width,
        );
        for s in samples.clone() {
            let ray = camera_sample(scene, &mut sampler, x, y, s);
            let r = integrator.li_parts(ray, &mut sampler, &mut counters, None);
            let l = r.total();
            if l.is_finite() {
                out.add(i, l);
                if let Some(parts) = parts.as_mut() {
                    for (p, v) in parts.iter_mut().zip(r.parts) {
                        p.add(i, v);
                    }
                }
            } else {
                nan += 1;
            }
        }
    }
    progress.inc(u64::from(samples.end - samples.start));
    Some(TileResult {
        sums: out,
        parts,
        counters,
        nan,
    })
}

/// Starts `sampler` on sample `s` of pixel `(x, y)` and returns its camera ray through the
/// position in the pixel the sampler's first two dimensions give.
fn camera_sample(scene: &RenderScene, sampler: &mut Sampler, x: u32, y: u32, s: u32) -> Ray {
    let p = &scene.params;
    sampler.start_pixel_sample(x, y, s);
    let (jx, jy) = sampler.pixel_2d();
    scene
        .camera
        .ray(x as f32 + jx, y as f32 + jy, p.width, p.height)
}

/// Traces sample `sample` of pixel `(x, y)` exactly as the renderer does, recording its ray tree.
pub fn trace_pixel(
    scene: &RenderScene,
    x: u32,
    y: u32,
    sample: u32,
) -> Result<(TraceLog, Vec3), RenderError> {
    trace_pixel_with(scene, x, y, sample, None)
}

/// [`trace_pixel`] with photon maps from the cache folder `photon_cache` (`--photon-cache`).
pub fn trace_pixel_with(
    scene: &RenderScene,
    x: u32,
    y: u32,
    sample: u32,
    photon_cache: Option<&std::path::Path>,
) -> Result<(TraceLog, Vec3), RenderError> {
    let p = &scene.params;
    if x >= p.width || y >= p.height {
        return Err(RenderError::PixelOutside(x, y, p.width, p.height));
    }
    let mut sampler = Sampler::new(p.sampler, p.seed, p.samples_per_pixel);
    let ray = camera_sample(scene, &mut sampler, x, y, sample);
    let mut log = TraceLog::default();
    let mut integrator = Integrator::prepare_with(scene, photon_cache);
    integrator.begin_pass(sample);
    let l = integrator.li(ray, &mut sampler, &mut Counters::default(), Some(&mut log));
    Ok((log, l))
}
