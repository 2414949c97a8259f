//! Watertight ray–triangle intersection (Woop, Benthin & Wald, JCGT 2013, in pbrt-v4's form):
//! rays never slip through shared edges or vertices of a closed mesh.

use glam::{BVec4A, DVec3, Vec3, Vec4};

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
    // A positive distance within the error bound is not certainly positive in f32.
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
    let t = if t <= delta_t {
        // Decided in f64 against the plane (the edge tests above stand, so the test stays
        // watertight; see `plane_hit_f64` for why this band is the one to decide).
        plane_hit_f64(
            r,
            Vec3::from_array(p0),
            Vec3::from_array(p1),
            Vec3::from_array(p2),
            t_max,
        )?
    } else {
        t
    };
    Some(TriHit {
        t,
        b0: e0 * inv_det,
        b1: e1 * inv_det,
        b2: e2 * inv_det,
    })
}

/// The distance along `r` to the plane of triangle `(p0, p1, p2)` computed in f64, when it lies
/// certainly in `(0, t_max)`: the decision of the watertight test for a hit whose f32 distance
/// `t` is positive but within its error bound `δt` of the origin (`0 < t ≤ δt`), every one of
/// which pbrt-v4 rejects (§6.8.7, conservatively). That rejection lets a ray from a point
/// micrometres before another surface pass through it: a shadow ray from a floor point at the
/// foot of a 2.4 m single-quad wall, up to ~30 µm from it, reached the light behind the wall
/// (issue 47, thin-wall-photon-leak). The line is the f32 test's own (the permuted axes, the
/// direction `(−sx, −sy, 1)` its edge tests used, `t = Δz·sz`). The vertices, origin and
/// shear are f32, so their differences are exact in f64 and the plane's normal is rounded by a
/// few units in 2⁻⁵³: a point 10⁻¹² of the scene's size off the plane is on a certain side.
///
/// **Why this band and no other.** A lane is decided here only when the f32 test found it
/// inside all three edges, in front of the origin (`t > 0`) and not beyond `t_max`, but not
/// *certainly* in front (`t ≤ δt`): these are the only hits that the f32 test's error bound
/// rejects. Lanes the f32 test puts behind the origin (`t ≤ 0`) stay rejected without a second
/// look, which keeps pbrt's early exit for packs whose triangles all lie behind the ray — the
/// common case, whose loss cost +4 % instructions on a path-traced Cornell box. A hit is then
/// missed only when the origin lies closer to the plane than the f32 distance's *actual*
/// rounding (a few units in the last place of the vertices' coordinates relative to the origin,
/// measured ≲ 10⁻⁷ of the triangle's extent by `a_ray_from_micrometres_before_a_wall_hits_it`,
/// against δt's ~10⁻⁵): that is the size of the origin's own error bound as a computed hit
/// point (`hit_point_error`, γ₇ of its coordinates), so which side of the plane it lies on is
/// not known in the first place. The band is rare: a spawned ray's own triangle (its origin
/// offset off it by that bound, `offset_ray_origin`) comes out with `t ≤ 0` in most cases and
/// costs nothing; when it lands in the band the f64 distance is certainly negative (the offset
/// is many times the f64 rounding), so the ray still never rehits its triangle or its creased
/// neighbours.
///
/// `None` when the hit is behind the origin, beyond `t_max`, or undecided even in f64 (the
/// origin on the plane, or the ray parallel to it).
#[cold]
#[inline(never)]
#[must_use]
pub fn plane_hit_f64(r: &TriRay, p0: Vec3, p1: Vec3, p2: Vec3, t_max: f32) -> Option<f32> {
    // The f32 test's own line: in the permuted axes (kx, ky, kz), through the origin along
    // (−sx, −sy, 1), with t = (z − o_z)·sz; its edge tests were made against exactly this line.
    let kx = (r.kz + 1) % 3;
    let ky = (kx + 1) % 3;
    let perm = |p: [f32; 3]| DVec3::new(p[kx].into(), p[ky].into(), p[r.kz].into());
    let (a, b, c) = (
        perm(p0.to_array()),
        perm(p1.to_array()),
        perm(p2.to_array()),
    );
    let o = perm(r.origin);
    let d = DVec3::new(-f64::from(r.sx), -f64::from(r.sy), 1.0);
    let n = (b - a).cross(c - a);
    let to = a - o;
    let (num, den) = (to.dot(n), d.dot(n));
    let eps = 8.0 * f64::EPSILON;
    let certain = |v: f64, u: DVec3| v.abs() > eps * u.abs().dot(n.abs());
    if !certain(num, to) || !certain(den, d) {
        return None;
    }
    let t = num / den * f64::from(r.sz);
    (t > 0.0 && t < f64::from(t_max)).then(|| (t as f32).max(f32::MIN_POSITIVE))
}

