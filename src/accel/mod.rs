//! Acceleration structures over primitive bounds.

pub(crate) mod build;
pub mod bvh;
mod query;
pub mod sphere_bvh;
mod traverse;

pub use build::BvhNode;
pub use bvh::{Bvh, BvhStats, Node8};
pub use sphere_bvh::{SphereBvh, SphereHit};
pub use traverse::RayBoxTest;
