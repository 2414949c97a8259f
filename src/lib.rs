//! caustic: a ray tracer driven by declarative RON/TOML scene files.
//!
//! The pipeline is `scene` (schema, load, validate) → `compile` (flat render scene) → `render`
//! (integrators, tiles, film), with `geometry`, `accel`, `shading` and `sampling` beneath.
//!
//! ```
//! use caustic::pipeline::{SceneOverrides, prepare};
//! use caustic::render::{RenderOptions, render};
//!
//! use caustic::scene::schema::RenderSettings;
//!
//! let size = RenderSettings { width: Some(8), height: Some(6), samples_per_pixel: Some(1), ..Default::default() };
//! let small = SceneOverrides { render: size, ..Default::default() };
//! let prepared = prepare(std::path::Path::new("scenes/cornell.ron"), &small)?;
//! let out = render(&prepared.render_scene, &RenderOptions::default())?;
//! assert_eq!((out.film.width, out.film.height), (8, 6));
//! assert_eq!(out.stats.nan_samples, 0);
//! # Ok::<(), caustic::Error>(())
//! ```

#![forbid(unsafe_code)]
#![warn(missing_docs)]
// `!(x > 0.0)` is used on purpose throughout: it is true for NaN, which must fail such checks.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod analysis;
pub mod bench;
pub mod binfile;
pub mod compile;
pub mod denoise;
pub mod error;
pub mod farm;
pub mod geometry;
pub mod integrators;
pub mod pipeline;
pub mod render;
pub mod render_scene;
pub mod sampling;
pub mod scene;
pub mod settings;
pub mod shading;
pub mod spatial;
pub mod texture;

pub use error::Error;
