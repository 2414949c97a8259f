//! Deterministic random streams and the warps that turn uniform numbers into directions.

pub mod alias;
#[cfg(test)]
pub(crate) mod chi2;
pub mod distribution;
pub mod equiangular;
pub mod rng;
pub mod sampler;
pub mod sobol;
pub mod special;
pub mod warp;

pub use rng::Rng;
pub use sampler::{Sampler, SamplerKind};
