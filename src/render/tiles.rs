//! The tile loop: the image is cut into 16×16 tiles that rayon renders in any order, each
//! pixel's samples drawn from its own random stream (the sampler is started per pixel and
//! sample index), so the image is identical for any thread count and tile order.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use indicatif::ProgressBar;

use super::options::Region;
use super::pixel_sums::PixelSums;
use crate::geometry::Ray;
use crate::integrators::splat::FilmSplats;
use crate::integrators::{Context, Counters, Integrator, LightPath, NoTrace};
use crate::render_scene::RenderScene;
use crate::sampling::Sampler;

/// Tile edge in pixels.
const TILE: u32 = 16;

/// Empty sums for each kind of light path.
pub(super) fn new_parts(width: u32, height: u32) -> Vec<PixelSums> {
    LightPath::ALL
        .iter()
        .map(|_| PixelSums::new(width, height))
        .collect()
}

/// Index in the region-sized buffer of pixel `i` (row-major) of `tile`.
pub(super) fn pixel_index(region: Region, tile: &Region, i: usize) -> usize {
    let (x, y) = (
        tile.x + i as u32 % tile.width,
        tile.y + i as u32 / tile.width,
    );
    ((y - region.y) * region.width + (x - region.x)) as usize
}

/// The tiles covering `r`: 16×16 (smaller at the right and bottom edges), row by row.
pub(super) fn tile_grid(r: Region) -> Vec<Region> {
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

/// One tile's share of a pass: its pixels' statistics over the pass (row-major in the tile) and
/// counters.
pub(super) struct TileResult {
    pub(super) sums: PixelSums,
    pub(super) parts: Option<Vec<PixelSums>>,
    pub(super) counters: Counters,
    pub(super) nan: u64,
}

/// What every tile of one sweep shares: the scene, the prepared integrator, whether the
/// light-path layers are kept, the job's splat buffers, the cancel flag and the progress bar.
pub(super) struct Sweep<'s, 'a> {
    pub(super) scene: &'s RenderScene,
    pub(super) integrator: &'s Integrator<'a>,
    pub(super) keep_parts: bool,
    pub(super) splats: Option<&'s FilmSplats>,
    pub(super) cancel: Option<&'s AtomicBool>,
    pub(super) progress: &'s ProgressBar,
}

/// Which sample indices a sweep takes of each pixel.
#[derive(Debug, Clone)]
pub(super) enum SampleRanges<'s> {
    /// The same indices of every pixel (uniform passes).
    All(Range<u32>),
    /// Pixel `i` of `region` (row-major) takes `from[i]..to[i]` (adaptive rounds).
    PerPixel {
        /// The job's region, which `from` and `to` cover.
        region: Region,
        /// First index per pixel.
        from: &'s [u32],
        /// One past the last index per pixel.
        to: &'s [u32],
    },
}

impl SampleRanges<'_> {
    /// The indices pixel `i` (row-major) of `tile` takes.
    fn of(&self, tile: &Region, i: usize) -> Range<u32> {
        match self {
            SampleRanges::All(r) => r.clone(),
            SampleRanges::PerPixel { region, from, to } => {
                let at = pixel_index(*region, tile, i);
                from[at]..to[at]
            }
        }
    }
}

/// Takes samples `samples` of each pixel of `tile`. `None` when `sweep.cancel` is raised: it
/// is checked before each pixel, never per ray.
pub(super) fn render_tile(
    sweep: &Sweep<'_, '_>,
    tile: &Region,
    samples: &SampleRanges<'_>,
) -> Option<TileResult> {
    let Sweep {
        scene,
        integrator,
        keep_parts,
        splats,
        cancel,
        progress,
    } = *sweep;
    let mut sampler = Sampler::new(
        scene.params.sampler,
        scene.params.seed,
        scene.params.samples_per_pixel,
    );
    let mut counters = Counters::default();
    let mut nan = 0u64;
    let mut out = PixelSums::new(tile.width, tile.height);
    let mut parts = keep_parts.then(|| new_parts(tile.width, tile.height));
    let mut taken = 0u64;
    for i in 0..(tile.width * tile.height) as usize {
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return None;
        }
        let (x, y) = (
            tile.x + i as u32 % tile.width,
            tile.y + i as u32 / tile.width,
        );
        let range = samples.of(tile, i);
        taken += u64::from(range.end.saturating_sub(range.start));
        for s in range {
            let ray = camera_sample(scene, &mut sampler, x, y, s);
            let r = integrator.li_parts(
                ray,
                &mut Context::new(&mut sampler, &mut counters, &mut NoTrace).with_splats(splats),
            );
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
    // Tile-samples: the samples per pixel of a uniform sweep, the mean over the tile's pixels
    // of an adaptive one.
    progress.inc(taken / u64::from(tile.width * tile.height).max(1));
    Some(TileResult {
        sums: out,
        parts,
        counters,
        nan,
    })
}

/// Starts `sampler` on sample `s` of pixel `(x, y)` and returns its camera ray through the
/// position in the pixel the sampler's first two dimensions give. A thin lens takes its lens
/// point from the next two (the camera's 2-D lens dimensions, before any integrator draw);
/// a pinhole draws nothing more, so its images stay what they were.
pub(super) fn camera_sample(
    scene: &RenderScene,
    sampler: &mut Sampler,
    x: u32,
    y: u32,
    s: u32,
) -> Ray {
    let p = &scene.params;
    sampler.start_pixel_sample(x, y, s);
    let (jx, jy) = sampler.pixel_2d();
    let (fx, fy) = (x as f32 + jx, y as f32 + jy);
    if scene.camera.needs_lens_sample() {
        let u_lens = sampler.next_2d();
        scene.camera.ray_lens(fx, fy, p.width, p.height, u_lens)
    } else {
        scene.camera.ray(fx, fy, p.width, p.height)
    }
}
