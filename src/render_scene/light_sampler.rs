//! Choosing one light per next-event estimate (or per photon) with probability proportional to
//! its power, so bright lights get most samples and the estimator stays unbiased by dividing by
//! the chosen light's probability.

use crate::sampling::alias::AliasTable;

use super::light::Light;

/// Picks lights with probability ∝ power, in O(1) per sample (an alias table).
///
/// "Power" is the mean of the light's three channel fluxes (W), as pbrt-v4's power light
/// sampler averages over wavelengths: any light that emits in some channel has a non-zero
/// probability (so the estimate stays unbiased in every channel), and a light's share does not
/// depend on how its colour is weighted. Lights of zero power are never chosen; with no light of
/// positive power, `sample` returns `None`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LightSampler {
    table: AliasTable,
}

impl LightSampler {
    /// The sampler for `lights` (indices into that slice).
    #[must_use]
    pub fn new(lights: &[Light]) -> Self {
        let weights: Vec<f32> = lights
            .iter()
            .map(|l| {
                let p = l.power();
                (p.x + p.y + p.z) / 3.0
            })
            .collect();
        Self {
            table: AliasTable::new(&weights),
        }
    }

    /// Chooses a light with `u ∈ [0, 1)`: its index and the probability it was chosen with.
    #[inline]
    #[must_use]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        self.table.sample(u)
    }

    /// [`LightSampler::sample`] with the number drawn by `u` only when there is a choice to
    /// make: with a single light the result does not depend on it, so a sampler's deferred draw
    /// ([`crate::sampling::Sampler::defer_1d`]) is never computed.
    #[inline]
    pub fn choose(&self, u: impl FnOnce() -> f32) -> Option<(usize, f32)> {
        if self.table.len() == 1 {
            self.table.sample(0.0)
        } else {
            self.table.sample(u())
        }
    }

    /// Probability that `sample` chooses light `i` (0 for dark lights and out-of-range indices);
    /// used for MIS when a BSDF-sampled ray hits light `i`.
    #[inline]
    #[must_use]
    pub fn pmf(&self, i: usize) -> f32 {
        self.table.pmf(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn choose_skips_the_number_only_when_it_cannot_matter() {
        let one = LightSampler::new(&[Light::sphere(Vec3::ONE, 0.5, Vec3::splat(2.0))]);
        for k in 0..1000 {
            let u = k as f32 / 1000.0;
            assert_eq!(one.sample(u), one.choose(|| panic!("not needed")));
        }
        let two = LightSampler::new(&[
            Light::point(Vec3::ZERO, Vec3::ONE),
            Light::sphere(Vec3::ONE, 0.5, Vec3::splat(2.0)),
        ]);
        for k in 0..1000 {
            let u = k as f32 / 1000.0;
            assert_eq!(two.sample(u), two.choose(|| u));
        }
        let dark = LightSampler::new(&[Light::point(Vec3::ZERO, Vec3::ZERO)]);
        assert_eq!(dark.choose(|| 0.3), None);
    }

    #[test]
    fn probabilities_follow_mean_channel_power() {
        let lights = [
            Light::point(Vec3::ZERO, Vec3::new(3.0, 0.0, 0.0)),
            Light::sphere(Vec3::ONE, 0.5, Vec3::splat(2.0)),
            Light::point(Vec3::ZERO, Vec3::ZERO),
            Light::sphere(Vec3::ONE, 2.0, Vec3::new(0.0, 0.0, 3.0)),
        ];
        let s = LightSampler::new(&lights);
        // Mean powers 1, 2, 0, 1 of a total 4.
        let want = [0.25, 0.5, 0.0, 0.25];
        for (i, w) in want.iter().enumerate() {
            assert!((s.pmf(i) - w).abs() < 1e-6, "{i}: {}", s.pmf(i));
        }
        assert_eq!(s.pmf(9), 0.0);
        // Sweeping u over a fine grid hits each light in proportion (the table is exact for
        // a uniform grid up to one column's rounding).
        let n = 4000;
        let mut counts = [0usize; 4];
        for k in 0..n {
            let (i, pmf) = s.sample((k as f32 + 0.5) / n as f32).unwrap();
            assert_eq!(pmf, want[i]);
            counts[i] += 1;
        }
        assert_eq!(counts, [1000, 2000, 0, 1000]);
    }

    #[test]
    fn no_lights_or_only_dark_ones_sample_nothing() {
        assert_eq!(LightSampler::new(&[]).sample(0.3), None);
        let dark = [Light::point(Vec3::ZERO, Vec3::ZERO)];
        let s = LightSampler::new(&dark);
        assert_eq!(s.sample(0.3), None);
        assert_eq!(s.pmf(0), 0.0);
    }
}
