//! The smooth Fresnel dielectric (glass, water): a delta lobe that reflects with the Fresnel
//! reflectance `F` (untinted) and refracts by Snell's law with `1 − F`, the refracted light
//! tinted by the BSDF mixture's tint. Sampling picks reflection or refraction in proportion to
//! `F` and `(1 − F)·ρ̄`; radiance crossing the boundary scales by (ηₒ/ηᵢ)² (pbrt-v4 §9.5).

use glam::Vec3;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::optics::{FresnelSplit, fresnel_dielectric, refract};
use super::scattering::{BsdfSample, LobeFlags, ShadingFrame, TransportMode, mode_correction};
use super::specular_reflection::mirror_above;

/// The dielectric lobe: the index of refraction of the inside relative to the outside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dielectric {
    /// Relative index of refraction (inside over outside).
    pub ior: f32,
}

impl Dielectric {
    /// Delta reflection and transmission.
    pub const FLAGS: LobeFlags = LobeFlags::DELTA
        .union(LobeFlags::REFLECTION)
        .union(LobeFlags::TRANSMISSION);

    /// The Fresnel split for `wo` in frame `fr`.
    #[inline]
    #[must_use]
    pub fn split(&self, wo: Vec3, fr: &ShadingFrame) -> FresnelSplit {
        let eta = if fr.entering {
            1.0 / self.ior
        } else {
            self.ior
        };
        let fresnel = fresnel_dielectric(fr.ns.dot(wo), eta);
        let refracted = if fresnel < 1.0 {
            refract_below(wo, fr.ns, fr.ng, eta)
        } else {
            None
        };
        FresnelSplit {
            fresnel: if refracted.is_some() { fresnel } else { 1.0 },
            refracted,
            eta,
        }
    }

    /// The lobe's weight when the mixture picks a lobe: `F + (1 − F)·ρ̄` (`rho` the tint's
    /// mean).
    #[inline]
    #[must_use]
    pub fn split_albedo(&self, split: &FresnelSplit, rho: f32) -> f32 {
        split.fresnel + (1.0 - split.fresnel) * rho
    }

    /// Reflection or refraction, chosen by `v ∈ [0, 1)` (refraction when `v ≥ F / (F + (1 −
    /// F)ρ̄)`), for a part of weight `weight` that the mixture chose with probability `prob`.
    /// The weight is `tint · weight (1 − F) η² / pdf` for refraction in radiance mode (the
    /// adjoint correction instead of η² in importance mode) and `weight · F / pdf` (untinted)
    /// for reflection. `None` when the reflection's probability is 0.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    #[must_use]
    pub fn split_sample(
        &self,
        d: &FresnelSplit,
        wo: Vec3,
        v: f32,
        fr: &ShadingFrame,
        mode: TransportMode,
        weight: f32,
        prob: f32,
        tint: Vec3,
        rho: f32,
    ) -> Option<BsdfSample> {
        // Reflect with probability F / (F + (1 − F)ρ̄).
        let denom = d.fresnel + (1.0 - d.fresnel) * rho;
        let p_reflect = if denom > 0.0 { d.fresnel / denom } else { 1.0 };
        match d.refracted {
            Some(wt) if v >= p_reflect => {
                let pdf = prob * (1.0 - p_reflect);
                let (scale, eta_scale) = match mode {
                    TransportMode::Radiance => (d.eta * d.eta, d.eta * d.eta),
                    TransportMode::Importance => (mode_correction(mode, wo, wt, fr), 1.0),
                };
                Some(BsdfSample {
                    wi: wt,
                    weight: tint * (weight * (1.0 - d.fresnel) * scale / pdf),
                    pdf,
                    delta: true,
                    transmitted: true,
                    eta_scale,
                })
            }
            _ => {
                let wi = mirror_above(wo, fr.ns, fr.ng);
                let pdf = prob * p_reflect;
                if !(pdf > 0.0) {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    weight: Vec3::splat(
                        weight * d.fresnel / pdf * mode_correction(mode, wo, wi, fr),
                    ),
                    pdf,
                    delta: true,
                    transmitted: false,
                    eta_scale: 1.0,
                })
            }
        }
    }

    /// Both delta directions at once, in radiance mode, for a part of weight `weight`: the
    /// mirror gets `weight · F`, the refraction `tint · weight (1 − F) η²`.
    #[inline]
    #[must_use]
    pub fn split_weights(&self, d: &FresnelSplit, weight: f32, tint: Vec3) -> DeltaWeights {
        DeltaWeights {
            reflect: Vec3::splat(weight * d.fresnel),
            refract: d.refracted.map(|dir| {
                let w = weight * (1.0 - d.fresnel) * d.eta * d.eta;
                (dir, tint * w, d.eta * d.eta)
            }),
        }
    }

    /// The fraction of light crossing in a straight line (see
    /// [`super::Bsdf::straight_transmittance`]) for a part of weight `weight`: `tint · weight ·
    /// (1 − F(θ)) · η²`, F taken from the outside at the angle `acos(cos)`.
    #[inline]
    #[must_use]
    pub fn straight_through(&self, weight: f32, tint: Vec3, cos: f32, entering: bool) -> Vec3 {
        let eta2 = if entering {
            1.0 / (self.ior * self.ior)
        } else {
            self.ior * self.ior
        };
        tint * (weight * (1.0 - fresnel_dielectric(cos, 1.0 / self.ior)) * eta2)
    }
}

