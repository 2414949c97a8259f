//! The render job: a [`RenderJob`] owns the worker pool, the prepared integrator and the film's
//! sums, and takes samples in passes over sample indices (the tile loop in
//! [`super::tiles`] does each sweep), so a render can be checkpointed, cancelled, budgeted or
//! split into farm shards without changing its bytes. [`render`] is the one-pass shortcut.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use super::Film;
use super::options::{
    ProgressiveStats, Region, RenderError, RenderOptions, RenderOutput, RenderStats, check_region,
};
use super::pixel_sums::PixelSums;
use super::tiles::{
    SampleRanges, Sweep, TileResult, new_parts, pixel_index, render_tile, tile_grid,
};
use crate::integrators::Integrator;
use crate::integrators::splat::FilmSplats;
use crate::render_scene::RenderScene;

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
    integrator: Integrator<'a>,
    region: Region,
    tiles: Vec<Region>,
    pool: rayon::ThreadPool,
    cancel: Option<Arc<AtomicBool>>,
    progress: ProgressBar,
    /// Per-pixel sample statistics over the samples done, row-major over the region.
    sums: PixelSums,
    /// Contributions to other pixels than the one sampled, for an estimator that splats.
    splats: Option<FilmSplats>,
    /// The same per kind of light path, when kept.
    parts: Option<Vec<PixelSums>>,
    /// First sample index this job takes.
    first: u32,
    /// Samples `first..done` are in `sums` (of every pixel).
    done: u32,
    /// Once adaptive rounds ([`RenderJob::render_round`]) have begun: one past the last
    /// sample index a round covered (the next round starts there).
    rounds_end: Option<u32>,
    /// Samples taken by adaptive rounds beyond `done` per pixel, summed over the pixels.
    extra: u64,
    /// One past the last pass (photon maps, one per sample index) a progressive integrator
    /// has begun, for the summary's radius.
    next_pass: u32,
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
        let splats = integrator.splats().then(|| {
            let layers = options.light_paths;
            FilmSplats::new((region.x, region.y), region.width, region.height, layers)
        });
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
            splats,
            parts: options
                .light_paths
                .then(|| new_parts(region.width, region.height)),
            first: range.start,
            done: range.start,
            rounds_end: None,
            extra: 0,
            next_pass: range.start,
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
        if let Some(start) = self.rounds_end {
            // After adaptive rounds: the next `n` sample indices of every pixel.
            let pixels = self.region.width as usize * self.region.height as usize;
            let end = start.saturating_add(n).min(self.end);
            return self.render_round(start..end, &vec![n; pixels]);
        }
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

    /// An adaptive round over the sample indices `round` (starting at or after every index
    /// taken so far, [`RenderJob::next_index`]): pixel `i` (row-major over the region) takes
    /// the first `counts[i]` of them (all of them at most). Sample `s` of a pixel is the
    /// sampler's sample `s` of that pixel whichever round takes it, and a progressive
    /// integrator traces pass `s`'s photon maps for it, as in a uniform render: once, for every
    /// pixel that takes sample `s` (see [`super::adaptive`]). The next round starts at
    /// `round.end` whatever the counts, so the rounds do not depend on the region.
    ///
    /// # Errors
    /// [`RenderError::Cancelled`] as [`RenderJob::render_pass`] (a progressive round keeps its
    /// completed passes); [`RenderError::Counts`] when `counts` is not one per pixel;
    /// [`RenderError::SampleRange`] when `round` overlaps the indices taken or passes the
    /// samples per pixel.
    pub fn render_round(&mut self, round: Range<u32>, counts: &[u32]) -> Result<(), RenderError> {
        let n = self.region.width as usize * self.region.height as usize;
        if counts.len() != n {
            return Err(RenderError::Counts(counts.len(), n));
        }
        if round.start < self.next_index() || round.end > self.end || round.start > round.end {
            return Err(RenderError::SampleRange(round.start, round.end, self.end));
        }
        if self.is_cancelled() {
            return Err(RenderError::Cancelled);
        }
        let len = round.end - round.start;
        let to: Vec<u32> = counts.iter().map(|&c| round.start + c.min(len)).collect();
        if !self.integrator.is_progressive() {
            let from = vec![round.start; n];
            self.sweep_counted(&from, &to)?;
        } else {
            let most = to.iter().copied().max().unwrap_or(round.start);
            for pass in round.start..most {
                let from: Vec<u32> = to.iter().map(|&e| pass.min(e)).collect();
                let next: Vec<u32> = to.iter().map(|&e| (pass + 1).min(e)).collect();
                let integrator = &mut self.integrator;
                self.pool.install(|| integrator.begin_pass(pass));
                self.sweep_counted(&from, &next)?;
                self.next_pass = self.next_pass.max(pass + 1);
                // A cancel after this pass leaves the round's later passes untaken.
                self.rounds_end = Some(pass + 1);
            }
        }
        self.rounds_end = Some(round.end);
        Ok(())
    }

    /// Takes each pixel's samples `from[i]..to[i]` in one sweep (adaptive rounds).
    fn sweep_counted(&mut self, from: &[u32], to: &[u32]) -> Result<(), RenderError> {
        let samples = SampleRanges::PerPixel {
            region: self.region,
            from,
            to,
        };
        self.sweep_ranges(samples)?;
        self.extra += from
            .iter()
            .zip(to)
            .map(|(&f, &t)| u64::from(t - f))
            .sum::<u64>();
        Ok(())
    }

    /// The first sample index no pixel has taken yet: where the next adaptive round starts.
    #[must_use]
    pub fn next_index(&self) -> u32 {
        self.rounds_end.unwrap_or(self.done)
    }

    /// What an adaptive render has taken so far, to be continued by another job
    /// ([`RenderJob::resume`]): the same bytes as if it had never stopped.
    #[must_use]
    pub fn state(&self) -> JobState {
        JobState {
            sums: self.sums.clone(),
            next_index: self.next_index(),
            next_pass: self.next_pass.max(self.done),
        }
    }

    /// Continues the render `state` was taken from ([`RenderJob::state`]) in this new job of the
    /// same scene, options and region (the light-path layers start empty).
    ///
    /// # Errors
    /// [`RenderError::Counts`] when `state` is not of this job's region's size.
    pub fn resume(&mut self, state: JobState) -> Result<(), RenderError> {
        let n = self.region.width as usize * self.region.height as usize;
        let size = state.sums.width as usize * state.sums.height as usize;
        if (state.sums.width, state.sums.height) != (self.region.width, self.region.height) {
            return Err(RenderError::Counts(size, n));
        }
        self.extra = (0..n).map(|i| u64::from(state.sums.count(i))).sum();
        self.sums = state.sums;
        self.rounds_end = Some(state.next_index);
        self.next_pass = state.next_pass;
        Ok(())
    }

    /// Takes samples `done..end` of every pixel in one sweep over the tiles.
    fn sweep(&mut self, end: u32) -> Result<(), RenderError> {
        if end == self.done {
            return Ok(());
        }
        self.sweep_ranges(SampleRanges::All(self.done..end))?;
        self.done = end;
        if self.next_pass < end {
            self.next_pass = end;
        }
        Ok(())
    }

    /// Takes `samples` of every pixel in one sweep over the tiles.
    fn sweep_ranges(&mut self, samples: SampleRanges<'_>) -> Result<(), RenderError> {
        let region = self.region;
        let sweep = Sweep {
            scene: self.scene,
            integrator: &self.integrator,
            keep_parts: self.parts.is_some(),
            splats: self.splats.as_ref(),
            cancel: self.cancel.as_deref(),
            progress: &self.progress,
        };
        let results: Option<Vec<TileResult>> = self.pool.install(|| {
            self.tiles
                .par_iter()
                .map(|t| render_tile(&sweep, t, &samples))
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
        if let Some(splats) = self.splats.as_mut() {
            // Exact fixed-point sums: the order of splats and tiles never shows in the bytes.
            merge_splats(splats, &mut self.sums, self.parts.as_mut());
        }
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

    /// The per-kind-of-light-path statistics so far, in `LightPath::ALL` order, when the job
    /// keeps them ([`RenderOptions::light_paths`]).
    #[must_use]
    pub fn parts(&self) -> Option<&[PixelSums]> {
        self.parts.as_deref()
    }

    /// Rays traced so far (by complete passes), for a live rays-per-second figure.
    #[must_use]
    pub fn rays_traced(&self) -> u64 {
        self.stats.rays
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
        self.start_region(region);
        self.render_pass(self.end - self.done)?;
        Ok(self.take_output())
    }

    /// Renders every sample of each of `regions` (as [`RenderJob::render_region`] does, one
    /// output per region, the same bytes), taking them pass by pass for a progressive
    /// integrator: each pass's photon maps are traced once for all the regions instead of once
    /// per region. For tools that render many small crops of one image (the doc-image test's
    /// row strips of a path-ppm scene traced every pass's photons once per strip).
    ///
    /// # Errors
    /// As [`RenderJob::render_region`], for the first region that fails.
    pub fn render_regions(&mut self, regions: &[Region]) -> Result<Vec<RenderOutput>, RenderError> {
        for &region in regions {
            check_region(region, self.scene.params.width, self.scene.params.height)?;
        }
        if !self.integrator.is_progressive() {
            return regions.iter().map(|&r| self.render_region(r)).collect();
        }
        // Each region's accumulators, swapped into the job for its sweeps.
        let mut states: Vec<RegionState> = regions
            .iter()
            .map(|&region| {
                self.start_region(region);
                self.take_state()
            })
            .collect();
        for sample in self.first..self.end {
            if self.is_cancelled() {
                return Err(RenderError::Cancelled);
            }
            let integrator = &mut self.integrator;
            self.pool.install(|| integrator.begin_pass(sample));
            for state in &mut states {
                self.swap_state(state);
                let swept = self.sweep(sample + 1);
                self.swap_state(state);
                swept?;
            }
        }
        Ok(states
            .iter_mut()
            .map(|state| {
                self.swap_state(state);
                self.take_output()
            })
            .collect())
    }

    /// Makes `region` the job's, with empty accumulators and no samples taken.
    fn start_region(&mut self, region: Region) {
        self.region = region;
        self.tiles = tile_grid(region);
        self.sums = PixelSums::new(region.width, region.height);
        if self.splats.is_some() {
            let layers = self.parts.is_some();
            let origin = (region.x, region.y);
            self.splats = Some(FilmSplats::new(origin, region.width, region.height, layers));
        }
        if self.parts.is_some() {
            self.parts = Some(new_parts(region.width, region.height));
        }
        self.done = self.first;
        self.rounds_end = None;
        self.extra = 0;
        self.next_pass = self.first;
        self.stats = RenderStats {
            threads: self.stats.threads,
            ..Default::default()
        };
        self.start = Instant::now();
    }

    /// The job's current region and accumulators, moved out.
    fn take_state(&mut self) -> RegionState {
        // The job keeps empty accumulators of the same kinds, so the next region gets them too.
        let layers = self.parts.is_some();
        let splats = self
            .splats
            .is_some()
            .then(|| FilmSplats::new((0, 0), 0, 0, layers));
        RegionState {
            region: self.region,
            tiles: std::mem::take(&mut self.tiles),
            sums: std::mem::replace(&mut self.sums, PixelSums::new(0, 0)),
            splats: std::mem::replace(&mut self.splats, splats),
            parts: std::mem::replace(&mut self.parts, layers.then(|| new_parts(0, 0))),
            done: self.done,
            stats: self.stats,
        }
    }

    /// Exchanges the job's region and accumulators with `state`'s.
    fn swap_state(&mut self, state: &mut RegionState) {
        std::mem::swap(&mut self.region, &mut state.region);
        std::mem::swap(&mut self.tiles, &mut state.tiles);
        std::mem::swap(&mut self.sums, &mut state.sums);
        std::mem::swap(&mut self.splats, &mut state.splats);
        std::mem::swap(&mut self.parts, &mut state.parts);
        std::mem::swap(&mut self.done, &mut state.done);
        std::mem::swap(&mut self.stats, &mut state.stats);
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
            * u64::from(self.done - self.first)
            + self.extra;
        stats.elapsed = self.start.elapsed();
        stats.progressive = self.integrator.progressive().map(|p| ProgressiveStats {
            totals: p.totals(),
            last_shrink: p.shrink(self.next_pass.max(self.done).saturating_sub(1)),
            caustic_radius: p
                .fields()
                .and_then(|f| f.caustic.as_ref())
                .map(|f| (f.typical(), f.fallback())),
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

/// The state of an adaptive render between rounds ([`RenderJob::state`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JobState {
    /// The film's sums, squares and counts.
    pub sums: PixelSums,
    /// The first sample index no pixel has taken (where the next round starts).
    pub next_index: u32,
    /// One past the last pass a progressive integrator began (for its summary).
    pub next_pass: u32,
}

/// One region's part of a [`RenderJob::render_regions`] call: what the job holds per region.
struct RegionState {
    region: Region,
    tiles: Vec<Region>,
    sums: PixelSums,
    splats: Option<FilmSplats>,
    parts: Option<Vec<PixelSums>>,
    done: u32,
    stats: RenderStats,
}

impl Drop for RenderJob<'_> {
    fn drop(&mut self) {
        self.progress.finish_and_clear();
    }
}

/// The tile progress bar on stderr (hidden unless `enabled`), counting tile-samples.
/// Adds the sweep's splats into the film (and its layers) and empties the buffers. The
/// buffers are made for the job's region, as the films are: the sizes always match.
fn merge_splats(splats: &mut FilmSplats, sums: &mut PixelSums, parts: Option<&mut Vec<PixelSums>>) {
    let (total, layers) = splats.buffers_mut();
    let merged = sums.add_splats(total);
    debug_assert!(merged.is_ok(), "splat buffers are the region's size");
    total.clear();
    if let (Some(films), Some(buffers)) = (parts, layers) {
        for (film, buffer) in films.iter_mut().zip(buffers.iter_mut()) {
            let merged = film.add_splats(buffer);
            debug_assert!(merged.is_ok(), "splat buffers are the region's size");
            buffer.clear();
        }
    }
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
