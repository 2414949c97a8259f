//! Rectangle (quad) area light of uniform radiance, sampled by solid angle with spherical
//! rectangles (C. Ureña, M. Fajardo, A. King, "An Area-Preserving Parametrization for Spherical
//! Rectangles", EGSR 2013) and by area where the rectangle subtends a tiny solid angle.
//!
//! Spherical-rectangle sampling makes the density of `wi` constant (`1/Ω`) over the solid angle
//! Ω the rectangle subtends, so an estimate of irradiance varies only with the receiver's cosine.
//! The set-up is computed in `f64`: Ω is a difference of angles near 2π, which would lose its
//! digits in `f32` for small rectangles. Below [`MIN_SPHERICAL_SOLID_ANGLE`] the light is
//! sampled uniformly by area instead (there the cosines and distances vary little, so area
//! sampling is as good, and Ω's rounding would not be). The choice depends on the shaded point
//! only, so [`RectLight::pdf_li`] always reports the density [`RectLight::sample_li`] used.
//! A parallelogram whose edges are not perpendicular is always sampled by area.

use glam::{DVec3, Vec3};

use super::area_emission::{area_le, area_power, pdf_area_le, sample_area_le};
use super::{EmissionSample, LightSample};

/// Solid angle (sr) below which the rectangle is sampled by area rather than by solid angle
/// (pbrt-v4 uses the same order of magnitude for its bilinear patches).
pub const MIN_SPHERICAL_SOLID_ANGLE: f64 = 3e-4;

/// A parallelogram `corner + s·edge_u + t·edge_v`, `s, t ∈ [0, 1]`, emitting uniform radiance.
///
/// One-sided lights emit on the side of `normal = normalize(edge_u × edge_v)` only; two-sided
/// lights emit the same radiance on both sides (and twice the power).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RectLight {
    /// One corner (world units).
    pub corner: Vec3,
    /// First edge from `corner`.
    pub edge_u: Vec3,
    /// Second edge from `corner`.
    pub edge_v: Vec3,
    /// Unit normal `normalize(edge_u × edge_v)`: the emitting side of a one-sided light.
    pub normal: Vec3,
    /// Area (m²).
    pub area: f32,
    /// Emitted radiance per channel (W/(m²·sr)).
    pub radiance: Vec3,
    /// Emits on both sides.
    pub two_sided: bool,
    /// The edges are perpendicular (within 1e-4 of their lengths' product): solid-angle
    /// sampling applies.
    pub is_rectangle: bool,
}

impl RectLight {
    /// The light spanning `corner + s·edge_u + t·edge_v`; `None` for a degenerate
    /// (zero-area or non-finite) parallelogram.
    #[must_use]
    pub fn new(
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
        radiance: Vec3,
        two_sided: bool,
    ) -> Option<Self> {
        let cross = edge_u.cross(edge_v);
        let area = cross.length();
        if !(area > 0.0 && area.is_finite() && corner.is_finite()) {
            return None;
        }
        let is_rectangle = edge_u.dot(edge_v).abs() <= 1e-4 * edge_u.length() * edge_v.length();
        Some(Self {
            corner,
            edge_u,
            edge_v,
            normal: cross / area,
            area,
            radiance,
            two_sided,
            is_rectangle,
        })
    }

    /// Total emitted flux (W): `π L A`, twice that when two-sided.
    #[must_use]
    pub fn power(&self) -> Vec3 {
        area_power(self.radiance, self.area, self.two_sided)
    }

    /// Radiance leaving the light in the unit direction `w` (pointing away from it): `L` on an
    /// emitting side, 0 on the back of a one-sided light.
    #[inline]
    #[must_use]
    pub fn le(&self, w: Vec3) -> Vec3 {
        area_le(self.radiance, self.two_sided, self.normal, w)
    }

    /// True when `p` sees an emitting side (in front of a one-sided light, off the plane of a
    /// two-sided one).
    #[inline]
    fn lit_from(&self, p: Vec3) -> bool {
        let h = (p - self.corner).dot(self.normal);
        if self.two_sided { h != 0.0 } else { h > 0.0 }
    }

