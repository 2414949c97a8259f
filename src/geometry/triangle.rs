//! Watertight ray–triangle intersection (Woop, Benthin & Wald, JCGT 2013, in pbrt-v4's form):
//! rays never slip through shared edges or vertices of a closed mesh.

use glam::Vec3;

use super::Ray;
use super::float::gamma;

/// Per-ray constants of the watertight test: the axis permutation and shear that map the ray to +z.
#[derive(Debug, Clone, Copy)]
pub struct TriRay {
    origin: [f32; 3],
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

/// Distance and barycentrics of a ray–triangle hit; the point is `b0·p0 + b1·p1 + b2·p2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriHit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric weight of `p0`.
    pub b0: f32,
    /// Barycentric weight of `p1`.
    pub b1: f32,
    /// Barycentric weight of `p2`.
    pub b2: f32,
}

impl TriRay {
    /// The ray direction's dominant axis (0 = x, 1 = y, 2 = z).
    #[inline]
    #[must_use]
    pub fn dominant_axis(&self) -> usize {
        self.kz
    }

    /// Precomputes the permutation and shear for `ray` (its direction must be non-zero and finite).
    #[inline]
    #[must_use]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir.to_array();
        let a = ray.dir.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let kx = (kz + 1) % 3;
        let ky = (kx + 1) % 3;
        let dz = d[kz];
        Self {
            origin: ray.origin.to_array(),
            kz,
            sx: -d[kx] / dz,
            sy: -d[ky] / dz,
            sz: 1.0 / dz,
        }
    }
}

/// Two-sided watertight intersection of a ray with triangle `(p0, p1, p2)` for `t` in `(0, t_max)`.
/// Degenerate (zero-area) triangles never report a hit.
#[inline]
#[must_use]
pub fn intersect_triangle(r: &TriRay, p0: Vec3, p1: Vec3, p2: Vec3, t_max: f32) -> Option<TriHit> {
    match r.kz {
        0 => intersect_triangle_k::<0>(r, p0, p1, p2, t_max),
        1 => intersect_triangle_k::<1>(r, p0, p1, p2, t_max),
        _ => intersect_triangle_k::<2>(r, p0, p1, p2, t_max),
    }
}

/// [`intersect_triangle`] for a ray whose dominant axis is known at compile time (`KZ` must equal
/// [`TriRay::dominant_axis`]); lets hot loops hoist the axis dispatch out of the primitive loop.
#[inline(always)]
#[must_use]
pub fn intersect_triangle_k<const KZ: usize>(
    r: &TriRay,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
    t_max: f32,
) -> Option<TriHit> {
    debug_assert_eq!(KZ, r.kz);
    let kz = KZ;
    let kx = (KZ + 1) % 3;
    let ky = (KZ + 2) % 3;
    let o = r.origin;
    let (p0, p1, p2) = (p0.to_array(), p1.to_array(), p2.to_array());
    // Translate to the ray origin and permute so that the ray's dominant axis is z.
    let (p0z, p1z, p2z) = (p0[kz] - o[kz], p1[kz] - o[kz], p2[kz] - o[kz]);
    // Shear so that the ray points along +z.
    let p0x = (p0[kx] - o[kx]) + r.sx * p0z;
    let p0y = (p0[ky] - o[ky]) + r.sy * p0z;
    let p1x = (p1[kx] - o[kx]) + r.sx * p1z;
    let p1y = (p1[ky] - o[ky]) + r.sy * p1z;
    let p2x = (p2[kx] - o[kx]) + r.sx * p2z;
    let p2y = (p2[ky] - o[ky]) + r.sy * p2z;
    // Edge functions; they are exactly antisymmetric across a shared edge.
    let mut e0 = p1x * p2y - p1y * p2x;
    let mut e1 = p2x * p0y - p2y * p0x;
    let mut e2 = p0x * p1y - p0y * p1x;
    if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
        // Exactly on an edge in f32: decide in f64 so neighbours agree.
        let (p0x, p0y, p1x, p1y, p2x, p2y) = (
            f64::from(p0x),
            f64::from(p0y),
            f64::from(p1x),
            f64::from(p1y),
            f64::from(p2x),
            f64::from(p2y),
        );
        e0 = (p1x * p2y - p1y * p2x) as f32;
        e1 = (p2x * p0y - p2y * p0x) as f32;
        e2 = (p0x * p1y - p0y * p1x) as f32;
    }
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    let det = e0 + e1 + e2;
    if det == 0.0 || det.is_nan() {
        return None;
    }
    let (z0, z1, z2) = (p0z * r.sz, p1z * r.sz, p2z * r.sz);
    let t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
    if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
        return None;
    }
    if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    // Conservatively reject hits whose distance is not certainly positive.
    let max_zt = z0.abs().max(z1.abs()).max(z2.abs());
    let delta_z = gamma(3) * max_zt;
    let max_xt = p0x.abs().max(p1x.abs()).max(p2x.abs());
    let max_yt = p0y.abs().max(p1y.abs()).max(p2y.abs());
    let delta_x = gamma(5) * (max_xt + max_zt);
    let delta_y = gamma(5) * (max_yt + max_zt);
    let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = e0.abs().max(e1.abs()).max(e2.abs());
    let delta_t =
        3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
    if t <= delta_t {
        return None;
    }
    Some(TriHit {
        t,
        b0: e0 * inv_det,
        b1: e1 * inv_det,
        b2: e2 * inv_det,
    })
}

