//! The one material model shared by every integrator, and the optics it is built from.

pub mod bsdf;
pub mod normals;
pub mod optics;

pub use bsdf::{
    Bsdf, BsdfSample, DeltaLobes, ShadingFrame, TransportMode, shading_normal_correction,
};
pub use normals::usable_shading_normal;
