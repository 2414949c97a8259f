//! Environment light: radiance arriving from infinitely far away in every direction — a
//! constant, or an equirectangular RGB float image (linear) rotated about +y — importance
//! sampled by a piecewise-constant 2-D distribution over the map (the idea of pbrt-v4's
//! `ImageInfiniteLight`, on an equirectangular map as in pbrt-v3).
//!
//! Map convention (Mitsuba 3's `envmap` directions; only its rows differ, see below): in the map's frame
//! +y is up, a direction `(x, y, z)` has `θ = acos y` (0 at the zenith) and `φ = atan2(x, −z)`
//! in `[0, 2π)`; image coordinates are `u = φ / 2π` (column, left to right) and `v = θ / π`
//! (row 0 at the top = zenith). Texel `(i, j)` is centred at `((i + ½)/w, (j + ½)/h)` and the
//! map is bilinearly interpolated between centres, wrapping in u and clamping in v.
//! (Mitsuba 3 puts row `j` at `v = j/(h − 1)`, pole to pole, measured with a one-hot map; the
//! comparison in `scripts/mitsuba/lights.py` resamples the map for it.) The map is
//! turned into the world by a rotation of `rotation` radians about +y (right-handed: +x towards
//! −z), i.e. `world = R_y(rotation) · map`.
//!
//! Sampling: the distribution's cell weights are the largest channel-mean of the texel and its
//! eight neighbours (so every cell the bilinear interpolant lights has a non-zero density),
//! times `sin θ` at the row's centre (the equirectangular map's area element), and a point
//! `(u, v)` of density `p(u, v)` is a direction of solid-angle density `p / (2π² sin θ)`.

use glam::Vec3;
use std::f32::consts::{PI, TAU};

use super::infinite::SceneSphere;
use super::{EmissionSample, LightSample};
use crate::sampling::distribution::Distribution2D;
use crate::sampling::warp::uniform_sphere;

/// Why an environment map cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EnvironmentError {
    /// The texel count is not `width × height`, or a side is 0.
    #[error("environment map: {width}×{height} needs {} texels, found {found}", .width * .height)]
    Size {
        /// Stated width.
        width: usize,
        /// Stated height.
        height: usize,
        /// Texels given.
        found: usize,
    },
    /// A texel is negative, NaN or infinite.
    #[error(
        "environment map: texel ({x}, {y}) is {value}; radiance must be finite and not negative"
    )]
    Texel {
        /// Column.
        x: usize,
        /// Row (0 at the top).
        y: usize,
        /// The offending value.
        value: Vec3,
    },
}

/// Where the environment's radiance comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum EnvironmentMap {
    /// The same radiance (W/(m²·sr)) from every direction.
    Constant(Vec3),
    /// An equirectangular image of radiance, row-major from the top-left.
    Image {
        /// Columns (u).
        width: usize,
        /// Rows (v).
        height: usize,
        /// `width × height` radiances.
        texels: Vec<Vec3>,
        /// Importance-sampling distribution over `(u, v)`.
        distribution: Distribution2D,
    },
}

/// An environment light: a map, its rotation about +y and the scene's bounding sphere.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentLight {
    /// The radiance map.
    pub map: EnvironmentMap,
    /// `(cos, sin)` of the rotation about +y from the map's frame to the world.
    pub rotation: (f32, f32),
    /// The scene's bounding sphere (shadow-ray ends, photon disc, power).
    pub scene: SceneSphere,
}

impl EnvironmentLight {
    /// A constant environment of radiance `radiance`.
    #[must_use]
    pub fn constant(radiance: Vec3, scene: SceneSphere) -> Self {
        Self {
            map: EnvironmentMap::Constant(radiance),
            rotation: (1.0, 0.0),
            scene,
        }
    }

