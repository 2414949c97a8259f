//! The lobes a BSDF mixture ([`super::Bsdf`]) is made of, dispatched by one enum (no virtual
//! calls per sample; pbrt-v4 tags its `BxDF`s the same way). Adding a lobe: write its file (its
//! `f`, `sample`, `pdf`, flags), add a variant here (the compiler lists every match to extend),
//! and give it a part in the mixture (`Bsdf::new`).

use glam::Vec3;

use super::coated::{CoatLayer, Coated};
use super::dielectric::{DeltaWeights, Dielectric, FresnelSplit};
use super::lambert::Lambert;
use super::optics::fresnel_dielectric;
use super::phong::Phong;
use super::rough_conductor::RoughConductor;
use super::rough_dielectric::RoughDielectric;
use super::scattering::{BsdfSample, LobeFlags, ShadingFrame, TransportMode};
use super::specular_conductor::SpecularConductor;
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
    /// Perfect mirror with a conductor's Fresnel reflectance (a polished metal).
    SpecularConductor(SpecularConductor),
    /// Smooth Fresnel dielectric.
    Dielectric(Dielectric),
    /// GGX microfacet metal ([`RoughConductor`]).
    RoughConductor {
        /// The microfacet lobe.
        lobe: RoughConductor,
        /// Multiply by the tint (a rough mirror without a conductor: its Fresnel is 1 and the
        /// material's colour is its reflectance, as for the perfect mirror).
        tinted: bool,
    },
    /// GGX microfacet dielectric ([`RoughDielectric`]): glossy reflection and transmission.
    RoughDielectric(RoughDielectric),
    /// One layer of a diffuse base under a smooth clear coat ([`Coated`]): the coat's Fresnel
    /// mirror (delta) or the base seen through it (diffuse); a coated material has one part of
    /// each.
    Coated {
        /// The coat and its diffuse reflectances.
        coat: Coated,
        /// Which layer this lobe is.
        layer: CoatLayer,
    },
}

