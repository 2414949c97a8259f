//! The lobes a BSDF mixture ([`super::Bsdf`]) is made of, dispatched by one enum (no virtual
//! calls per sample; pbrt-v4 tags its `BxDF`s the same way). Adding a lobe: write its file (its
//! `f`, `sample`, `pdf`, flags), add a variant here (the compiler lists every match to extend),
//! and give it a part in the mixture (`Bsdf::new`).

use glam::Vec3;

use super::dielectric::{DeltaWeights, Dielectric, FresnelSplit};
use super::lambert::Lambert;
use super::phong::Phong;
use super::scattering::{BsdfSample, LobeFlags, ShadingFrame, TransportMode};
use super::specular_reflection::SpecularReflection;

/// One lobe of the mixture. Lobes tinted by the material's colour (Lambert's albedo, the mirror's
/// reflectance, the dielectric's transmittance) take it as the `tint` argument, so a colour
/// texture changes one value in the mixture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Lobe {
    /// Ideal diffuse reflection.
    Lambert(Lambert),
    /// Normalised Phong glossy reflection.
    Phong(Phong),
    /// Perfect mirror.
    SpecularReflection(SpecularReflection),
    /// Smooth Fresnel dielectric.
    Dielectric(Dielectric),
}

/// What a lobe works out once per outgoing direction and reuses while the mixture weighs and
/// samples it: the dielectric's Fresnel split; nothing for the others.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Prepared {
    /// The lobe needs nothing.
    Nothing,
    /// The dielectric's split.
    Fresnel(FresnelSplit),
}

impl Lobe {
    /// The lobe's kind of scattering.
    #[inline]
    #[must_use]
    pub fn flags(&self) -> LobeFlags {
        match self {
            Lobe::Lambert(_) => Lambert::FLAGS,
            Lobe::Phong(_) => Phong::FLAGS,
            Lobe::SpecularReflection(_) => SpecularReflection::FLAGS,
            Lobe::Dielectric(_) => Dielectric::FLAGS,
        }
    }

    /// True if the lobe scatters nothing with this tint (so choosing it never matters).
    #[inline]
    #[must_use]
    pub fn is_black(&self, tint: Vec3) -> bool {
        match self {
            Lobe::Lambert(_) | Lobe::SpecularReflection(_) => tint == Vec3::ZERO,
            Lobe::Phong(p) => p.specular == Vec3::ZERO,
            Lobe::Dielectric(_) => false,
        }
    }

    /// True if the lobe's own sampling reads the lobe number (the dielectric chooses between
    /// reflection and refraction with it).
    #[inline]
    #[must_use]
    pub fn uses_lobe_number(&self) -> bool {
        match self {
            Lobe::Lambert(_) | Lobe::Phong(_) | Lobe::SpecularReflection(_) => false,
            Lobe::Dielectric(_) => true,
        }
    }

    /// The lobe's per-direction state for `wo`.
    #[inline]
    #[must_use]
    pub fn prepare(&self, wo: Vec3, fr: &ShadingFrame) -> Prepared {
        match self {
            Lobe::Lambert(_) | Lobe::Phong(_) | Lobe::SpecularReflection(_) => Prepared::Nothing,
            Lobe::Dielectric(d) => Prepared::Fresnel(d.split(wo, fr)),
        }
    }

    /// The lobe's sampling weight (a mean albedo) at the prepared direction, `rho` the tint's
    /// mean.
    #[inline]
    #[must_use]
    pub fn albedo(&self, prepared: &Prepared, rho: f32) -> f32 {
        match (self, prepared) {
            (Lobe::Lambert(_) | Lobe::SpecularReflection(_), _) => rho,
            (Lobe::Phong(p), _) => p.albedo(),
            (Lobe::Dielectric(d), Prepared::Fresnel(s)) => d.albedo(s, rho),
            (Lobe::Dielectric(_), Prepared::Nothing) => 0.0,
        }
    }