/// Absolute error bound of the interpolated hit point `b0·p0 + b1·p1 + b2·p2`.
#[inline]
#[must_use]
pub fn hit_point_error(hit: &TriHit, p0: Vec3, p1: Vec3, p2: Vec3) -> Vec3 {
    ((p0 * hit.b0).abs() + (p1 * hit.b1).abs() + (p2 * hit.b2).abs()) * gamma(7)
}

/// True if the triangle has zero area in f32 (such triangles are dropped at compile time).
#[inline]
#[must_use]
pub fn is_degenerate(p0: Vec3, p1: Vec3, p2: Vec3) -> bool {
    let c = (p1 - p0).cross(p2 - p0);
    !(c.length_squared() > 0.0) || !c.is_finite()
}

#[cfg(test)]
#[allow(clippy::excessive_precision, clippy::inconsistent_digit_grouping)]
mod tests {
    use super::*;

    fn hit(o: Vec3, d: Vec3, p: [Vec3; 3]) -> Option<TriHit> {
        let ray = Ray::new(o, d);
        intersect_triangle(&TriRay::new(&ray), p[0], p[1], p[2], f32::INFINITY)
    }

    const TRI: [Vec3; 3] = [Vec3::ZERO, Vec3::X, Vec3::Y];

    #[test]
    fn hit_distance_and_barycentrics_are_exact_for_simple_case() {
        let h = hit(Vec3::new(0.25, 0.25, -1.0), Vec3::Z, TRI).unwrap();
        assert_eq!(h.t, 1.0);
        assert!(
            (h.b1 - 0.25).abs() < 1e-7 && (h.b2 - 0.25).abs() < 1e-7 && (h.b0 - 0.5).abs() < 1e-7
        );
        // Two-sided.
        assert!(hit(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, TRI).is_some());
        // Behind the origin.
        assert!(hit(Vec3::new(0.25, 0.25, 1.0), Vec3::Z, TRI).is_none());
    }

    #[test]
    fn precision_within_16_ulp_on_sampled_points() {
        let mut worst = 0.0f32;
        for i in 1..40 {
            for j in 1..(40 - i) {
                let (u, v) = (i as f32 / 40.0, j as f32 / 40.0);
                let target = Vec3::new(u, v, 0.0);
                let o = Vec3::new(0.0, 0.0, -1.0);
                let h = hit(o, target - o, TRI).unwrap();
                worst = worst
                    .max((h.t - 1.0).abs())
                    .max((h.b1 - u).abs())
                    .max((h.b2 - v).abs());
            }
        }
        assert!(worst <= 16.0 * f32::EPSILON, "worst error {worst}");
    }

