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
use super::trace_log::TraceLog;
use super::whitted::{Counters, Whitted};
use crate::geometry::Ray;
use crate::render_scene::RenderScene;
use crate::sampling::Rng;

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
    /// Worker threads used.
    pub threads: usize,
    /// Wall-clock time of the render (excluding scene loading).
    pub elapsed: Duration,
}

/// A rendered film with its statistics.
#[derive(Debug, Clone)]
pub struct RenderOutput {
    /// The (possibly cropped) image.
    pub film: Film,
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

/// A render done in passes over sample indices: pass after pass adds samples `[done, done + n)`
/// to every pixel, in ascending sample order, so the finished film is bit-identical to the
/// one-pass [`render`] whatever the pass sizes. Between passes the image so far can be read
/// (for checkpoints), and a cancelled pass leaves the job as it was after the previous one.
pub struct RenderJob<'a> {
    scene: &'a RenderScene,
    region: Region,
    tiles: Vec<Region>,
    pool: rayon::ThreadPool,
    cancel: Option<Arc<AtomicBool>>,
    progress: ProgressBar,
    /// Per-pixel radiance sums over the samples done, row-major over the region.
    sums: Vec<Vec3>,
    done: u32,
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
        if region.width == 0 || region.height == 0 {
            return Err(RenderError::EmptyRegion);
        }
        if u64::from(region.x) + u64::from(region.width) > u64::from(w)
            || u64::from(region.y) + u64::from(region.height) > u64::from(h)
        {
            return Err(RenderError::RegionOutside(region, w, h));
        }
        let threads = options
            .threads
            .unwrap_or_else(rayon::current_num_threads)
            .max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| RenderError::Threads(threads, e.to_string()))?;
        let tiles = tile_grid(region);
        let spp = u64::from(scene.params.samples_per_pixel);
        let progress = progress_bar(options.progress, tiles.len() as u64 * spp);
        Ok(Self {
            scene,
            region,
            tiles,
            pool,
            cancel: options.cancel.clone(),
            progress,
            sums: vec![Vec3::ZERO; region.width as usize * region.height as usize],
            done: 0,
            stats: RenderStats {
                threads,
                ..Default::default()
            },
            start: Instant::now(),
        })
    }

    /// Samples per pixel of the finished render.
    #[must_use]
    pub fn samples_per_pixel(&self) -> u32 {
        self.scene.params.samples_per_pixel
    }

    /// Samples per pixel taken so far (by complete passes).
    #[must_use]
    pub fn samples_done(&self) -> u32 {
        self.done
    }

    /// Takes the next `n` samples of every pixel (fewer if fewer remain; none is a no-op).
    ///
    /// # Errors
    /// [`RenderError::Cancelled`] when the cancel flag is raised before the pass ends; the job
    /// then still holds the image of its previous complete pass.
    pub fn render_pass(&mut self, n: u32) -> Result<(), RenderError> {
        let end = self.done + n.min(self.samples_per_pixel() - self.done);
        if self.is_cancelled() {
            return Err(RenderError::Cancelled);
        }
        if end == self.done {
            return Ok(());
        }
        let (scene, region, sums, samples) = (self.scene, self.region, &self.sums, self.done..end);
        let (progress, cancel) = (&self.progress, self.cancel.as_deref());
        let results: Option<Vec<TileResult>> = self.pool.install(|| {
            self.tiles
                .par_iter()
                .map(|t| render_tile(scene, t, region, sums, samples.clone(), cancel, progress))
                .collect()
        });
        let Some(results) = results else {
            return Err(RenderError::Cancelled);
        };
        for (tile, r) in self.tiles.iter().zip(results) {
            for (i, s) in r.sums.into_iter().enumerate() {
                self.sums[pixel_index(region, tile, i)] = s;
            }
            self.stats.rays += r.counters.rays;
            self.stats.nan_samples += r.nan;
        }
        self.done = end;
        Ok(())
    }

    /// The image so far: each pixel's sum over the samples done, divided by their number (black
    /// before the first pass).
    #[must_use]
    pub fn snapshot(&self) -> Film {
        self.film_over(self.done.max(1))
    }

    /// Takes the remaining samples in one pass and returns the finished film.
    ///
    /// # Errors
    /// As [`RenderJob::render_pass`].
    pub fn finish(mut self) -> Result<RenderOutput, RenderError> {
        self.render_pass(self.samples_per_pixel() - self.done)?;
        self.progress.finish_and_clear();
        let spp = self.samples_per_pixel();
        let film = self.film_over(spp);
        let mut stats = self.stats;
        stats.samples =
            u64::from(self.region.width) * u64::from(self.region.height) * u64::from(spp);
        stats.elapsed = self.start.elapsed();
        Ok(RenderOutput { film, stats })
    }

    fn film_over(&self, samples: u32) -> Film {
        let mut film = Film::new(self.region.width, self.region.height);
        for (p, s) in film.pixels.iter_mut().zip(&self.sums) {
            *p = *s / samples as f32;
        }
        film
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

/// One tile's share of a pass: its pixels' new radiance sums (row-major in the tile) and counts.
struct TileResult {
    sums: Vec<Vec3>,
    counters: Counters,
    nan: u64,
}

/// Adds samples `samples` of each pixel of `tile` to its sum so far (taken from `sums`), in
/// ascending sample order. `None` when `cancel` is raised: it is checked before each pixel, never
/// per ray.
fn render_tile(
    scene: &RenderScene,
    tile: &Region,
    region: Region,
    sums: &[Vec3],
    samples: Range<u32>,
    cancel: Option<&AtomicBool>,
    progress: &ProgressBar,
) -> Option<TileResult> {
    let integrator = Whitted::new(scene);
    let mut counters = Counters::default();
    let mut nan = 0u64;
    let mut out = Vec::with_capacity((tile.width * tile.height) as usize);
    for i in 0..(tile.width * tile.height) as usize {
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return None;
        }
        let (x, y) = (
            tile.x + i as u32 % tile.width,
            tile.y + i as u32 / tile.width,
        );
        let mut sum = sums[pixel_index(region, tile, i)];
        for s in samples.clone() {
            let (ray, mut rng) = camera_sample(scene, x, y, s);
            let l = integrator.li(ray, &mut rng, &mut counters, None);
            if l.is_finite() {
                sum += l;
            } else {
                nan += 1;
            }
        }
        out.push(sum);
    }
    progress.inc(u64::from(samples.end - samples.start));
    Some(TileResult {
        sums: out,
        counters,
        nan,
    })
}

