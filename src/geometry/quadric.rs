//! Ray intersection with the unit disc and the unit open cylinder in their object space, in f64
//! (as the sphere, [`super::sphere`]): the disc `z = 0, x² + y² ≤ 1` facing +z, and the cylinder
//! `x² + y² = 1, −½ ≤ z ≤ ½` about +z without caps (Mitsuba 3's and pbrt-v4's `cylinder` are open
//! too). A node's radius and height, and its transform, map them to the world.
//!
//! The cylinder's roots use the same cancellation-free discriminant as the sphere (Haines et al.,
//! *Precision Improvements for Ray/Sphere Intersection*, Ray Tracing Gems ch. 7) in the xy plane.
//! Parameterisations are pbrt-v4's (`Disk`, `Cylinder`, §6.3–6.4): the disc's
//! `u = φ/2π, v = 1 − r`, the cylinder's `u = φ/2π, v = z + ½`.

use glam::{DMat3, DVec2, DVec3};
use std::f64::consts::TAU;

/// The two kinds of analytic surface besides spheres.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QuadricShape {
    /// The unit disc in the xy plane, normal +z.
    Disc,
    /// The unit-radius open cylinder about +z, `z ∈ [−½, ½]`, normal outwards.
    Cylinder,
}

impl QuadricShape {
    /// The nearest `t > 0` where `o + t·d` (object space) meets the shape, in f64.
    #[inline]
    #[must_use]
    pub fn hit_t(self, o: DVec3, d: DVec3) -> Option<f64> {
        match self {
            QuadricShape::Disc => disc_t(o, d),
            QuadricShape::Cylinder => cylinder_ts(o, d).into_iter().flatten().next(),
        }
    }

    /// Every `t > 0` where the line meets the shape (nearest first; at most two).
    #[inline]
    #[must_use]
    pub fn hit_ts(self, o: DVec3, d: DVec3) -> [Option<f64>; 2] {
        match self {
            QuadricShape::Disc => [disc_t(o, d), None],
            QuadricShape::Cylinder => cylinder_ts(o, d),
        }
    }

    /// The f32 distance of [`QuadricShape::hit_t`] within `(0, t_max)`.
    #[inline]
    #[must_use]
    pub fn intersect(self, o: DVec3, d: DVec3, t_max: f32) -> Option<f32> {
        let t = self.hit_t(o, d)? as f32;
        (t > 0.0 && t < t_max).then_some(t)
    }

    /// The point `p` (object space, near the surface) moved exactly onto it: the disc's z set
    /// to 0, the cylinder's (x, y) scaled to unit length.
    #[inline]
    #[must_use]
    pub fn reproject(self, p: DVec3) -> DVec3 {
        match self {
            QuadricShape::Disc => DVec3::new(p.x, p.y, 0.0),
            QuadricShape::Cylinder => {
                let r = p.truncate().length();
                if r == 0.0 {
                    DVec3::new(1.0, 0.0, p.z)
                } else {
                    DVec3::new(p.x / r, p.y / r, p.z)
                }
            }
        }
    }

    /// The object-space normal at a surface point `p`: +z for the disc, `(x, y, 0)` outwards
    /// for the cylinder.
    #[inline]
    #[must_use]
    pub fn normal(self, p: DVec3) -> DVec3 {
        match self {
            QuadricShape::Disc => DVec3::Z,
            QuadricShape::Cylinder => DVec3::new(p.x, p.y, 0.0),
        }
    }

    /// Texture coordinates and the object-space derivatives `∂p/∂u`, `∂p/∂v` at a surface point
    /// `p` (pbrt-v4's parameterisations, see the module docs). At the disc's centre, where
    /// `∂p/∂v` vanishes, it is taken along +x.
    #[must_use]
    pub fn uv(self, p: DVec3) -> (DVec2, DVec3, DVec3) {
        let phi = p.y.atan2(p.x).rem_euclid(TAU);
        match self {
            QuadricShape::Disc => {
                let r = p.truncate().length();
                let dpdu = DVec3::new(-TAU * p.y, TAU * p.x, 0.0);
                let dpdv = if r > 0.0 {
                    DVec3::new(-p.x / r, -p.y / r, 0.0)
                } else {
                    DVec3::NEG_X
                };
                (DVec2::new(phi / TAU, 1.0 - r), dpdu, dpdv)
            }
            QuadricShape::Cylinder => (
                DVec2::new(phi / TAU, p.z + 0.5),
                DVec3::new(-TAU * p.y, TAU * p.x, 0.0),
                DVec3::Z,
            ),
        }
    }

