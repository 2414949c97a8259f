//! Compiled lights: incident-light sampling for next-event estimation (`sample_li`, `pdf_li`),
//! emitted radiance when a ray hits an emitter (`le`), and emission sampling for light and photon
//! paths (`sample_le`, `pdf_le`).
//!
//! Sphere lights are sampled by the cone of directions they subtend (uniform in solid angle), not
//! by their area: the density is constant over the visible cap, so the estimator's only variance
//! is the cosine and the BSDF (pbrt-v4 §12.2.2 describes the same strategy for spheres).
//!
//! The other shapes live in their own files and are wrapped as variants here, so every
//! integrator and photon pass reaches them through the same methods: rectangles
//! ([`rect`], spherical rectangles), emissive triangle meshes ([`triangle_mesh`], by area),
//! spot lights ([`spot`], pbrt-v4's fall-off), distant lights ([`distant`], the sun's cone) and
//! environment lights ([`environment`], an importance-sampled equirectangular map). Lights at
//! infinity are reached by rays that escape the scene ([`escape`]); a distant light's cone is
//! not (it is sampled by next-event estimation only, see [`Light::sample_li`]).

use glam::Vec3;
use std::f32::consts::{PI, TAU};
use std::sync::Arc;

use crate::geometry::offset::offset_ray_origin;
use crate::geometry::{Frame, Ray};
use crate::sampling::Sampler;
use crate::sampling::warp::{cosine_hemisphere, uniform_sphere};

pub use distant::DistantLight;
pub use environment::EnvironmentLight;
pub use infinite::SceneSphere;
pub use quadric::QuadricLight;
pub use rect::RectLight;
pub use sky::SkyLight;
pub use spot::SpotLight;
pub use triangle_mesh::MeshLight;

/// A light source in world space.
///
/// Cloning is cheap: the variants with large tables (meshes, environment maps) share them.
#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    /// Point light with radiant intensity `intensity = Φ/(4π)` (W/sr).
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity per channel.
        intensity: Vec3,
    },
    /// Spherical emitter of uniform radiance `radiance = Φ/(4π²r²)`; also a sphere primitive.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
        /// Emitted radiance per channel.
        radiance: Vec3,
    },
    /// A parallelogram (a `Quad` node with `emission`), sampled by solid angle.
    Rect(RectLight),
    /// An emissive triangle mesh (a `Cube` or `Mesh` node with `emission`), sampled by area.
    Mesh(Arc<MeshLight>),
    /// An emissive disc or cylinder (a `Disc` or `Cylinder` node with `emission`), by area.
    Quadric(Box<QuadricLight>),
    /// A spot light (a point light with a cone and pbrt-v4's smooth fall-off).
    Spot(SpotLight),
    /// A distant light (the sun), optionally with an angular radius.
    Distant(DistantLight),
    /// Radiance from every direction at infinity (constant or an image).
    Environment(Arc<EnvironmentLight>),
    /// A physical clear sky above a ground (Preetham et al. 1999), tabulated as an environment.
    Sky(Arc<SkyLight>),
}

/// One sample of incident light at a point (from [`Light::sample_li`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shaded point towards the light.
    pub wi: Vec3,
    /// Distance from the shaded point to `point` along `wi`.
    pub distance: f32,
    /// The sampled point on the light (shadow rays end just before it).
    pub point: Vec3,
    /// Incident radiance along `wi`; for a point light, `intensity / distance²` (the weight of
    /// the delta distribution).
    pub radiance: Vec3,
    /// Solid-angle density of `wi` (1 for a delta light, whose `delta` is true).
    pub pdf: f32,
    /// True when the light is a delta distribution in direction (point lights): BSDF sampling
    /// can never hit it, so no MIS weight applies.
    pub delta: bool,
    /// `radiance / pdf`: what callers multiply by `f · cos θ` (and the shadow-ray visibility).
    pub weight: Vec3,
}

