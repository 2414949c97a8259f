//! The rough conductor (brushed and rough metals): a GGX microfacet BRDF with height-correlated
//! Smith masking-shadowing and a conductor Fresnel (Walter et al., "Microfacet Models for
//! Refraction through Rough Surfaces", EGSR 2007, eq. 20; Heitz 2014):
//!
//! `f(wo, wi) = F(wo·h) D(h) G2(wo, wi) / (4 |cos θo| |cos θi|)`, `h = (wo + wi)/|wo + wi|`,
//!
//! sampled by visible normals (Heitz 2018): `h ~ D_wo`, `wi = reflect(wo, h)`, with density
//! `pdf(wi) = D_wo(h) / (4 |wo·h|)`; the sample's weight `f cos θi / pdf = F G2 / G1(wo)`.
//!
//! The model is single scattering: light that would bounce between microfacets is lost, so a
//! white rough metal reflects less than 1 at grazing angles and high roughness (the figures
//! are in docs/material.md). Roughness 0 is not this lobe: a material of roughness 0 is the
//! perfect mirror ([`super::bsdf`]'s mirror part), bit for bit, which the scene compiler
//! substitutes. `f` is the same in both transport modes (a reflection has no η² factor); the
//! adjoint shading-normal correction is applied by [`RoughConductor::sample_alone`] as for every
//! `BsdfSample`, and by the mixture's `eval` for `f`.

use glam::Vec3;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::conductor::ConductorFresnel;
use super::microfacet::Ggx;
use super::optics::reflect;
use super::{BsdfSample, LobeFlags, ShadingFrame, TransportMode, shading_normal_correction};
use crate::geometry::Frame;

/// A rough metal: its microfacet distribution and its Fresnel reflectance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughConductor {
    /// The microfacet normals' distribution (its `x` axis is the shading frame's first tangent).
    pub distribution: Ggx,
    /// Reflectance of one microfacet.
    pub fresnel: ConductorFresnel,
    /// Multiply by the mixture's tint (a rough mirror without a conductor: its Fresnel is 1 and
    /// the material's colour is its reflectance, as for the perfect mirror).
    pub tinted: bool,
}

impl RoughConductor {
    /// `f(wo, wi)` in the local frame (`z` the shading normal), per steradian: 0 unless both
    /// directions are above the surface. Symmetric in `wo` and `wi`.
    #[inline]
    #[must_use]
    pub fn f_local(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let Some(h) = (wo + wi).try_normalize() else {
            return Vec3::ZERO;
        };
        let d = self.distribution.d(h);
        let g = self.distribution.g2(wo, wi);
        self.fresnel.eval(wo.dot(h)) * (d * g / (4.0 * wo.z * wi.z))
    }

    /// Solid-angle density with which [`RoughConductor::sample_local`] returns `wi`:
    /// `D_wo(h) / (4 wo·h)` above the surface, 0 below.
    #[inline]
    #[must_use]
    pub fn pdf_local(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let Some(h) = (wo + wi).try_normalize() else {
            return 0.0;
        };
        let c = wo.dot(h);
        if c <= 0.0 {
            return 0.0;
        }
        self.distribution.visible_pdf(wo, h) / (4.0 * c)
    }

    /// A direction reflected about a visible normal drawn with `u ∈ [0, 1)²`; `None` when `wo`
    /// is below the surface or the reflection goes below it (that probability is lost: the
    /// density [`RoughConductor::pdf_local`] integrates to less than 1).
    #[inline]
    #[must_use]
    pub fn sample_local(&self, wo: Vec3, u: (f32, f32)) -> Option<Vec3> {
        if wo.z <= 0.0 {
            return None;
        }
        let h = self.distribution.sample_visible(wo, u);
        let wi = reflect(wo, h);
        (wi.z > 0.0).then_some(wi)
    }

    /// The lobe's mean reflectance at the macro-surface, `mean F(|wo·ns|)`: its share when the
    /// mixture picks a lobe.
    #[inline]
    #[must_use]
    pub fn mean_reflectance(&self, wo: Vec3, fr: &ShadingFrame) -> f32 {
        let f = self.fresnel.eval(wo.dot(fr.ns).abs());
        (f.x + f.y + f.z) * (1.0 / 3.0)
    }

