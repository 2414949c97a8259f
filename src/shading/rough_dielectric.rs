//! The rough dielectric (frosted glass, rough water): GGX reflection and transmission through
//! a rough boundary (Walter, Marschner, Li, Torrance, "Microfacet Models for Refraction through
//! Rough Surfaces", EGSR 2007), sampled by visible normals (Heitz 2018).
//!
//! In the local frame (`z` the shading normal on the side of `wo`, so `wo.z > 0`), with `η` the
//! index on the side of `wi` over the index on the side of `wo` for a transmission (`ior`
//! entering, `1/ior` leaving) and `F` the dielectric Fresnel reflectance at `wo·h`:
//!
//! - reflection (`wi.z > 0`): `h = (wo + wi)/|·|`, `f_r = F D G2 / (4 cos θo cos θi)` (untinted);
//! - transmission (`wi.z < 0`): the generalised half vector `h ∝ ±(wo + η wi)` (Walter eq. 16,
//!   oriented so `h.z > 0`), valid when `wo·h > 0 > wi·h`;
//!   `f_t = tint (1 − F) D G2 |wo·h| |wi·h| / (|cos θo| |cos θi| (wo·h + η wi·h)²) · s`,
//!   with `s = 1` in radiance mode (Walter eq. 21: radiance crossing into the side of `wi`
//!   scales by `(ηₒ/ηᵢ)² = 1/η²`, the same convention as the smooth dielectric) and `s = η²` in
//!   importance mode (flux is conserved). So `f_radiance(wo, wi) = f_importance(wi, wo)`
//!   (Veach 1997, §5.2: the adjoint BSDF), and `f_radiance(wo, wi)/ηₒ² = f_radiance(wi, wo)/ηᵢ²`.
//!
//! Sampling draws `h ~ D_wo`, then reflection with probability `P_r = F/(F + (1 − F)ρ̄)` (`ρ̄`
//! the tint's mean, as the smooth dielectric does; `P_r = F` for clear glass) and refraction
//! otherwise; `pdf = D_wo(h) P_r / (4 wo·h)` for reflection and `D_wo(h) (1 − P_r) η² |wi·h| /
//! (wo·h + η wi·h)²` for transmission (Walter eq. 17, the Jacobian of the refracted half vector).
//!
//! Two cases are not this lobe: roughness 0 is the smooth dielectric (the scene compiler
//! substitutes it, bit for bit); and `ior = 1` (an index-matched surface, whose microfacets bend
//! nothing) is a pass-through at any roughness: [`RoughDielectric::is_pass_through`], `f` and
//! `pdf` are 0 and [`RoughDielectric::sample_alone`] returns the delta sample `wi = −wo`, weight
//! `tint`.

use glam::Vec3;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::dielectric::Dielectric;
use super::microfacet::Ggx;
use super::optics::{fresnel_dielectric, reflect, refract};
use super::{BsdfSample, LobeFlags, ShadingFrame, TransportMode, shading_normal_correction};
use crate::geometry::Frame;

/// A rough dielectric boundary: its microfacet distribution and index of refraction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughDielectric {
    /// The microfacet normals' distribution (its `x` axis is the shading frame's first tangent).
    pub distribution: Ggx,
    /// Index of refraction of the inside relative to the outside, > 0.
    pub ior: f32,
}

/// A sampled direction in the local frame, with the lobe's value and density there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalSample {
    /// The direction (local frame).
    pub wi: Vec3,
    /// `f(wo, wi)` in the requested transport mode.
    pub f: Vec3,
    /// Solid-angle density of `wi`.
    pub pdf: f32,
    /// `wi` is below the surface (refraction).
    pub transmitted: bool,
}

/// Mean of the three channels.
#[inline]
fn mean(c: Vec3) -> f32 {
    (c.x + c.y + c.z) * (1.0 / 3.0)
}

/// Probability of choosing reflection at a microfacet of Fresnel reflectance `fresnel`.
#[inline]
fn reflect_probability(fresnel: f32, rho: f32) -> f32 {
    let denom = fresnel + (1.0 - fresnel) * rho;
    if denom > 0.0 { fresnel / denom } else { 1.0 }
}