/// A ray leaving a light, for light and photon paths (from [`Light::sample_le`]).
///
/// The flux the ray carries is `le · |cos θ| / (pdf_pos · pdf_dir)` for an area light (θ between
/// `dir` and `normal`) and `le / (pdf_pos · pdf_dir)` for a point light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmissionSample {
    /// Point on the light (exactly on the surface: offset it along `normal` before tracing).
    pub origin: Vec3,
    /// Outward unit surface normal at `origin`; zero for point lights.
    pub normal: Vec3,
    /// Unit direction of the emitted ray.
    pub dir: Vec3,
    /// Radiance (sphere light, W/(m²·sr)) or intensity (point light, W/sr) along `dir`.
    pub le: Vec3,
    /// Area density of `origin` (1/m²); 1 for point lights (a delta in position).
    pub pdf_pos: f32,
    /// Solid-angle density of `dir` (1/sr).
    pub pdf_dir: f32,
}

impl Light {
    /// A point light emitting `power` watts.
    #[must_use]
    pub fn point(position: Vec3, power: Vec3) -> Self {
        Light::Point {
            position,
            intensity: power / (4.0 * PI),
        }
    }

    /// A sphere light emitting `power` watts from its surface.
    #[must_use]
    pub fn sphere(center: Vec3, radius: f32, power: Vec3) -> Self {
        Light::Sphere {
            center,
            radius,
            radiance: power / (4.0 * PI * PI * radius * radius),
        }
    }

    /// True for lights whose samples carry no MIS weight because BSDF sampling never reaches
    /// them: point and spot lights (deltas in position) and distant lights of angular radius 0
    /// (a delta direction). A distant light with a disc (the sun) is not: escaping rays see it
    /// ([`Light::le_escaped`]).
    #[inline]
    #[must_use]
    pub fn is_delta(&self) -> bool {
        match self {
            Light::Distant(d) => d.is_delta(),
            Light::Point { .. } | Light::Spot(_) => true,
            Light::Sphere { .. }
            | Light::Rect(_)
            | Light::Mesh(_)
            | Light::Quadric(_)
            | Light::Environment(_)
            | Light::Sky(_) => false,
        }
    }

    /// True for lights at infinity (distant and environment lights): their shadow rays end
    /// beyond the scene's bounding sphere and their photons start on a disc of it.
    #[inline]
    #[must_use]
    pub fn is_infinite(&self) -> bool {
        match self {
            Light::Distant(_) | Light::Environment(_) | Light::Sky(_) => true,
            Light::Point { .. }
            | Light::Sphere { .. }
            | Light::Rect(_)
            | Light::Mesh(_)
            | Light::Quadric(_)
            | Light::Spot(_) => false,
        }
    }

    /// What the light sends back along a ray escaping the scene in direction `dir` (any
    /// non-zero length; each kind normalises it as its own lookups do): for an environment or
    /// sky, the map's radiance in that direction; for a distant light with a disc (the sun), its
    /// radiance inside the disc. `None` where it sends nothing: outside a sun's disc, for a delta
    /// distant light, a black map direction, and for every light with a position (point,
    /// sphere, rectangle, mesh, spot), which rays meet as surfaces or never.
    #[inline]
    #[must_use]
    pub fn le_escaped(&self, dir: Vec3) -> Option<escape::Escape> {
        let (le, wi) = match self {
            Light::Distant(d) => {
                let wi = dir.try_normalize()?;
                (d.le(wi), wi)
            }
            Light::Environment(e) => {
                let wi = dir / dir.length();
                (e.le(wi), wi)
            }
            Light::Sky(s) => {
                let wi = dir / dir.length();
                (s.map.le(wi), wi)
            }
            Light::Point { .. }
            | Light::Sphere { .. }
            | Light::Rect(_)
            | Light::Mesh(_)
            | Light::Quadric(_)
            | Light::Spot(_) => return None,
        };
        (le != Vec3::ZERO).then_some(escape::Escape { le, wi })
    }

    /// True for the lights at infinity that fill the sphere of directions (environment, sky): ray
    /// trees name escaping rays after the first of them, which compilation gives an object.
    #[inline]
    #[must_use]
    pub fn fills_sky(&self) -> bool {
        match self {
            Light::Environment(_) | Light::Sky(_) => true,
            Light::Point { .. }
            | Light::Sphere { .. }
            | Light::Rect(_)
            | Light::Mesh(_)
            | Light::Quadric(_)
            | Light::Spot(_)
            | Light::Distant(_) => false,
        }
    }

