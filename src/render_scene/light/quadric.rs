//! Disc and cylinder area lights (a `Disc` or `Cylinder` node with `emission`): uniform radiance
//! on the side the surface normal faces (+z of a disc, outwards on a cylinder), or both sides.
//! Sampled uniformly by area (pdf `1/A`, `d²/(A |cos θ_l|)` in solid angle: pbrt-v4 §12.3's
//! area sampling, the same as a mesh light's).
//!
//! A point is uniform on the object-space surface and mapped by the node's affine transform,
//! whose Jacobian on the surface is constant for a disc (any transform: an ellipse of area
//! `π |M x × M y|`) and for a round cylinder (`M x ⟂ M y`, equal lengths r, the axis `M z` of
//! length h perpendicular to both: area `2π r h`), so the world points are uniform too.
//! Compilation refuses an emissive cylinder that is not round.

use glam::{DAffine3, DMat3, DVec3, Vec3};
use std::f32::consts::TAU;

use super::area_emission::{
    area_le, area_power, pdf_area_le, pdf_area_li_hit, sample_area_le, sample_area_li,
};
use super::{EmissionSample, LightSample};
use crate::geometry::quadric::QuadricShape;
use crate::sampling::warp::concentric_disk;

/// An emitting disc or cylinder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadricLight {
    /// Which surface.
    pub shape: QuadricShape,
    /// World-from-object transform of the unit shape.
    pub world_from_object: DAffine3,
    /// Object-from-world transform.
    pub object_from_world: DAffine3,
    /// Inverse transpose of the linear part (normals).
    pub normal_to_world: DMat3,
    /// Emitted radiance (W/(m²·sr) per channel).
    pub radiance: Vec3,
    /// Emits on both sides.
    pub two_sided: bool,
    /// Area of one side (m²).
    pub area: f32,
}

impl QuadricLight {
    /// The light of the unit `shape` under `m`. `None` for a cylinder that is not round (its
    /// area element would vary) or a shape of no area.
    #[must_use]
    pub fn new(shape: QuadricShape, m: DAffine3, radiance: Vec3, two_sided: bool) -> Option<Self> {
        let l = m.matrix3;
        let (x, y, z) = (l.x_axis, l.y_axis, l.z_axis);
        if shape == QuadricShape::Cylinder {
            let r = x.length();
            let tol = 1e-6 * r.max(z.length());
            let round = (y.length() - r).abs() <= tol
                && x.dot(y).abs() <= tol * r
                && x.dot(z).abs() <= tol * z.length()
                && y.dot(z).abs() <= tol * z.length();
            if !round {
                return None;
            }
        }
        let area = shape.area(l);
        let area = area as f32;
        (area > 0.0 && area.is_finite() && l.determinant() != 0.0).then(|| Self {
            shape,
            world_from_object: m,
            object_from_world: m.inverse(),
            normal_to_world: l.inverse().transpose(),
            radiance,
            two_sided,
            area,
        })
    }

    /// Total flux (W): `π L A`, twice that for a two-sided light.
    #[must_use]
    pub fn power(&self) -> Vec3 {
        area_power(self.radiance, self.area, self.two_sided)
    }

    /// Radiance leaving a point with unit normal `n` (the surface's) in direction `w`.
    #[inline]
    #[must_use]
    pub fn le(&self, n: Vec3, w: Vec3) -> Vec3 {
        area_le(self.radiance, self.two_sided, n, w)
    }

    /// A uniform point of the surface (from `u ∈ [0, 1)²`) and its unit normal.
    #[must_use]
    pub fn sample_position(&self, u: (f32, f32)) -> (Vec3, Vec3) {
        let po = match self.shape {
            QuadricShape::Disc => {
                let (a, b) = concentric_disk(u);
                DVec3::new(f64::from(a), f64::from(b), 0.0)
            }
            QuadricShape::Cylinder => {
                let phi = f64::from(TAU * u.0);
                DVec3::new(phi.cos(), phi.sin(), f64::from(u.1) - 0.5)
            }
        };
        self.at(po)
    }

    /// The world point and unit normal of the object-space surface point `po`.
    fn at(&self, po: DVec3) -> (Vec3, Vec3) {
        let p = self.world_from_object.transform_point3(po).as_vec3();
        let n = (self.normal_to_world * self.shape.normal(po))
            .as_vec3()
            .normalize();
        (p, n)
    }

    /// A direction towards a uniform point of the light from `p`, density `d²/(A |cos θ_l|)`.
    /// `None` behind a one-sided light, for a black light, or where the density is not finite.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, u: (f32, f32)) -> Option<LightSample> {
        if self.radiance == Vec3::ZERO {
            return None;
        }
        let (point, n) = self.sample_position(u);
        sample_area_li(p, point, n, self.radiance, self.area, self.two_sided)
    }

    /// [`QuadricLight::sample_li`]'s density of the direction to the surface point `point`
    /// (unit normal `n`) from `p`: a BSDF-sampled ray's MIS partner when it hits the light.
    #[inline]
    #[must_use]
    pub fn pdf_li_hit(&self, p: Vec3, point: Vec3, n: Vec3) -> f32 {
        pdf_area_li_hit(p, point, n, self.area, self.two_sided)
    }

    /// Density of the direction `wi` from `p`: the sum over every point where the line meets
    /// the surface (a cylinder can be met twice).
    #[must_use]
    pub fn pdf_li(&self, p: Vec3, wi: Vec3) -> f32 {
        let o = self.object_from_world.transform_point3(p.as_dvec3());
        let d = self.object_from_world.transform_vector3(wi.as_dvec3());
        self.shape
            .hit_ts(o, d)
            .into_iter()
            .flatten()
            .map(|t| {
                let (point, n) = self.at(self.shape.reproject(o + d * t));
                self.pdf_li_hit(p, point, n)
            })
            .fold(0.0, |a, b| a + b)
    }

    /// A ray leaving the light: a uniform point (`pdf_pos = 1/A`), a cosine-distributed
    /// direction about the normal (on a random side for a two-sided light).
    #[must_use]
    pub fn sample_le(&self, u_pos: (f32, f32), u_dir: (f32, f32)) -> Option<EmissionSample> {
        if self.radiance == Vec3::ZERO || !self.radiance.is_finite() {
            return None;
        }
        let (origin, n) = self.sample_position(u_pos);
        sample_area_le(origin, n, self.radiance, self.area, self.two_sided, u_dir)
    }

    /// `(pdf_pos, pdf_dir)` of [`QuadricLight::sample_le`] for a ray along `dir` from a point
    /// with unit normal `n`.
    #[must_use]
    pub fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        pdf_area_le(n.dot(dir), self.area, self.two_sided)
    }
}

#[cfg(test)]
mod tests;
