//! Acceleration structures over primitive bounds.

pub(crate) mod build;
pub mod bvh;
mod traverse;

pub use bvh::{Bvh, BvhNode, BvhStats, Node8};
pub use traverse::RayBoxTest;
