//! The one interface every lobe implements ([`Bxdf`], after pbrt-v4's `BxDF`: `f`, `Sample_f`,
//! `PDF`, `Flags`), with the same arguments for every lobe whatever it reads of them: the
//! outgoing side of the query in one [`LobeContext`], a sample's numbers and the mixture's
//! choice in one [`LobeDraw`]. [`super::Lobe`] dispatches to it, so a new lobe is its own file
//! implementing [`Bxdf`] and one line in `lobe.rs`.
//!
//! Unlike pbrt's `BxDF`, a lobe is one part of a weighted mixture ([`super::Bsdf`]), and the
//! mixture's numbers enter a lobe's arithmetic where they always have (a delta sample's weight
//! is `weight / prob` times the lobe's own factor, a density is `share · pdf` in each lobe's
//! order), so that images stay bit-identical; hence `share` in [`Bxdf::pdf`] and `weight`,
//! `prob` in [`LobeDraw`].

use glam::Vec3;

use super::microfacet::Ggx;
use super::optics::FresnelSplit;
use super::scattering::{BsdfSample, LobeFlags, ShadingFrame, TransportMode};
use crate::binfile::KeyHash;

/// The outgoing side of a lobe query: what [`Bxdf`]'s methods receive besides the incident
/// direction or the sample's numbers.
#[derive(Debug, Clone, Copy)]
pub struct LobeContext<'a> {
    /// Unit outgoing direction, away from the surface.
    pub wo: Vec3,
    /// The shading frame (normals on the side of `wo`, whether `wo` is outside).
    pub fr: &'a ShadingFrame,
    /// The mixture's tint (the material's colour at the point; tinted lobes scale by it).
    pub tint: Vec3,
}

/// What a lobe works out once per outgoing direction and reuses while the mixture weighs and
/// samples it ([`Bxdf::prepare`]): the dielectric's Fresnel split, the mean macro-surface
/// reflectance of the metals, the rough dielectric and the coat; nothing for the others.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Prepared {
    /// The lobe needs nothing.
    Nothing,
    /// The dielectric's split.
    Fresnel(FresnelSplit),
    /// The mean Fresnel reflectance at the macro-surface normal.
    Reflectance(f32),
}

/// A sample's inputs ([`Bxdf::sample`]): the random numbers, the transport mode, and the
/// mixture's choice of the lobe's part.
#[derive(Debug, Clone, Copy)]
pub struct LobeDraw<'a> {
    /// The lobe's per-direction state ([`Bxdf::prepare`]; [`Prepared::Nothing`] where the
    /// mixture did not prepare the part, which the lobe then works out itself).
    pub prepared: &'a Prepared,
    /// The tint's mean.
    pub rho: f32,
    /// The rest of the lobe number, in [0, 1) (the dielectrics' choice of reflection or
    /// refraction; 0 for lobes that do not read it, [`Bxdf::uses_lobe_number`]).
    pub v: f32,
    /// The direction's two numbers, in [0, 1)².
    pub u: (f32, f32),
    /// Radiance (camera paths) or importance (light and photon paths).
    pub mode: TransportMode,
    /// The weight of the lobe's part in the mixture.
    pub weight: f32,
    /// The probability with which the mixture chose the part.
    pub prob: f32,
}

/// What [`Bxdf::sample`] returns: a delta lobe's finished sample (its weight includes the
/// part's `weight / prob`), or a non-delta lobe's direction, which the mixture weighs with the
/// whole mixture's value and density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LobeSample {
    /// A delta lobe's sample.
    Delta(BsdfSample),
    /// A non-delta lobe's direction.
    Direction(Vec3),
}

/// What a delta lobe sends along the mirror direction and through the surface in radiance mode
/// ([`Bxdf::delta_weights`]; see [`super::DeltaLobes`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeltaWeights {
    /// Weight of the mirror direction.
    pub reflect: Vec3,
    /// Refracted direction, its weight, and the (ηₒ/ηᵢ)² included in it.
    pub refract: Option<(Vec3, Vec3, f32)>,
}

impl DeltaWeights {
    /// Nothing in either direction (non-delta lobes).
    pub const NONE: Self = Self {
        reflect: Vec3::ZERO,
        refract: None,
    };
}

/// One lobe of the BSDF mixture (module docs). Every method is required: a lobe says what it
/// does for each question, so none silently answers with a default. [`KeyHash`] puts the
/// lobe's parameters in the scene key.
pub trait Bxdf: KeyHash {
    /// What the lobe is, whatever the directions ([`LobeInfo`]).
    fn info(&self) -> LobeInfo;

    /// The lobe's value `f(wo, wi)` (per steradian) in mode `mode`: 0 for delta lobes and where
    /// the lobe does not scatter.
    fn f(&self, ctx: &LobeContext<'_>, wi: Vec3, mode: TransportMode) -> Vec3;

    /// `share` times the lobe's solid-angle sampling density at `wi` (0 for delta lobes). The
    /// density is the same in both transport modes.
    fn pdf(&self, ctx: &LobeContext<'_>, wi: Vec3, share: f32) -> f32;

    /// A sample: a delta lobe's finished sample, or a non-delta lobe's direction (`None` when
    /// the sample is lost below the surface or its probability is 0).
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample>;

    /// The lobe's per-direction state for `ctx.wo`.
    fn prepare(&self, ctx: &LobeContext<'_>) -> Prepared;

    /// The lobe's sampling weight (a mean albedo) given its prepared state and the tint's mean
    /// `rho`.
    fn albedo(&self, prepared: &Prepared, rho: f32) -> f32;

    /// What a delta lobe of a part of weight `weight` sends along the mirror direction and
    /// through the surface in radiance mode ([`DeltaWeights::NONE`] for non-delta lobes).
    fn delta_weights(&self, ctx: &LobeContext<'_>, weight: f32) -> DeltaWeights;

    /// The straight-line transmittance of a part of weight `weight` with tint `tint` at the
    /// incidence cosine `cos` (0 unless the lobe transmits; see
    /// [`super::Bsdf::straight_transmittance`]).
    fn straight_transmittance(&self, weight: f32, tint: Vec3, cos: f32, entering: bool) -> Vec3;

    /// True if the lobe scatters nothing with this tint (so choosing it never matters).
    fn is_black(&self, tint: Vec3) -> bool;

    /// True if the lobe's non-delta value, where it has one, is the same for every incident
    /// direction above the surface, or it has none, or it is black with this tint
    /// ([`super::Bsdf::is_diffuse_only`]).
    fn is_flat(&self, tint: Vec3) -> bool;
}

/// What a lobe is, whatever the directions ([`Bxdf::info`]). Each lobe writes it as a struct
/// literal, so an entry added here is a compile error in every lobe until it says its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeInfo {
    /// The lobe's kind of scattering.
    pub flags: LobeFlags,
    /// The lobe's own sampling reads the rest of the lobe number ([`LobeDraw::v`]; the
    /// dielectrics' choice of reflection or refraction).
    pub uses_lobe_number: bool,
    /// The fraction of a delta part's weight that can focus light, by which caustic photons are
    /// aimed (1 for mirrors and dielectrics, a coat's mean reflectance; 0 for non-delta lobes).
    pub focusing_fraction: f32,
    /// The relative index of refraction (inside over outside) of a transmitting lobe.
    pub ior: Option<f32>,
    /// The microfacet distribution of a microfacet lobe (what
    /// [`super::Bsdf::is_near_specular`] compares).
    pub distribution: Option<Ggx>,
}