/// What a lobe works out once per outgoing direction and reuses while the mixture weighs and
/// samples it: the dielectric's Fresnel split, the mean macro-surface reflectance of the metals
/// and the rough dielectric; nothing for the others.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Prepared {
    /// The lobe needs nothing.
    Nothing,
    /// The dielectric's split.
    Fresnel(FresnelSplit),
    /// The mean Fresnel reflectance at the macro-surface normal.
    Reflectance(f32),
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
            Lobe::SpecularConductor(_) => SpecularConductor::FLAGS,
            Lobe::Dielectric(_) => Dielectric::FLAGS,
            Lobe::RoughConductor { .. } => LobeFlags::GLOSSY.union(LobeFlags::REFLECTION),
            Lobe::RoughDielectric(_) => LobeFlags::GLOSSY
                .union(LobeFlags::REFLECTION)
                .union(LobeFlags::TRANSMISSION),
            Lobe::Coated {
                layer: CoatLayer::Coat,
                ..
            } => Coated::COAT_FLAGS,
            Lobe::Coated {
                layer: CoatLayer::Base,
                ..
            } => Coated::BASE_FLAGS,
        }
    }

    /// True if the lobe scatters nothing with this tint (so choosing it never matters).
    #[inline]
    #[must_use]
    pub fn is_black(&self, tint: Vec3) -> bool {
        match self {
            Lobe::Lambert(_) | Lobe::SpecularReflection(_) => tint == Vec3::ZERO,
            Lobe::Phong(p) => p.specular == Vec3::ZERO,
            Lobe::RoughConductor { tinted, .. } => *tinted && tint == Vec3::ZERO,
            Lobe::Coated { layer, .. } => *layer == CoatLayer::Base && tint == Vec3::ZERO,
            Lobe::SpecularConductor(_) | Lobe::Dielectric(_) | Lobe::RoughDielectric(_) => false,
        }
    }

    /// True if the lobe's non-delta value, where it has one, is the same for every incident
    /// direction above the surface (Lambert), or it has none (delta lobes), or it is black with
    /// this tint: what lets a photon map's irradiance stand in for a density estimate
    /// ([`super::Bsdf::is_diffuse_only`]).
    #[inline]
    #[must_use]
    pub fn is_flat(&self, tint: Vec3) -> bool {
        match self {
            Lobe::Lambert(_)
            | Lobe::SpecularReflection(_)
            | Lobe::SpecularConductor(_)
            | Lobe::Dielectric(_) => true,
            Lobe::Coated {
                layer: CoatLayer::Coat,
                ..
            } => true,
            // The base's value follows the coat's transmittance 1 − F(θᵢ).
            Lobe::Coated {
                layer: CoatLayer::Base,
                ..
            }
            | Lobe::Phong(_)
            | Lobe::RoughConductor { .. }
            | Lobe::RoughDielectric(_) => self.is_black(tint),
        }
    }

    /// The fraction of a delta part's weight that can focus light (by which caustic photons are
    /// aimed at an object): 1 for mirrors and dielectrics, the coat's mean reflectance
    /// `F_dr,ext` for a coat; 0 for non-delta lobes.
    #[inline]
    #[must_use]
    pub fn focusing_fraction(&self) -> f32 {
        match self {
            Lobe::SpecularReflection(_) | Lobe::SpecularConductor(_) | Lobe::Dielectric(_) => 1.0,
            Lobe::Coated {
                coat,
                layer: CoatLayer::Coat,
            } => coat.external_reflectance(),
            Lobe::Coated {
                layer: CoatLayer::Base,
                ..
            }
            | Lobe::Lambert(_)
            | Lobe::Phong(_)
            | Lobe::RoughConductor { .. }
            | Lobe::RoughDielectric(_) => 0.0,
        }
    }

    /// True if the lobe's own sampling reads the lobe number (the dielectrics choose between
    /// reflection and refraction with it).
    #[inline]
    #[must_use]
    pub fn uses_lobe_number(&self) -> bool {
        match self {
            Lobe::Lambert(_)
            | Lobe::Phong(_)
            | Lobe::SpecularReflection(_)
            | Lobe::SpecularConductor(_)
            | Lobe::RoughConductor { .. }
            | Lobe::Coated { .. } => false,
            Lobe::Dielectric(_) | Lobe::RoughDielectric(_) => true,
        }
    }

    /// The lobe's per-direction state for `wo`.
    #[inline]
    #[must_use]
    pub fn prepare(&self, wo: Vec3, fr: &ShadingFrame) -> Prepared {
        match self {
            Lobe::Lambert(_) | Lobe::Phong(_) | Lobe::SpecularReflection(_) => Prepared::Nothing,
            Lobe::Dielectric(d) => Prepared::Fresnel(d.split(wo, fr)),
            Lobe::SpecularConductor(s) => Prepared::Reflectance(s.albedo(wo, fr)),
            Lobe::RoughConductor { lobe, .. } => Prepared::Reflectance(lobe.albedo(wo, fr)),
            Lobe::RoughDielectric(d) => {
                Prepared::Reflectance(fresnel_dielectric(wo.dot(fr.ns), 1.0 / d.eta(fr.entering)))
            }
            Lobe::Coated { coat, .. } => Prepared::Reflectance(coat.fresnel_at(wo, fr)),
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
            (Lobe::Dielectric(_), Prepared::Nothing | Prepared::Reflectance(_)) => 0.0,
            (Lobe::SpecularConductor(_), Prepared::Reflectance(r)) => *r,
            (Lobe::RoughConductor { tinted, .. }, Prepared::Reflectance(r)) => {
                if *tinted {
                    r * rho
                } else {
                    *r
                }
            }
            (Lobe::RoughDielectric(_), Prepared::Reflectance(f)) => f + (1.0 - f) * rho,
            (Lobe::Coated { coat, layer }, Prepared::Reflectance(f)) => {
                coat.albedo(*layer, *f, rho)
            }
            (
                Lobe::SpecularConductor(_)
                | Lobe::RoughConductor { .. }
                | Lobe::RoughDielectric(_)
                | Lobe::Coated { .. },
                Prepared::Nothing | Prepared::Fresnel(_),
            ) => 0.0,
        }
    }

    /// The lobe's value `f(wo, wi)` (per steradian) in frame `fr` and transport mode `mode`
    /// (only the rough dielectric's transmission depends on it: η² in importance mode): 0 for
    /// delta lobes.
    #[inline]
    #[must_use]
    pub fn f(
        &self,
        wo: Vec3,
        wi: Vec3,
        fr: &ShadingFrame,
        mode: TransportMode,
        tint: Vec3,
    ) -> Vec3 {
        match self {
            Lobe::Lambert(l) => l.f(tint, wi, fr.ns),
            Lobe::Phong(p) => p.f(wo, wi, fr.ns),
            Lobe::SpecularReflection(s) => s.f(),
            Lobe::Dielectric(d) => d.f(),
            Lobe::SpecularConductor(_) => Vec3::ZERO,
            Lobe::RoughConductor { lobe, tinted } => {
                let f = lobe.f(wo, wi, fr);
                if *tinted { f * tint } else { f }
            }
            Lobe::RoughDielectric(d) => d.f(wo, wi, fr, mode, tint),
            Lobe::Coated {
                coat,
                layer: CoatLayer::Base,
            } => coat.base_f(tint, wo, wi, fr.ns),
            Lobe::Coated {
                layer: CoatLayer::Coat,
                ..
            } => Vec3::ZERO,
        }
    }

    /// `share` times the lobe's sampling density at `wi` (0 for delta lobes).
    #[inline]
    #[must_use]
    pub fn scaled_pdf(&self, share: f32, wo: Vec3, wi: Vec3, fr: &ShadingFrame, tint: Vec3) -> f32 {
        match self {
            Lobe::Lambert(l) => l.scaled_pdf(share, wi, fr),
            Lobe::Phong(p) => p.scaled_pdf(share, wo, wi, fr),
            Lobe::SpecularReflection(s) => share * s.pdf(),
            Lobe::Dielectric(d) => share * d.pdf(),
            Lobe::SpecularConductor(_) => 0.0,
            Lobe::RoughConductor { lobe, .. } => share * lobe.pdf(wo, wi, fr),
            Lobe::RoughDielectric(d) => share * d.pdf(wo, wi, fr, tint),
            Lobe::Coated {
                layer: CoatLayer::Base,
                ..
            } => Lambert.scaled_pdf(share, wi, fr),
            Lobe::Coated {
                layer: CoatLayer::Coat,
                ..
            } => 0.0,
        }
    }

    /// A direction from a non-delta lobe's density (`None` for delta lobes, which the mixture
    /// samples through [`Lobe::sample_delta`], and when the sample is lost below the surface);
    /// `v ∈ [0, 1)` is the rest of the lobe number (the rough dielectric's choice of reflection
    /// or refraction).
    #[inline]
    #[must_use]
    pub fn sample_direction(
        &self,
        wo: Vec3,
        v: f32,
        u: (f32, f32),
        fr: &ShadingFrame,
        tint: Vec3,
    ) -> Option<Vec3> {
        match self {
            Lobe::Lambert(l) => Some(l.sample(u, fr)),
            Lobe::Phong(p) => Some(p.sample(wo, u, fr)),
            Lobe::SpecularReflection(_)
            | Lobe::SpecularConductor(_)
            | Lobe::Dielectric(_)
            | Lobe::Coated {
                layer: CoatLayer::Coat,
                ..
            } => None,
            Lobe::Coated {
                layer: CoatLayer::Base,
                ..
            } => Some(Lambert.sample(u, fr)),
            Lobe::RoughConductor { lobe, .. } => lobe.sample_direction(wo, u, fr),
            Lobe::RoughDielectric(d) => d.sample_direction(wo, v, u, fr, tint),
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
            (
                Lobe::Lambert(_)
                | Lobe::Phong(_)
                | Lobe::RoughConductor { .. }
                | Lobe::RoughDielectric(_)
                | Lobe::Coated {
                    layer: CoatLayer::Base,
                    ..
                },
                _,
            ) => None,
            (
                Lobe::Coated {
                    coat,
                    layer: CoatLayer::Coat,
                },
                Prepared::Reflectance(f),
            ) => coat.sample_coat(*f, wo, fr, mode, weight, prob),
            (
                Lobe::Coated {
                    coat,
                    layer: CoatLayer::Coat,
                },
                Prepared::Nothing | Prepared::Fresnel(_),
            ) => coat.sample_coat(coat.fresnel_at(wo, fr), wo, fr, mode, weight, prob),
            (Lobe::SpecularReflection(s), _) => s.sample(wo, fr, mode, weight, prob, tint),
            (Lobe::SpecularConductor(s), _) => s.sample(wo, fr, mode, weight, prob),
            (Lobe::Dielectric(d), Prepared::Fresnel(split)) => {
                d.sample(split, wo, v, fr, mode, weight, prob, tint, rho)
            }
            (Lobe::Dielectric(d), Prepared::Nothing | Prepared::Reflectance(_)) => {
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
            Lobe::Lambert(_)
            | Lobe::Phong(_)
            | Lobe::RoughConductor { .. }
            | Lobe::RoughDielectric(_)
            | Lobe::Coated {
                layer: CoatLayer::Base,
                ..
            } => DeltaWeights {
                reflect: Vec3::ZERO,
                refract: None,
            },
            Lobe::Coated {
                coat,
                layer: CoatLayer::Coat,
            } => DeltaWeights {
                reflect: Vec3::splat(coat.fresnel_at(wo, fr) * weight),
                refract: None,
            },
            Lobe::SpecularReflection(_) => DeltaWeights {
                reflect: tint * weight,
                refract: None,
            },
            Lobe::SpecularConductor(s) => DeltaWeights {
                reflect: s.reflectance(wo, fr) * weight,
                refract: None,
            },
            Lobe::Dielectric(d) => d.delta_weights(&d.split(wo, fr), weight, tint),
        }
    }

    /// The straight-line transmittance of a part of weight `weight` (0 unless it transmits);
    /// a rough dielectric is treated as its smooth counterpart (its Fresnel at the
    /// macro-surface), for integrators that do not follow refraction.
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
            Lobe::Lambert(_)
            | Lobe::Phong(_)
            | Lobe::SpecularReflection(_)
            | Lobe::SpecularConductor(_)
            | Lobe::RoughConductor { .. }
            | Lobe::Coated { .. } => Vec3::ZERO,
            Lobe::Dielectric(d) => d.straight_transmittance(weight, tint, cos, entering),
            Lobe::RoughDielectric(r) => {
                Dielectric { ior: r.ior }.straight_transmittance(weight, tint, cos, entering)
            }
        }
    }

    /// The relative index of refraction of a transmitting lobe.
    #[inline]
    #[must_use]
    pub fn ior(&self) -> Option<f32> {
        match self {
            Lobe::Lambert(_)
            | Lobe::Phong(_)
            | Lobe::SpecularReflection(_)
            | Lobe::SpecularConductor(_)
            | Lobe::RoughConductor { .. }
            | Lobe::Coated { .. } => None,
            Lobe::Dielectric(d) => Some(d.ior),
            Lobe::RoughDielectric(r) => Some(r.ior),
        }
    }
}
