//! Warps from the unit square to directions and points.

use glam::Vec3;
use std::f32::consts::TAU;

use crate::geometry::Frame;

/// A direction uniformly distributed in the cone of half-angle `acos(cos_max)` around `axis`
/// (unit); its density is `1 / (2π(1 − cos_max))`.
#[inline]
#[must_use]
pub fn uniform_cone(u: (f32, f32), axis: Vec3, cos_max: f32) -> Vec3 {
    let cos_t = 1.0 - u.0 * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = TAU * u.1;
    Frame::from_normal(axis).to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t))
}

/// A direction uniformly distributed in the cone around the unit `axis` whose half-angle θmax has
/// `1 − cos θmax = one_minus_cos_max` (in `[0, 2]`); its density is `1 / (2π · one_minus_cos_max)`.
///
/// Unlike [`uniform_cone`] it keeps full precision for tiny cones (a far or small sphere light):
/// it samples `1 − cos θ` directly and derives `sin θ` from it, so directions still spread over
/// the cone when `cos θmax` rounds to 1 in `f32`.
#[inline]
#[must_use]
pub fn uniform_cone_narrow(u: (f32, f32), axis: Vec3, one_minus_cos_max: f32) -> Vec3 {
    let one_minus_cos = (u.0 * one_minus_cos_max).clamp(0.0, 2.0);
    let cos_t = 1.0 - one_minus_cos;
    let sin_t = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let phi = TAU * u.1;
    Frame::from_normal(axis).to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t))
}

/// A direction uniformly distributed over the unit sphere; density `1 / (4π)`.
#[inline]
#[must_use]
pub fn uniform_sphere(u: (f32, f32)) -> Vec3 {
    let z = 1.0 - 2.0 * u.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * u.1;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Cosine-weighted direction in the hemisphere around the unit `n`; density `cos θ / π`.
#[inline]
#[must_use]
pub fn cosine_hemisphere(u: (f32, f32), n: Vec3) -> Vec3 {
    let r = u.0.sqrt();
    let phi = TAU * u.1;
    let z = (1.0 - u.0).max(0.0).sqrt();
    Frame::from_normal(n).to_world(Vec3::new(r * phi.cos(), r * phi.sin(), z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn cone_samples_stay_inside_the_cone() {
        let mut r = Rng::new(0, 0);
        let axis = Vec3::new(1.0, 2.0, -0.5).normalize();
        for _ in 0..10_000 {
            let d = uniform_cone(r.next_2d(), axis, 0.9);
            assert!(d.dot(axis) >= 0.9 - 1e-5);
            assert!((d.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn cosine_hemisphere_mean_cosine_is_two_thirds() {
        let mut r = Rng::new(0, 1);
        let n = Vec3::Y;
        let mean: f32 = (0..100_000)
            .map(|_| cosine_hemisphere(r.next_2d(), n).dot(n))
            .sum::<f32>()
            / 100_000.0;
        assert!((mean - 2.0 / 3.0).abs() < 0.005, "{mean}");
    }
}