    /// `f(wo, wi)` for world directions in frame `fr` (the tangent frame is
    /// `Frame::from_normal(fr.ns)`), 0 unless `wi` is above both the shading and the geometric
    /// surface.
    // Out of line: inlined into the BSDF mixture, its frame and half-vector arithmetic was
    // hoisted above the lobe test and paid by every material (measured: scripts/hot_share.sh).
    #[inline(never)]
    #[must_use]
    pub fn value(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> Vec3 {
        if fr.ng.dot(wi) <= 0.0 {
            return Vec3::ZERO;
        }
        let frame = Frame::from_normal(fr.ns);
        self.f_local(frame.to_local(wo), frame.to_local(wi))
    }

    /// The density of [`RoughConductor::sample_alone`] at the world direction `wi` (0 where `f` is 0).
    // Out of line: inlined into the BSDF mixture, its frame and half-vector arithmetic was
    // hoisted above the lobe test and paid by every material (measured: scripts/hot_share.sh).
    #[inline(never)]
    #[must_use]
    pub fn density(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
        if fr.ng.dot(wi) <= 0.0 {
            return 0.0;
        }
        let frame = Frame::from_normal(fr.ns);
        self.pdf_local(frame.to_local(wo), frame.to_local(wi))
    }

    /// A world direction from [`RoughConductor::sample_local`] (the visible normals) for the
    /// world direction `wo` in frame `fr`, without its weight (the BSDF mixture weighs it);
    /// `None` when the sample is lost.
    // Out of line: inlined into the BSDF mixture, its frame and half-vector arithmetic was
    // hoisted above the lobe test and paid by every material (measured: scripts/hot_share.sh).
    #[inline(never)]
    #[must_use]
    pub fn direction(&self, wo: Vec3, u: (f32, f32), fr: &ShadingFrame) -> Option<Vec3> {
        let frame = Frame::from_normal(fr.ns);
        let li = self.sample_local(frame.to_local(wo), u)?;
        Some(frame.to_world(li))
    }

    /// A sampled world direction with its weight `f |ns·wi| / pdf` (times the adjoint
    /// correction in importance mode); `None` when the direction falls below the shading or
    /// geometric surface.
    #[inline]
    #[must_use]
    pub fn sample_alone(
        &self,
        wo: Vec3,
        u: (f32, f32),
        fr: &ShadingFrame,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        let frame = Frame::from_normal(fr.ns);
        let lo = frame.to_local(wo);
        let li = self.sample_local(lo, u)?;
        let wi = frame.to_world(li);
        if fr.ng.dot(wi) <= 0.0 {
            return None;
        }
        let pdf = self.pdf_local(lo, li);
        if !(pdf > 0.0) {
            return None;
        }
        let correction = match mode {
            TransportMode::Radiance => 1.0,
            TransportMode::Importance => shading_normal_correction(wo, wi, fr),
        };
        Some(BsdfSample {
            wi,
            weight: self.f_local(lo, li) * (li.z / pdf * correction),
            pdf,
            delta: false,
            transmitted: false,
            eta_scale: 1.0,
        })
    }
}

impl Bxdf for RoughConductor {
    fn info(&self) -> LobeInfo {
        LobeInfo {
            flags: LobeFlags::GLOSSY.union(LobeFlags::REFLECTION),
            uses_lobe_number: false,
            focusing_fraction: 0.0,
            ior: None,
            distribution: Some(self.distribution),
        }
    }

    /// [`RoughConductor::value`], times the tint if tinted.
    #[inline]
    fn f(&self, ctx: &LobeContext<'_>, wi: Vec3, _mode: TransportMode) -> Vec3 {
        let f = self.value(ctx.wo, wi, ctx.fr);
        if self.tinted { f * ctx.tint } else { f }
    }

    #[inline]
    fn pdf(&self, ctx: &LobeContext<'_>, wi: Vec3, share: f32) -> f32 {
        share * self.density(ctx.wo, wi, ctx.fr)
    }

    /// A direction from the visible normals ([`RoughConductor::direction`]).
    #[inline]
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        self.direction(ctx.wo, draw.u, ctx.fr)
            .map(LobeSample::Direction)
    }

    /// The mean reflectance at `wo`.
    fn prepare(&self, ctx: &LobeContext<'_>) -> Prepared {
        Prepared::Reflectance(self.mean_reflectance(ctx.wo, ctx.fr))
    }

    /// The prepared mean reflectance, times `rho` if tinted (0 if unprepared).
    fn albedo(&self, prepared: &Prepared, rho: f32) -> f32 {
        match prepared {
            Prepared::Reflectance(r) => {
                if self.tinted {
                    r * rho
                } else {
                    *r
                }
            }
            Prepared::Nothing | Prepared::Fresnel(_) => 0.0,
        }
    }

    fn delta_weights(&self, _ctx: &LobeContext<'_>, _weight: f32) -> DeltaWeights {
        DeltaWeights::NONE
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
        self.tinted && tint == Vec3::ZERO
    }

    fn is_flat(&self, tint: Vec3) -> bool {
        self.is_black(tint)
    }
}

crate::key_hash_struct!(RoughConductor {
    distribution,
    fresnel,
    tinted
});

#[cfg(test)]
#[path = "rough_conductor_tests.rs"]
mod tests;