    /// The scene's bounding sphere a light at infinity places its shadow-ray ends and photons
    /// on; `None` for lights with a position.
    #[inline]
    #[must_use]
    pub fn scene_sphere(&self) -> Option<SceneSphere> {
        match self {
            Light::Distant(d) => Some(d.scene),
            Light::Environment(e) => Some(e.scene),
            Light::Sky(s) => Some(s.map.scene),
            Light::Point { .. }
            | Light::Sphere { .. }
            | Light::Rect(_)
            | Light::Mesh(_)
            | Light::Quadric(_)
            | Light::Spot(_) => None,
        }
    }

    /// True when the light's own surface can lie between a shaded point and a point sampled
    /// on it (a mesh that is not convex, seen through itself): shadow rays towards it must test
    /// its primitives. False for spheres (the sample is on the near side) and flat lights.
    #[inline]
    #[must_use]
    pub fn can_shadow_itself(&self) -> bool {
        match self {
            Light::Mesh(_) => true,
            Light::Quadric(q) => q.shape.can_shadow_itself(),
            Light::Point { .. }
            | Light::Sphere { .. }
            | Light::Rect(_)
            | Light::Spot(_)
            | Light::Distant(_)
            | Light::Environment(_)
            | Light::Sky(_) => false,
        }
    }