    /// The spherical rectangle seen from `p`, if solid-angle sampling applies there.
    fn spherical(&self, p: Vec3) -> Option<SphericalRect> {
        if !self.is_rectangle {
            return None;
        }
        let s = SphericalRect::new(p, self.corner, self.edge_u, self.edge_v)?;
        (s.solid_angle >= MIN_SPHERICAL_SOLID_ANGLE).then_some(s)
    }

    /// Samples a direction towards the light from `p` with `u ∈ [0, 1)²`: uniform in solid
    /// angle (spherical rectangle) or, for tiny solid angles and parallelograms, uniform in
    /// area converted to solid angle (`pdf = d² / (A |cos θ_l|)`). `None` when `p` sees no
    /// emitting side, the light is black, or the density is not finite.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, u: (f32, f32)) -> Option<LightSample> {
        if !self.lit_from(p) || self.radiance == Vec3::ZERO {
            return None;
        }
        let (point, pdf) = match self.spherical(p) {
            Some(s) => (s.sample(u).as_vec3(), (1.0 / s.solid_angle) as f32),
            None => {
                let q = self.corner + self.edge_u * u.0 + self.edge_v * u.1;
                let d = q - p;
                let dist2 = d.length_squared();
                let cos_l = (d.dot(self.normal)).abs() / dist2.sqrt();
                (q, dist2 / (self.area * cos_l))
            }
        };
        let d = point - p;
        let distance = d.length();
        if !(distance > 0.0 && pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        let weight = self.radiance / pdf;
        weight.is_finite().then(|| LightSample {
            wi: d / distance,
            distance,
            point,
            radiance: self.radiance,
            pdf,
            delta: false,
            weight,
        })
    }

    /// Solid-angle density with which [`RectLight::sample_li`] at `p` returns the unit `wi`: 0
    /// when the ray misses the light or meets a side that does not emit towards `p`.
    #[must_use]
    pub fn pdf_li(&self, p: Vec3, wi: Vec3) -> f32 {
        if !self.lit_from(p) {
            return 0.0;
        }
        let Some(t) = self.hit(p, wi) else {
            return 0.0;
        };
        match self.spherical(p) {
            Some(s) => (1.0 / s.solid_angle) as f32,
            None => {
                let cos_l = wi.dot(self.normal).abs();
                let pdf = t * t / (self.area * cos_l);
                if pdf.is_finite() { pdf } else { 0.0 }
            }
        }
    }

    /// The distance along the unit `wi` from `p` to the parallelogram, if the ray meets it
    /// (edges widened by 1e-5 of their length, so samples on the rim count as hits).
    fn hit(&self, p: Vec3, wi: Vec3) -> Option<f32> {
        let denom = wi.dot(self.normal);
        if denom == 0.0 {
            return None;
        }
        let t = (self.corner - p).dot(self.normal) / denom;
        if !(t > 0.0 && t.is_finite()) {
            return None;
        }
        let q = (p + wi * t - self.corner).as_dvec3();
        let (eu, ev) = (self.edge_u.as_dvec3(), self.edge_v.as_dvec3());
        // Solve q = s·eu + t·ev in the plane (Gram matrix).
        let (uu, uv, vv) = (eu.dot(eu), eu.dot(ev), ev.dot(ev));
        let det = uu * vv - uv * uv;
        let (qu, qv) = (q.dot(eu), q.dot(ev));
        let s = (vv * qu - uv * qv) / det;
        let r = (uu * qv - uv * qu) / det;
        let slack = 1e-5;
        ((-slack..=1.0 + slack).contains(&s) && (-slack..=1.0 + slack).contains(&r)).then_some(t)
    }

    /// Samples a ray leaving the light from two pairs of uniforms: a uniform point
    /// (`pdf_pos = 1/A`) and a cosine-weighted direction about the emitting side's normal
    /// (`pdf_dir = cos θ / π`; a two-sided light picks its side with `u_dir.0 < ½` and has
    /// `pdf_dir = |cos θ| / (2π)`), so every sample carries the light's whole power. The
    /// sample's `normal` is the side it leaves from. `None` for black lights and grazing
    /// directions.
    #[must_use]
    pub fn sample_le(&self, u_pos: (f32, f32), u_dir: (f32, f32)) -> Option<EmissionSample> {
        if self.radiance == Vec3::ZERO || !self.radiance.is_finite() {
            return None;
        }
        let origin = self.corner + self.edge_u * u_pos.0 + self.edge_v * u_pos.1;
        sample_area_le(
            origin,
            self.normal,
            self.radiance,
            self.area,
            self.two_sided,
            u_dir,
        )
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`RectLight::sample_le`] for a ray leaving in the
    /// unit `dir`: `(1/A, cos θ/π)` on the emitting side (`(1/A, |cos θ|/(2π))` two-sided),
    /// `pdf_dir = 0` behind a one-sided light.
    #[must_use]
    pub fn pdf_le(&self, dir: Vec3) -> (f32, f32) {
        pdf_area_le(self.normal.dot(dir), self.area, self.two_sided)
    }
}

