//! The coated (glazed) lobe: a Lambertian base under a smooth dielectric clear coat — a glazed
//! tub, a plastic, varnished wood. Weidlich & Wilkie, "Arbitrarily Layered Micro-Facet
//! Surfaces" (GRAPHITE 2007), with a smooth coat: the coat reflects the Fresnel reflectance
//! `F(θₒ)` as a delta mirror (untinted), and the light it transmits reaches the base, scatters
//! diffusely and leaves through the coat again:
//!
//! ```text
//! f_base(ωₒ, ωᵢ) = (1 − F(θₒ)) (1 − F(θᵢ)) / η² · ρ / (π (1 − F_dr,int))
//! ```
//!
//! `η` the coat's index, `F` its dielectric Fresnel seen from outside, `ρ` the base albedo, and
//! `1/(1 − F_dr,int)` the Saunderson correction (Saunderson 1942) for the light the base
//! returns, which the inside of the coat reflects back down with its hemispherical
//! (cosine-weighted) internal reflectance `F_dr,int`, over and over: the geometric series
//! `Σ F_dr,intᵏ` of a white base, applied linearly so that the base keeps the colour the scene
//! gives it. This is the model of Mitsuba 3's `plastic` with `nonlinear = false` (its
//! `nonlinear = true`, the colour-dependent series `ρ Σ (F_dr,int ρ)ᵏ` that darkens and
//! saturates colours, is not offered). `F_dr` is integrated numerically here (not fitted), so the
//! identity `η² (1 − F_dr,int) = 1 − F_dr,ext` holds and the directional albedo is exactly
//! `F(θₒ) + (1 − F(θₒ)) ρ`: 1 at every angle for a white base.
//!
//! The BSDF mixture holds the two layers as two parts of weight 1 ([`CoatLayer`]): the coat's
//! delta reflection, and the base (non-delta, sampled by the cosine). Sampling chooses between
//! them in proportion to `F(θₒ)` and `(1 − F(θₒ)) ρ̄`, as Mitsuba's plastic does. The value is
//! symmetric in `ωₒ` and `ωᵢ` (reciprocal) and the same in both transport modes. A rough coat
//! (a GGX interface) is not implemented.

use glam::Vec3;
use std::f32::consts::PI;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::lambert::Lambert;
use super::optics::fresnel_dielectric;
use super::scattering::{BsdfSample, LobeFlags, ShadingFrame, TransportMode};
use super::specular_reflection::SpecularReflection;

/// Which layer of a coated material a lobe of the mixture is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoatLayer {
    /// The clear coat's Fresnel mirror (a delta lobe).
    Coat,
    /// The diffuse base seen through the coat (a non-delta lobe).
    Base,
}

/// One layer of a coated material as a lobe of the mixture: the coat's Fresnel mirror (delta)
/// or the base seen through it (diffuse); a coated material has one part of each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoatedLobe {
    /// The coat and its diffuse reflectances.
    pub coat: Coated,
    /// Which layer this lobe is.
    pub layer: CoatLayer,
}

/// A smooth clear coat of index `ior` over a Lambertian base whose albedo is the mixture's
/// tint. Build it with [`Coated::new`], which integrates the coat's diffuse reflectances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coated {
    /// The coat's index of refraction relative to the outside (> 0; 1.5 for a glaze).
    pub ior: f32,
    /// `1/(η² π (1 − F_dr,int))`: the base's value per unit albedo and coat transmittances.
    scale: f32,
    /// `1/η²`.
    inv_eta2: f32,
    /// The coat's cosine-weighted hemispherical reflectance seen from inside (towards the base),
    /// `F_dr,int`, total internal reflection included.
    internal: f32,
    /// The same seen from outside, `F_dr,ext`: the coat's mean reflectance under uniform light.
    external: f32,
}