impl RoughDielectric {
    /// True for an index-matched boundary (`ior == 1`): a straight pass-through (a delta lobe).
    #[inline]
    #[must_use]
    pub fn is_pass_through(&self) -> bool {
        self.ior == 1.0
    }

    /// `η = η(wi side) / η(wo side)` of a transmission: `ior` when `wo` is outside.
    #[inline]
    #[must_use]
    pub fn eta(&self, entering: bool) -> f32 {
        if entering { self.ior } else { 1.0 / self.ior }
    }

    /// The value and density at `(wo, wi)` in the local frame (`wo.z > 0`), sharing the half
    /// vector, D, G2 and F; `(0, 0)` where the lobe cannot scatter.
    #[inline]
    fn eval_local(
        &self,
        wo: Vec3,
        wi: Vec3,
        entering: bool,
        mode: TransportMode,
        tint: Vec3,
    ) -> (Vec3, f32) {
        const NONE: (Vec3, f32) = (Vec3::ZERO, 0.0);
        if self.is_pass_through() || wo.z <= 0.0 || wi.z == 0.0 {
            return NONE;
        }
        let reflection = wi.z > 0.0;
        let eta = self.eta(entering);
        let h = if reflection { wo + wi } else { wo + wi * eta };
        let Some(h) = h.try_normalize() else {
            return NONE;
        };
        let h = if h.z < 0.0 { -h } else { h };
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        // Each direction must lie on its own side of the microfacet too.
        if oh <= 0.0 || ih * wi.z <= 0.0 {
            return NONE;
        }
        let d = self.distribution.d(h);
        let fresnel = fresnel_dielectric(oh, 1.0 / eta);
        let p_r = reflect_probability(fresnel, mean(tint));
        let vis = self.distribution.visible_pdf(wo, h);
        let g = self.distribution.g2(wo, wi);
        if reflection {
            let f = fresnel * d * g / (4.0 * wo.z * wi.z);
            (Vec3::splat(f), vis * p_r / (4.0 * oh))
        } else {
            let denom = oh + eta * ih;
            let denom2 = denom * denom;
            if !(denom2 > 0.0) {
                return NONE;
            }
            let scale = match mode {
                TransportMode::Radiance => 1.0,
                TransportMode::Importance => eta * eta,
            };
            let f = (1.0 - fresnel) * d * g * (oh * ih).abs() / (wo.z * wi.z.abs() * denom2);
            let jacobian = eta * eta * ih.abs() / denom2;
            (tint * (f * scale), vis * (1.0 - p_r) * jacobian)
        }
    }

    /// `f(wo, wi)` in the local frame (`z` the shading normal on the side of `wo`), per
    /// steradian, in transport mode `mode`, the transmitted part tinted by `tint`; `entering`
    /// says `wo` is outside. 0 for `wo.z ≤ 0` and for a pass-through.
    #[inline]
    #[must_use]
    pub fn f_local(
        &self,
        wo: Vec3,
        wi: Vec3,
        entering: bool,
        mode: TransportMode,
        tint: Vec3,
    ) -> Vec3 {
        self.eval_local(wo, wi, entering, mode, tint).0
    }

    /// Solid-angle density with which [`RoughDielectric::sample_local`] returns `wi` (it
    /// depends on the tint through the reflection probability).
    #[inline]
    #[must_use]
    pub fn pdf_local(&self, wo: Vec3, wi: Vec3, entering: bool, tint: Vec3) -> f32 {
        self.eval_local(wo, wi, entering, TransportMode::Radiance, tint)
            .1
    }

    /// A direction from a visible normal drawn with `u ∈ [0, 1)²`, reflected or refracted as
    /// `u_lobe ∈ [0, 1)` chooses, with its value and density. `None` when `wo.z ≤ 0`, for a
    /// pass-through, or when the direction ends on the wrong side of the surface (that
    /// probability is lost).
    #[inline]
    #[must_use]
    pub fn sample_local(
        &self,
        wo: Vec3,
        u_lobe: f32,
        u: (f32, f32),
        entering: bool,
        mode: TransportMode,
        tint: Vec3,
    ) -> Option<LocalSample> {
        if self.is_pass_through() || wo.z <= 0.0 {
            return None;
        }
        let eta = self.eta(entering);
        let h = self.distribution.sample_visible(wo, u);
        let fresnel = fresnel_dielectric(wo.dot(h), 1.0 / eta);
        let (wi, transmitted) = if u_lobe < reflect_probability(fresnel, mean(tint)) {
            (reflect(wo, h), false)
        } else {
            (refract(wo, h, 1.0 / eta)?, true)
        };
        if (wi.z < 0.0) != transmitted || wi.z == 0.0 {
            return None;
        }
        let (f, pdf) = self.eval_local(wo, wi, entering, mode, tint);
        (pdf > 0.0).then_some(LocalSample {
            wi,
            f,
            pdf,
            transmitted,
        })
    }