    /// An equirectangular map of `width × height` radiances (row 0 at the zenith), turned by
    /// `rotation` radians about +y.
    ///
    /// # Errors
    /// [`EnvironmentError`] for a size mismatch or a negative or non-finite texel.
    pub fn image(
        width: usize,
        height: usize,
        texels: Vec<Vec3>,
        rotation: f32,
        scene: SceneSphere,
    ) -> Result<Self, EnvironmentError> {
        if width == 0 || height == 0 || texels.len() != width * height {
            return Err(EnvironmentError::Size {
                width,
                height,
                found: texels.len(),
            });
        }
        if let Some(i) = texels
            .iter()
            .position(|t| !t.is_finite() || t.min_element() < 0.0)
        {
            return Err(EnvironmentError::Texel {
                x: i % width,
                y: i / width,
                value: texels[i],
            });
        }
        let mean = |x: usize, y: usize| texels[y * width + x].element_sum() / 3.0;
        let mut weights = Vec::with_capacity(width * height);
        for y in 0..height {
            let sin_t = (PI * (y as f32 + 0.5) / height as f32).sin();
            for x in 0..width {
                let mut m = 0.0f32;
                for dy in [-1i64, 0, 1] {
                    let yy = (y as i64 + dy).clamp(0, height as i64 - 1) as usize;
                    for dx in [width - 1, 0, 1] {
                        m = m.max(mean((x + dx) % width, yy));
                    }
                }
                weights.push(m * sin_t);
            }
        }
        let distribution = Distribution2D::new(&weights, width, height);
        Ok(Self {
            map: EnvironmentMap::Image {
                width,
                height,
                texels,
                distribution,
            },
            rotation: (rotation.cos(), rotation.sin()),
            scene,
        })
    }

    /// Map frame → world: `R_y(rotation)`.
    #[inline]
    fn to_world(&self, d: Vec3) -> Vec3 {
        let (c, s) = self.rotation;
        Vec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z)
    }

    /// World → map frame: `R_y(−rotation)`.
    #[inline]
    fn to_map(&self, w: Vec3) -> Vec3 {
        let (c, s) = self.rotation;
        Vec3::new(c * w.x - s * w.z, w.y, s * w.x + c * w.z)
    }

    /// Radiance arriving along a ray that leaves the scene in the unit direction `w`: the
    /// constant, or the bilinearly interpolated map at `w`'s `(u, v)`.
    #[must_use]
    pub fn le(&self, w: Vec3) -> Vec3 {
        match &self.map {
            EnvironmentMap::Constant(l) => *l,
            EnvironmentMap::Image {
                width,
                height,
                texels,
                ..
            } => {
                let (u, v) = direction_to_uv(self.to_map(w));
                bilinear(texels, *width, *height, u, v)
            }
        }
    }

    /// A direction towards the environment from `p`: uniform over the sphere (constant) or by
    /// the map's distribution, with the radiance along it; the shadow ray ends beyond the
    /// scene's bounding sphere. `None` for a black map or a sample at a pole (`sin θ = 0`).
    #[must_use]
    pub fn sample_li(&self, p: Vec3, u: (f32, f32)) -> Option<LightSample> {
        let (wi, pdf) = self.sample_direction(u)?;
        let radiance = self.le(wi);
        let weight = radiance / pdf;
        let distance = self.scene.far_distance(p);
        weight.is_finite().then(|| LightSample {
            wi,
            distance,
            point: p + wi * distance,
            radiance,
            pdf,
            delta: false,
            weight,
        })
    }

    /// A direction (towards the sky) and its solid-angle density.
    fn sample_direction(&self, u: (f32, f32)) -> Option<(Vec3, f32)> {
        match &self.map {
            EnvironmentMap::Constant(l) => {
                (*l != Vec3::ZERO).then(|| (uniform_sphere(u), 1.0 / (4.0 * PI)))
            }
            EnvironmentMap::Image { distribution, .. } => {
                if !(distribution.integral() > 0.0) {
                    return None;
                }
                let s = distribution.sample(u);
                let (d, sin_t) = uv_to_direction(s.x, s.y);
                let pdf = s.pdf / (2.0 * PI * PI * sin_t);
                (sin_t > 0.0 && pdf.is_finite() && pdf > 0.0).then(|| (self.to_world(d), pdf))
            }
        }
    }

    /// Solid-angle density of [`EnvironmentLight::sample_li`] for the unit `wi`:
    /// `1/(4π)` (constant) or `p(u, v) / (2π² sin θ)`; 0 for a black map.
    #[must_use]
    pub fn pdf_li(&self, _p: Vec3, wi: Vec3) -> f32 {
        match &self.map {
            EnvironmentMap::Constant(l) => {
                if *l == Vec3::ZERO {
                    0.0
                } else {
                    1.0 / (4.0 * PI)
                }
            }
            EnvironmentMap::Image { distribution, .. } => {
                if !(distribution.integral() > 0.0) {
                    return 0.0;
                }
                let d = self.to_map(wi);
                let sin_t = (d.x * d.x + d.z * d.z).sqrt();
                let (u, v) = direction_to_uv(d);
                let pdf = distribution.pdf(u, v) / (2.0 * PI * PI * sin_t);
                if pdf.is_finite() { pdf } else { 0.0 }
            }
        }
    }

    /// A photon: a direction `wi` from the sampling distribution, travelling along `dir = −wi`
    /// from a uniform point of the bounding sphere's disc perpendicular to it (`pdf_pos = 1/(π
    /// R²)`, `pdf_dir = pdf_li(wi)`, `normal = dir`, `le = le(wi)`; flux `le / (pdf_pos ·
    /// pdf_dir)`).
    #[must_use]
    pub fn sample_le(&self, u_pos: (f32, f32), u_dir: (f32, f32)) -> Option<EmissionSample> {
        let (wi, pdf_dir) = self.sample_direction(u_dir)?;
        let dir = -wi;
        Some(EmissionSample {
            origin: self.scene.disc_origin(dir, u_pos),
            normal: dir,
            dir,
            le: self.le(wi),
            pdf_pos: 1.0 / self.scene.disc_area(),
            pdf_dir,
        })
    }

    /// `(pdf_pos, pdf_dir)` of [`EnvironmentLight::sample_le`] for a photon travelling along
    /// the unit `dir`.
    #[must_use]
    pub fn pdf_le(&self, dir: Vec3) -> (f32, f32) {
        (1.0 / self.scene.disc_area(), self.pdf_li(Vec3::ZERO, -dir))
    }

    /// Flux (W) through the bounding sphere's disc, `π R² ∫ L dω`: exact for the constant
    /// (`4π · π R² L`); for a map, the texels times their exact solid angles
    /// `(2π/w)(cos θ_j − cos θ_{j+1})` (the bilinear interpolant's integral differs from that
    /// by the map's curvature, a small fraction for smooth skies) — an estimate for choosing
    /// lights by power.
    #[must_use]
    pub fn power(&self) -> Vec3 {
        let integral = match &self.map {
            EnvironmentMap::Constant(l) => *l * (4.0 * PI),
            EnvironmentMap::Image {
                width,
                height,
                texels,
                ..
            } => {
                let mut sum = glam::DVec3::ZERO;
                for y in 0..*height {
                    let t0 = std::f64::consts::PI * y as f64 / *height as f64;
                    let t1 = std::f64::consts::PI * (y + 1) as f64 / *height as f64;
                    let omega = std::f64::consts::TAU / *width as f64 * (t0.cos() - t1.cos());
                    let row: glam::DVec3 = texels[y * width..(y + 1) * width]
                        .iter()
                        .map(|t| t.as_dvec3())
                        .sum();
                    sum += row * omega;
                }
                sum.as_vec3()
            }
        };
        integral * self.scene.disc_area()
    }
}