impl Coated {
    /// Flags of the coat layer: delta reflection.
    pub const COAT_FLAGS: LobeFlags = LobeFlags::DELTA.union(LobeFlags::REFLECTION);
    /// Flags of the base layer: diffuse reflection.
    pub const BASE_FLAGS: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::REFLECTION);

    /// A coat of relative index `ior` (finite, > 0; validated by the scene checks): its
    /// internal and external diffuse reflectances by quadrature ([`diffuse_fresnel`]).
    #[must_use]
    pub fn new(ior: f32) -> Self {
        let eta = f64::from(ior);
        let internal = diffuse_fresnel(eta);
        Self {
            ior,
            scale: (1.0 / (eta * eta * std::f64::consts::PI * (1.0 - internal))) as f32,
            inv_eta2: (1.0 / (eta * eta)) as f32,
            internal: internal as f32,
            external: diffuse_fresnel(1.0 / eta) as f32,
        }
    }

    /// The same coat with another internal reflectance `F_dr,int` (tests: Mitsuba's fitted one).
    #[cfg(test)]
    #[must_use]
    pub(crate) fn with_internal_reflectance(mut self, internal: f32) -> Self {
        self.internal = internal;
        self.scale = self.inv_eta2 / (PI * (1.0 - internal));
        self
    }

    /// `F_dr,int`: the coat's cosine-weighted reflectance seen from the base.
    #[must_use]
    pub fn internal_reflectance(&self) -> f32 {
        self.internal
    }

    /// `F_dr,ext`: the coat's cosine-weighted reflectance seen from outside.
    #[must_use]
    pub fn external_reflectance(&self) -> f32 {
        self.external
    }

    /// The coat's Fresnel reflectance at incidence cosine `cos` (outside, ≥ 0).
    #[inline]
    #[must_use]
    pub fn fresnel(&self, cos: f32) -> f32 {
        fresnel_dielectric(cos, 1.0 / self.ior)
    }

    /// The coat's reflectance at `wo` (what [`Bxdf::prepare`] keeps for both layers).
    #[inline]
    #[must_use]
    pub fn fresnel_at(&self, wo: Vec3, fr: &ShadingFrame) -> f32 {
        self.fresnel(wo.dot(fr.ns).abs())
    }

    /// The layer's sampling weight given the coat's reflectance `fresnel` at `wo` and the
    /// tint's mean `rho`: `F` for the coat, `(1 − F) ρ̄` for the base.
    #[inline]
    #[must_use]
    pub fn albedo(&self, layer: CoatLayer, fresnel: f32, rho: f32) -> f32 {
        match layer {
            CoatLayer::Coat => fresnel,
            CoatLayer::Base => (1.0 - fresnel) * rho,
        }
    }

    /// The base's value `f_base(wo, wi)` (per steradian, see the module docs) for albedo
    /// `tint`: 0 unless both directions are above the shading normal `n`.
    #[inline]
    #[must_use]
    pub fn base_f(&self, tint: Vec3, wo: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
        let (co, ci) = (n.dot(wo), n.dot(wi));
        if co <= 0.0 || ci <= 0.0 {
            return Vec3::ZERO;
        }
        tint * ((1.0 - self.fresnel(co)) * (1.0 - self.fresnel(ci)) * self.scale)
    }

    /// The coat's mirror direction, chosen by the mixture with probability `prob` for a part of
    /// weight `weight`: weight `F(θₒ) · weight / prob` (times the adjoint correction in
    /// importance mode), `pdf = prob`. `None` when `prob` is 0.
    #[inline]
    #[must_use]
    pub fn sample_coat(
        &self,
        fresnel: f32,
        wo: Vec3,
        fr: &ShadingFrame,
        mode: TransportMode,
        weight: f32,
        prob: f32,
    ) -> Option<BsdfSample> {
        SpecularReflection::mirror_sample(wo, fr, mode, weight, prob, Vec3::splat(fresnel))
    }

    /// The directional albedo `F(θₒ) + ∫ f_base cos θᵢ dωᵢ` in closed form for incidence
    /// cosine `cos` and base albedo `rho`: `F + (1 − F) ρ (1 − F_dr,ext) / (η² (1 − F_dr,int))`
    /// per channel (`F + (1 − F) ρ` with the integrated `F_dr`).
    #[must_use]
    pub fn directional_albedo(&self, cos: f32, rho: Vec3) -> Vec3 {
        let f = self.fresnel(cos);
        Vec3::splat(f) + rho * ((1.0 - f) * (1.0 - self.external) * self.scale * PI)
    }
}

/// The cosine-weighted hemispherical reflectance `F_dr(η) = ∫₀¹ F(μ; η) 2μ dμ` of a smooth
/// boundary for light arriving from the side of relative index `eta = η_incident/η_transmitted`
/// (total internal reflection counts as 1), in f64: the part beyond the critical angle in closed
/// form (`μ_c²`), the rest by 4 096-point midpoint quadrature in `s = √(μ − μ_c)` (which removes the square-root kink at the critical angle); the error is
/// below 10⁻⁸.
#[must_use]
pub fn diffuse_fresnel(eta: f64) -> f64 {
    let mu_c = if eta > 1.0 {
        (1.0 - 1.0 / (eta * eta)).sqrt()
    } else {
        0.0
    };
    let span = (1.0 - mu_c).sqrt();
    let n = 4096;
    let ds = span / f64::from(n);
    let mut sum = 0.0f64;
    for i in 0..n {
        let s = (f64::from(i) + 0.5) * ds;
        let mu = mu_c + s * s;
        // dμ = 2s ds.
        sum += fresnel_f64(mu, eta) * 2.0 * mu * 2.0 * s;
    }
    mu_c * mu_c + sum * ds
}