    /// Samples a direction towards the light from `p` with `u ∈ [0, 1)²`.
    ///
    /// Sphere lights: uniform over the cone of directions the sphere subtends at `p`; the sample
    /// point is where the ray `p + t·wi` first meets the sphere. Point lights: the one direction.
    /// `None` when `p` is inside (or on) the emitter, the light is black, or the cone is too
    /// small for `f32` (a sphere so far away that its density overflows; its contribution then
    /// rounds to zero anyway). Never returns NaN or infinite fields.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, u: (f32, f32)) -> Option<LightSample> {
        match *self {
            Light::Point {
                position,
                intensity,
            } => {
                let d = position - p;
                let dist2 = d.length_squared();
                if !(dist2 > 0.0 && dist2.is_finite()) || intensity == Vec3::ZERO {
                    return None;
                }
                let dist = dist2.sqrt();
                let radiance = intensity / dist2;
                if !radiance.is_finite() {
                    // A point light (almost) on the surface: its irradiance exceeds f32. Such a
                    // point is never a pixel's whole story, and an infinite sample would be
                    // dropped anyway; give no light rather than Inf.
                    return None;
                }
                Some(LightSample {
                    wi: d / dist,
                    distance: dist,
                    point: position,
                    radiance,
                    pdf: 1.0,
                    delta: true,
                    weight: radiance,
                })
            }
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                let d = center - p;
                let dist2 = d.length_squared();
                let r2 = radius * radius;
                if !(dist2 > r2 && dist2.is_finite()) || radiance == Vec3::ZERO {
                    return None;
                }
                let dist = dist2.sqrt();
                let axis = d / dist;
                let one_minus_cos_max = cone_one_minus_cos(r2, dist2);
                let pdf = 1.0 / (TAU * one_minus_cos_max);
                if !pdf.is_finite() {
                    return None;
                }
                // Uniform in solid angle: 1 − cos θ uniform in [0, 1 − cos θmax]. Sampling
                // 1 − cos θ (not cos θ) keeps tiny cones from collapsing onto the axis.
                let one_minus_cos = (u.0 * one_minus_cos_max).min(one_minus_cos_max);
                let cos_t = 1.0 - one_minus_cos;
                let sin2_t = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0);
                let sin_t = sin2_t.sqrt();
                let phi = TAU * u.1;
                let wi = Frame::from_normal(axis)
                    .to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t))
                    .normalize();
                // Near intersection t = D cos θ − √(r² − D² sin² θ), written without the
                // cancellation: t = (D² − r²) / (D cos θ + √(r² − D² sin² θ)).
                let root = (r2 - dist2 * sin2_t).max(0.0).sqrt();
                let denom = dist * cos_t + root;
                let t = if denom > 0.0 {
                    ((dist2 - r2) / denom).max(0.0)
                } else {
                    0.0
                };
                let weight = radiance * (TAU * one_minus_cos_max);
                if !(weight.is_finite() && t.is_finite()) {
                    return None;
                }
                Some(LightSample {
                    wi,
                    distance: t,
                    point: p + wi * t,
                    radiance,
                    pdf,
                    delta: false,
                    weight,
                })
            }
            Light::Rect(ref r) => r.sample_li(p, u),
            Light::Mesh(ref m) => m.sample_li(p, u).map(|s| s.light),
            Light::Quadric(ref q) => q.sample_li(p, u),
            Light::Spot(ref s) => s.sample_li(p, u),
            // The sun's cone: escaping rays see it too (`Light::le_escaped`), so its samples
            // are MIS-weighted against BSDF sampling as an environment's are.
            Light::Distant(ref d) => d.sample_li(p, u),
            Light::Environment(ref e) => e.sample_li(p, u),
            Light::Sky(ref s) => s.map.sample_li(p, u),
        }
    }

    /// Solid-angle density with which [`Light::sample_li`] at `p` returns the unit direction
    /// `wi`: 0 for point lights (a delta), 0 outside the cone a sphere subtends or when `p` is
    /// inside it. Used for the MIS weight when a BSDF-sampled ray hits a sphere light.
    /// Spot lights and delta distant lights give 0 (their samples carry no MIS weight); a sun's
    /// disc gives `1/(2π(1 − cos α))` inside its cone; a mesh gives the
    /// density of the direction (every triangle the line meets, O(triangles): integrators use
    /// [`Light::pdf_li_hit`], which knows the point hit).
    #[must_use]
    pub fn pdf_li(&self, p: Vec3, wi: Vec3) -> f32 {
        match *self {
            Light::Point { .. } => 0.0,
            Light::Sphere { center, radius, .. } => {
                let d = center - p;
                let dist2 = d.length_squared();
                let r2 = radius * radius;
                if !(dist2 > r2 && dist2.is_finite()) || wi.dot(d) <= 0.0 {
                    return 0.0;
                }
                // Inside the cone ⇔ the line along wi passes within r of the centre. The slack
                // is the f32 resolution of a unit direction (about an ulp, times the distance)
                // plus a few ulps of r, so directions sampled on the rim (and rays that graze
                // the sphere) count as inside; it adds a relative ~2 · RIM_SLACK · D/r to the
                // cone's mass (more for cones near a hemisphere, whose rim is tangent).
                let perp2 = wi.cross(d).length_squared();
                let reach = radius * (1.0 + 5e-7) + RIM_SLACK * dist2.sqrt();
                if perp2 > reach * reach {
                    return 0.0;
                }
                let pdf = 1.0 / (TAU * cone_one_minus_cos(r2, dist2));
                if pdf.is_finite() { pdf } else { 0.0 }
            }
            Light::Rect(ref r) => r.pdf_li(p, wi),
            Light::Mesh(ref m) => m.pdf_li(p, wi),
            Light::Quadric(ref q) => q.pdf_li(p, wi),
            Light::Spot(ref s) => s.pdf_li(p, wi),
            Light::Distant(ref d) => d.pdf_li(p, wi),
            Light::Environment(ref e) => e.pdf_li(p, wi),
            Light::Sky(ref s) => s.map.pdf_li(p, wi),
        }
    }

    /// [`Light::pdf_li`] for a ray from `p` that hit the light at `point` (geometric normal
    /// `n`, outward by winding): what a BSDF-sampled ray needs for its MIS weight. A mesh's
    /// density is that of the point hit (the triangles behind it are other paths); every other
    /// light gives `pdf_li(p, normalize(point − p))` (for lights at infinity `point` is any
    /// point along the escaping ray).
    #[inline]
    #[must_use]
    pub fn pdf_li_hit(&self, p: Vec3, wi: Vec3, point: Vec3, n: Vec3) -> f32 {
        match self {
            Light::Mesh(m) => m.pdf_li_hit(p, point, n),
            Light::Quadric(q) => q.pdf_li_hit(p, point, n),
            Light::Point { .. }
            | Light::Sphere { .. }
            | Light::Rect(_)
            | Light::Spot(_)
            | Light::Distant(_)
            | Light::Environment(_)
            | Light::Sky(_) => self.pdf_li(p, wi),
        }
    }

    /// Radiance the light emits from a surface point with outward unit normal `n` in direction
    /// `w` (unit, pointing away from the light): the sphere's radiance on its outer side, zero
    /// otherwise and for point lights (which rays cannot hit). Rectangles and meshes: their
    /// radiance on an emitting side (`n` is the triangle's winding normal). Environment: the
    /// radiance arriving along a ray escaping in direction `−w` (`n` unused). Spot and distant
    /// lights: zero (rays never hit them as surfaces; an escaping ray sees a sun's disc through
    /// [`Light::le_escaped`]).
    #[inline]
    #[must_use]
    pub fn le(&self, n: Vec3, w: Vec3) -> Vec3 {
        match *self {
            Light::Point { .. } => Vec3::ZERO,
            Light::Sphere { radiance, .. } => {
                if n.dot(w) > 0.0 {
                    radiance
                } else {
                    Vec3::ZERO
                }
            }
            Light::Rect(ref r) => r.le(w),
            Light::Mesh(ref m) => m.le(n, w),
            Light::Quadric(ref q) => q.le(n, w),
            Light::Spot(_) | Light::Distant(_) => Vec3::ZERO,
            Light::Environment(ref e) => e.le(-w),
            Light::Sky(ref s) => s.map.le(-w),
        }
    }

    /// Samples a ray leaving the light, for light and photon paths, from two independent pairs
    /// of uniforms in `[0, 1)²`.
    ///
    /// Sphere: a uniform point on the surface (`pdf_pos = 1/(4πr²)`) and a cosine-weighted
    /// direction about its normal (`pdf_dir = cos θ / π`), so every sample carries exactly the
    /// same flux `le · cos θ / (pdf_pos · pdf_dir) = Φ`. Point: uniform directions over the
    /// sphere (`pdf_dir = 1/(4π)`), flux `le / pdf_dir = Φ`. `None` for black lights and for
    /// the measure-zero grazing directions where `pdf_dir` would be 0.
    #[must_use]
    pub fn sample_le(&self, u_pos: (f32, f32), u_dir: (f32, f32)) -> Option<EmissionSample> {
        match *self {
            Light::Point {
                position,
                intensity,
            } => {
                if intensity == Vec3::ZERO {
                    return None;
                }
                Some(EmissionSample {
                    origin: position,
                    normal: Vec3::ZERO,
                    dir: point_emission_direction(u_dir),
                    le: intensity,
                    pdf_pos: 1.0,
                    pdf_dir: 1.0 / (4.0 * PI),
                })
            }
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                if radiance == Vec3::ZERO || !radiance.is_finite() {
                    return None;
                }
                let normal = uniform_sphere(u_pos);
                let dir = cosine_hemisphere(u_dir, normal);
                let cos_t = dir.dot(normal);
                let pdf_pos = 1.0 / (4.0 * PI * radius * radius);
                if !(cos_t > 0.0 && pdf_pos.is_finite()) {
                    return None;
                }
                Some(EmissionSample {
                    origin: center + normal * radius,
                    normal,
                    dir,
                    le: radiance,
                    pdf_pos,
                    pdf_dir: cos_t / PI,
                })
            }
            Light::Rect(ref r) => r.sample_le(u_pos, u_dir),
            Light::Mesh(ref m) => m.sample_le(u_pos, u_dir),
            Light::Quadric(ref q) => q.sample_le(u_pos, u_dir),
            Light::Spot(ref s) => s.sample_le(u_pos, u_dir),
            Light::Distant(ref d) => d.sample_le(u_pos, u_dir),
            Light::Environment(ref e) => e.sample_le(u_pos, u_dir),
            Light::Sky(ref s) => s.map.sample_le(u_pos, u_dir),
        }
    }

    /// The densities `(pdf_pos, pdf_dir)` with which [`Light::sample_le`] produces a ray leaving
    /// a point with outward normal `normal` in direction `dir` (both unit; `normal` is ignored
    /// for point, spot and infinite lights, and by a rectangle, which knows its own). `pdf_dir`
    /// is 0 for directions below the surface (and outside a spot's cone).
    #[must_use]
    pub fn pdf_le(&self, normal: Vec3, dir: Vec3) -> (f32, f32) {
        match *self {
            Light::Point { .. } => (1.0, 1.0 / (4.0 * PI)),
            Light::Sphere { radius, .. } => (
                1.0 / (4.0 * PI * radius * radius),
                normal.dot(dir).max(0.0) / PI,
            ),
            Light::Rect(ref r) => r.pdf_le(dir),
            Light::Mesh(ref m) => m.pdf_le(normal, dir),
            Light::Quadric(ref q) => q.pdf_le(normal, dir),
            Light::Spot(ref s) => s.pdf_le(dir),
            Light::Distant(ref d) => d.pdf_le(dir),
            Light::Environment(ref e) => e.pdf_le(dir),
            Light::Sky(ref s) => s.map.pdf_le(dir),
        }
    }

    /// Total emitted flux (W) per channel.
    #[must_use]
    pub fn power(&self) -> Vec3 {
        match *self {
            Light::Point { intensity, .. } => intensity * 4.0 * PI,
            Light::Sphere {
                radius, radiance, ..
            } => radiance * 4.0 * PI * PI * radius * radius,
            Light::Rect(ref r) => r.power(),
            Light::Mesh(ref m) => m.power(),
            Light::Quadric(ref q) => q.power(),
            Light::Spot(ref s) => s.power(),
            Light::Distant(ref d) => d.power(),
            Light::Environment(ref e) => e.power(),
            Light::Sky(ref s) => s.map.power(),
        }
    }
}