/// Refraction of `wo` through `n`, replaced by refraction through `ng` if the result would not
/// cross the geometric surface.
#[inline]
fn refract_below(wo: Vec3, n: Vec3, ng: Vec3, eta: f32) -> Option<Vec3> {
    match refract(wo, n, eta) {
        Some(t) if t.dot(ng) < 0.0 => Some(t),
        _ => refract(wo, ng, eta).filter(|t| t.dot(ng) < 0.0),
    }
}

impl Bxdf for Dielectric {
    fn info(&self) -> LobeInfo {
        // The lobe number chooses between reflection and refraction.
        LobeInfo {
            flags: Self::FLAGS,
            uses_lobe_number: true,
            focusing_fraction: 1.0,
            ior: Some(self.ior),
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

    /// Reflection or refraction by `draw.v` ([`Dielectric::split_sample`]), from the prepared
    /// split (worked out here if the part was not prepared).
    #[inline]
    fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        let (wo, fr) = (ctx.wo, ctx.fr);
        let (v, mode, weight, prob, tint, rho) = (
            draw.v,
            draw.mode,
            draw.weight,
            draw.prob,
            ctx.tint,
            draw.rho,
        );
        match draw.prepared {
            Prepared::Fresnel(split) => {
                self.split_sample(split, wo, v, fr, mode, weight, prob, tint, rho)
            }
            Prepared::Nothing | Prepared::Reflectance(_) => self.split_sample(
                &self.split(wo, fr),
                wo,
                v,
                fr,
                mode,
                weight,
                prob,
                tint,
                rho,
            ),
        }
        .map(LobeSample::Delta)
    }

    /// The Fresnel split at `wo`.
    fn prepare(&self, ctx: &LobeContext<'_>) -> Prepared {
        Prepared::Fresnel(self.split(ctx.wo, ctx.fr))
    }

    /// `F + (1 − F)·ρ̄` of the prepared split (0 if unprepared).
    fn albedo(&self, prepared: &Prepared, rho: f32) -> f32 {
        match prepared {
            Prepared::Fresnel(s) => self.split_albedo(s, rho),
            Prepared::Nothing | Prepared::Reflectance(_) => 0.0,
        }
    }

    /// Both delta directions ([`Dielectric::split_weights`]).
    fn delta_weights(&self, ctx: &LobeContext<'_>, weight: f32) -> DeltaWeights {
        self.split_weights(&self.split(ctx.wo, ctx.fr), weight, ctx.tint)
    }

    /// [`Dielectric::straight_through`].
    fn straight_transmittance(&self, weight: f32, tint: Vec3, cos: f32, entering: bool) -> Vec3 {
        self.straight_through(weight, tint, cos, entering)
    }

    /// Glass reflects whatever its tint.
    fn is_black(&self, _tint: Vec3) -> bool {
        false
    }

    fn is_flat(&self, _tint: Vec3) -> bool {
        true
    }
}

crate::key_hash_struct!(Dielectric { ior });

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn frame(entering: bool) -> ShadingFrame {
        ShadingFrame {
            ns: Vec3::Z,
            ng: Vec3::Z,
            entering,
        }
    }

