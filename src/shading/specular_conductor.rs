//! The smooth metal: a delta lobe reflecting `wo` about the shading normal with a conductor's
//! Fresnel reflectance `F(cos θ)` ([`super::conductor`]): what a rough conductor becomes at
//! roughness 0 (the limit of the GGX lobe as α → 0 is a mirror weighted by `F`; Walter et al.
//! 2007, §5). The material's colour does not tint it: a metal's colour is its Fresnel.

use glam::Vec3;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::conductor::ConductorFresnel;
use super::scattering::{BsdfSample, LobeFlags, ShadingFrame, TransportMode, mean};
use super::specular_reflection::SpecularReflection;

/// A polished metal: the Fresnel reflectance of its perfect mirror.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpecularConductor {
    /// Reflectance at the incidence cosine `|wo·ns|`.
    pub fresnel: ConductorFresnel,
}

impl SpecularConductor {
    /// Delta reflection.
    pub const FLAGS: LobeFlags = LobeFlags::DELTA.union(LobeFlags::REFLECTION);

    /// The reflectance `F(|wo·ns|)` per channel.
    #[inline]
    #[must_use]
    pub fn reflectance(&self, wo: Vec3, fr: &ShadingFrame) -> Vec3 {
        self.fresnel.eval(wo.dot(fr.ns).abs())
    }

    /// The lobe's sampling weight: the mean reflectance at `wo`.
    #[inline]
    #[must_use]
    pub fn mean_reflectance(&self, wo: Vec3, fr: &ShadingFrame) -> f32 {
        mean(self.reflectance(wo, fr))
    }

    /// The mirror direction, chosen by the mixture with probability `prob` for a part of
    /// weight `weight`: weight `F · weight / prob` (times the adjoint correction in importance
    /// mode), `pdf = prob`. `None` when `prob` is 0.
    #[inline]
    #[must_use]
    pub fn mirror_sample(
        &self,
        wo: Vec3,
        fr: &ShadingFrame,
        mode: TransportMode,
        weight: f32,
        prob: f32,
    ) -> Option<BsdfSample> {
        // The mirror lobe's sample with the Fresnel reflectance as its tint.
        SpecularReflection::mirror_sample(wo, fr, mode, weight, prob, self.reflectance(wo, fr))
    }
}

impl Bxdf for SpecularConductor {
    fn info(&self) -> LobeInfo {
        LobeInfo {
            flags: Self::FLAGS,
            uses_lobe_number: false,
            focusing_fraction: 1.0,
            ior: None,
            distribution: None,
        }
    }

    /// A delta lobe has no value: 0.
    #[inline]
    fn f(&self, _ctx: &LobeContext<'_>, _wi: Vec3, _mode: TransportMode) -> Vec3 {
        Vec3::ZERO
    }

    /// A delta lobe has no density: 0.
    #[inline]
    fn pdf(&self, _ctx: &LobeContext<'_>, _wi: Vec3, _share: f32) -> f32 {
        0.0
    }

    /// The mirror direction of weight `F · weight / prob` ([`SpecularConductor::mirror_sample`]).
    #[inline]
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        self.mirror_sample(ctx.wo, ctx.fr, draw.mode, draw.weight, draw.prob)
            .map(LobeSample::Delta)
    }

    /// The mean reflectance at `wo`.
    fn prepare(&self, ctx: &LobeContext<'_>) -> Prepared {
        Prepared::Reflectance(self.mean_reflectance(ctx.wo, ctx.fr))
    }

    /// The prepared mean reflectance (0 if unprepared).
    fn albedo(&self, prepared: &Prepared, _rho: f32) -> f32 {
        match prepared {
            Prepared::Reflectance(r) => *r,
            Prepared::Nothing | Prepared::Fresnel(_) => 0.0,
        }
    }

    /// `F(|wo·ns|)` times the part's weight along the mirror direction.
    fn delta_weights(&self, ctx: &LobeContext<'_>, weight: f32) -> DeltaWeights {
        DeltaWeights {
            reflect: self.reflectance(ctx.wo, ctx.fr) * weight,
            refract: None,
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

    /// A metal's colour is its Fresnel, never black by the tint.
    fn is_black(&self, _tint: Vec3) -> bool {
        false
    }

    fn is_flat(&self, _tint: Vec3) -> bool {
        true
    }
}

crate::key_hash_struct!(SpecularConductor { fresnel });

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::conductor::{ConductorPreset, fresnel_conductor};

    #[test]
    fn reflects_with_the_conductor_fresnel_at_the_incidence_angle() {
        let fr = ShadingFrame {
            ns: Vec3::Z,
            ng: Vec3::Z,
            entering: true,
        };
        let gold = SpecularConductor {
            fresnel: ConductorFresnel::preset(ConductorPreset::Gold),
        };
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let s = gold
            .mirror_sample(wo, &fr, TransportMode::Radiance, 0.5, 0.25)
            .expect("sample");
        assert!(s.wi.distance(Vec3::new(-0.6, 0.0, 0.8)) < 1e-6);
        // By hand: the red channel's F at cos 0.8 from gold's (η, k), times 0.5 / 0.25.
        let (eta, k) = ConductorPreset::Gold.complex_index();
        let want = 2.0 * fresnel_conductor(0.8, eta.x, k.x);
        assert!((s.weight.x - want).abs() < 1e-6, "{} vs {want}", s.weight.x);
        assert!(s.delta && s.pdf == 0.25 && !s.transmitted);
        assert!(
            gold.mirror_sample(wo, &fr, TransportMode::Radiance, 0.5, 0.0)
                .is_none()
        );
    }
}