impl Light {
    /// Shadow rays an estimator that lights every point from every light (Whitted) casts
    /// towards this light: one for a delta light (every sample would be the same ray),
    /// `per_area_light` (`render.light_samples`) for a light with extent.
    #[inline]
    #[must_use]
    pub fn shadow_samples(&self, per_area_light: u32) -> u32 {
        match self {
            Light::Point { .. } | Light::Spot(_) => 1,
            Light::Distant(d) if d.is_delta() => 1,
            Light::Sphere { .. }
            | Light::Rect(_)
            | Light::Mesh(_)
            | Light::Quadric(_)
            | Light::Distant(_)
            | Light::Environment(_)
            | Light::Sky(_) => per_area_light,
        }
    }

    /// One of `n` photons (or light paths) leaving the light with evenly spread directions, and
    /// its flux (W per channel). A light that emits from one point uniformly over the sphere
    /// takes its direction from `lattice()` (a unit direction of an even point set of density
    /// `1/(4π)`, such as a rotated spherical Fibonacci lattice) and carries `Φ / n`; a light
    /// with area draws a ray from [`Light::sample_le`] with two pairs of `sampler` uniforms and
    /// carries `Le · cos θ / (pdf_pos · pdf_dir · n)`. `None` for a black light or a grazing
    /// emission direction.
    #[must_use]
    pub fn emit_spread(
        &self,
        lattice: impl FnOnce() -> Vec3,
        sampler: &mut Sampler,
        n: f32,
    ) -> Option<(Ray, Vec3)> {
        match *self {
            Light::Point { position, .. } => {
                let dir = lattice();
                let power = self.power() / n;
                (power.max_element() > 0.0).then(|| (Ray::new(position, dir.normalize()), power))
            }
            Light::Sphere { .. } | Light::Rect(_) | Light::Mesh(_) | Light::Quadric(_) => {
                let u_pos = sampler.next_2d();
                let u_dir = sampler.next_2d();
                let e = self.sample_le(u_pos, u_dir)?;
                let cos = e.dir.dot(e.normal);
                let power = e.le * (cos / (e.pdf_pos * e.pdf_dir * n));
                Some((
                    Ray::new(leave_surface(e.origin, e.normal, e.dir), e.dir),
                    power,
                ))
            }
            // No surface to leave: a spot's photons start at its position, those of lights at
            // infinity on the disc of the scene's bounding sphere; flux le / (pdf_pos pdf_dir).
            Light::Spot(_) | Light::Distant(_) | Light::Environment(_) | Light::Sky(_) => {
                let u_pos = sampler.next_2d();
                let u_dir = sampler.next_2d();
                let e = self.sample_le(u_pos, u_dir)?;
                let power = e.le / (e.pdf_pos * e.pdf_dir * n);
                (power.is_finite() && power.max_element() > 0.0)
                    .then(|| (Ray::new(e.origin, e.dir), power))
            }
        }
    }

