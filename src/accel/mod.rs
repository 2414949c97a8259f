//! Acceleration structures over primitive bounds.

pub(crate) mod build;
pub mod bvh;
mod traverse;

pub use bvh::{Bvh, BvhNode, BvhStats, NodePair};
pub use traverse::RayBoxTest;
