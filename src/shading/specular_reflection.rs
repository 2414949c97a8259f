//! The perfect mirror: a delta lobe reflecting `wo` about the shading normal, tinted by the BSDF
//! mixture's tint (the material's colour).

use glam::Vec3;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::optics::reflect;
use super::scattering::{BsdfSample, LobeFlags, ShadingFrame, TransportMode, mode_correction};

/// The mirror lobe (its reflectance is the tint the mixture passes in).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SpecularReflection;

impl SpecularReflection {
    /// Delta reflection.
    pub const FLAGS: LobeFlags = LobeFlags::DELTA.union(LobeFlags::REFLECTION);

    /// The mirror direction, chosen by the mixture with probability `prob` for a part of
    /// weight `weight`: weight `tint · weight / prob` (times the adjoint correction in
    /// importance mode), `pdf = prob`. `None` when `prob` is 0.
    #[inline]
    #[must_use]
    pub fn mirror_sample(
        wo: Vec3,
        fr: &ShadingFrame,
        mode: TransportMode,
        weight: f32,
        prob: f32,
        tint: Vec3,
    ) -> Option<BsdfSample> {
        if prob == 0.0 {
            return None;
        }
        let wi = mirror_above(wo, fr.ns, fr.ng);
        Some(BsdfSample {
            wi,
            weight: tint * (weight / prob * mode_correction(mode, wo, wi, fr)),
            pdf: prob,
            delta: true,
            transmitted: false,
            eta_scale: 1.0,
        })
    }
}

/// Mirror of `wo` about `n`, replaced by the mirror about `ng` if it would go below the geometric
/// surface (shading normals must not send rays into the surface they leave).
#[inline]
#[must_use]
pub fn mirror_above(wo: Vec3, n: Vec3, ng: Vec3) -> Vec3 {
    let r = reflect(wo, n);
    if r.dot(ng) > 0.0 { r } else { reflect(wo, ng) }
}

impl Bxdf for SpecularReflection {
    fn info(&self) -> LobeInfo {
        LobeInfo {
            flags: Self::FLAGS,
            uses_lobe_number: false,
            focusing_fraction: 1.0,
            ior: None,
            distribution: None,
        }
    }

    /// A delta lobe has no value for any pair of directions: 0.
    #[inline]
    fn f(&self, _ctx: &LobeContext<'_>, _wi: Vec3, _mode: TransportMode) -> Vec3 {
        Vec3::ZERO
    }

    /// A delta lobe has no solid-angle density: 0.
    #[inline]
    fn pdf(&self, _ctx: &LobeContext<'_>, _wi: Vec3, share: f32) -> f32 {
        share * 0.0
    }

    /// The mirror direction, of weight `tint · weight / prob` ([`SpecularReflection::mirror_sample`]).
    #[inline]
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        Self::mirror_sample(ctx.wo, ctx.fr, draw.mode, draw.weight, draw.prob, ctx.tint)
            .map(LobeSample::Delta)
    }

    fn prepare(&self, _ctx: &LobeContext<'_>) -> Prepared {
        Prepared::Nothing
    }

    /// The tint's mean.
    fn albedo(&self, _prepared: &Prepared, rho: f32) -> f32 {
        rho
    }

    /// The tint times the part's weight along the mirror direction.
    fn delta_weights(&self, ctx: &LobeContext<'_>, weight: f32) -> DeltaWeights {
        DeltaWeights {
            reflect: ctx.tint * weight,
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

    fn is_black(&self, tint: Vec3) -> bool {
        tint == Vec3::ZERO
    }

    fn is_flat(&self, _tint: Vec3) -> bool {
        true
    }
}

crate::key_hash_struct!(SpecularReflection {});

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflects_with_the_tint_and_stays_above_the_surface() {
        let fr = ShadingFrame {
            ns: Vec3::Z,
            ng: Vec3::Z,
            entering: true,
        };
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let tint = Vec3::new(0.9, 0.5, 0.1);
        let ctx = LobeContext { wo, fr: &fr, tint };
        let draw = |prob| LobeDraw {
            prepared: &Prepared::Nothing,
            rho: 0.5,
            v: 0.0,
            u: (0.5, 0.5),
            mode: TransportMode::Radiance,
            weight: 0.4,
            prob,
        };
        let Some(LobeSample::Delta(s)) = SpecularReflection.sample(&ctx, &draw(0.5)) else {
            panic!("a delta sample")
        };
        assert!(s.wi.distance(Vec3::new(-0.6, 0.0, 0.8)) < 1e-6);
        // weight = tint · 0.4 / 0.5: the part's weight over the probability of choosing it.
        assert!(s.weight.distance(tint * 0.8) < 1e-6 && s.delta && s.pdf == 0.5);
        assert!(SpecularReflection.sample(&ctx, &draw(0.0)).is_none());
        // A shading normal tilted so far that its mirror would dive: mirrored about ng.
        let ns = Vec3::new(0.8, 0.0, 0.6);
        let wo = Vec3::new(-0.99, 0.0, 0.141).normalize();
        let d = mirror_above(wo, ns, Vec3::Z);
        assert!(d.z > 0.0, "{d}");
        assert_eq!(
            SpecularReflection.f(&ctx, Vec3::Z, TransportMode::Radiance),
            Vec3::ZERO
        );
        assert_eq!(SpecularReflection.pdf(&ctx, Vec3::Z, 1.0), 0.0);
    }
}