    /// One of `n` photons leaving the light in an aimed direction, and its flux: the emitting
    /// point (the light's position, or a uniform point on its surface from one `sampler` pair),
    /// then `aim(point, sampler)` gives a unit direction and its solid-angle density (1/sr);
    /// the flux divides by that density. `None` when `aim` gives nothing, the direction leaves
    /// the surface inwards (no light goes there; the photon still counts as emitted, so the
    /// estimate stays unbiased) or the flux is not finite. A spot's aimed photon carries the
    /// intensity along its direction (none outside the cone).
    ///
    /// Lights at infinity have no point to aim from: their direction is drawn as
    /// [`Light::sample_le`] draws it (one `sampler` pair), then `cross(dir, sampler)` gives a
    /// point the photon's line passes through and the density (1/m², over the plane
    /// perpendicular to `dir`) of the line chosen — the projection of the targets instead of
    /// the whole disc of the scene's bounding sphere that [`Light::emit_spread`] uses. The
    /// photon starts where that line enters the bounding sphere's upstream plane, with flux
    /// `L / (pdf_dir · pdf_line · n)`. Every caustic path's first segment meets a target, so
    /// lines that meet none carry nothing the caustic map keeps: leaving them out is unbiased.
    #[must_use]
    pub fn emit_aimed(
        &self,
        sampler: &mut Sampler,
        aim: impl FnOnce(Vec3, &mut Sampler) -> Option<(Vec3, f32)>,
        cross: impl FnOnce(Vec3, &mut Sampler) -> Option<(Vec3, f32)>,
        n: f32,
    ) -> Option<(Ray, Vec3)> {
        match *self {
            Light::Point {
                position,
                intensity,
            } => {
                let (dir, pdf) = aim(position, sampler)?;
                let power = intensity / (pdf * n);
                power.is_finite().then(|| (Ray::new(position, dir), power))
            }
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                let normal = uniform_sphere(sampler.next_2d());
                let origin = center + normal * radius;
                let (dir, pdf) = aim(origin, sampler)?;
                let cos = dir.dot(normal);
                if !(cos > 0.0) {
                    return None;
                }
                let pdf_pos = 1.0 / (4.0 * PI * radius * radius);
                let power = radiance * (cos / (pdf_pos * pdf * n));
                power
                    .is_finite()
                    .then(|| (Ray::new(leave_surface(origin, normal, dir), dir), power))
            }
            Light::Rect(ref r) => {
                let u = sampler.next_2d();
                let origin = r.corner + r.edge_u * u.0 + r.edge_v * u.1;
                let surface = AreaEmitter {
                    origin,
                    normal: r.normal,
                    area: r.area,
                    radiance: r.radiance,
                    two_sided: r.two_sided,
                };
                surface.emit_aimed(sampler, aim, n)
            }
            Light::Quadric(ref q) => {
                let (origin, normal) = q.sample_position(sampler.next_2d());
                let surface = AreaEmitter {
                    origin,
                    normal,
                    area: q.area,
                    radiance: q.radiance,
                    two_sided: q.two_sided,
                };
                surface.emit_aimed(sampler, aim, n)
            }
            Light::Mesh(ref m) => {
                let (origin, normal) = m.sample_position(sampler.next_2d())?;
                let surface = AreaEmitter {
                    origin,
                    normal,
                    area: m.area,
                    radiance: m.radiance,
                    two_sided: m.two_sided,
                };
                surface.emit_aimed(sampler, aim, n)
            }
            Light::Spot(s) => {
                let (dir, pdf) = aim(s.position, sampler)?;
                let power = s.intensity_towards(dir) / (pdf * n);
                (power.is_finite() && power.max_element() > 0.0)
                    .then(|| (Ray::new(s.position, dir), power))
            }
            Light::Distant(ref d) => Self::emit_crossing(
                d.sample_le((0.5, 0.5), sampler.next_2d()),
                d.scene,
                sampler,
                cross,
                n,
            ),
            Light::Environment(ref e) => Self::emit_crossing(
                e.sample_le((0.5, 0.5), sampler.next_2d()),
                e.scene,
                sampler,
                cross,
                n,
            ),
            Light::Sky(ref s) => Self::emit_crossing(
                s.map.sample_le((0.5, 0.5), sampler.next_2d()),
                s.map.scene,
                sampler,
                cross,
                n,
            ),
        }
    }

    /// The photon of a light at infinity whose direction (and radiance, density) `e` holds,
    /// along the line `cross` chooses (see [`Light::emit_aimed`]).
    fn emit_crossing(
        e: Option<EmissionSample>,
        scene: SceneSphere,
        sampler: &mut Sampler,
        cross: impl FnOnce(Vec3, &mut Sampler) -> Option<(Vec3, f32)>,
        n: f32,
    ) -> Option<(Ray, Vec3)> {
        let e = e?;
        let (x, pdf_line) = cross(e.dir, sampler)?;
        // Upstream of the whole bounding sphere, on the line through `x`.
        let origin = x - e.dir * ((x - scene.center).dot(e.dir) + scene.radius);
        let power = e.le / (pdf_line * e.pdf_dir * n);
        (power.is_finite() && power.max_element() > 0.0).then(|| (Ray::new(origin, e.dir), power))
    }
}

