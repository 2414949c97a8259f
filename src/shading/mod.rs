//! The one material model shared by every integrator, and the optics it is built from.

pub mod absorption;
pub mod bsdf;
pub mod conductor;
pub mod microfacet;
pub mod normals;
pub mod optics;
pub mod rough_conductor;
pub mod rough_dielectric;

pub use bsdf::{
    Bsdf, BsdfSample, DeltaLobes, ShadingFrame, TransportMode, shading_normal_correction,
};
pub use normals::usable_shading_normal;
