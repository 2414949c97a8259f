//! The normalised (energy-conserving) Phong lobe (Lewis, "Making Shaders More Physically
//! Plausible", 1994): `f = k_s (m+2)/(2π) max(0, r·wi)^m` about the mirror direction `r` of
//! `wo`, sampled from the `cos^m` lobe about `r`. The BSDF mixture's glossy lobe.

use glam::Vec3;
use std::f32::consts::TAU;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::optics::reflect;
use super::scattering::{LobeFlags, ShadingFrame, TransportMode, mean};
use crate::geometry::Frame;

/// The Phong lobe: reflectance and exponent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phong {
    /// Reflectance `k_s` per channel.
    pub specular: Vec3,
    /// Exponent `m` (larger: tighter highlight).
    pub exponent: f32,
}

impl Phong {
    /// Glossy reflection.
    pub const FLAGS: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::REFLECTION);

    /// `k_s (m+2)/(2π) max(0, r·wi)^m` (per steradian) for `wi` above the shading normal `n`,
    /// `r` the mirror of `wo` about `n`; else 0 (and 0 for a black lobe, `k_s = 0`, whatever
    /// the exponent). Symmetric in `wo` and `wi`.
    #[inline]
    #[must_use]
    pub fn value(&self, wo: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
        if self.specular == Vec3::ZERO || n.dot(wi) <= 0.0 {
            return Vec3::ZERO;
        }
        let cos_a = reflect(wo, n).dot(wi).max(0.0);
        self.specular * ((self.exponent + 2.0) / TAU * cos_a.powf(self.exponent))
    }

    /// The mean reflectance: the lobe's share when the mixture picks a lobe.
    #[inline]
    #[must_use]
    pub fn mean_reflectance(&self) -> f32 {
        mean(self.specular)
    }

    /// A direction from the `cos^m` lobe about the mirror direction of `wo` (it may lie below
    /// the surface; the mixture then gives it no density and drops the sample).
    #[inline]
    #[must_use]
    pub fn direction(&self, wo: Vec3, u: (f32, f32), fr: &ShadingFrame) -> Vec3 {
        let r = reflect(wo, fr.ns);
        let cos_a = u.0.powf(1.0 / (self.exponent + 1.0));
        let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
        let phi = TAU * u.1;
        Frame::from_normal(r).to_world(Vec3::new(sin_a * phi.cos(), sin_a * phi.sin(), cos_a))
    }

    /// `share ·` the solid-angle density of [`Phong::direction`] at `wi`: `(m+1)/(2π) (r·wi)^m`
    /// inside the lobe's hemisphere about `r`, 0 outside (it integrates to 1 over the sphere).
    #[inline]
    #[must_use]
    pub fn scaled_density(&self, share: f32, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
        let c = reflect(wo, fr.ns).dot(wi);
        let d = if c <= 0.0 {
            0.0
        } else {
            (self.exponent + 1.0) / TAU * c.powf(self.exponent)
        };
        share * d
    }
}

impl Bxdf for Phong {
    fn info(&self) -> LobeInfo {
        LobeInfo {
            flags: Self::FLAGS,
            uses_lobe_number: false,
            focusing_fraction: 0.0,
            ior: None,
            distribution: None,
        }
    }

    #[inline]
    fn f(&self, ctx: &LobeContext<'_>, wi: Vec3, _mode: TransportMode) -> Vec3 {
        self.value(ctx.wo, wi, ctx.fr.ns)
    }

    #[inline]
    fn pdf(&self, ctx: &LobeContext<'_>, wi: Vec3, share: f32) -> f32 {
        self.scaled_density(share, ctx.wo, wi, ctx.fr)
    }

    #[inline]
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        Some(LobeSample::Direction(
            self.direction(ctx.wo, draw.u, ctx.fr),
        ))
    }

    fn prepare(&self, _ctx: &LobeContext<'_>) -> Prepared {
        Prepared::Nothing
    }

    /// The mean reflectance (the tint does not colour Phong).
    fn albedo(&self, _prepared: &Prepared, _rho: f32) -> f32 {
        self.mean_reflectance()
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

    fn is_black(&self, _tint: Vec3) -> bool {
        self.specular == Vec3::ZERO
    }

    fn is_flat(&self, tint: Vec3) -> bool {
        self.is_black(tint)
    }
}

crate::key_hash_struct!(Phong { specular, exponent });

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{SphereBins, chi2_test, sidak_alpha};

    #[test]
    fn chi2_sample_follows_pdf_for_several_exponents_and_angles() {
        let fr = ShadingFrame {
            ns: Vec3::Z,
            ng: Vec3::Z,
            entering: true,
        };
        let cases = [(3.0f32, 0.0f32), (20.0, 45.0), (80.0, 80.0)];
        let alpha = sidak_alpha(0.01, cases.len());
        for (k, (m, theta)) in cases.into_iter().enumerate() {
            let lobe = Phong {
                specular: Vec3::ONE,
                exponent: m,
            };
            let t = theta.to_radians();
            let wo = Vec3::new(t.sin(), 0.0, t.cos());
            let r = chi2_test(
                100_000,
                20 + k as u64,
                &SphereBins::sphere(Vec3::Z, 16, 32),
                |rng| Some(lobe.direction(wo, rng.next_2d(), &fr)),
                |wi| lobe.scaled_density(1.0, wo, wi, &fr),
            );
            assert!(
                r.impossible == 0 && r.passes(alpha),
                "m {m} at {theta}°: {r:?}"
            );
        }
    }

    #[test]
    fn value_at_the_mirror_direction_by_hand() {
        let lobe = Phong {
            specular: Vec3::splat(0.5),
            exponent: 10.0,
        };
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let r = Vec3::new(-0.6, 0.0, 0.8);
        // k_s (m+2)/(2π) = 0.5 · 12 / 2π at the peak; density (m+1)/(2π) = 11/2π.
        let f = lobe.value(wo, r, Vec3::Z);
        assert!((f.x - 0.5 * 12.0 / TAU).abs() < 1e-5, "{f}");
        let fr = ShadingFrame {
            ns: Vec3::Z,
            ng: Vec3::Z,
            entering: true,
        };
        assert!((lobe.scaled_density(1.0, wo, r, &fr) - 11.0 / TAU).abs() < 1e-5);
        assert_eq!(lobe.value(wo, -Vec3::Z, Vec3::Z), Vec3::ZERO);
        assert!((lobe.mean_reflectance() - 0.5).abs() < 1e-7);
    }
}