/// A uniformly chosen point of a flat-faced area light (rectangle or mesh), for aimed photons.
struct AreaEmitter {
    origin: Vec3,
    /// Unit winding normal of the face `origin` is on.
    normal: Vec3,
    /// The light's whole area (m²): the point's density is `1/area`.
    area: f32,
    radiance: Vec3,
    two_sided: bool,
}

impl AreaEmitter {
    /// The photon leaving `origin` along `aim`'s direction (density `pdf`): flux
    /// `L cos θ · area / (pdf · n)`, from the front or (two-sided) the back; `None` behind a
    /// one-sided light or for a flux that is not finite.
    fn emit_aimed(
        &self,
        sampler: &mut Sampler,
        aim: impl FnOnce(Vec3, &mut Sampler) -> Option<(Vec3, f32)>,
        n: f32,
    ) -> Option<(Ray, Vec3)> {
        let (dir, pdf) = aim(self.origin, sampler)?;
        let c = dir.dot(self.normal);
        let (cos, normal) = if c > 0.0 {
            (c, self.normal)
        } else if self.two_sided {
            (-c, -self.normal)
        } else {
            return None;
        };
        if !(cos > 0.0) {
            return None;
        }
        let power = self.radiance * (cos * self.area / (pdf * n));
        power.is_finite().then(|| {
            (
                Ray::new(leave_surface(self.origin, normal, dir), dir),
                power,
            )
        })
    }
}