/// `(u, v) ∈ [0, 1)²` of a unit direction in the map's frame (see the module docs).
#[inline]
#[must_use]
pub fn direction_to_uv(d: Vec3) -> (f32, f32) {
    let phi = d.x.atan2(-d.z).rem_euclid(TAU);
    let theta = d.y.clamp(-1.0, 1.0).acos();
    (
        (phi / TAU).min(1.0 - f32::EPSILON / 2.0),
        (theta / PI).min(1.0 - f32::EPSILON / 2.0),
    )
}

/// The unit direction in the map's frame at `(u, v)`, and its `sin θ`.
#[inline]
#[must_use]
pub fn uv_to_direction(u: f32, v: f32) -> (Vec3, f32) {
    let (sin_t, cos_t) = (PI * v).sin_cos();
    let (sin_p, cos_p) = (TAU * u).sin_cos();
    (Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p), sin_t)
}

/// Bilinear interpolation of `texels` between texel centres at `(u, v)`, wrapping in u and
/// clamping in v.
fn bilinear(texels: &[Vec3], w: usize, h: usize, u: f32, v: f32) -> Vec3 {
    let fx = u * w as f32 - 0.5;
    let fy = (v * h as f32 - 0.5).clamp(0.0, (h - 1) as f32);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let xa = (x0 as i64).rem_euclid(w as i64) as usize;
    let xb = (xa + 1) % w;
    let ya = y0 as usize;
    let yb = (ya + 1).min(h - 1);
    let at = |x: usize, y: usize| texels[y * w + x];
    (at(xa, ya) * (1.0 - tx) + at(xb, ya) * tx) * (1.0 - ty)
        + (at(xa, yb) * (1.0 - tx) + at(xb, yb) * tx) * ty
}

#[cfg(test)]
mod tests;
