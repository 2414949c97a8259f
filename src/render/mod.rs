//! Rendering: integrators, the tile scheduler, the film and image output.

pub mod film;
pub mod golden;
pub mod layers;
pub mod metrics;
pub mod output;
pub mod part_meta;
pub mod pixel_sums;
pub mod progressive;
pub mod shard;
pub mod tiles;

pub use film::Film;
pub use layers::{Layer, UnknownLayer, encode_layers, write_layers};
pub use part_meta::PartMeta;
pub use pixel_sums::PixelSums;
pub use shard::Shard;
pub use tiles::{
    ProgressiveStats, Region, RenderError, RenderJob, RenderOptions, RenderOutput, RenderStats,
    render, trace_pixel,
};
