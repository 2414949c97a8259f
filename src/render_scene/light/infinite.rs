//! What lights at infinity (distant and environment lights) share: the scene's bounding sphere,
//! the far end of their shadow rays, and the disc their photons start from.

use glam::Vec3;
use std::f32::consts::PI;

use crate::geometry::Frame;
use crate::sampling::warp::concentric_disk;

/// The scene's bounding sphere (world units), which lights at infinity need to place their
/// shadow-ray end points and the disc photons leave from, and to state their power.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneSphere {
    /// Centre of the sphere.
    pub center: Vec3,
    /// Radius (> 0; a zero radius is raised to 1e-3 by [`SceneSphere::new`]).
    pub radius: f32,
}

impl SceneSphere {
    /// The sphere of `center` and `radius` (non-finite or tiny radii become 1e-3, so photon
    /// discs keep a finite density).
    #[must_use]
    pub fn new(center: Vec3, radius: f32) -> Self {
        let radius = if radius.is_finite() && radius > 1e-3 {
            radius
        } else {
            1e-3
        };
        Self { center, radius }
    }

    /// Area of a disc of the sphere's radius, `π R²` (m²): the cross-section every photon of a
    /// light at infinity crosses, so its power is `π R² ∫ L dω`.
    #[inline]
    #[must_use]
    pub fn disc_area(&self) -> f32 {
        PI * self.radius * self.radius
    }

    /// Distance from `p` along any direction to a point surely outside the sphere:
    /// `2 (|p − c| + R)`, where shadow rays towards a light at infinity end.
    #[inline]
    #[must_use]
    pub fn far_distance(&self, p: Vec3) -> f32 {
        2.0 * ((p - self.center).length() + self.radius)
    }

    /// The origin of a photon travelling along the unit `dir`: a uniform point (concentric
    /// map of `u`) on the disc of radius R perpendicular to `dir`, centred R upstream of the
    /// centre, so the ray crosses the whole sphere. Area density `1 / (π R²)`.
    #[inline]
    #[must_use]
    pub fn disc_origin(&self, dir: Vec3, u: (f32, f32)) -> Vec3 {
        let (a, b) = concentric_disk(u);
        let f = Frame::from_normal(dir);
        self.center + (f.s * a + f.t * b) * self.radius - dir * self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_origins_are_upstream_and_cover_the_cross_section() {
        let s = SceneSphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0);
        let dir = Vec3::new(0.3, -0.8, 0.2).normalize();
        for u in [(0.0, 0.0), (0.5, 0.5), (1.0, 0.3), (0.9, 0.1)] {
            let o = s.disc_origin(dir, u);
            let rel = o - s.center;
            // On the plane R upstream, within R of the axis.
            assert!((rel.dot(dir) + 2.0).abs() < 1e-5);
            assert!((rel + dir * 2.0).length() <= 2.0 + 1e-5);
        }
        assert!((s.disc_area() - 4.0 * PI).abs() < 1e-5);
        assert_eq!(SceneSphere::new(Vec3::ZERO, f32::NAN).radius, 1e-3);
        assert!(s.far_distance(Vec3::ZERO) > (Vec3::ZERO - s.center).length() + s.radius);
    }
}
