//! caustic: a ray tracer driven by declarative RON/TOML scene files.
//!
//! The pipeline is `scene` (schema, load, validate) → `compile` (flat render scene) → `render`
//! (integrators, tiles, film), with `geometry`, `accel`, `shading` and `sampling` beneath.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod accel;
pub mod geometry;
pub mod bench;
pub mod scene;
