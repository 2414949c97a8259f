//! Rays that escape the scene and meet the lights at infinity (pbrt-v4's `infiniteLights`,
//! Tungsten's `intersectInfinites`): an unbounded ray that meets no primitive loops over
//! [`RenderScene::infinite_lights`] and asks each light, through [`Light::le_escaped`](super::Light::le_escaped), what it
//! sends back along the ray — an environment or sky map in every direction, a sun only inside
//! its disc. Integrators weight each term against the light's own samples with
//! [`Light::pdf_li`](super::Light::pdf_li) at the direction [`Escape::wi`] names, as they weight an emitter hit; no
//! integrator names a kind of light at infinity.
//!
//! Without the suns in this loop a path tracer would never find light that reaches a diffuse
//! surface from the sun through a mirror, glass or water (sun → specular → diffuse: the caustics
//! under the bath's water, the sun's reflections off glazes and mirrors), which the photon maps
//! carry.

use glam::Vec3;

use crate::geometry::Ray;
use crate::render_scene::geometry::{Hit, PrimKind, PrimRef};
use crate::render_scene::{EmitterHit, RenderScene, SurfacePoint};

/// The light at infinity that ray trees (`debug-pixel`) record escaping rays against: its index
/// in `RenderScene::lights` and the object (without primitives) that names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InfinityRef {
    /// Index of the light in `RenderScene::lights`.
    pub light: u32,
    /// Index of its object in `RenderScene::objects`.
    pub object: u32,
}

/// What one light at infinity sends back along an escaping ray ([`Light::le_escaped`](super::Light::le_escaped)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Escape {
    /// Radiance arriving along the ray (W·m⁻²·sr⁻¹ per channel), not zero.
    pub le: Vec3,
    /// The unit direction (towards the light) at which [`Light::pdf_li`](super::Light::pdf_li) gives the density of
    /// this direction for the MIS weight.
    pub wi: Vec3,
}

impl RenderScene {
    /// The lights at infinity that the ray escaping the scene along `ray` sees: each one's index
    /// in `lights` and what it sends back ([`Light::le_escaped`](super::Light::le_escaped)), in the order of
    /// [`RenderScene::infinite_lights`]. Nothing for a ray that ends (`t_max` finite: a shadow
    /// ray). Integrators add these to the background, each with the MIS weight of
    /// [`Light::pdf_li`](super::Light::pdf_li) at [`Escape::wi`] against the light's own samples.
    #[inline]
    pub fn lights_escaped<'s>(&'s self, ray: &Ray) -> impl Iterator<Item = (usize, Escape)> + 's {
        let unbounded = ray.t_max == f32::INFINITY;
        let dir = ray.dir;
        let lights: &[u32] = if unbounded {
            &self.infinite_lights
        } else {
            &[]
        };
        lights.iter().filter_map(move |&i| {
            let i = i as usize;
            self.lights[i].le_escaped(dir).map(|e| (i, e))
        })
    }

    /// The point at infinity where an unbounded `ray` that escaped the scene is recorded in ray
    /// trees: beyond the scene's bounding sphere along the ray, with the normal facing the ray
    /// and the object of [`RenderScene::infinity`]. `None` for a bounded ray or a scene without a
    /// light that fills the sky.
    #[must_use]
    pub fn escape_record(&self, ray: &Ray) -> Option<EmitterHit> {
        let at = self.infinity?;
        if ray.t_max != f32::INFINITY {
            return None;
        }
        let scene = self.lights[at.light as usize].scene_sphere()?;
        let len = ray.dir.length();
        let wo = -ray.dir / len;
        let far = scene.far_distance(ray.origin);
        let p = ray.origin - wo * far;
        Some(EmitterHit {
            hit: Hit {
                t: far / len,
                prim: PrimRef::new(PrimKind::Triangle, 0),
                b1: 0.0,
                b2: 0.0,
            },
            sp: SurfacePoint::at_infinity(p, wo, at.object),
            wo,
            light: Some(at.light),
        })
    }
}