/// [`plane_hit_f64`] for the pack lanes in `lanes` (lane `l` is lane `l % 4` of `packs[l / 4]`):
/// where it finds a hit, sets the lane's distance, scaled distance and determinant in `hits`
/// (`[t, t_scaled, det]`, with `det` 1 so that [`PackHits::within`] compares the distance
/// itself) and returns the hit lanes' bits.
pub(super) fn near_lanes_f64<const N: usize>(
    r: &TriRay,
    packs: &[&TriPack4],
    lanes: u32,
    t_max: f32,
    hits: &mut [[f32; N]; 3],
) -> u32 {
    let mut found = 0;
    for l in 0..N {
        if lanes & (1 << l) == 0 {
            continue;
        }
        let Some(pack) = packs.get(l / 4) else {
            continue;
        };
        let v = |i: usize| {
            Vec3::new(
                pack.v[i][0][l % 4],
                pack.v[i][1][l % 4],
                pack.v[i][2][l % 4],
            )
        };
        if let Some(t) = plane_hit_f64(r, v(0), v(1), v(2), t_max) {
            found |= 1 << l;
            for (lane, value) in hits.iter_mut().zip([t, t, 1.0]) {
                lane[l] = value;
            }
        }
    }
    found
}

mod pack8;
pub use pack8::{PackHits8, intersect_pack8_k};

/// Four triangles in structure-of-arrays layout for [`intersect_pack_k`]: `v[vertex][axis]` holds
/// that coordinate of the four triangles, one triangle per SIMD lane (144 bytes). An unused lane
/// holds NaN coordinates, which the test never reports as a hit.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(16))]
pub struct TriPack4 {
    /// `v[vertex][axis]`: coordinate `axis` of vertex `vertex`, per lane.
    pub v: [[Vec4; 3]; 3],
}

impl TriPack4 {
    /// A pack with no triangles (every lane NaN).
    pub const EMPTY: TriPack4 = TriPack4 {
        v: [[Vec4::NAN; 3]; 3],
    };

    /// Puts triangle `(p0, p1, p2)` in lane `lane` (0..4).
    pub fn set(&mut self, lane: usize, p0: Vec3, p1: Vec3, p2: Vec3) {
        for (vertex, p) in [p0, p1, p2].into_iter().enumerate() {
            for axis in 0..3 {
                self.v[vertex][axis][lane] = p[axis];
            }
        }
    }
}

/// What [`intersect_pack_k`] found: the lanes whose triangle the ray hits within `(0, t_max)`,
/// and per lane the quantities a caller needs to pick among them exactly as a lane-by-lane
/// [`intersect_triangle_k`] loop would (meaningful only in `mask` lanes).
#[derive(Debug, Clone, Copy)]
pub struct PackHits {
    /// Bit `l` set if lane `l` is hit (never 0).
    pub mask: u32,
    /// Ray parameter per lane.
    pub t: Vec4,
    /// Unnormalised distance `t · det` per lane, for [`PackHits::within`].
    t_scaled: Vec4,
    /// Determinant (sum of the edge functions) per lane.
    det: Vec4,
    /// Barycentric weights of `p0` per lane.
    pub b0: Vec4,
    /// Barycentric weights of `p1` per lane.
    pub b1: Vec4,
    /// Barycentric weights of `p2` per lane.
    pub b2: Vec4,
}

