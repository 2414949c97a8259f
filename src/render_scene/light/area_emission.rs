//! Emission from a point of an area light (rectangle, triangle mesh, disc, cylinder): the one
//! cosine-weighted direction sampling, one- or two-sided, that every area light's `sample_le`
//! and `pdf_le` share, so photons leave every shape by the same rule; and the power, the
//! radiance leaving a side, and the direction towards a point sampled by area, that the shapes
//! sampled by area (triangle mesh, disc, cylinder) share.

use glam::Vec3;
use std::f32::consts::PI;

use super::{EmissionSample, LightSample};
use crate::sampling::warp::cosine_hemisphere;

/// A ray leaving `origin` (a uniformly chosen point, `pdf_pos = 1/area`, `area` in m²) of a
/// surface with unit normal `n` and radiance `radiance`: a cosine-weighted direction about the
/// emitting side's normal (`pdf_dir = cos θ/π`); two-sided, the side is chosen by
/// `u_dir.0 < ½` and `pdf_dir = |cos θ|/(2π)`. The sample's `normal` is the side it leaves
/// from. `None` for a grazing direction.
#[must_use]
pub(super) fn sample_area_le(
    origin: Vec3,
    n: Vec3,
    radiance: Vec3,
    area: f32,
    two_sided: bool,
    u_dir: (f32, f32),
) -> Option<EmissionSample> {
    let (normal, u, side_pdf) = if !two_sided {
        (n, u_dir, 1.0)
    } else if u_dir.0 < 0.5 {
        (n, (2.0 * u_dir.0, u_dir.1), 0.5)
    } else {
        (-n, (2.0 * u_dir.0 - 1.0, u_dir.1), 0.5)
    };
    let dir = cosine_hemisphere(u, normal);
    let cos_t = dir.dot(normal);
    (cos_t > 0.0).then(|| EmissionSample {
        origin,
        normal,
        dir,
        le: radiance,
        pdf_pos: 1.0 / area,
        pdf_dir: side_pdf * cos_t / PI,
    })
}

/// The densities `(pdf_pos, pdf_dir)` of [`sample_area_le`] for a ray whose direction makes
/// cosine `cos_t` with the surface's normal: `(1/A, cos θ/π)` on the emitting side
/// (`(1/A, |cos θ|/(2π))` two-sided), `pdf_dir = 0` behind a one-sided light.
#[must_use]
pub(super) fn pdf_area_le(cos_t: f32, area: f32, two_sided: bool) -> (f32, f32) {
    let pdf_dir = if two_sided {
        cos_t.abs() / (2.0 * PI)
    } else {
        cos_t.max(0.0) / PI
    };
    (1.0 / area, pdf_dir)
}

/// Solid-angle density at `p` of sampling a point uniformly by area on an emitter of area
/// `area` (m²), for the sample `point` with unit normal `n`: `|p − point|² / (A |cos θ_l|)`, 0
/// behind a one-sided light or where the density is not finite (`p` on the surface). What a
/// BSDF-sampled ray that hits the light weighs against light sampling (MIS).
#[inline]
#[must_use]
pub(super) fn pdf_area_li_hit(p: Vec3, point: Vec3, n: Vec3, area: f32, two_sided: bool) -> f32 {
    let d = point - p;
    let dist2 = d.length_squared();
    let cos_l = -n.dot(d) / dist2.sqrt();
    if !(two_sided || cos_l > 0.0) {
        return 0.0;
    }
    let pdf = dist2 / (area * cos_l.abs());
    if pdf.is_finite() { pdf } else { 0.0 }
}

/// Total flux (W) of an emitter of uniform `radiance` (W/(m²·sr)) and `area` (m²): `π L A`,
/// twice that when it emits on both sides.
#[inline]
#[must_use]
pub(super) fn area_power(radiance: Vec3, area: f32, two_sided: bool) -> Vec3 {
    radiance * (PI * area * if two_sided { 2.0 } else { 1.0 })
}

/// Radiance leaving a point of unit normal `n` in direction `w`: `radiance` on an emitting
/// side, 0 behind a one-sided emitter.
#[inline]
#[must_use]
pub(super) fn area_le(radiance: Vec3, two_sided: bool, n: Vec3, w: Vec3) -> Vec3 {
    if two_sided || n.dot(w) > 0.0 {
        radiance
    } else {
        Vec3::ZERO
    }
}

/// The direction from `p` towards `point` (sampled uniformly by area, unit normal `n`) on an
/// emitter of uniform `radiance` and `area` (m²), with its solid-angle density
/// `d²/(A |cos θ_l|)`. `None` behind a one-sided emitter or where the density or the weight is
/// not finite (`p` on the surface, a grazing point).
#[inline]
#[must_use]
pub(super) fn sample_area_li(
    p: Vec3,
    point: Vec3,
    n: Vec3,
    radiance: Vec3,
    area: f32,
    two_sided: bool,
) -> Option<LightSample> {
    let d = point - p;
    let dist2 = d.length_squared();
    let distance = dist2.sqrt();
    let wi = d / distance;
    let cos_l = -n.dot(wi);
    if !(two_sided || cos_l > 0.0) {
        return None;
    }
    let pdf = dist2 / (area * cos_l.abs());
    let weight = radiance / pdf;
    (pdf.is_finite() && pdf > 0.0 && weight.is_finite()).then_some(LightSample {
        wi,
        distance,
        point,
        radiance,
        pdf,
        delta: false,
        weight,
    })
}
