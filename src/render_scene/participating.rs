//! A homogeneous participating medium (docs/media.md): absorption σa and scattering σs per RGB
//! channel (per metre) and a Henyey–Greenstein phase function, with free-flight sampling of
//! the distance to the next scattering event.
//!
//! Free-flight sampling with per-channel coefficients (chromatic media): a channel `c` is
//! chosen uniformly and the distance drawn from `σt,c · exp(−σt,c t)`; the estimate is weighted
//! by the one-sample multiple-importance balance heuristic over the three channels' strategies,
//! i.e. divided by the mean density `p(t) = ⅓ Σ_c σt,c exp(−σt,c t)` (the "hero" spectral MIS of
//! Wilkie et al. 2014, "Hero wavelength spectral sampling", applied to RGB as pbrt-v3's
//! `HomogeneousMedium::Sample` does, §15.2.2). A scattering event at `t` before the surface at
//! `t_s` then carries `σs · T(t) / p(t)`, and passing on to the surface `T(t_s) / P(t_s)` with
//! `P(t_s) = ⅓ Σ_c exp(−σt,c t_s)` (the probability of drawing no event before it): unbiased for
//! every channel, and exactly 1 per event for a grey, non-absorbing medium.

use glam::Vec3;

use crate::shading::phase::HenyeyGreenstein;

/// A homogeneous medium as compiled: coefficients per metre and the phase function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HomogeneousMedium {
    /// Absorption coefficient per channel (per metre, ≥ 0).
    pub sigma_a: Vec3,
    /// Scattering coefficient per channel (per metre, ≥ 0).
    pub sigma_s: Vec3,
    /// The phase function of its scattering.
    pub phase: HenyeyGreenstein,
}

/// What free-flight sampling found along a segment ([`HomogeneousMedium::sample_distance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FreeFlight {
    /// A scattering event `t` metres along the segment; multiply the path weight by `weight`
    /// (`σs T(t) / p(t)`) and scatter by the phase function there.
    Scatter {
        /// Distance from the segment's start, metres.
        t: f32,
        /// Path-weight factor.
        weight: Vec3,
    },
    /// No event before the segment's end: multiply the path weight by `weight` (`T / P`).
    Pass {
        /// Path-weight factor.
        weight: Vec3,
    },
}

impl HomogeneousMedium {
    /// Extinction coefficient σt = σa + σs per channel.
    #[inline]
    #[must_use]
    pub fn sigma_t(&self) -> Vec3 {
        self.sigma_a + self.sigma_s
    }

    /// True if the medium scatters in some channel (else it only absorbs, and paths cross it
    /// with [`Self::transmittance`] instead of sampling events).
    #[inline]
    #[must_use]
    pub fn scatters(&self) -> bool {
        self.sigma_s.max_element() > 0.0
    }

    /// The fraction of light kept over `distance` metres, `exp(−σt d)` per channel (0 over an
    /// infinite distance in a channel that attenuates at all).
    #[inline]
    #[must_use]
    pub fn transmittance(&self, distance: f32) -> Vec3 {
        transmittance(self.sigma_t(), distance)
    }

    /// The density (per metre) with which [`Self::sample_distance`] places a scattering event
    /// `t` metres along a segment longer than `t`: `p(t) = ⅓ Σ_c σt,c exp(−σt,c t)` (module
    /// docs); what multiple importance sampling weighs another distance sampler against
    /// (equiangular sampling, `integrators::path`). 0 for a medium that does not scatter.
    #[inline]
    #[must_use]
    pub fn scatter_pdf(&self, t: f32) -> f32 {
        if !self.scatters() {
            return 0.0;
        }
        let st = self.sigma_t();
        (st * transmittance(st, t)).element_sum() / 3.0
    }

    /// Draws the next scattering event along a segment `t_max` metres long (infinite for a ray
    /// that escapes) from two uniform numbers: `u.0` chooses the channel, `u.1` the distance
    /// (module docs). A medium that does not scatter only passes, weighted by its
    /// transmittance.
    #[inline]
    #[must_use]
    pub fn sample_distance(&self, t_max: f32, u: (f32, f32)) -> FreeFlight {
        if !self.scatters() {
            return FreeFlight::Pass {
                weight: self.transmittance(t_max),
            };
        }
        let st = self.sigma_t();
        let channel = ((u.0 * 3.0) as usize).min(2);
        let s = st[channel];
        let t = if s > 0.0 {
            -(1.0 - u.1).ln() / s
        } else {
            f32::INFINITY
        };
        if t < t_max {
            let tr = transmittance(st, t);
            let pdf = (st * tr).element_sum() / 3.0;
            FreeFlight::Scatter {
                t,
                weight: if pdf > 0.0 {
                    self.sigma_s * tr / pdf
                } else {
                    Vec3::ZERO
                },
            }
        } else {
            let tr = transmittance(st, t_max);
            let p = tr.element_sum() / 3.0;
            FreeFlight::Pass {
                weight: if p > 0.0 { tr / p } else { Vec3::ZERO },
            }
        }
    }
}