    #[test]
    fn ray_starting_on_the_triangle_does_not_rehit_it() {
        let tri = [
            Vec3::new(1e4, 0.0, 3.0),
            Vec3::new(1e4 + 1.0, 0.2, 3.1),
            Vec3::new(1e4, 1.0, 2.9),
        ];
        let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
        let mut rehits = 0;
        for i in 1..20 {
            for j in 1..(20 - i) {
                let h = TriHit {
                    t: 0.0,
                    b0: 1.0 - (i + j) as f32 / 20.0,
                    b1: i as f32 / 20.0,
                    b2: j as f32 / 20.0,
                };
                let p = tri[0] * h.b0 + tri[1] * h.b1 + tri[2] * h.b2;
                let err = hit_point_error(&h, tri[0], tri[1], tri[2]);
                for w in [
                    n,
                    -n,
                    (n + Vec3::X).normalize(),
                    (Vec3::Y - n * 0.999).normalize(),
                ] {
                    let o = crate::geometry::offset::offset_ray_origin(p, err, n, w);
                    if hit(o, w, tri).is_some() {
                        rehits += 1;
                    }
                    // Grazing: almost in the plane.
                    let graze = (w - n * n.dot(w) + n * 1e-4 * n.dot(w).signum()).normalize();
                    if hit(o, graze, tri).is_some() {
                        rehits += 1;
                    }
                }
            }
        }
        assert_eq!(rehits, 0);
    }

    #[test]
    fn degenerate_triangles_never_hit() {
        let same = [Vec3::ONE, Vec3::ONE, Vec3::ONE];
        let collinear = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        for tri in [same, collinear] {
            assert!(is_degenerate(tri[0], tri[1], tri[2]));
            for d in [Vec3::Z, Vec3::X, Vec3::new(0.3, 0.2, 0.9)] {
                assert!(hit(Vec3::new(0.5, 0.0, 0.0) - d, d, tri).is_none());
                assert!(hit(Vec3::ONE - d, d, tri).is_none());
            }
        }
        assert!(!is_degenerate(TRI[0], TRI[1], TRI[2]));
    }

    #[test]
    fn pbrt_bad_case_needle_triangle_is_degenerate_and_missed() {
        let p = [
            Vec3::new(-1113.454_59, -79.049_614, -56.243_190_8),
            Vec3::new(-1113.454_59, -87.092_269_9, -56.243_190_8),
            Vec3::new(-1113.454_59, -79.209_014_9, -56.243_190_8),
        ];
        let mut ray = Ray::new(
            Vec3::new(-1081.479_25, 99.999_954_2, 87.770_111_1),
            Vec3::new(-32.107_299_8, -183.355_865, -144.607_635),
        );
        ray.t_max = 0.9999;
        // Its vertices are collinear in f32: the compiler drops it before it reaches the BVH
        // (tests/it/primitives.rs checks that the ray then misses the scene). The intersector
        // alone does report a hit on it, so the drop is what makes it missed.
        assert!(is_degenerate(p[0], p[1], p[2]));
        assert!(intersect_triangle(&TriRay::new(&ray), p[0], p[1], p[2], ray.t_max).is_some());
    }

    #[test]
    fn shared_edge_is_watertight_from_many_directions() {
        // Two triangles sharing the diagonal of a unit square, rotated off the axes.
        let rot = glam::Quat::from_axis_angle(Vec3::ONE.normalize(), std::f32::consts::FRAC_PI_2);
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)].map(|p| rot * p);
        let tris = [[v[0], v[1], v[2]], [v[1], v[3], v[2]]];
        let target = rot * Vec3::new(0.5, 0.5, 0.0);
        let n = rot * Vec3::Z;
        let frame = crate::geometry::Frame::from_normal(n);
        let mut misses = 0;
        for i in 0..32 {
            for j in 0..32 {
                let u = 0.05 + 0.9 * i as f32 / 31.0;
                let w = 0.05 + 0.9 * j as f32 / 31.0;
                let r = u.sqrt();
                let phi = std::f32::consts::TAU * w;
                let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u).max(0.0).sqrt());
                let d = frame.to_world(local);
                let o = target + d;
                if tris.iter().all(|t| hit(o, -d, *t).is_none()) {
                    misses += 1;
                }
            }
        }
        assert_eq!(misses, 0);
    }
}
