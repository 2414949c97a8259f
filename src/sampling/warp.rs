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

/// Point `i` of the `n`-point spherical Fibonacci lattice (González, "Measurement of areas on a
/// sphere using Fibonacci and latitude–longitude lattices", Math. Geosciences 2010): heights
/// `z = 1 − (2i + 1)/n` (equal-area bands), longitudes advancing by the golden angle. Every
/// point stands for the same solid angle `4π/n`, so `n` photons sent along the lattice sample
/// an isotropic light with density `1/(4π)` and far less clumping than random directions.
/// `i < n`; computed in f64 so the longitude stays exact for large `i`.
#[inline]
#[must_use]
pub fn spherical_fibonacci(i: u32, n: u32) -> Vec3 {
    // 2π (1 − 1/φ): the golden angle in radians.
    const GOLDEN_ANGLE: f64 = 2.399_963_229_728_653;
    let n = f64::from(n.max(1));
    let z = 1.0 - (2.0 * f64::from(i) + 1.0) / n;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = (GOLDEN_ANGLE * f64::from(i)) % std::f64::consts::TAU;
    Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
}

/// A uniformly distributed random rotation from three uniforms (Shoemake, "Uniform random
/// rotations", Graphics Gems III, 1992): a unit quaternion uniform on the 3-sphere.
#[must_use]
pub fn uniform_rotation(u: [f32; 3]) -> glam::Quat {
    let (a, b) = ((1.0 - u[0]).sqrt(), u[0].sqrt());
    let (t1, t2) = (TAU * u[1], TAU * u[2]);
    glam::Quat::from_xyzw(a * t1.sin(), a * t1.cos(), b * t2.sin(), b * t2.cos()).normalize()
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

/// A point uniformly distributed on the unit disc from `u ∈ [0, 1)²` by Shirley and Chiu's
/// concentric map ("A Low Distortion Map Between Disk and Square", JGT 1997): squares around the
/// centre go to circles, so stratified samples stay stratified. Density `1/π` per unit area;
/// the square's boundary (`max(|2u − 1|) = 1`) maps to the unit circle.
#[inline]
#[must_use]
pub fn concentric_disk(u: (f32, f32)) -> (f32, f32) {
    let (a, b) = (2.0 * u.0 - 1.0, 2.0 * u.1 - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, std::f32::consts::FRAC_PI_4 * (b / a))
    } else {
        (
            b,
            std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4 * (a / b),
        )
    };
    (r * phi.cos(), r * phi.sin())
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

    #[test]
    fn concentric_disk_is_uniform_and_maps_the_border_to_the_circle() {
        use crate::sampling::chi2::pearson;
        // Equal-area bins: 4 rings of equal r² width × 8 sectors.
        let mut r = Rng::new(5, 0);
        let mut counts = vec![0u64; 32];
        let n = 64_000;
        for _ in 0..n {
            let (x, y) = concentric_disk(r.next_2d());
            let r2 = x * x + y * y;
            assert!(r2 <= 1.0 + 1e-6);
            let ring = ((r2 * 4.0) as usize).min(3);
            let phi = y.atan2(x).rem_euclid(TAU);
            let sector = ((phi / TAU * 8.0) as usize).min(7);
            counts[ring * 8 + sector] += 1;
        }
        let res = pearson(&counts, &vec![f64::from(n) / 32.0; 32]);
        assert!(res.p_value > 0.01, "{res:?}");
        for t in [0.0, 0.3, 0.5, 0.9] {
            let (x, y) = concentric_disk((1.0, t));
            assert!(((x * x + y * y).sqrt() - 1.0).abs() < 1e-6);
        }
    }
}
