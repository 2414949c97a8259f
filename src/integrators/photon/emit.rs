//! Photon emission: how many photons each light sends (in proportion to power, so photons carry
//! roughly equal flux, as in the report) and the ray and flux of each one.
//!
//! - Global photons leave point lights along a spherical Fibonacci lattice turned by a seeded
//!   random rotation per map and light (the report's evenly spaced directions, without a lattice
//!   that would imprint on the image), and sphere lights through [`Light::sample_le`].
//! - Caustic photons are aimed at the specular objects ([`super::aim`]); their flux divides by
//!   the aiming density, so the fraction of the light's directions that the targets cover is in
//!   every photon's flux.

use glam::{Mat3, Vec3};

use super::aim::{AimCone, CausticTargets, sample_cones};
use crate::geometry::Ray;
use crate::render_scene::Light;
use crate::sampling::Sampler;
use crate::sampling::warp::{spherical_fibonacci, uniform_rotation};

/// Splits `total` photons among lights with the given non-negative `weights` (their power),
/// proportionally, by largest remainder: the counts sum to `total` exactly (0 when every weight
/// is 0), and equal weights differ by at most one photon.
#[must_use]
pub fn split_by_power(total: u64, weights: &[f64]) -> Vec<u64> {
    let sum: f64 = weights.iter().filter(|w| w.is_finite() && **w > 0.0).sum();
    if !(sum > 0.0) || total == 0 {
        return vec![0; weights.len()];
    }
    let share = |w: f64| {
        if w.is_finite() && w > 0.0 {
            total as f64 * w / sum
        } else {
            0.0
        }
    };
    let mut counts: Vec<u64> = weights.iter().map(|&w| share(w).floor() as u64).collect();
    let assigned: u64 = counts.iter().sum();
    let mut order: Vec<usize> = (0..weights.len()).collect();
    // Largest fractional part first; ties to the lower index (deterministic).
    order.sort_by(|&a, &b| {
        let fa = share(weights[a]) - share(weights[a]).floor();
        let fb = share(weights[b]) - share(weights[b]).floor();
        fb.total_cmp(&fa).then(a.cmp(&b))
    });
    for &i in order.iter().take(total.saturating_sub(assigned) as usize) {
        counts[i] += 1;
    }
    counts
}

/// The emission of one light for one map: how many photons, and the per-map state (the
/// lattice rotation) they share.
#[derive(Debug, Clone)]
pub struct LightEmitter {
    /// The light.
    pub light: Light,
    /// Photons this light emits into the map.
    pub count: u64,
    /// Random rotation of the Fibonacci lattice (point lights, global map), as a matrix: its
    /// product with a vector is plain multiplies and adds in every build (glam's quaternion
    /// product fuses them into FMAs when the target has FMA, which would change the photons
    /// with the compiler flags).
    pub rotation: Mat3,
}

impl LightEmitter {
    /// An emitter of `count` photons from `light`; the lattice rotation is drawn from
    /// `sampler`'s stream `stream` (so it depends on the seed, the map and the light only).
    #[must_use]
    pub fn new(light: Light, count: u64, sampler: &mut Sampler, stream: u64) -> Self {
        sampler.start_stream(stream, 0);
        let (a, b) = sampler.next_2d();
        let c = sampler.next_1d();
        Self {
            light,
            count,
            rotation: Mat3::from_quat(uniform_rotation([a, b, c])),
        }
    }

    /// Photon `index` of a global map: its ray and flux (W per channel), through
    /// [`Light::emit_spread`]: lights that emit from a point follow the rotated lattice, lights
    /// with area draw from `sampler` (started on this photon). Every photon carries
    /// `Φ / count` on average. `None` for a black light.
    #[must_use]
    pub fn global(&self, index: u64, sampler: &mut Sampler) -> Option<(Ray, Vec3)> {
        let n = self.count.max(1) as f32;
        let lattice = || {
            let i = u32::try_from(index).unwrap_or(u32::MAX);
            let m = u32::try_from(self.count).unwrap_or(u32::MAX);
            self.rotation * spherical_fibonacci(i, m)
        };
        self.light.emit_spread(lattice, sampler, n)
    }

    /// Photon `index` of a caustic map, aimed at `targets` ([`Light::emit_aimed`]; lights at
    /// infinity along lines through the targets, [`CausticTargets::sample_crossing`]): its ray
    /// and flux, or `None` when the drawn direction leaves the light's surface inwards (no
    /// light goes there; the photon still counts as emitted, so the estimate stays unbiased).
    /// `cones` is scratch space.
    #[must_use]
    pub fn caustic(
        &self,
        targets: &CausticTargets,
        sampler: &mut Sampler,
        cones: &mut Vec<AimCone>,
    ) -> Option<(Ray, Vec3)> {
        let n = self.count.max(1) as f32;
        let aim = |from: Vec3, sampler: &mut Sampler| {
            let total = targets.cones(from, cones);
            let u_pick = sampler.next_1d();
            sample_cones(cones, total, u_pick, sampler.next_2d())
        };
        let cross = |dir: Vec3, sampler: &mut Sampler| {
            let u_pick = sampler.next_1d();
            targets.sample_crossing(dir, u_pick, sampler.next_2d())
        };
        self.light.emit_aimed(sampler, aim, cross, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_follows_power_and_sums_exactly() {
        assert_eq!(split_by_power(10, &[1.0, 1.0]), vec![5, 5]);
        assert_eq!(split_by_power(10, &[3.0, 1.0]), vec![8, 2]); // 7.5 / 2.5: ties to the lower
        assert_eq!(split_by_power(7, &[0.0, 2.0, 0.0]), vec![0, 7, 0]);
        assert_eq!(split_by_power(5, &[0.0, 0.0]), vec![0, 0]);
        let c = split_by_power(1_000_003, &[0.3, 0.5, 0.2, 1e-9]);
        assert_eq!(c.iter().sum::<u64>(), 1_000_003);
        assert!((c[1] as f64 - 500_001.5).abs() <= 1.0);
    }
}