/// The unpolarised dielectric Fresnel reflectance in f64 (the formula of
/// [`fresnel_dielectric`]).
fn fresnel_f64(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

// Every field, the ones `Coated::new` derives from `ior` too.
crate::key_hash_struct!(Coated {
    ior,
    scale,
    inv_eta2,
    internal,
    external
});

crate::key_hash_struct!(CoatedLobe { coat, layer });

impl Bxdf for CoatedLobe {
    fn info(&self) -> LobeInfo {
        // The coat: delta reflection, focusing its mean reflectance `F_dr,ext`; the base: diffuse.
        let (flags, focusing_fraction) = match self.layer {
            CoatLayer::Coat => (Coated::COAT_FLAGS, self.coat.external_reflectance()),
            CoatLayer::Base => (Coated::BASE_FLAGS, 0.0),
        };
        LobeInfo {
            flags,
            uses_lobe_number: false,
            focusing_fraction,
            ior: None,
            distribution: None,
        }
    }

    /// The base's value ([`Coated::base_f`]); 0 for the coat (a delta lobe).
    #[inline]
    fn f(&self, ctx: &LobeContext<'_>, wi: Vec3, _mode: TransportMode) -> Vec3 {
        match self.layer {
            CoatLayer::Base => self.coat.base_f(ctx.tint, ctx.wo, wi, ctx.fr.ns),
            CoatLayer::Coat => Vec3::ZERO,
        }
    }

    /// The base samples like Lambert; the coat has no density.
    #[inline]
    fn pdf(&self, ctx: &LobeContext<'_>, wi: Vec3, share: f32) -> f32 {
        match self.layer {
            CoatLayer::Base => Lambert::scaled_density(share, wi, ctx.fr),
            CoatLayer::Coat => 0.0,
        }
    }

    /// The base: a cosine-distributed direction; the coat: its mirror direction of weight
    /// `F(θₒ) · weight / prob` ([`Coated::sample_coat`]).
    #[inline]
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        let coat = &self.coat;
        let (wo, fr, mode, weight, prob) = (ctx.wo, ctx.fr, draw.mode, draw.weight, draw.prob);
        match (self.layer, draw.prepared) {
            (CoatLayer::Base, _) => Some(LobeSample::Direction(Lambert::direction(draw.u, fr))),
            (CoatLayer::Coat, Prepared::Reflectance(f)) => coat
                .sample_coat(*f, wo, fr, mode, weight, prob)
                .map(LobeSample::Delta),
            (CoatLayer::Coat, Prepared::Nothing | Prepared::Fresnel(_)) => coat
                .sample_coat(coat.fresnel_at(wo, fr), wo, fr, mode, weight, prob)
                .map(LobeSample::Delta),
        }
    }

    /// The coat's reflectance at `wo` (both layers).
    fn prepare(&self, ctx: &LobeContext<'_>) -> Prepared {
        Prepared::Reflectance(self.coat.fresnel_at(ctx.wo, ctx.fr))
    }

    /// [`Coated::albedo`] of the layer (0 if unprepared).
    fn albedo(&self, prepared: &Prepared, rho: f32) -> f32 {
        match prepared {
            Prepared::Reflectance(f) => self.coat.albedo(self.layer, *f, rho),
            Prepared::Nothing | Prepared::Fresnel(_) => 0.0,
        }
    }

    /// The coat: `F(θₒ)` times the part's weight along the mirror direction.
    fn delta_weights(&self, ctx: &LobeContext<'_>, weight: f32) -> DeltaWeights {
        match self.layer {
            CoatLayer::Coat => DeltaWeights {
                reflect: Vec3::splat(self.coat.fresnel_at(ctx.wo, ctx.fr) * weight),
                refract: None,
            },
            CoatLayer::Base => DeltaWeights::NONE,
        }
    }

    fn straight_transmittance(
        &self,
        _weight: f32,
        _tint: Vec3,
        _cos: f32,
        _entering: bool,
    ) -> Vec3 {
        Vec3::ZERO
    }

    fn is_black(&self, tint: Vec3) -> bool {
        self.layer == CoatLayer::Base && tint == Vec3::ZERO
    }

    /// The coat has no non-delta value; the base's follows the coat's transmittance
    /// `1 − F(θᵢ)`.
    fn is_flat(&self, tint: Vec3) -> bool {
        match self.layer {
            CoatLayer::Coat => true,
            CoatLayer::Base => self.is_black(tint),
        }
    }
}

impl crate::binfile::KeyHash for CoatLayer {
    fn key_hash(&self, h: &mut crate::binfile::Fnv) {
        h.str(match self {
            CoatLayer::Coat => "Coat",
            CoatLayer::Base => "Base",
        });
    }
}

#[cfg(test)]
#[path = "coated_tests.rs"]
mod tests;
