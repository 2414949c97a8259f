//! Acceleration structures over primitive bounds.

pub(crate) mod build;
pub mod bvh;
mod query;
mod traverse;

pub use build::BvhNode;
pub use bvh::{Bvh, BvhStats, Node8};
pub use traverse::RayBoxTest;
