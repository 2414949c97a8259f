//! Rendering: integrators, the tile scheduler, the film and image output.

pub mod film;
pub mod metrics;
pub mod output;
pub mod pixel_sums;
pub mod progressive;
pub mod tiles;

pub use film::Film;
pub use pixel_sums::PixelSums;
pub use tiles::{
    ProgressiveStats, Region, RenderError, RenderJob, RenderOptions, RenderOutput, RenderStats,
    render, trace_pixel,
};