/// `exp(−σ d)` per channel; exactly 1 where σ is 0 (even over an infinite distance).
#[inline]
fn transmittance(sigma: Vec3, distance: f32) -> Vec3 {
    Vec3::new(
        tr1(sigma.x, distance),
        tr1(sigma.y, distance),
        tr1(sigma.z, distance),
    )
}

#[inline]
fn tr1(sigma: f32, d: f32) -> f32 {
    if sigma == 0.0 {
        1.0
    } else {
        (-sigma * d).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn medium(sigma_a: Vec3, sigma_s: Vec3) -> HomogeneousMedium {
        HomogeneousMedium {
            sigma_a,
            sigma_s,
            phase: HenyeyGreenstein { g: 0.0 },
        }
    }

    #[test]
    fn free_flight_estimates_transmittance_and_scattering_per_channel_without_bias() {
        // Along a segment of length L in a chromatic medium, the expected "pass" weight is
        // T(L) = exp(−σt L) per channel, and the expected sum of scatter weights over events
        // with t in [0, L) is ∫ σs exp(−σt t) dt = σs/σt (1 − exp(−σt L)).
        let m = medium(Vec3::new(0.1, 0.5, 0.0), Vec3::new(0.9, 0.2, 1.5));
        let st = m.sigma_t();
        let l = 1.3f32;
        let n = 400_000;
        let mut rng = Rng::new(9, 0);
        let (mut pass, mut scatter) = (Vec3::ZERO, Vec3::ZERO);
        for _ in 0..n {
            match m.sample_distance(l, rng.next_2d()) {
                FreeFlight::Scatter { t, weight } => {
                    assert!(t < l);
                    scatter += weight;
                }
                FreeFlight::Pass { weight } => pass += weight,
            }
        }
        let (pass, scatter) = (pass / n as f32, scatter / n as f32);
        for c in 0..3 {
            let want_pass = (-st[c] * l).exp();
            let want_scatter = m.sigma_s[c] / st[c] * (1.0 - want_pass);
            assert!(
                (pass[c] - want_pass).abs() < 0.01,
                "{c}: {pass} vs {want_pass}"
            );
            assert!(
                (scatter[c] - want_scatter).abs() < 0.01,
                "{c}: {scatter} vs {want_scatter}"
            );
        }
    }

    #[test]
    fn scatter_pdf_is_the_density_of_sampled_events() {
        // The fraction of 400 000 draws scattering in [t0, t1) against ∫ p(t) dt over it,
        // p's integral in closed form: ⅓ Σ_c (e^{−σt,c t0} − e^{−σt,c t1}).
        let m = medium(Vec3::new(0.1, 0.5, 0.0), Vec3::new(0.9, 0.2, 1.5));
        let st = m.sigma_t();
        let (t0, t1) = (0.3f32, 0.8f32);
        let n = 400_000;
        let mut rng = Rng::new(11, 0);
        let mut inside = 0u32;
        for _ in 0..n {
            if let FreeFlight::Scatter { t, .. } = m.sample_distance(2.0, rng.next_2d())
                && (t0..t1).contains(&t)
            {
                inside += 1;
            }
        }
        let want = (0..3)
            .map(|c| ((-st[c] * t0).exp() - (-st[c] * t1).exp()) / 3.0)
            .sum::<f32>();
        let got = inside as f32 / n as f32;
        assert!((got - want).abs() < 0.003, "{got} vs {want}");
        // And p itself against that integral by the midpoint rule.
        let steps = 10_000;
        let h = (t1 - t0) / steps as f32;
        let integral: f32 = (0..steps)
            .map(|i| m.scatter_pdf(t0 + (i as f32 + 0.5) * h) * h)
            .sum();
        assert!((integral - want).abs() < 1e-4, "{integral} vs {want}");
    }

    #[test]
    fn a_grey_albedo_one_medium_weighs_every_event_one() {
        let m = medium(Vec3::ZERO, Vec3::splat(2.0));
        let mut rng = Rng::new(3, 0);
        for _ in 0..1000 {
            let w = match m.sample_distance(f32::INFINITY, rng.next_2d()) {
                FreeFlight::Scatter { weight, .. } | FreeFlight::Pass { weight } => weight,
            };
            assert!((w - Vec3::ONE).abs().max_element() < 1e-5, "{w}");
        }
    }

    #[test]
    fn an_absorbing_slab_transmits_exp_minus_sigma_d() {
        let m = medium(Vec3::new(0.5, 1.0, 2.0), Vec3::ZERO);
        let FreeFlight::Pass { weight } = m.sample_distance(0.7, (0.5, 0.5)) else {
            panic!("a medium that does not scatter only passes");
        };
        let want = Vec3::new((-0.35f32).exp(), (-0.7f32).exp(), (-1.4f32).exp());
        assert!(
            (weight - want).abs().max_element() < 1e-6,
            "{weight} vs {want}"
        );
    }
}
