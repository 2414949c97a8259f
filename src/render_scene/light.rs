//! Compiled lights and their sampling for direct illumination.

use glam::Vec3;
use std::f32::consts::PI;

use crate::sampling::warp::uniform_cone;

/// A light source in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// Point light with radiant intensity `intensity = Φ/(4π)` (W/sr).
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity per channel.
        intensity: Vec3,
    },
    /// Spherical emitter of uniform radiance `radiance = Φ/(4π²r²)`; also a sphere primitive.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
        /// Emitted radiance per channel.
        radiance: Vec3,
    },
}

/// One sample of incident light at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shaded point towards the light.
    pub wi: Vec3,
    /// Distance to the sampled light point along `wi`.
    pub distance: f32,
    /// The sampled point on the light (shadow rays end just before it).
    pub point: Vec3,
    /// Incident radiance divided by the sample density (already includes 1/r² for points).
    pub weight: Vec3,
}

impl Light {
    /// A point light emitting `power` watts.
    #[must_use]
    pub fn point(position: Vec3, power: Vec3) -> Self {
        Light::Point {
            position,
            intensity: power / (4.0 * PI),
        }
    }

    /// A sphere light emitting `power` watts from its surface.
    #[must_use]
    pub fn sphere(center: Vec3, radius: f32, power: Vec3) -> Self {
        Light::Sphere {
            center,
            radius,
            radiance: power / (4.0 * PI * PI * radius * radius),
        }
    }

    /// Samples incident light at `p`; `None` if `p` is inside the emitter or the light is black.
    #[must_use]
    pub fn sample(&self, p: Vec3, u: (f32, f32)) -> Option<LightSample> {
        match *self {
            Light::Point {
                position,
                intensity,
            } => {
                let d = position - p;
                let dist2 = d.length_squared();
                if !(dist2 > 0.0) || intensity == Vec3::ZERO {
                    return None;
                }
                let dist = dist2.sqrt();
                Some(LightSample {
                    wi: d / dist,
                    distance: dist,
                    point: position,
                    weight: intensity / dist2,
                })
            }
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                let d = center - p;
                let dist2 = d.length_squared();
                let r2 = radius * radius;
                if dist2 <= r2 || radiance == Vec3::ZERO {
                    return None;
                }
                let dist = dist2.sqrt();
                let axis = d / dist;
                // Uniform over the cone subtended by the sphere: pdf = 1 / (2π(1 − cos θmax)).
                let sin2_max = r2 / dist2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                let one_minus_cos = if sin2_max < 1e-4 {
                    0.5 * sin2_max
                } else {
                    1.0 - cos_max
                };
                let wi = uniform_cone(u, axis, cos_max);
                // Distance to the near side of the sphere along wi.
                let b = wi.dot(d);
                let disc = (r2 - (d - wi * b).length_squared()).max(0.0);
                let t = (b - disc.sqrt()).max(0.0);
                Some(LightSample {
                    wi,
                    distance: t,
                    point: p + wi * t,
                    weight: radiance * (2.0 * PI * one_minus_cos),
                })
            }
        }
    }

    /// Total emitted flux (W) per channel.
    #[must_use]
    pub fn power(&self) -> Vec3 {
        match *self {
            Light::Point { intensity, .. } => intensity * 4.0 * PI,
            Light::Sphere {
                radius, radiance, ..
            } => radiance * 4.0 * PI * PI * radius * radius,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn point_light_follows_inverse_square() {
        let l = Light::point(Vec3::new(0.0, 2.0, 0.0), Vec3::splat(4.0 * PI));
        let s = l.sample(Vec3::ZERO, (0.5, 0.5)).unwrap();
        assert!((s.weight.x - 0.25).abs() < 1e-6);
        assert!(s.wi.distance(Vec3::Y) < 1e-6);
        assert!((s.distance - 2.0).abs() < 1e-6);
    }

    #[test]
    fn sphere_light_irradiance_matches_a_point_light_far_away() {
        // E at distance D from a sphere of power Φ equals Φ/(4πD²) for D ≫ r (exactly, for a
        // Lambertian sphere facing the normal) — check by Monte Carlo.
        let power = Vec3::splat(100.0);
        let l = Light::sphere(Vec3::new(0.0, 10.0, 0.0), 0.5, power);
        let mut r = Rng::new(0, 0);
        let n = 200_000;
        let mut e = 0.0f64;
        for _ in 0..n {
            let s = l.sample(Vec3::ZERO, r.next_2d()).unwrap();
            e += f64::from(s.weight.x * s.wi.y.max(0.0));
        }
        let e = e / f64::from(n);
        let expected = 100.0 / (4.0 * std::f64::consts::PI * 100.0);
        assert!((e / expected - 1.0).abs() < 0.005, "{e} vs {expected}");
        assert!((l.power() - power).abs().max_element() < 1e-3);
    }
}
