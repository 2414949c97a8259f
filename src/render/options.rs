//! The types a render is described and reported with: the crop [`Region`], the
//! [`RenderOptions`] a caller passes, the [`RenderStats`] and [`RenderOutput`] it gets back, and
//! the [`RenderError`] when it cannot start or finish.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use super::Film;
use super::pixel_sums::PixelSums;
use crate::integrators::photon::PassTotals;

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
    /// Also keep the radiance of each kind of light path ([`crate::integrators::LightPath`]) per
    /// pixel, for the layers of `--layers` (EXR channels, or PNG pictures beside the image).
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
    /// The fraction of the initial radius `R(x)` the last pass taken read (1 for the first
    /// pass; it shrinks by Knaus & Zwicker's schedule).
    pub last_shrink: f32,
    /// The caustic map's initial radius field, if any: its typical `R` (median over the pilot
    /// photons) and its value where the pilot map found no photon (scene units).
    pub caustic_radius: Option<(f32, f32)>,
}

/// A rendered film with its statistics.
#[derive(Debug, Clone)]
pub struct RenderOutput {
    /// The (possibly cropped) image: each pixel's mean.
    pub film: Film,
    /// The per-pixel sums, squares and counts the image was made from (mergeable).
    pub sums: PixelSums,
    /// With [`RenderOptions::light_paths`]: the same sums for each kind of light path, in
    /// [`crate::integrators::LightPath::ALL`] order (they add up to `sums`' means).
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
    /// An adaptive round's sample counts are not one per pixel of the region.
    #[error("an adaptive round gave {0} sample counts for a region of {1} pixels")]
    Counts(usize, usize),
    /// The cancel flag of [`RenderOptions`] was raised; no image is returned.
    #[error("the render was cancelled")]
    Cancelled,
}

/// Checks that `region` is non-empty and inside a `w` × `h` image.
pub(super) fn check_region(region: Region, w: u32, h: u32) -> Result<(), RenderError> {
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