    /// χ² (one degree of freedom) of the reflect / refract choice against its probabilities
    /// F/(F + (1 − F)ρ̄) and the rest, at several incidences from both sides: the discrete
    /// counterpart of the non-delta lobes' χ² tests.
    #[test]
    fn chi2_choice_between_reflection_and_refraction_follows_its_probabilities() {
        let glass = Dielectric { ior: 1.5 };
        let (tint, rho) = (Vec3::splat(0.6), 0.6);
        let mut rng = Rng::new(5, 3);
        for entering in [true, false] {
            for theta in [0.0f32, 30.0, 40.0, 70.0] {
                let t = theta.to_radians();
                let wo = Vec3::new(t.sin(), 0.0, t.cos());
                let fr = frame(entering);
                let d = glass.split(wo, &fr);
                let n = 100_000u32;
                let mut refracted = 0u32;
                for _ in 0..n {
                    let v = rng.next_f32();
                    let s = glass
                        .split_sample(&d, wo, v, &fr, TransportMode::Radiance, 1.0, 1.0, tint, rho)
                        .expect("a sample");
                    refracted += u32::from(s.transmitted);
                }
                let p_t = (1.0 - d.fresnel) * rho / (d.fresnel + (1.0 - d.fresnel) * rho);
                let expected = [
                    f64::from(p_t) * f64::from(n),
                    f64::from(1.0 - p_t) * f64::from(n),
                ];
                let observed = [f64::from(refracted), f64::from(n - refracted)];
                let chi2: f64 = expected
                    .iter()
                    .zip(observed)
                    .filter(|(e, _)| **e > 0.0)
                    .map(|(e, o)| (o - e) * (o - e) / e)
                    .sum();
                // 10.83: the χ²₁ quantile at α = 10⁻³.
                assert!(chi2 < 10.83, "{theta}° entering {entering}: χ² {chi2}");
                if expected[0] == 0.0 {
                    assert_eq!(refracted, 0, "total internal reflection never refracts");
                }
            }
        }
    }

    #[test]
    fn expected_weight_is_one_for_clear_glass_in_importance_mode() {
        // E[weight] = F + (1 − F) = 1: a clear dielectric loses no flux.
        let glass = Dielectric { ior: 1.33 };
        let wo = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
        for entering in [true, false] {
            let fr = frame(entering);
            let d = glass.split(wo, &fr);
            let n = 20_000;
            let sum: f32 = (0..n)
                .filter_map(|i| {
                    let v = (i as f32 + 0.5) / n as f32;
                    glass.split_sample(
                        &d,
                        wo,
                        v,
                        &fr,
                        TransportMode::Importance,
                        1.0,
                        1.0,
                        Vec3::ONE,
                        1.0,
                    )
                })
                .map(|s| s.weight.x)
                .sum();
            assert!((sum / n as f32 - 1.0).abs() < 1e-3, "{}", sum / n as f32);
        }
        let fr = frame(true);
        let ctx = LobeContext {
            wo,
            fr: &fr,
            tint: Vec3::ONE,
        };
        assert_eq!(glass.f(&ctx, -wo, TransportMode::Radiance), Vec3::ZERO);
        assert_eq!(glass.pdf(&ctx, -wo, 1.0), 0.0);
    }
}