    /// The lobe's value `f(wo, wi)` (per steradian) with shading normal `n`: 0 for delta lobes.
    #[inline]
    #[must_use]
    pub fn f(&self, wo: Vec3, wi: Vec3, n: Vec3, tint: Vec3) -> Vec3 {
        match self {
            Lobe::Lambert(l) => l.f(tint, wi, n),
            Lobe::Phong(p) => p.f(wo, wi, n),
            Lobe::SpecularReflection(s) => s.f(),
            Lobe::Dielectric(d) => d.f(),
        }
    }

    /// `share` times the lobe's sampling density at `wi` (0 for delta lobes).
    #[inline]
    #[must_use]
    pub fn scaled_pdf(&self, share: f32, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
        match self {
            Lobe::Lambert(l) => l.scaled_pdf(share, wi, fr),
            Lobe::Phong(p) => p.scaled_pdf(share, wo, wi, fr),
            Lobe::SpecularReflection(s) => share * s.pdf(),
            Lobe::Dielectric(d) => share * d.pdf(),
        }
    }

    /// A direction from a non-delta lobe's density (`None` for delta lobes, which the mixture
    /// samples through [`Lobe::sample_delta`]).
    #[inline]
    #[must_use]
    pub fn sample_direction(&self, wo: Vec3, u: (f32, f32), fr: &ShadingFrame) -> Option<Vec3> {
        match self {
            Lobe::Lambert(l) => Some(l.sample(u, fr)),
            Lobe::Phong(p) => Some(p.sample(wo, u, fr)),
            Lobe::SpecularReflection(_) | Lobe::Dielectric(_) => None,
        }
    }

    /// A delta lobe's sample (`None` for non-delta lobes), for a part of weight `weight` chosen
    /// with probability `prob`; `v ∈ [0, 1)` is the rest of the lobe number.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    #[must_use]
    pub fn sample_delta(
        &self,
        prepared: &Prepared,
        wo: Vec3,
        v: f32,
        fr: &ShadingFrame,
        mode: TransportMode,
        weight: f32,
        prob: f32,
        tint: Vec3,
        rho: f32,
    ) -> Option<BsdfSample> {
        match (self, prepared) {
            (Lobe::Lambert(_) | Lobe::Phong(_), _) => None,
            (Lobe::SpecularReflection(s), _) => s.sample(wo, fr, mode, weight, prob, tint),
            (Lobe::Dielectric(d), Prepared::Fresnel(split)) => {
                d.sample(split, wo, v, fr, mode, weight, prob, tint, rho)
            }
            (Lobe::Dielectric(d), Prepared::Nothing) => {
                d.sample(&d.split(wo, fr), wo, v, fr, mode, weight, prob, tint, rho)
            }
        }
    }

    /// What a delta lobe of a part of weight `weight` sends along the mirror direction and
    /// through the surface in radiance mode (nothing for non-delta lobes).
    #[inline]
    #[must_use]
    pub fn delta_weights(
        &self,
        wo: Vec3,
        fr: &ShadingFrame,
        weight: f32,
        tint: Vec3,
    ) -> DeltaWeights {
        match self {
            Lobe::Lambert(_) | Lobe::Phong(_) => DeltaWeights {
                reflect: Vec3::ZERO,
                refract: None,
            },
            Lobe::SpecularReflection(_) => DeltaWeights {
                reflect: tint * weight,
                refract: None,
            },
            Lobe::Dielectric(d) => d.delta_weights(&d.split(wo, fr), weight, tint),
        }
    }

    /// The straight-line transmittance of a part of weight `weight` (0 unless it transmits).
    #[inline]
    #[must_use]
    pub fn straight_transmittance(
        &self,
        weight: f32,
        tint: Vec3,
        cos: f32,
        entering: bool,
    ) -> Vec3 {
        match self {
            Lobe::Lambert(_) | Lobe::Phong(_) | Lobe::SpecularReflection(_) => Vec3::ZERO,
            Lobe::Dielectric(d) => d.straight_transmittance(weight, tint, cos, entering),
        }
    }

    /// The relative index of refraction of a transmitting lobe.
    #[inline]
    #[must_use]
    pub fn ior(&self) -> Option<f32> {
        match self {
            Lobe::Lambert(_) | Lobe::Phong(_) | Lobe::SpecularReflection(_) => None,
            Lobe::Dielectric(d) => Some(d.ior),
        }
    }
}
