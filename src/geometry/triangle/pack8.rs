//! The watertight test of [`intersect_pack_k`](super::intersect_pack_k) on eight triangles at
//! once: two [`TriPack4`] side by side in eight-lane registers (one AVX register per coordinate
//! when AVX is enabled at build time, two SSE halves otherwise), for leaves of five to eight
//! triangles. Every operation is the four-lane test's, in the same order, lane by lane, so each
//! lane's result is bit for bit the scalar test's (Woop, Benthin & Wald, JCGT 2013).

use wide::f32x8;

use super::{TriPack4, TriRay, near_lanes_f64};
use crate::geometry::float::gamma;

/// What [`intersect_pack8_k`] found: like [`PackHits`](super::PackHits) for eight lanes, lane
/// `l` being lane `l % 4` of the first pack (`l < 4`) or of the second.
#[derive(Debug, Clone, Copy)]
pub struct PackHits8 {
    /// Bit `l` set if lane `l` is hit (never 0).
    pub mask: u32,
    t: [f32; 8],
    t_scaled: [f32; 8],
    det: [f32; 8],
    b1: [f32; 8],
    b2: [f32; 8],
}

impl PackHits8 {
    /// [`PackHits::within`](super::PackHits::within) for lane `l` (0..8).
    #[inline(always)]
    #[must_use]
    pub fn within(&self, l: usize, t_max: f32) -> bool {
        let (ts, det) = (self.t_scaled[l & 7], self.det[l & 7]);
        if det < 0.0 {
            !(ts < t_max * det)
        } else {
            !(ts > t_max * det)
        }
    }

    /// The ray parameter of the hit in lane `l`.
    #[inline(always)]
    #[must_use]
    pub fn t(&self, l: usize) -> f32 {
        self.t[l & 7]
    }

    /// Barycentric weights of `p1` and `p2` of the hit in lane `l`.
    #[inline(always)]
    #[must_use]
    pub fn b12(&self, l: usize) -> (f32, f32) {
        (self.b1[l & 7], self.b2[l & 7])
    }
}

