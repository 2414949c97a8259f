//! The one material model shared by every integrator, and the optics it is built from.

pub mod material;
pub mod normals;
pub mod optics;

pub use material::Material;
pub use normals::usable_shading_normal;
