//! Lambertian (ideal diffuse) reflection: `f = ρ/π` above the surface, sampled by the cosine
//! (Malley's method), the BSDF mixture's diffuse lobe. Its albedo `ρ` is the mixture's tint
//! (the material's colour or colour texture).

use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::scattering::{LobeFlags, ShadingFrame, TransportMode};
use crate::sampling::warp::cosine_hemisphere;

/// The Lambert lobe (its albedo is the tint the mixture passes in).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lambert;

impl Lambert {
    /// Diffuse reflection.
    pub const FLAGS: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::REFLECTION);

    /// `tint/π` (per steradian) for `wi` above the shading normal `n`, else 0.
    #[inline]
    #[must_use]
    pub fn value(tint: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
        if n.dot(wi) <= 0.0 {
            return Vec3::ZERO;
        }
        tint * FRAC_1_PI
    }

    /// A cosine-distributed direction about the shading normal from `u ∈ [0, 1)²`.
    #[inline]
    #[must_use]
    pub fn direction(u: (f32, f32), fr: &ShadingFrame) -> Vec3 {
        cosine_hemisphere(u, fr.ns)
    }

    /// `share ·` the density of [`Lambert::direction`] at `wi`, `cos θ / π` above the shading
    /// normal (0 below), multiplied in the order the mixture has always used
    /// (`share · cos θ · 1/π`), so renders stay bit-identical.
    #[inline]
    #[must_use]
    pub fn scaled_density(share: f32, wi: Vec3, fr: &ShadingFrame) -> f32 {
        let c = fr.ns.dot(wi);
        if c <= 0.0 { 0.0 } else { share * c * FRAC_1_PI }
    }
}

impl Bxdf for Lambert {
    fn info(&self) -> LobeInfo {
        LobeInfo {
            flags: Self::FLAGS,
            uses_lobe_number: false,
            focusing_fraction: 0.0,
            ior: None,
            distribution: None,
        }
    }

    /// `f(wo, wi) = tint/π` above the shading normal, else 0.
    #[inline]
    fn f(&self, ctx: &LobeContext<'_>, wi: Vec3, _mode: TransportMode) -> Vec3 {
        Self::value(ctx.tint, wi, ctx.fr.ns)
    }

    #[inline]
    fn pdf(&self, ctx: &LobeContext<'_>, wi: Vec3, share: f32) -> f32 {
        Self::scaled_density(share, wi, ctx.fr)
    }

    #[inline]
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        Some(LobeSample::Direction(Self::direction(draw.u, ctx.fr)))
    }

    fn prepare(&self, _ctx: &LobeContext<'_>) -> Prepared {
        Prepared::Nothing
    }

    /// The tint's mean.
    fn albedo(&self, _prepared: &Prepared, rho: f32) -> f32 {
        rho
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
        tint == Vec3::ZERO
    }

    fn is_flat(&self, _tint: Vec3) -> bool {
        true
    }
}

crate::key_hash_struct!(Lambert {});

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{SphereBins, chi2_test};

    fn frame(ns: Vec3) -> ShadingFrame {
        ShadingFrame {
            ns,
            ng: Vec3::Z,
            entering: true,
        }
    }

    #[test]
    fn albedo_is_the_tint_and_pdf_integrates_to_one() {
        // ∫ f cos dω = ρ and ∫ pdf dω = 1 by midpoint quadrature over the hemisphere.
        let fr = frame(Vec3::Z);
        let (mut a, mut p) = (0.0f64, 0.0f64);
        let n = 400;
        for i in 0..n {
            let z = (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            for j in 0..n {
                let ph = (j as f64 + 0.5) / n as f64 * std::f64::consts::TAU;
                let wi = Vec3::new((r * ph.cos()) as f32, (r * ph.sin()) as f32, z as f32);
                a += f64::from(Lambert::value(Vec3::splat(0.6), wi, Vec3::Z).x) * z;
                p += f64::from(Lambert::scaled_density(1.0, wi, &fr));
            }
        }
        let dw = std::f64::consts::TAU / (n * n) as f64;
        assert!((a * dw - 0.6).abs() < 1e-3, "{}", a * dw);
        assert!((p * dw - 1.0).abs() < 1e-3, "{}", p * dw);
        assert_eq!(Lambert::value(Vec3::ONE, -Vec3::Z, Vec3::Z), Vec3::ZERO);
        assert_eq!(Lambert::scaled_density(1.0, -Vec3::Z, &fr), 0.0);
    }

    #[test]
    fn chi2_sample_follows_pdf_about_a_tilted_normal() {
        let ns = Vec3::new(0.5, 0.0, 1.0).normalize();
        let fr = frame(ns);
        let r = chi2_test(
            100_000,
            11,
            &SphereBins::sphere(Vec3::Z, 16, 32),
            |rng| Some(Lambert::direction(rng.next_2d(), &fr)),
            |wi| Lambert::scaled_density(1.0, wi, &fr),
        );
        assert!(r.impossible == 0 && r.passes(1e-3), "{r:?}");
    }
}