impl PackHits {
    /// True if the hit in lane `lane` (one of `mask`) also passes [`intersect_triangle_k`]'s
    /// distance test against the smaller bound `t_max`, with the same rounding: a caller that
    /// takes hits lane by lane, shrinking `t_max` as it goes, keeps exactly the hits the scalar
    /// loop over the same triangles would keep.
    #[inline(always)]
    #[must_use]
    pub fn within(&self, lane: usize, t_max: f32) -> bool {
        let (ts, det) = (self.t_scaled[lane], self.det[lane]);
        if det < 0.0 {
            !(ts < t_max * det)
        } else {
            !(ts > t_max * det)
        }
    }

    /// The hit in lane `lane` as a [`TriHit`].
    #[inline(always)]
    #[must_use]
    pub fn hit(&self, lane: usize) -> TriHit {
        TriHit {
            t: self.t[lane],
            b0: self.b0[lane],
            b1: self.b1[lane],
            b2: self.b2[lane],
        }
    }
}

/// [`intersect_triangle_k`] on four triangles at once (one per SIMD lane): the same operations
/// in the same order per lane, so every lane's hit, distance and barycentrics are bit for bit
/// those of the scalar test (Woop, Benthin & Wald, JCGT 2013, watertight). `KZ` must equal
/// [`TriRay::dominant_axis`]. `None` if no lane is hit.
#[inline(always)]
#[must_use]
pub fn intersect_pack_k<const KZ: usize>(
    r: &TriRay,
    pack: &TriPack4,
    t_max: f32,
) -> Option<PackHits> {
    debug_assert_eq!(KZ, r.kz);
    let kz = KZ;
    let kx = (KZ + 1) % 3;
    let ky = (KZ + 2) % 3;
    let o = r.origin;
    let (ox, oy, oz) = (Vec4::splat(o[kx]), Vec4::splat(o[ky]), Vec4::splat(o[kz]));
    let (sx, sy) = (Vec4::splat(r.sx), Vec4::splat(r.sy));
    let [v0, v1, v2] = &pack.v;
    let (p0z, p1z, p2z) = (v0[kz] - oz, v1[kz] - oz, v2[kz] - oz);
    let p0x = (v0[kx] - ox) + sx * p0z;
    let p0y = (v0[ky] - oy) + sy * p0z;
    let p1x = (v1[kx] - ox) + sx * p1z;
    let p1y = (v1[ky] - oy) + sy * p1z;
    let p2x = (v2[kx] - ox) + sx * p2z;
    let p2y = (v2[ky] - oy) + sy * p2z;
    let mut e0 = p1x * p2y - p1y * p2x;
    let mut e1 = p2x * p0y - p2y * p0x;
    let mut e2 = p0x * p1y - p0y * p1x;
    let zero = Vec4::ZERO;
    let on_edge = (e0.cmpeq(zero) | e1.cmpeq(zero) | e2.cmpeq(zero)).bitmask();
    if on_edge != 0 {
        edge_functions_f64(
            [p0x, p0y, p1x, p1y, p2x, p2y],
            on_edge,
            [&mut e0, &mut e1, &mut e2],
        );
    }
    let neg = e0.cmplt(zero) | e1.cmplt(zero) | e2.cmplt(zero);
    let pos = e0.cmpgt(zero) | e1.cmpgt(zero) | e2.cmpgt(zero);
    let det = e0 + e1 + e2;
    let det_neg = det.cmplt(zero);
    let det_pos = det.cmpgt(zero);
    let inside = !(neg & pos) & (det_neg | det_pos);
    if !inside.any() {
        return None;
    }
    let sz = Vec4::splat(r.sz);
    let (z0, z1, z2) = (p0z * sz, p1z * sz, p2z * sz);
    let t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
    let t_max_det = Vec4::splat(t_max) * det;
    let reject_neg = det_neg & (t_scaled.cmpge(zero) | t_scaled.cmplt(t_max_det));
    let reject_pos = det_pos & (t_scaled.cmple(zero) | t_scaled.cmpgt(t_max_det));
    let mask: BVec4A = inside & !reject_neg & !reject_pos;
    if !mask.any() {
        return None;
    }
    let inv_det = Vec4::ONE / det;
    let t = t_scaled * inv_det;
    let max_zt = z0.abs().max(z1.abs()).max(z2.abs());
    let delta_z = Vec4::splat(gamma(3)) * max_zt;
    let max_xt = p0x.abs().max(p1x.abs()).max(p2x.abs());
    let max_yt = p0y.abs().max(p1y.abs()).max(p2y.abs());
    let delta_x = Vec4::splat(gamma(5)) * (max_xt + max_zt);
    let delta_y = Vec4::splat(gamma(5)) * (max_yt + max_zt);
    let delta_e = Vec4::splat(2.0)
        * (Vec4::splat(gamma(2)) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = e0.abs().max(e1.abs()).max(e2.abs());
    let delta_t = Vec4::splat(3.0)
        * (Vec4::splat(gamma(3)) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
        * inv_det.abs();
    let near = mask & t.cmple(delta_t);
    let hits = PackHits {
        mask: (mask & !near).bitmask(),
        t,
        t_scaled,
        det,
        b0: e0 * inv_det,
        b1: e1 * inv_det,
        b2: e2 * inv_det,
    };
    if near.any() {
        // Within the f32 bound of the origin: decided in f64 (see `plane_hit_f64`).
        return near_pack_f64(r, pack, near.bitmask(), t_max, hits);
    }
    (hits.mask != 0).then_some(hits)
}

/// [`intersect_pack_k`]'s lanes `near` (positive distance within the f32 error bound) decided
/// by [`plane_hit_f64`], added to `hits`; `None` if no lane is hit after all.
#[cold]
#[inline(never)]
fn near_pack_f64(
    r: &TriRay,
    pack: &TriPack4,
    near: u32,
    t_max: f32,
    mut hits: PackHits,
) -> Option<PackHits> {
    let mut ts = [
        hits.t.to_array(),
        hits.t_scaled.to_array(),
        hits.det.to_array(),
    ];
    hits.mask |= near_lanes_f64(r, &[pack], near, t_max, &mut ts);
    [hits.t, hits.t_scaled, hits.det] = ts.map(Vec4::from_array);
    (hits.mask != 0).then_some(hits)
}

/// The scalar test's f64 fallback for the lanes in `lanes` (an edge function exactly 0 in f32):
/// recomputes all three edge functions of those lanes in f64, so neighbours sharing the edge agree.
#[cold]
#[inline(never)]
fn edge_functions_f64(p: [Vec4; 6], lanes: u32, e: [&mut Vec4; 3]) {
    let [e0, e1, e2] = e;
    for l in 0..4 {
        if lanes & (1 << l) == 0 {
            continue;
        }
        let [p0x, p0y, p1x, p1y, p2x, p2y] = p.map(|v| f64::from(v[l]));
        e0[l] = (p1x * p2y - p1y * p2x) as f32;
        e1[l] = (p2x * p0y - p2y * p0x) as f32;
        e2[l] = (p0x * p1y - p0y * p1x) as f32;
    }
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

    /// Lane-by-lane comparison of the pack test with the scalar test: same lanes hit, same bits.
    fn pack_mismatches(ray: &Ray, tris: &[[Vec3; 3]], t_max: f32) -> usize {
        let r = TriRay::new(ray);
        let mut bad = 0;
        for group in tris.chunks(4) {
            let mut pack = TriPack4::EMPTY;
            for (lane, t) in group.iter().enumerate() {
                pack.set(lane, t[0], t[1], t[2]);
            }
            let h = match r.dominant_axis() {
                0 => intersect_pack_k::<0>(&r, &pack, t_max),
                1 => intersect_pack_k::<1>(&r, &pack, t_max),
                _ => intersect_pack_k::<2>(&r, &pack, t_max),
            };
            let mask = h.map_or(0, |h| h.mask);
            for lane in 0..4 {
                let scalar = group
                    .get(lane)
                    .and_then(|t| intersect_triangle(&r, t[0], t[1], t[2], t_max));
                let simd = h.filter(|_| mask & (1 << lane) != 0).map(|h| h.hit(lane));
                let bits = |x: Option<TriHit>| x.map(|x| [x.t, x.b0, x.b1, x.b2].map(f32::to_bits));
                if bits(scalar) != bits(simd) {
                    bad += 1;
                }
            }
        }
        for group in tris.chunks(8) {
            let mut packs = [TriPack4::EMPTY; 2];
            for (lane, t) in group.iter().enumerate() {
                packs[lane / 4].set(lane % 4, t[0], t[1], t[2]);
            }
            let [a, b] = &packs;
            let h = match r.dominant_axis() {
                0 => intersect_pack8_k::<0>(&r, a, b, t_max),
                1 => intersect_pack8_k::<1>(&r, a, b, t_max),
                _ => intersect_pack8_k::<2>(&r, a, b, t_max),
            };
            let mask = h.map_or(0, |h| h.mask);
            for lane in 0..8 {
                let scalar = group
                    .get(lane)
                    .and_then(|t| intersect_triangle(&r, t[0], t[1], t[2], t_max))
                    .map(|x| [x.t, x.b1, x.b2].map(f32::to_bits));
                let simd = h.filter(|_| mask & (1 << lane) != 0).map(|h| {
                    let (b1, b2) = h.b12(lane);
                    [h.t(lane), b1, b2].map(f32::to_bits)
                });
                if scalar != simd {
                    bad += 1;
                }
            }
        }
        bad
    }

    #[test]
    fn pack_test_agrees_bit_for_bit_with_the_scalar_test() {
        // A fan of triangles sharing vertices and edges (so rays aimed at them take the f64
        // path), plus random triangles, far from and near the origin; rays aimed at vertices,
        // edge midpoints and random points, with infinite and finite t_max.
        let mut rng = crate::sampling::Rng::new(7, 8);
        let mut rnd = |s: f32| {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * (2.0 * s) - Vec3::splat(s)
        };
        let mut total = 0;
        let mut hits = 0;
        let mut mismatches = 0;
        for (centre, scale) in [(Vec3::ZERO, 1.0), (Vec3::new(1e4, -3e3, 2e4), 10.0)] {
            let hub = centre;
            let rim: Vec<Vec3> = (0..7)
                .map(|i| {
                    let a = i as f32 * std::f32::consts::TAU / 7.0;
                    centre + Vec3::new(a.cos(), a.sin(), 0.3 * (3.0 * a).sin()) * scale
                })
                .collect();
            let mut tris: Vec<[Vec3; 3]> =
                (0..7).map(|i| [hub, rim[i], rim[(i + 1) % 7]]).collect();
            tris.extend((0..9).map(|_| {
                let c = centre + rnd(scale);
                [c + rnd(scale), c + rnd(scale), c + rnd(scale)]
            }));
            let mut targets: Vec<Vec3> = rim.clone();
            targets.push(hub);
            targets.extend(
                tris.iter()
                    .flat_map(|t| [(t[0] + t[1]) * 0.5, (t[1] + t[2]) * 0.5]),
            );
            targets.extend((0..200).map(|_| centre + rnd(scale)));
            for &target in &targets {
                for _ in 0..8 {
                    let o = centre + rnd(3.0 * scale);
                    let ray = Ray::new(o, target - o);
                    for t_max in [f32::INFINITY, 1.0, 0.999_999] {
                        mismatches += pack_mismatches(&ray, &tris, t_max);
                        total += 1;
                        hits += usize::from(tris.iter().any(|t| {
                            intersect_triangle(&TriRay::new(&ray), t[0], t[1], t[2], t_max)
                                .is_some()
                        }));
                    }
                }
            }
        }
        assert_eq!(mismatches, 0);
        // The comparison is not vacuous: a good share of the rays hit something.
        assert!(hits * 3 > total, "{hits} of {total}");
    }

    #[test]
    fn a_ray_from_just_before_a_plane_hits_it_unless_within_its_own_rounding() {
        // Random large triangles (extent 1 to 100, anywhere within their size of the origin),
        // and a ray from a point a gap g before the plane (log-uniform from 10⁻¹⁰ to 10⁻³ of
        // the extent, projecting inside the triangle) to a point beyond it: the ray crosses
        // the triangle inside its edges. Independent reference: the f32 origin's signed
        // distance to the plane in f64. Every ray whose origin is farther from the plane than
        // the origin's own error bound as a computed point (γ₇ of its largest coordinate,
        // `hit_point_error`'s scale) must hit; pbrt's rule (reject t ≤ δt) misses most of
        // those below ~10⁻⁵ of the extent, and packs agree with the scalar test bit for bit.
        let mut rng = crate::sampling::Rng::new(47, 11);
        let (mut checked, mut within_pbrt_band, mut missed_below) = (0, 0, 0);
        let mut u = || rng.next_f32();
        for i in 0..4000 {
            let size = [1.0f32, 10.0, 100.0][i % 3];
            let rand3 = |u: &mut dyn FnMut() -> f32| Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5);
            let centre = size * rand3(&mut u);
            let tri = [
                centre + size * rand3(&mut u),
                centre + size * rand3(&mut u),
                centre + size * rand3(&mut u),
            ];
            let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
            let extent = (tri[1] - tri[0]).length().max((tri[2] - tri[0]).length());
            if n.length() < 0.05 * extent * extent {
                continue; // a needle: its inside is too thin to aim at
            }
            let n = n.normalize();
            let inside = |u: &mut dyn FnMut() -> f32| {
                let (a, b) = (0.15 + 0.35 * u(), 0.15 + 0.35 * u());
                tri[0] * (1.0 - a - b) + tri[1] * a + tri[2] * b
            };
            let g = extent * 10f32.powf(-10.0 + 7.0 * u());
            let o = inside(&mut u) - g * n;
            let target = inside(&mut u) + extent * (0.1 + u()) * n;
            let ray = Ray {
                origin: o,
                dir: target - o,
                t_max: 1.0,
            };
            let d64 = |v: Vec3| v.as_dvec3();
            let n64 = (d64(tri[1]) - d64(tri[0])).cross(d64(tri[2]) - d64(tri[0]));
            let s = (d64(o) - d64(tri[0])).dot(n64) / n64.length();
            let own = f64::from(gamma(7) * o.abs().max_element());
            let r = TriRay::new(&ray);
            let hit = intersect_triangle(&r, tri[0], tri[1], tri[2], 1.0);
            assert_eq!(pack_mismatches(&ray, &tri.map(|_| tri), 1.0), 0, "{i}");
            if s >= 0.0 {
                continue; // the rounded origin landed on or beyond the plane
            }
            if -s > own {
                checked += 1;
                within_pbrt_band += usize::from(-s < 1e-5 * f64::from(extent));
                assert!(
                    hit.is_some(),
                    "{i}: gap {s:e} (own bound {own:e}), extent {extent}"
                );
            } else {
                missed_below += usize::from(hit.is_none());
            }
        }
        assert!(
            checked > 2000 && within_pbrt_band > 600,
            "{checked} {within_pbrt_band}"
        );
        eprintln!(
            "{checked} rays checked ({within_pbrt_band} within 1e-5 of the extent); {missed_below} missed within the origin's own bound"
        );
    }

    #[test]
    fn a_ray_from_micrometres_before_a_wall_hits_it() {
        // Issue 47 (thin-wall-photon-leak): the reported divider, a 2.4 m quad at x = 0, and a
        // shadow ray from a floor point at distance `gap` before it towards the light at
        // (1.2, 1.2, 0.3). In f32 alone the hit lies within the error bound of the origin up
        // to ~30 µm (2.4 m × a few 10⁻⁶ × 3) and was dropped: the path tracer's seam leak.
        let wall = [
            [
                Vec3::new(0.0, -0.2, -1.2),
                Vec3::new(0.0, 2.2, -1.2),
                Vec3::new(0.0, 2.2, 1.2),
            ],
            [
                Vec3::new(0.0, -0.2, -1.2),
                Vec3::new(0.0, 2.2, 1.2),
                Vec3::new(0.0, -0.2, 1.2),
            ],
        ];
        let light = Vec3::new(1.2, 1.2, 0.3);
        for gap in [1e-3f32, 1e-4, 3e-5, 1e-5, 1e-6, 1e-7, 1e-9] {
            for z in [-0.5f32, 0.3, 0.9485] {
                let o = Vec3::new(-gap, 1e-7, z);
                let ray = Ray {
                    origin: o,
                    dir: light - o,
                    t_max: 1.0 - 1e-4,
                };
                let r = TriRay::new(&ray);
                let hits = wall
                    .iter()
                    .filter_map(|t| intersect_triangle(&r, t[0], t[1], t[2], ray.t_max))
                    .count();
                assert_eq!(hits, 1, "gap {gap}, z {z}");
                assert_eq!(pack_mismatches(&ray, &wall, ray.t_max), 0);
                // From the far side, the wall is behind the origin.
                let o = Vec3::new(gap, 1e-7, z);
                let ray = Ray {
                    origin: o,
                    dir: light - o,
                    t_max: 1.0 - 1e-4,
                };
                let r = TriRay::new(&ray);
                assert!(
                    wall.iter()
                        .all(|t| intersect_triangle(&r, t[0], t[1], t[2], ray.t_max).is_none()),
                    "gap {gap}, z {z}: hit from the lit side"
                );
                assert_eq!(pack_mismatches(&ray, &wall, ray.t_max), 0);
            }
        }
    }

    #[test]
    fn rays_spawned_off_a_triangle_do_not_rehit_it_or_its_neighbours_in_packs() {
        // The f64 decision near the origin keeps pbrt's guarantee: an origin offset by its
        // error bound is certainly off its own triangle and the coplanar or creased neighbours
        // sharing its edges (scalar and packs agree bit for bit).
        let floor = [
            [
                Vec3::new(-2.0, 0.0, -1.0),
                Vec3::new(-2.0, 0.0, 1.0),
                Vec3::new(2.0, 0.0, 1.0),
            ],
            [
                Vec3::new(-2.0, 0.0, -1.0),
                Vec3::new(2.0, 0.0, 1.0),
                Vec3::new(2.0, 0.0, -1.0),
            ],
            // A wall standing on the floor's edge at x = 2 (a concave crease).
            [
                Vec3::new(2.0, 0.0, -1.0),
                Vec3::new(2.0, 0.0, 1.0),
                Vec3::new(2.0, 2.0, 1.0),
            ],
        ];
        let mut rng = crate::sampling::Rng::new(3, 5);
        let mut rehits = 0;
        for _ in 0..2000 {
            let (u, v) = rng.next_2d();
            let (b1, b2) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let tri = floor[usize::from(rng.next_f32() < 0.5)];
            let h = TriHit {
                t: 0.0,
                b0: 1.0 - b1 - b2,
                b1,
                b2,
            };
            let p = tri[0] * h.b0 + tri[1] * h.b1 + tri[2] * h.b2;
            let err = hit_point_error(&h, tri[0], tri[1], tri[2]);
            let (a, b) = rng.next_2d();
            // Any direction of the upper hemisphere, some grazing, none into the wall.
            let phi = std::f32::consts::TAU * a;
            let cos = 1e-4 + 0.9999 * b * b;
            let sin = (1.0 - cos * cos).sqrt();
            let w = Vec3::new(-(sin * phi.cos()).abs(), cos, sin * phi.sin());
            let o = crate::geometry::offset::offset_ray_origin(p, err, Vec3::Y, w);
            let ray = Ray::new(o, w);
            let r = TriRay::new(&ray);
            rehits += floor[..2]
                .iter()
                .filter(|t| intersect_triangle(&r, t[0], t[1], t[2], f32::INFINITY).is_some())
                .count();
            assert_eq!(pack_mismatches(&ray, &floor, f32::INFINITY), 0);
        }
        assert_eq!(rehits, 0);
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