/// [`intersect_pack_k`](super::intersect_pack_k) on the eight triangles of packs `a` (lanes
/// 0..4) and `b` (lanes 4..8). `KZ` must equal [`TriRay::dominant_axis`]. `None` if no lane is hit.
#[inline(always)]
#[must_use]
pub fn intersect_pack8_k<const KZ: usize>(
    r: &TriRay,
    a: &TriPack4,
    b: &TriPack4,
    t_max: f32,
) -> Option<PackHits8> {
    debug_assert_eq!(KZ, r.kz);
    let (kx, ky, kz) = ((KZ + 1) % 3, (KZ + 2) % 3, KZ);
    let w = |vertex: usize, axis: usize| {
        let (l, h) = (a.v[vertex][axis], b.v[vertex][axis]);
        f32x8::new([l.x, l.y, l.z, l.w, h.x, h.y, h.z, h.w])
    };
    let splat = f32x8::splat;
    let o = r.origin;
    let (ox, oy, oz) = (splat(o[kx]), splat(o[ky]), splat(o[kz]));
    let (sx, sy) = (splat(r.sx), splat(r.sy));
    let (p0z, p1z, p2z) = (w(0, kz) - oz, w(1, kz) - oz, w(2, kz) - oz);
    let p0x = (w(0, kx) - ox) + sx * p0z;
    let p0y = (w(0, ky) - oy) + sy * p0z;
    let p1x = (w(1, kx) - ox) + sx * p1z;
    let p1y = (w(1, ky) - oy) + sy * p1z;
    let p2x = (w(2, kx) - ox) + sx * p2z;
    let p2y = (w(2, ky) - oy) + sy * p2z;
    let mut e0 = p1x * p2y - p1y * p2x;
    let mut e1 = p2x * p0y - p2y * p0x;
    let mut e2 = p0x * p1y - p0y * p1x;
    let zero = f32x8::ZERO;
    let on_edge = (e0.simd_eq(zero) | e1.simd_eq(zero) | e2.simd_eq(zero)).to_bitmask();
    if on_edge != 0 {
        (e0, e1, e2) = edge_functions_f64([p0x, p0y, p1x, p1y, p2x, p2y], on_edge, [e0, e1, e2]);
    }
    let neg = (e0.simd_lt(zero) | e1.simd_lt(zero) | e2.simd_lt(zero)).to_bitmask();
    let pos = (e0.simd_gt(zero) | e1.simd_gt(zero) | e2.simd_gt(zero)).to_bitmask();
    let det = e0 + e1 + e2;
    let det_neg = det.simd_lt(zero);
    let det_pos = det.simd_gt(zero);
    let inside = !(neg & pos) & (det_neg | det_pos).to_bitmask();
    if inside == 0 {
        return None;
    }
    let sz = splat(r.sz);
    let (z0, z1, z2) = (p0z * sz, p1z * sz, p2z * sz);
    let t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
    let t_max_det = splat(t_max) * det;
    let reject_neg = det_neg & (t_scaled.simd_ge(zero) | t_scaled.simd_lt(t_max_det));
    let reject_pos = det_pos & (t_scaled.simd_le(zero) | t_scaled.simd_gt(t_max_det));
    let mask = inside & !(reject_neg | reject_pos).to_bitmask();
    if mask == 0 {
        return None;
    }
    let inv_det = splat(1.0) / det;
    let t = t_scaled * inv_det;
    let max_zt = z0.abs().fast_max(z1.abs()).fast_max(z2.abs());
    let delta_z = splat(gamma(3)) * max_zt;
    let max_xt = p0x.abs().fast_max(p1x.abs()).fast_max(p2x.abs());
    let max_yt = p0y.abs().fast_max(p1y.abs()).fast_max(p2y.abs());
    let delta_x = splat(gamma(5)) * (max_xt + max_zt);
    let delta_y = splat(gamma(5)) * (max_yt + max_zt);
    let delta_e =
        splat(2.0) * (splat(gamma(2)) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = e0.abs().fast_max(e1.abs()).fast_max(e2.abs());
    let delta_t = splat(3.0)
        * (splat(gamma(3)) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
        * inv_det.abs();
    let near = mask & t.simd_le(delta_t).to_bitmask();
    let mask = mask & !near;
    if near != 0 {
        // Within the f32 bound of the origin: decided in f64 (see `plane_hit_f64`).
        let hits = [t.to_array(), t_scaled.to_array(), det.to_array()];
        let b12 = [(e1 * inv_det).to_array(), (e2 * inv_det).to_array()];
        return near_pack8_f64(r, [a, b], mask, near, t_max, hits, b12);
    }
    if mask == 0 {
        return None;
    }
    Some(PackHits8 {
        mask,
        t: t.to_array(),
        t_scaled: t_scaled.to_array(),
        det: det.to_array(),
        b1: (e1 * inv_det).to_array(),
        b2: (e2 * inv_det).to_array(),
    })
}

/// [`intersect_pack8_k`]'s lanes `near` (positive distance within the f32 error bound) decided
/// by [`plane_hit_f64`](super::plane_hit_f64), added to the lanes `mask` already hit; `None`
/// if no lane is hit after all.
#[cold]
#[inline(never)]
fn near_pack8_f64(
    r: &TriRay,
    packs: [&TriPack4; 2],
    mask: u32,
    near: u32,
    t_max: f32,
    mut hits: [[f32; 8]; 3],
    b12: [[f32; 8]; 2],
) -> Option<PackHits8> {
    let mask = mask | near_lanes_f64(r, &packs, near, t_max, &mut hits);
    let [t, t_scaled, det] = hits;
    let [b1, b2] = b12;
    (mask != 0).then_some(PackHits8 {
        mask,
        t,
        t_scaled,
        det,
        b1,
        b2,
    })
}

/// The scalar test's f64 fallback for the lanes in `lanes` (an edge function exactly 0 in f32):
/// recomputes all three edge functions of those lanes in f64, so neighbours sharing the edge agree.
#[cold]
#[inline(never)]
fn edge_functions_f64(p: [f32x8; 6], lanes: u32, e: [f32x8; 3]) -> (f32x8, f32x8, f32x8) {
    let p = p.map(f32x8::to_array);
    let [mut e0, mut e1, mut e2] = e.map(f32x8::to_array);
    for l in 0..8 {
        if lanes & (1 << l) == 0 {
            continue;
        }
        let [p0x, p0y, p1x, p1y, p2x, p2y] = p.map(|v| f64::from(v[l]));
        e0[l] = (p1x * p2y - p1y * p2x) as f32;
        e1[l] = (p2x * p0y - p2y * p0x) as f32;
        e2[l] = (p0x * p1y - p0y * p1x) as f32;
    }
    (f32x8::new(e0), f32x8::new(e1), f32x8::new(e2))
}