    /// True when a line can meet the shape twice, so a point sampled on it may lie behind
    /// another part of it (the cylinder's far wall); false for the flat disc.
    #[must_use]
    pub fn can_shadow_itself(self) -> bool {
        match self {
            QuadricShape::Disc => false,
            QuadricShape::Cylinder => true,
        }
    }

    /// The largest curvature (1/length) of the shape under the linear map `m`: 0 for the flat
    /// disc, `1/r` for a cylinder (the smaller of its two radii when it is elliptic).
    #[must_use]
    pub fn curvature(self, m: DMat3) -> f64 {
        match self {
            QuadricShape::Disc => 0.0,
            QuadricShape::Cylinder => 1.0 / m.x_axis.length().min(m.y_axis.length()),
        }
    }

    /// Area of the shape under the linear map `m`: `π |m x × m y|` for the disc (exact for any
    /// map), `2π √(|m x| |m y|) |m z|` for the cylinder (exact when it is round, the
    /// geometric-mean radius otherwise).
    #[must_use]
    pub fn area(self, m: DMat3) -> f64 {
        match self {
            QuadricShape::Disc => std::f64::consts::PI * m.x_axis.cross(m.y_axis).length(),
            QuadricShape::Cylinder => {
                TAU * (m.x_axis.length() * m.y_axis.length()).sqrt() * m.z_axis.length()
            }
        }
    }

    /// Corners of the object-space box around the shape.
    #[must_use]
    pub fn corners(self) -> [DVec3; 8] {
        let h = match self {
            QuadricShape::Disc => 0.0,
            QuadricShape::Cylinder => 0.5,
        };
        let mut c = [DVec3::ZERO; 8];
        for (i, v) in c.iter_mut().enumerate() {
            *v = DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -h } else { h },
            );
        }
        c
    }
}

/// The `t > 0` where `o + t·d` meets the plane z = 0 inside the unit circle.
#[inline]
fn disc_t(o: DVec3, d: DVec3) -> Option<f64> {
    if d.z == 0.0 || !d.z.is_finite() {
        return None;
    }
    let t = -o.z / d.z;
    if !(t > 0.0 && t.is_finite()) {
        return None;
    }
    let (x, y) = (o.x + t * d.x, o.y + t * d.y);
    (x * x + y * y <= 1.0).then_some(t)
}