/// The camera ray and random stream of sample `s` of pixel `(x, y)`: stratified jitter on a
/// ⌈√spp⌉-column grid over the pixel.
fn camera_sample(scene: &RenderScene, x: u32, y: u32, s: u32) -> (Ray, Rng) {
    let p = &scene.params;
    let mut rng = Rng::for_pixel_sample(p.seed, x, y, s);
    let cols = (f64::from(p.samples_per_pixel).sqrt().ceil() as u32).max(1);
    let rows = p.samples_per_pixel.div_ceil(cols);
    let (jx, jy) = rng.next_2d();
    let fx = x as f32 + ((s % cols) as f32 + jx) / cols as f32;
    let fy = y as f32 + ((s / cols) as f32 + jy) / rows as f32;
    (scene.camera.ray(fx, fy, p.width, p.height), rng)
}

/// Traces sample `sample` of pixel `(x, y)` exactly as the renderer does, recording its ray tree.
pub fn trace_pixel(
    scene: &RenderScene,
    x: u32,
    y: u32,
    sample: u32,
) -> Result<(TraceLog, Vec3), RenderError> {
    let p = &scene.params;
    if x >= p.width || y >= p.height {
        return Err(RenderError::PixelOutside(x, y, p.width, p.height));
    }
    let (ray, mut rng) = camera_sample(scene, x, y, sample);
    let mut log = TraceLog::default();
    let l = Whitted::new(scene).li(ray, &mut rng, &mut Counters::default(), Some(&mut log));
    Ok((log, l))
}
