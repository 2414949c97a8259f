//! The perfect mirror: a delta lobe reflecting `wo` about the shading normal, tinted by the BSDF
//! mixture's tint (the material's colour).

use glam::Vec3;

use super::optics::reflect;
use super::scattering::{BsdfSample, LobeFlags, ShadingFrame, TransportMode, mode_correction};

/// The mirror lobe (its reflectance is the tint the mixture passes in).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SpecularReflection;

impl SpecularReflection {
    /// Delta reflection.
    pub const FLAGS: LobeFlags = LobeFlags::DELTA.union(LobeFlags::REFLECTION);

    /// A delta lobe has no value for any pair of directions: 0.
    #[inline]
    #[must_use]
    pub fn f(&self) -> Vec3 {
        Vec3::ZERO
    }

    /// A delta lobe has no solid-angle density: 0.
    #[inline]
    #[must_use]
    pub fn pdf(&self) -> f32 {
        0.0
    }

    /// The mirror direction, chosen by the mixture with probability `prob` for a part of
    /// weight `weight`: weight `tint · weight / prob` (times the adjoint correction in
    /// importance mode), `pdf = prob`. `None` when `prob` is 0.
    #[inline]
    #[must_use]
    pub fn sample(
        &self,
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
        let s = SpecularReflection
            .sample(wo, &fr, TransportMode::Radiance, 0.4, 0.5, tint)
            .expect("sample");
        assert!(s.wi.distance(Vec3::new(-0.6, 0.0, 0.8)) < 1e-6);
        // weight = tint · 0.4 / 0.5: the part's weight over the probability of choosing it.
        assert!(s.weight.distance(tint * 0.8) < 1e-6 && s.delta && s.pdf == 0.5);
        assert!(
            SpecularReflection
                .sample(wo, &fr, TransportMode::Radiance, 0.4, 0.0, tint)
                .is_none()
        );
        // A shading normal tilted so far that its mirror would dive: mirrored about ng.
        let ns = Vec3::new(0.8, 0.0, 0.6);
        let wo = Vec3::new(-0.99, 0.0, 0.141).normalize();
        let d = mirror_above(wo, ns, Vec3::Z);
        assert!(d.z > 0.0, "{d}");
        assert_eq!(SpecularReflection.f(), Vec3::ZERO);
        assert_eq!(SpecularReflection.pdf(), 0.0);
    }
}
