//! Rendering: the render job and its tile loop, the film and its mergeable sums, image output.

pub mod adaptive;
pub mod auto_exposure;
pub mod denoised;
pub mod error_estimate;
pub mod exr;
pub mod features;
pub mod film;
pub mod golden;
pub mod job;
pub mod layer_pictures;
pub mod layers;
pub mod options;
pub mod output;
pub mod passes;
pub mod pixel_sums;
pub mod tiles;
pub mod tonemap;
pub mod trace_pixel;
pub mod wide_sum;

pub use features::{FeatureSample, Features};
pub use film::Film;
pub use job::{JobState, RenderJob, render};
pub use layer_pictures::{
    NotAPicture, layer_path, picture_layers, write_with_extras, write_with_layers,
};
pub use layers::{
    Layer, LayerExtras, UnknownLayer, encode_layers, encode_layers_with, write_layers,
    write_layers_with,
};
pub use options::{
    ProgressiveStats, Region, RenderError, RenderOptions, RenderOutput, RenderStats,
};
pub use pixel_sums::PixelSums;
pub use trace_pixel::{trace_pixel, trace_pixel_with};
