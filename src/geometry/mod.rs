//! Rays, bounds, frames and ray–primitive intersection (triangles, spheres, discs, cylinders): the geometric layer beneath everything else.
//!
//! Only `glam` is imported here. Intersection routines are two-phase: a cheap test that returns the
//! distance (and barycentrics) and a separate step that builds the full surface record for the
//! closest hit only.

pub mod aabb;
pub mod float;
pub mod frame;
pub mod offset;
pub mod quadric;
pub mod ray;
pub mod sphere;
pub mod triangle;

pub use aabb::Aabb;
pub use frame::Frame;
pub use ray::Ray;
