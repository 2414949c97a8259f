//! The Henyey–Greenstein phase function (Henyey & Greenstein 1941; pbrt-v4 §11.3.1): the
//! angular distribution of light scattered in a participating medium,
//!
//! `p(cos θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2})`,
//!
//! θ the angle between the direction light travelled before and after scattering and `g` the
//! mean cosine (0 isotropic, > 0 forward). It integrates to 1 over the sphere and is sampled
//! exactly by inverting its cumulative distribution in cos θ, so a sample's weight `p/pdf` is 1.

use std::f32::consts::PI;

use glam::Vec3;

use crate::geometry::Frame;

/// A Henyey–Greenstein phase function of asymmetry `g` in (−1, 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HenyeyGreenstein {
    /// Mean cosine of the scattering angle.
    pub g: f32,
}

/// A direction drawn from a phase function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseSample {
    /// Unit direction the light travels after scattering.
    pub wi: Vec3,
    /// Its solid-angle density, equal to the phase function's value (the weight is 1).
    pub pdf: f32,
}

impl HenyeyGreenstein {
    /// The phase function's value (per steradian) for light travelling along unit `d_in`
    /// before and unit `d_out` after scattering; it is also the density [`Self::sample`] draws
    /// `d_out` with. Symmetric under exchanging and negating both, so radiance and importance
    /// transport use the same value.
    #[inline]
    #[must_use]
    pub fn p(&self, d_in: Vec3, d_out: Vec3) -> f32 {
        hg(d_in.dot(d_out), self.g)
    }

    /// Draws the direction light travels after scattering, given it travelled along unit
    /// `d_in` before, from two uniform numbers in [0, 1).
    #[inline]
    #[must_use]
    pub fn sample(&self, d_in: Vec3, u: (f32, f32)) -> PhaseSample {
        let g = self.g;
        // Inverse of the CDF in cos θ (pbrt-v4 §11.3.1 derives the same closed form).
        let cos = if g.abs() < 1e-3 {
            1.0 - 2.0 * u.0
        } else {
            let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.0);
            (1.0 + g * g - s * s) / (2.0 * g)
        }
        .clamp(-1.0, 1.0);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * u.1;
        let frame = Frame::from_normal(d_in);
        let wi = frame
            .to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos))
            .normalize();
        PhaseSample {
            wi,
            pdf: hg(cos, g),
        }
    }
}

/// `p(cos θ)` of Henyey–Greenstein with asymmetry `g`.
#[inline]
fn hg(cos: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos;
    (1.0 - g * g) / (4.0 * PI * denom * denom.max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::sampling::chi2::{SphereBins, chi2_test, integrate_sphere};

    #[test]
    fn integrates_to_one_and_its_mean_cosine_is_g() {
        let d = Vec3::new(0.3, -0.2, 0.9).normalize();
        for g in [-0.7f32, -0.2, 0.0, 0.3, 0.8] {
            let hg = HenyeyGreenstein { g };
            let total = integrate_sphere(d, |w| hg.p(d, w));
            assert!((total - 1.0).abs() < 1e-4, "g = {g}: ∫p = {total}");
            // ∫ cos θ p dω = g: the defining property of the asymmetry parameter.
            let mean = integrate_sphere(d, |w| hg.p(d, w) * d.dot(w));
            assert!(
                (mean - f64::from(g)).abs() < 1e-3,
                "g = {g}: mean cos {mean}"
            );
        }
    }

    #[test]
    fn samples_follow_the_density_it_evaluates_chi2() {
        let d = Vec3::new(-0.5, 0.4, 0.2).normalize();
        for (i, g) in [-0.6f32, 0.0, 0.5, 0.9].into_iter().enumerate() {
            let hg = HenyeyGreenstein { g };
            let r = chi2_test(
                100_000,
                30 + i as u64,
                &SphereBins::sphere(d, 16, 16),
                |rng: &mut Rng| {
                    let s = hg.sample(d, rng.next_2d());
                    // The reported pdf is the evaluated value.
                    assert!((s.pdf - hg.p(d, s.wi)).abs() <= 1e-3 * s.pdf, "{s:?}");
                    Some(s.wi)
                },
                |w| hg.p(d, w),
            );
            assert!(r.impossible == 0 && r.passes(1e-3), "g = {g}: {r:?}");
        }
    }
}
