//! Triangle-mesh area light: every triangle of an emissive mesh emits uniform radiance. Next
//! event estimation picks a triangle by an alias table over the areas and a uniform point on it,
//! so points are uniform over the whole mesh (area density `1/A`), converted to solid angle by
//! `d² / |cos θ_l|` (pbrt-v4 §12.3's area sampling; our own code).
//!
//! Radiance is constant today. Texture hook: a textured emitter will take `le` from the
//! triangle's uv at the sampled barycentrics — [`MeshLightSample::triangle`] and
//! [`MeshLightSample::barycentrics`] are what it needs; the alias weights may then include
//! each triangle's mean texture luminance.

use glam::Vec3;

use super::area_emission::{
    area_le, area_power, pdf_area_le, pdf_area_li_hit, sample_area_le, sample_area_li,
};
use super::{EmissionSample, LightSample};
use crate::geometry::Ray;
use crate::geometry::triangle::{TriRay, intersect_triangle};
use crate::sampling::alias::AliasTable;

/// An emissive triangle mesh (world space).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshLight {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as vertex indices; the emitting side of a one-sided light is the one the
    /// winding's normal `(p1 − p0) × (p2 − p0)` points to.
    pub triangles: Vec<[u32; 3]>,
    /// Emitted radiance per channel (W/(m²·sr)).
    pub radiance: Vec3,
    /// Emits on both sides of every triangle.
    pub two_sided: bool,
    /// Total area (m²) of the non-degenerate triangles.
    pub area: f32,
    /// Triangle choice by area.
    table: AliasTable,
}

/// Where on the mesh a light sample landed (for textured emission and for the hit record).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshLightSample {
    /// The incident-light sample.
    pub light: LightSample,
    /// Index of the triangle.
    pub triangle: usize,
    /// Barycentric weights of its three vertices.
    pub barycentrics: [f32; 3],
}

impl MeshLight {
    /// The mesh light; `None` if no triangle has a positive, finite area or an index is out of
    /// range (the compiler validates meshes before this).
    #[must_use]
    pub fn new(
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        radiance: Vec3,
        two_sided: bool,
    ) -> Option<Self> {
        let n = positions.len();
        if triangles.iter().flatten().any(|&i| i as usize >= n) {
            return None;
        }
        let areas: Vec<f32> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .collect();
        let table = AliasTable::new(&areas);
        if table.is_empty() {
            return None;
        }
        let area = table.total() as f32;
        Some(Self {
            positions,
            triangles,
            radiance,
            two_sided,
            area,
            table,
        })
    }

    /// The vertices of triangle `i`.
    #[inline]
    fn vertices(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| self.positions[v as usize])
    }

    /// The unit geometric normal of triangle `i` (winding order).
    #[inline]
    #[must_use]
    pub fn normal(&self, i: usize) -> Vec3 {
        let [a, b, c] = self.vertices(i);
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Total emitted flux (W): `π L A`, twice that when two-sided.
    #[must_use]
    pub fn power(&self) -> Vec3 {
        area_power(self.radiance, self.area, self.two_sided)
    }

    /// Radiance leaving a point of normal `n` (the triangle's geometric normal) in the unit
    /// direction `w`: `L` on an emitting side, 0 behind a one-sided light.
    #[inline]
    #[must_use]
    pub fn le(&self, n: Vec3, w: Vec3) -> Vec3 {
        area_le(self.radiance, self.two_sided, n, w)
    }

    /// A uniform point on the mesh from `u`: `u.0` picks the triangle (and is remapped), then
    /// the pair is warped onto it. Returns the triangle, barycentrics and the point.
    #[inline]
    fn sample_point(&self, u: (f32, f32)) -> Option<(usize, [f32; 3], Vec3)> {
        let (i, _, u0) = self.table.sample_remapped(u.0)?;
        let s = u0.sqrt();
        let (b0, b1) = (1.0 - s, u.1 * s);
        let b = [b0, b1, 1.0 - b0 - b1];
        let [p0, p1, p2] = self.vertices(i);
        Some((i, b, p0 * b[0] + p1 * b[1] + p2 * b[2]))
    }

    /// A uniform point of the mesh (area density `1/A`) from `u`, and the unit winding normal
    /// of its triangle: where aimed photons leave from.
    #[inline]
    #[must_use]
    pub fn sample_position(&self, u: (f32, f32)) -> Option<(Vec3, Vec3)> {
        let (i, _, p) = self.sample_point(u)?;
        Some((p, self.normal(i)))
    }

    /// Samples a direction towards the mesh from `p` (uniform by area; solid-angle density `d²
    /// / (A |cos θ_l|)`). `None` for a black light, a point on a triangle's back (one-sided:
    /// no light goes that way; [`MeshLight::pdf_li`] gives such directions density 0), or a
    /// grazing point.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, u: (f32, f32)) -> Option<MeshLightSample> {
        if self.radiance == Vec3::ZERO {
            return None;
        }
        let (i, barycentrics, point) = self.sample_point(u)?;
        let light = sample_area_li(
            p,
            point,
            self.normal(i),
            self.radiance,
            self.area,
            self.two_sided,
        )?;
        Some(MeshLightSample {
            light,
            triangle: i,
            barycentrics,
        })
    }

    /// Solid-angle density of [`MeshLight::sample_li`] at `p` for the sample point `point` on
    /// a triangle of unit normal `n` (what an integrator knows after its BSDF ray hit the
    /// mesh): `|p − point|² / (A |cos θ_l|)`, 0 on the back of a one-sided light.
    #[inline]
    #[must_use]
    pub fn pdf_li_hit(&self, p: Vec3, point: Vec3, n: Vec3) -> f32 {
        pdf_area_li_hit(p, point, n, self.area, self.two_sided)
    }

    /// Solid-angle density of [`MeshLight::sample_li`] for the unit direction `wi` from `p`:
    /// the sum of [`MeshLight::pdf_li_hit`] over every triangle the line meets (an occluded
    /// triangle is still sampled). O(triangles): a reference for tests, not for rendering.
    #[must_use]
    pub fn pdf_li(&self, p: Vec3, wi: Vec3) -> f32 {
        let ray = Ray::new(p, wi);
        let tri_ray = TriRay::new(&ray);
        (0..self.triangles.len())
            .filter_map(|i| {
                let [a, b, c] = self.vertices(i);
                let hit = intersect_triangle(&tri_ray, a, b, c, f32::INFINITY)?;
                Some(self.pdf_li_hit(p, p + wi * hit.t, self.normal(i)))
            })
            .sum()
    }

    /// A ray leaving the mesh: a uniform point (`pdf_pos = 1/A`) and a cosine-weighted
    /// direction about the emitting side's normal (`pdf_dir = cos θ/π`; two-sided: the side by
    /// `u_dir.0 < ½` and `|cos θ|/(2π)`), carrying the whole power per sample.
    #[must_use]
    pub fn sample_le(&self, u_pos: (f32, f32), u_dir: (f32, f32)) -> Option<EmissionSample> {
        if self.radiance == Vec3::ZERO || !self.radiance.is_finite() {
            return None;
        }
        let (i, _, origin) = self.sample_point(u_pos)?;
        let n = self.normal(i);
        sample_area_le(origin, n, self.radiance, self.area, self.two_sided, u_dir)
    }

    /// `(pdf_pos, pdf_dir)` of [`MeshLight::sample_le`] for a ray leaving a point of the
    /// triangle with geometric normal `n` in the unit `dir`.
    #[must_use]
    pub fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        pdf_area_le(n.dot(dir), self.area, self.two_sided)
    }
}

#[cfg(test)]
mod tests;