/// A ray origin just outside an emitter's surface at `p` (normal `n`), on the side of `dir`.
fn leave_surface(p: Vec3, n: Vec3, dir: Vec3) -> Vec3 {
    let err = p.abs() * (4.0 * f32::EPSILON) + Vec3::splat(f32::MIN_POSITIVE);
    offset_ray_origin(p, err, n, dir)
}

/// The direction a point light emits its photon/light path with `u ∈ [0, 1)²`: uniform over the
/// sphere today. This is the one place to change for stratified point emission (a spherical
/// Fibonacci lattice keyed by the photon index), which must keep density `1/(4π)`.
#[inline]
fn point_emission_direction(u: (f32, f32)) -> Vec3 {
    uniform_sphere(u)
}

/// Angular tolerance (radians) of [`Light::pdf_li`]'s rim test: about one `f32` ulp of a unit
/// vector's components.
pub const RIM_SLACK: f32 = 5e-8;

/// `1 − cos θmax` of the cone a sphere of squared radius `r2` subtends from squared distance
/// `dist2 > r2`, as `sin²θmax / (1 + cos θmax)`: exact for tiny cones where `1 − cos θmax` would
/// round to 0.
#[inline]
fn cone_one_minus_cos(r2: f32, dist2: f32) -> f32 {
    let sin2_max = (r2 / dist2).min(1.0);
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    sin2_max / (1.0 + cos_max)
}

#[cfg(test)]
mod tests;

// The light shapes of issue #25, standalone until they are wired in as `Light` variants.
mod area_emission;
pub mod distant;
pub mod environment;
pub mod escape;
pub mod infinite;
pub mod quadric;
pub mod rect;
pub mod sky;
pub mod spot;
#[cfg(test)]
mod test_support;
pub mod triangle_mesh;