/// The `t > 0` (nearest first) where `o + t·d` meets the unit cylinder within `|z| ≤ ½`.
#[inline]
fn cylinder_ts(o: DVec3, d: DVec3) -> [Option<f64>; 2] {
    let (o2, d2) = (o.truncate(), d.truncate());
    let a = d2.length_squared();
    if a == 0.0 || !a.is_finite() {
        return [None, None];
    }
    let inv_a = 1.0 / a;
    let b = 2.0 * d2.dot(o2);
    let c = o2.length_squared() - 1.0;
    // 4a(1 − |v|²), v the perpendicular from the axis to the line in the xy plane.
    let v = o2 - (0.5 * b * inv_a) * d2;
    let disc = 4.0 * a * (1.0 - v.length_squared());
    if !(disc >= 0.0) {
        return [None, None];
    }
    let root = disc.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    if q == 0.0 {
        return [None, None];
    }
    let (mut t0, mut t1) = (q * inv_a, c / q);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    let ok = |t: f64| (t > 0.0 && (o.z + t * d.z).abs() <= 0.5).then_some(t);
    match (ok(t0), ok(t1)) {
        (Some(a), b) => [Some(a), b],
        (None, b) => [b, None],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_hits_inside_the_circle_only() {
        let t = QuadricShape::Disc.hit_t(DVec3::new(0.3, 0.4, 2.0), DVec3::NEG_Z);
        assert_eq!(t, Some(2.0));
        // Oblique: from (0, 0, 1) towards (0.6, 0.8, 0) (|r| = 1: on the rim).
        let d = DVec3::new(0.6, 0.8, -1.0);
        assert!((QuadricShape::Disc.hit_t(DVec3::Z, d).unwrap() - 1.0).abs() < 1e-15);
        assert!(
            QuadricShape::Disc
                .hit_t(DVec3::Z, d * DVec3::new(1.01, 1.01, 1.0))
                .is_none()
        );
        // Parallel and away.
        assert!(QuadricShape::Disc.hit_t(DVec3::Z, DVec3::X).is_none());
        assert!(QuadricShape::Disc.hit_t(DVec3::Z, DVec3::Z).is_none());
        assert_eq!(QuadricShape::Disc.normal(DVec3::ZERO), DVec3::Z);
    }

    #[test]
    fn cylinder_roots_normals_and_open_ends() {
        let c = QuadricShape::Cylinder;
        // From outside along −x through the axis: enters at x = 1 (t = 4), leaves at x = −1.
        let o = DVec3::new(5.0, 0.0, 0.2);
        let [a, b] = c.hit_ts(o, DVec3::NEG_X);
        assert_eq!((a, b), (Some(4.0), Some(6.0)));
        let p = o + DVec3::NEG_X * a.unwrap();
        assert_eq!(c.normal(p), DVec3::X);
        // Off axis at distance 0.6: the chord's half-length is 0.8.
        let o = DVec3::new(5.0, 0.6, 0.0);
        assert!((c.hit_t(o, DVec3::NEG_X).unwrap() - 4.2).abs() < 1e-12);
        // From inside: the far wall only.
        let [a, b] = c.hit_ts(DVec3::ZERO, DVec3::Y);
        assert_eq!((a, b), (Some(1.0), None));
        // Along the axis (a = 0) and through the open ends: no hit.
        assert!(c.hit_t(DVec3::new(0.0, 0.0, -3.0), DVec3::Z).is_none());
        // Enters through the open top (above z = ½ where it crosses x = 1, at t = 0.5) and meets
        // the far wall from inside at (−1, 0, 0), t = 2.5.
        let o = DVec3::new(1.5, 0.0, 1.5);
        let d = DVec3::new(-1.0, 0.0, -0.6);
        assert!((c.hit_t(o, d).unwrap() - 2.5).abs() < 1e-12);
        // Beyond the height: miss.
        assert!(c.hit_t(DVec3::new(5.0, 0.0, 0.6), DVec3::NEG_X).is_none());
    }

    #[test]
    fn uv_follow_pbrt() {
        let (uv, dpdu, dpdv) = QuadricShape::Cylinder.uv(DVec3::new(0.0, 1.0, 0.25));
        assert!((uv - DVec2::new(0.25, 0.75)).length() < 1e-12);
        assert!((dpdu - DVec3::new(-TAU, 0.0, 0.0)).length() < 1e-12);
        assert_eq!(dpdv, DVec3::Z);
        let (uv, dpdu, dpdv) = QuadricShape::Disc.uv(DVec3::new(-0.5, 0.0, 0.0));
        assert!((uv - DVec2::new(0.5, 0.5)).length() < 1e-12);
        assert!((dpdu - DVec3::new(0.0, -0.5 * TAU, 0.0)).length() < 1e-12);
        assert!((dpdv - DVec3::X).length() < 1e-12);
        // dp/du is the derivative of p(u) = (cos 2πu, sin 2πu, z): finite difference.
        let p = |u: f64| DVec3::new((TAU * u).cos(), (TAU * u).sin(), 0.1);
        let (uv, dpdu, _) = QuadricShape::Cylinder.uv(p(0.3));
        let fd = (p(0.3 + 1e-6) - p(0.3 - 1e-6)) / 2e-6;
        assert!((dpdu - fd).length() < 1e-5 && (uv.x - 0.3).abs() < 1e-12);
    }
}
