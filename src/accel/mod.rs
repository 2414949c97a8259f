//! Acceleration structures over primitive bounds.

pub mod bvh;
pub(crate) mod build;
mod traverse;

pub use bvh::{Bvh, BvhNode, BvhStats};
pub use traverse::RayBoxTest;