/// A rectangle as seen from a point, in the rectangle's own frame (Ureña et al. 2013, §3):
/// the point at the origin, the rectangle in the plane `z = z0 < 0` spanning `[x0, x1] × [y0,
/// y1]`, with the constants of its sampling map.
#[derive(Debug, Clone, Copy)]
struct SphericalRect {
    origin: DVec3,
    x: DVec3,
    y: DVec3,
    z: DVec3,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    z0: f64,
    b0: f64,
    b1: f64,
    k: f64,
    solid_angle: f64,
}

impl SphericalRect {
    /// The rectangle `corner + s·eu + t·ev` (perpendicular edges) seen from `p`; `None` when
    /// `p` lies in its plane.
    fn new(p: Vec3, corner: Vec3, eu: Vec3, ev: Vec3) -> Option<Self> {
        let (o, s, eu, ev) = (
            p.as_dvec3(),
            corner.as_dvec3(),
            eu.as_dvec3(),
            ev.as_dvec3(),
        );
        let (lu, lv) = (eu.length(), ev.length());
        let x = eu / lu;
        let y = ev / lv;
        let mut z = x.cross(y);
        let d = s - o;
        let mut z0 = d.dot(z);
        if z0 > 0.0 {
            z0 = -z0;
            z = -z;
        }
        if !(z0 < 0.0) {
            return None;
        }
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + lu, y0 + lv);
        // Normals of the planes through the origin and each edge.
        let n0 = DVec3::new(0.0, z0, -y0).normalize();
        let n1 = DVec3::new(-z0, 0.0, x1).normalize();
        let n2 = DVec3::new(0.0, -z0, y1).normalize();
        let n3 = DVec3::new(z0, 0.0, -x0).normalize();
        // Internal angles of the spherical rectangle.
        let angle = |a: DVec3, b: DVec3| (-a.dot(b)).clamp(-1.0, 1.0).acos();
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let k = std::f64::consts::TAU - g2 - g3;
        let solid_angle = g0 + g1 - k;
        (solid_angle > 0.0 && solid_angle.is_finite()).then_some(Self {
            origin: o,
            x,
            y,
            z,
            x0,
            x1,
            y0,
            y1,
            z0,
            b0: n0.z,
            b1: n2.z,
            k,
            solid_angle,
        })
    }

    /// The point on the rectangle whose direction is uniformly distributed over the spherical
    /// rectangle as `u` is over `[0, 1)²` (paper §4: `u.0` picks the sub-rectangle's area, so
    /// the x coordinate; `u.1` the height along y).
    fn sample(&self, u: (f32, f32)) -> DVec3 {
        let (u0, u1) = (f64::from(u.0), f64::from(u.1));
        let au = u0 * self.solid_angle + self.k;
        let fu = (au.cos() * self.b0 - self.b1) / au.sin();
        let cu = (1.0 / (fu * fu + self.b0 * self.b0).sqrt()).copysign(fu);
        let cu = cu.clamp(-1.0, 1.0);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).max(0.0).sqrt()).clamp(self.x0, self.x1);
        let xu = if xu.is_nan() { self.x0 } else { xu };
        let d = (xu * xu + self.z0 * self.z0).sqrt();
        let h0 = self.y0 / (d * d + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (d * d + self.y1 * self.y1).sqrt();
        let hv = h0 + u1 * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 {
            (hv * d / (1.0 - hv2).sqrt()).clamp(self.y0, self.y1)
        } else {
            self.y1
        };
        self.origin + self.x * xu + self.y * yv + self.z * self.z0
    }
}

#[cfg(test)]
mod tests;
