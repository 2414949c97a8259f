//! caustic: a ray tracer driven by declarative RON/TOML scene files.
//!
//! The pipeline is `scene` (schema, load, validate) → `compile` (flat render scene) → `render`
//! (integrators, tiles, film), with `geometry`, `accel`, `shading` and `sampling` beneath.

#![forbid(unsafe_code)]
#![warn(missing_docs)]
// `!(x > 0.0)` is used on purpose throughout: it is true for NaN, which must fail such checks.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod bench;
pub mod compile;
pub mod error;
pub mod geometry;
pub mod pipeline;
pub mod render;
pub mod render_scene;
pub mod sampling;
pub mod scene;
pub mod shading;
pub mod texture;

pub use error::Error;
