//! Rendering: integrators, the tile scheduler, the film and image output.

pub mod film;
pub mod metrics;
pub mod output;
pub mod tiles;
pub mod trace_log;
pub mod whitted;

pub use film::Film;
pub use tiles::{
    Region, RenderError, RenderJob, RenderOptions, RenderOutput, RenderStats, render, trace_pixel,
};
