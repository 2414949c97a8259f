//! Signed distance functions (negative inside) and the operators that combine them, after
//! Quilez's catalogue ("Distance functions", iquilezles.org). Only `+ − × ÷`, `min`, `max`
//! and `sqrt`, which IEEE 754 rounds exactly, so a field evaluates to the same bits on every
//! platform; rotations take their cosine and sine from [`cos_sin`], a Taylor series.

use glam::{DVec2, DVec3};

/// Sphere of radius `r` about `c`.
pub fn sphere(p: DVec3, c: DVec3, r: f64) -> f64 {
    (p - c).length() - r
}

/// Ellipsoid with semi-axes `r` about `c` (Quilez's bound: exact zero set, distance
/// approximate away from it).
pub fn ellipsoid(p: DVec3, c: DVec3, r: DVec3) -> f64 {
    let q = p - c;
    let k0 = (q / r).length();
    let k1 = (q / (r * r)).length();
    if k1 == 0.0 {
        return -r.min_element();
    }
    k0 * (k0 - 1.0) / k1
}

/// Box with half-sizes `b` about `c`, edges rounded by `r` (the box grows by `r`).
pub fn round_box(p: DVec3, c: DVec3, b: DVec3, r: f64) -> f64 {
    let q = (p - c).abs() - b;
    q.max(DVec3::ZERO).length() + q.max_element().min(0.0) - r
}

/// Vertical capped cylinder of radius `r` from `y0` to `y1` on the axis through `(x, z)`,
/// edges rounded by `round` (inside the given size).
pub fn cylinder_y(p: DVec3, x: f64, z: f64, r: f64, y0: f64, y1: f64, round: f64) -> f64 {
    let radial = DVec2::new(p.x - x, p.z - z).length() - (r - round);
    let axial = (p.y - 0.5 * (y0 + y1)).abs() - (0.5 * (y1 - y0) - round);
    let d = DVec2::new(radial, axial);
    d.max(DVec2::ZERO).length() + d.max_element().min(0.0) - round
}

/// Capsule: the points within `r` of the segment from `a` to `b`.
pub fn capsule(p: DVec3, a: DVec3, b: DVec3, r: f64) -> f64 {
    let (pa, ba) = (p - a, b - a);
    let h = (pa.dot(ba) / ba.dot(ba)).clamp(0.0, 1.0);
    (pa - ba * h).length() - r
}

/// Capped cylinder along z, radius `r`, from `z0` to `z1` on the axis through `(x, y)`, edges
/// rounded by `round`: [`cylinder_y`] with the y and z axes exchanged.
pub fn cylinder_z(p: DVec3, x: f64, y: f64, r: f64, z0: f64, z1: f64, round: f64) -> f64 {
    cylinder_y(DVec3::new(p.x, p.z, p.y), x, y, r, z0, z1, round)
}

/// Signed distance to a 2D triangle `a, b, c` (Quilez).
pub fn triangle_2d(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let (e0, e1, e2) = (b - a, c - b, a - c);
    let (v0, v1, v2) = (p - a, p - b, p - c);
    let seg = |v: DVec2, e: DVec2| v - e * (v.dot(e) / e.dot(e)).clamp(0.0, 1.0);
    let (pq0, pq1, pq2) = (seg(v0, e0), seg(v1, e1), seg(v2, e2));
    let s = (e0.x * e2.y - e0.y * e2.x).signum();
    let d = [
        (pq0.dot(pq0), s * (v0.x * e0.y - v0.y * e0.x)),
        (pq1.dot(pq1), s * (v1.x * e1.y - v1.y * e1.x)),
        (pq2.dot(pq2), s * (v2.x * e2.y - v2.y * e2.x)),
    ];
    let dist = d[0].0.min(d[1].0).min(d[2].0);
    let side = d[0].1.min(d[1].1).min(d[2].1);
    -dist.sqrt() * side.signum()
}

/// Smooth union of two fields, blending over a width `k` (polynomial smooth minimum).
pub fn smooth_union(a: f64, b: f64, k: f64) -> f64 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// Smooth intersection of two fields over a width `k`.
pub fn smooth_intersection(a: f64, b: f64, k: f64) -> f64 {
    -smooth_union(-a, -b, k)
}

/// Cosine and sine of an angle in degrees, by Taylor series in f64 (platform-independent).
pub fn cos_sin(degrees: f64) -> (f64, f64) {
    let x = degrees / 180.0 * std::f64::consts::PI;
    let (mut c, mut s) = (0.0, 0.0);
    let mut term = 1.0; // x^k / k!
    for k in 0..40 {
        match k % 4 {
            0 => c += term,
            1 => s += term,
            2 => c -= term,
            _ => s -= term,
        }
        term *= x / f64::from(k + 1);
    }
    (c, s)
}

/// `p` rotated about the z axis by `-degrees` around `pivot`: evaluating a field at it turns
/// the field's shape by `+degrees` (counter-clockwise seen from +z).
pub fn rotate_z(p: DVec3, pivot: DVec3, degrees: f64) -> DVec3 {
    let (c, s) = cos_sin(degrees);
    let q = p - pivot;
    pivot + DVec3::new(c * q.x + s * q.y, -s * q.x + c * q.y, q.z)
}