    /// The lobe's share when the mixture picks a lobe: `F + (1 − F)ρ̄` at the macro-surface
    /// (as the smooth dielectric), `rho` the tint's mean; `rho` for a pass-through.
    #[inline]
    #[must_use]
    pub fn mean_albedo(&self, wo: Vec3, fr: &ShadingFrame, rho: f32) -> f32 {
        if self.is_pass_through() {
            return rho;
        }
        let fresnel = fresnel_dielectric(wo.dot(fr.ns), 1.0 / self.eta(fr.entering));
        fresnel + (1.0 - fresnel) * rho
    }

    /// Whether the world direction `wi` is a valid reflection (above both normals) or
    /// transmission (below both) in `fr`, and its local coordinates.
    #[inline]
    fn classify(fr: &ShadingFrame, frame: &Frame, wi: Vec3) -> Option<Vec3> {
        let li = frame.to_local(wi);
        let g = fr.ng.dot(wi);
        ((li.z > 0.0 && g > 0.0) || (li.z < 0.0 && g < 0.0)).then_some(li)
    }

    /// `f(wo, wi)` for world directions in frame `fr` (tangent frame `Frame::from_normal(fr.ns)`),
    /// in mode `mode`: 0 when the shading and geometric normals disagree about which side `wi`
    /// is on (no light leaks through a surface a shading normal leans over).
    // Out of line: inlined into the BSDF mixture, its frame and half-vector arithmetic was
    // hoisted above the lobe test and paid by every material (measured: scripts/hot_share.sh).
    #[inline(never)]
    #[must_use]
    pub fn value(
        &self,
        wo: Vec3,
        wi: Vec3,
        fr: &ShadingFrame,
        mode: TransportMode,
        tint: Vec3,
    ) -> Vec3 {
        let frame = Frame::from_normal(fr.ns);
        Self::classify(fr, &frame, wi).map_or(Vec3::ZERO, |li| {
            self.f_local(frame.to_local(wo), li, fr.entering, mode, tint)
        })
    }

    /// The density of [`RoughDielectric::sample_alone`]'s non-delta samples at the world direction
    /// `wi` (0 where `f` is 0, and for a pass-through).
    // Out of line: inlined into the BSDF mixture, its frame and half-vector arithmetic was
    // hoisted above the lobe test and paid by every material (measured: scripts/hot_share.sh).
    #[inline(never)]
    #[must_use]
    pub fn density(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame, tint: Vec3) -> f32 {
        let frame = Frame::from_normal(fr.ns);
        Self::classify(fr, &frame, wi).map_or(0.0, |li| {
            self.pdf_local(frame.to_local(wo), li, fr.entering, tint)
        })
    }

    /// A world direction from [`RoughDielectric::sample_local`] (radiance mode's choice of
    /// reflection or refraction by `v`) for the world direction `wo` in frame `fr`, without its
    /// weight (the BSDF mixture weighs it); `None` when the sample is lost.
    // Out of line: inlined into the BSDF mixture, its frame and half-vector arithmetic was
    // hoisted above the lobe test and paid by every material (measured: scripts/hot_share.sh).
    #[inline(never)]
    #[must_use]
    pub fn direction(
        &self,
        wo: Vec3,
        v: f32,
        u: (f32, f32),
        fr: &ShadingFrame,
        tint: Vec3,
    ) -> Option<Vec3> {
        let frame = Frame::from_normal(fr.ns);
        let s = self.sample_local(
            frame.to_local(wo),
            v,
            u,
            fr.entering,
            TransportMode::Radiance,
            tint,
        )?;
        Some(frame.to_world(s.wi))
    }

