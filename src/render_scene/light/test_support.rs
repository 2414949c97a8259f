//! Closed forms and estimators shared by the tests of the light shapes (test-only).

use glam::{DVec3, Vec3};

use crate::geometry::Frame;
use crate::sampling::Rng;

/// Irradiance at `p` (unit normal `n`) from a planar polygon of uniform radiance `l` that lies
/// wholly above `p`'s horizon, by Lambert's formula E = (L/2) |Σᵢ θᵢ cos γᵢ|: θᵢ the angle the
/// edge (vᵢ, vᵢ₊₁) subtends at `p`, γᵢ the angle between `n` and the normal of the plane
/// through `p` and that edge. Exact (in f64).
pub(crate) fn lambert_polygon_irradiance(p: Vec3, n: Vec3, vertices: &[Vec3], l: f64) -> f64 {
    let (p, n) = (p.as_dvec3(), n.as_dvec3());
    let units: Vec<DVec3> = vertices
        .iter()
        .map(|v| (v.as_dvec3() - p).normalize())
        .collect();
    let mut sum = 0.0;
    for i in 0..units.len() {
        let (a, b) = (units[i], units[(i + 1) % units.len()]);
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        let gamma = a.cross(b).normalize();
        sum += theta * gamma.dot(n);
    }
    0.5 * l * sum.abs()
}

/// Stratified uniforms: an `n × n` grid jittered by `rng`, in row order.
pub(crate) fn stratified(n: usize, rng: &mut Rng) -> impl Iterator<Item = (f32, f32)> + '_ {
    (0..n * n).map(move |i| {
        let (a, b) = rng.next_2d();
        (
            ((i % n) as f32 + a) / n as f32,
            ((i / n) as f32 + b) / n as f32,
        )
    })
}

/// The direction `w` in the frame around `n` (for χ² of directions about a normal).
pub(crate) fn local(n: Vec3, w: Vec3) -> Vec3 {
    Frame::from_normal(n).to_local(w)
}

/// The axis and `1 − cos` half-width of a cap around the directions from `p` to `points`,
/// widened by 25 % so the χ² histogram also bins the empty band around them.
pub(crate) fn cap_around(p: Vec3, points: &[Vec3]) -> (Vec3, f64) {
    let centre = points.iter().copied().sum::<Vec3>() / points.len() as f32;
    let axis = (centre - p).normalize();
    let widest = points
        .iter()
        .map(|&q| 1.0 - f64::from((q - p).normalize().dot(axis)))
        .fold(0.0, f64::max);
    (axis, (1.25 * widest).min(2.0))
}
