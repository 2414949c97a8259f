//! The one material model shared by every integrator: a BSDF mixture of lobes, each lobe in its
//! own file, and the optics they are built from.

pub mod absorption;
pub mod bsdf;
pub mod bsdf_at;
pub mod bxdf;
pub mod coated;
pub mod conductor;
pub mod dielectric;
pub mod lambert;
pub mod lobe;
pub mod microfacet;
pub mod normals;
pub mod optics;
mod part;
pub mod phase;
pub mod phong;
pub mod rough_conductor;
pub mod rough_dielectric;
pub mod scattering;
pub mod specular_conductor;
pub mod specular_reflection;

pub use bsdf::{Bsdf, DeltaLobes, NEAR_SPECULAR_ALPHA};
pub use bsdf_at::BsdfAt;
pub use bxdf::{Bxdf, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
pub use lobe::Lobe;
pub use normals::usable_shading_normal;
pub use scattering::{
    BsdfSample, LobeFlags, ShadingFrame, TransportMode, shading_normal_correction,
};