    /// A sampled world direction with its weight `f |ns·wi| / pdf` (times the adjoint
    /// correction in importance mode; in radiance mode a refraction's weight includes
    /// `1/η² = (ηₒ/ηᵢ)²`, reported in `eta_scale`). A pass-through returns the delta sample
    /// `−wo` of weight `tint` and probability 1.
    #[inline]
    #[must_use]
    pub fn sample_alone(
        &self,
        wo: Vec3,
        u_lobe: f32,
        u: (f32, f32),
        fr: &ShadingFrame,
        mode: TransportMode,
        tint: Vec3,
    ) -> Option<BsdfSample> {
        if self.is_pass_through() {
            return Some(BsdfSample {
                wi: -wo,
                weight: tint,
                pdf: 1.0,
                delta: true,
                transmitted: true,
                eta_scale: 1.0,
            });
        }
        let frame = Frame::from_normal(fr.ns);
        let lo = frame.to_local(wo);
        let s = self.sample_local(lo, u_lobe, u, fr.entering, mode, tint)?;
        let wi = frame.to_world(s.wi);
        Self::classify(fr, &frame, wi)?;
        let correction = match mode {
            TransportMode::Radiance => 1.0,
            TransportMode::Importance => shading_normal_correction(wo, wi, fr),
        };
        let eta = self.eta(fr.entering);
        let eta_scale = if s.transmitted && mode == TransportMode::Radiance {
            1.0 / (eta * eta)
        } else {
            1.0
        };
        Some(BsdfSample {
            wi,
            weight: s.f * (s.wi.z.abs() / s.pdf * correction),
            pdf: s.pdf,
            delta: false,
            transmitted: s.transmitted,
            eta_scale,
        })
    }
}

impl Bxdf for RoughDielectric {
    fn info(&self) -> LobeInfo {
        // The lobe number chooses between reflection and refraction.
        LobeInfo {
            flags: LobeFlags::GLOSSY
                .union(LobeFlags::REFLECTION)
                .union(LobeFlags::TRANSMISSION),
            uses_lobe_number: true,
            focusing_fraction: 0.0,
            ior: Some(self.ior),
            distribution: Some(self.distribution),
        }
    }

    #[inline]
    fn f(&self, ctx: &LobeContext<'_>, wi: Vec3, mode: TransportMode) -> Vec3 {
        self.value(ctx.wo, wi, ctx.fr, mode, ctx.tint)
    }

    #[inline]
    fn pdf(&self, ctx: &LobeContext<'_>, wi: Vec3, share: f32) -> f32 {
        share * self.density(ctx.wo, wi, ctx.fr, ctx.tint)
    }

    /// A direction, reflection or refraction chosen by `draw.v` ([`RoughDielectric::direction`]).
    #[inline]
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        self.direction(ctx.wo, draw.v, draw.u, ctx.fr, ctx.tint)
            .map(LobeSample::Direction)
    }

    /// The Fresnel reflectance at the macro-surface.
    fn prepare(&self, ctx: &LobeContext<'_>) -> Prepared {
        Prepared::Reflectance(fresnel_dielectric(
            ctx.wo.dot(ctx.fr.ns),
            1.0 / self.eta(ctx.fr.entering),
        ))
    }

    /// `F + (1 − F)·ρ̄` of the prepared reflectance (0 if unprepared).
    fn albedo(&self, prepared: &Prepared, rho: f32) -> f32 {
        match prepared {
            Prepared::Reflectance(f) => f + (1.0 - f) * rho,
            Prepared::Nothing | Prepared::Fresnel(_) => 0.0,
        }
    }

    fn delta_weights(&self, _ctx: &LobeContext<'_>, _weight: f32) -> DeltaWeights {
        DeltaWeights::NONE
    }

    /// As its smooth counterpart (its Fresnel at the macro-surface), for integrators that do
    /// not follow refraction.
    fn straight_transmittance(&self, weight: f32, tint: Vec3, cos: f32, entering: bool) -> Vec3 {
        Dielectric { ior: self.ior }.straight_through(weight, tint, cos, entering)
    }

    fn is_black(&self, _tint: Vec3) -> bool {
        false
    }

    fn is_flat(&self, tint: Vec3) -> bool {
        self.is_black(tint)
    }
}

crate::key_hash_struct!(RoughDielectric { distribution, ior });

#[cfg(test)]
#[path = "rough_dielectric_tests.rs"]
mod tests;
