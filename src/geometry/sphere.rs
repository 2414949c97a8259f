//! Ray–sphere intersection, evaluated in f64 with the cancellation-free discriminant
//! (Haines et al., Ray Tracing Gems ch. 7), so distant and tiny spheres stay correct.

use glam::{DVec3, Vec3};

use super::Ray;

/// Nearest `t` in `(0, ray.t_max)` where `ray` meets the sphere, if any. The ray may start inside.
#[inline]
#[must_use]
pub fn intersect_sphere(center: Vec3, radius: f32, ray: &Ray) -> Option<f32> {
    intersect_unit_quadric(
        ray.origin.as_dvec3() - center.as_dvec3(),
        ray.dir.as_dvec3(),
        f64::from(radius),
        ray.t_max,
    )
}

/// Nearest `t` in `(0, t_max)` for a ray from `o` (relative to the centre) along `d` against a
/// sphere of radius `r` at the origin, in f64.
#[inline]
#[must_use]
pub fn intersect_unit_quadric(o: DVec3, d: DVec3, r: f64, t_max: f32) -> Option<f32> {
    let t = unit_quadric_t(o, d, r)?;
    let t32 = t as f32;
    (t32 > 0.0 && t32 < t_max).then_some(t32)
}

/// The f64 root [`intersect_unit_quadric`] rounds to f32: the nearer root if positive, else the
/// farther one, if positive. Shading recomputes it, because the f32 `t` can be off by more than
/// a thin ellipsoid's thickness (in object space, `o + t·d` then lands on the wrong side).
#[inline]
#[must_use]
pub fn unit_quadric_t(o: DVec3, d: DVec3, r: f64) -> Option<f64> {
    let a = d.length_squared();
    if a == 0.0 || !a.is_finite() {
        return None;
    }
    // 1/a once, off the critical path (a division is the slowest step of this test).
    let inv_a = 1.0 / a;
    let b = 2.0 * d.dot(o);
    let c = o.length_squared() - r * r;
    // Discriminant as 4a(r² - |v|²), v the perpendicular from the centre to the ray line:
    // computed as a vector, it does not suffer the cancellation of b² - 4ac (Haines et al.).
    // In f64 the difference of squares loses nothing that the f32 result could show, and
    // spares the square root of |v|.
    let v = o - (0.5 * b * inv_a) * d;
    let disc = 4.0 * a * (r * r - v.length_squared());
    if !(disc >= 0.0) {
        return None;
    }
    let root = disc.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    if q == 0.0 {
        return None;
    }
    let (mut t0, mut t1) = (q * inv_a, c / q);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    let t = if t0 > 0.0 { t0 } else { t1 };
    (t > 0.0).then_some(t)
}

/// Projects a point onto the sphere's surface (removing the error of `o + t·d`) in f64.
#[inline]
#[must_use]
pub fn reproject_to_sphere(center: DVec3, radius: f64, p: DVec3) -> DVec3 {
    let rel = p - center;
    let len = rel.length();
    if len == 0.0 {
        center + DVec3::new(radius, 0.0, 0.0)
    } else {
        center + rel * (radius / len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: Vec3, d: Vec3) -> Ray {
        Ray::new(o, d)
    }

    #[test]
    fn hits_from_outside_and_inside() {
        let t =
            intersect_sphere(Vec3::ZERO, 1.0, &ray(Vec3::new(0.0, 0.0, -5.0), Vec3::Z)).unwrap();
        assert!((t - 4.0).abs() < 1e-6);
        let t = intersect_sphere(Vec3::ZERO, 1.0, &ray(Vec3::ZERO, Vec3::Y)).unwrap();
        assert!((t - 1.0).abs() < 1e-6, "from the centre");
        let t =
            intersect_sphere(Vec3::ZERO, 1.0, &ray(Vec3::new(0.5, 0.0, 0.0), -Vec3::X)).unwrap();
        assert!((t - 1.5).abs() < 1e-6, "from inside, off centre");
        assert!(
            intersect_sphere(Vec3::ZERO, 1.0, &ray(Vec3::new(0.0, 0.0, 5.0), Vec3::Z)).is_none(),
            "behind"
        );
    }

    #[test]
    fn respects_t_max() {
        let mut r = ray(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        r.t_max = 3.9;
        assert!(intersect_sphere(Vec3::ZERO, 1.0, &r).is_none());
    }

    #[test]
    fn grazing_the_silhouette() {
        // Impact parameter just inside and just outside the radius.
        let inside = ray(Vec3::new(-5.0, 0.999_99, 0.0), Vec3::X);
        let outside = ray(Vec3::new(-5.0, 1.000_01, 0.0), Vec3::X);
        assert!(intersect_sphere(Vec3::ZERO, 1.0, &inside).is_some());
        assert!(intersect_sphere(Vec3::ZERO, 1.0, &outside).is_none());
    }

    #[test]
    fn ray_starting_on_the_surface_going_out_does_not_rehit() {
        let p = Vec3::new(0.6, 0.8, 0.0);
        let n = p;
        let o = super::super::offset::offset_ray_origin(
            p,
            p.abs() * super::super::float::gamma(2),
            n,
            n,
        );
        assert!(intersect_sphere(Vec3::ZERO, 1.0, &ray(o, n)).is_none());
        // Going in, it reaches the far side at distance 2.
        let o = super::super::offset::offset_ray_origin(
            p,
            p.abs() * super::super::float::gamma(2),
            n,
            -n,
        );
        let t = intersect_sphere(Vec3::ZERO, 1.0, &ray(o, -n)).unwrap();
        assert!((t - 2.0).abs() < 1e-5);
    }

    #[test]
    fn distant_small_sphere_is_classified_correctly() {
        // D/r = 1e5 with impact parameters 0.99 r and 1.01 r: naive b²-4ac gets many of these wrong.
        let mut wrong = 0;
        for i in 0..200 {
            let ang = i as f32 * 0.031;
            let dir = Vec3::new(ang.cos(), ang.sin(), 0.3).normalize();
            let perp = dir.any_orthonormal_vector();
            for (b, expect) in [(0.99f32, true), (1.01, false)] {
                let o = -dir * 1e5 + perp * b;
                if intersect_sphere(Vec3::ZERO, 1.0, &ray(o, dir)).is_some() != expect {
                    wrong += 1;
                }
            }
        }
        assert_eq!(wrong, 0);
    }

    #[test]
    fn axis_aligned_and_degenerate_directions() {
        for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            let t = intersect_sphere(Vec3::ZERO, 2.0, &ray(-d * 10.0, d)).unwrap();
            assert!((t - 8.0).abs() < 1e-5);
        }
        assert!(
            intersect_sphere(Vec3::ZERO, 1.0, &ray(Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO))
                .is_none()
        );
        assert!(
            intersect_sphere(Vec3::ZERO, 1.0, &ray(Vec3::new(0.0, 0.0, -5.0), Vec3::NAN)).is_none()
        );
    }
}
