//! The tile scheduler: rayon over 16×16 tiles, each pixel's samples drawn from its own random
//! stream, so the image is identical for any thread count and tile order.

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

/// Why a render could not start.
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
}

/// Renders `scene` (or a region of it).
pub fn render(scene: &RenderScene, options: &RenderOptions) -> Result<RenderOutput, RenderError> {
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
    let progress = progress_bar(options.progress, tiles.len() as u64);
    let start = Instant::now();
    let results: Vec<(Vec<Vec3>, Counters, u64)> = pool.install(|| {
        tiles
            .par_iter()
            .map(|t| render_tile(scene, t, &progress))
            .collect()
    });
    progress.finish_and_clear();
    let mut film = Film::new(region.width, region.height);
    let mut stats = RenderStats {
        threads,
        ..Default::default()
    };
    for (tile, (pixels, counters, nan)) in tiles.iter().zip(results) {
        for (i, p) in pixels.into_iter().enumerate() {
            let (x, y) = (
                tile.x + i as u32 % tile.width,
                tile.y + i as u32 / tile.width,
            );
            film.pixels[((y - region.y) * region.width + (x - region.x)) as usize] = p;
        }
        stats.rays += counters.rays;
        stats.nan_samples += nan;
    }
    stats.samples = u64::from(region.width)
        * u64::from(region.height)
        * u64::from(scene.params.samples_per_pixel);
    stats.elapsed = start.elapsed();
    Ok(RenderOutput { film, stats })
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

fn render_tile(
    scene: &RenderScene,
    tile: &Region,
    progress: &ProgressBar,
) -> (Vec<Vec3>, Counters, u64) {
    let integrator = Whitted::new(scene);
    let spp = scene.params.samples_per_pixel;
    let mut counters = Counters::default();
    let mut nan = 0u64;
    let mut pixels = Vec::with_capacity((tile.width * tile.height) as usize);
    for y in tile.y..tile.y + tile.height {
        for x in tile.x..tile.x + tile.width {
            let mut sum = Vec3::ZERO;
            for s in 0..spp {
                let (ray, mut rng) = camera_sample(scene, x, y, s);
                let l = integrator.li(ray, &mut rng, &mut counters, None);
                if l.is_finite() {
                    sum += l;
                } else {
                    nan += 1;
                }
            }
            pixels.push(sum / spp as f32);
        }
    }
    progress.inc(1);
    (pixels, counters, nan)
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
