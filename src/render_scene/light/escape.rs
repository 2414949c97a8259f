//! Rays that escape the scene and meet an environment light: the escape is resolved as a hit
//! on the environment, an emitter at infinity, so that every integrator sees the environment
//! (directly, through mirrors and glass, and as the MIS partner of its light samples) through
//! [`Interaction::Emitter`] and [`Light`]'s methods, with no case of its own.
//!
//! A distant light with an angular radius (the sun's disc) is also seen by escaping rays, in
//! addition to the environment: [`RenderScene::suns_seen`] lists those whose disc an escaping
//! ray points into. Without it a path tracer never finds light that reaches a diffuse surface
//! from the sun through a mirror, glass or water (sun → specular → diffuse: the caustics under
//! the bath's water, the sun's reflections off glazes and mirrors), which the photon maps carry.

use super::Light;
use crate::geometry::Ray;
use crate::render_scene::geometry::{Hit, PrimKind, PrimRef};
use crate::render_scene::{EmitterHit, Interaction, RenderScene, SurfacePoint};

/// Where a scene's environment light is: its index in `RenderScene::lights` and the object
/// (without primitives) that names it in diagnostics and `debug-pixel`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EnvironmentRef {
    /// Index of the [`Light::Environment`] in `RenderScene::lights`.
    pub light: u32,
    /// Index of its object in `RenderScene::objects`.
    pub object: u32,
}

impl RenderScene {
    /// What a ray that met no primitive finds: [`Interaction::Escaped`] (the background),
    /// or — when the scene has an environment light and the ray is unbounded (`t_max` infinite;
    /// a shadow ray's segment never reaches infinity) — an [`EmitterHit`] on the environment, at
    /// a point beyond the scene's bounding sphere along the ray, with the normal facing the
    /// ray (so [`Light::le`] reads the map in the ray's direction).
    #[inline]
    #[must_use]
    pub fn escape(&self, ray: &Ray) -> Interaction<'_> {
        let Some(env) = self.environment else {
            return Interaction::Escaped;
        };
        if ray.t_max != f32::INFINITY {
            return Interaction::Escaped;
        }
        let Light::Environment(e) = &self.lights[env.light as usize] else {
            return Interaction::Escaped;
        };
        let len = ray.dir.length();
        let wo = -ray.dir / len;
        let far = e.scene.far_distance(ray.origin);
        let p = ray.origin - wo * far;
        Interaction::Emitter(EmitterHit {
            hit: Hit {
                t: far / len,
                prim: PrimRef::new(PrimKind::Triangle, 0),
                b1: 0.0,
                b2: 0.0,
            },
            sp: SurfacePoint::at_infinity(p, wo, env.object),
            wo,
            light: Some(env.light),
        })
    }
}

impl RenderScene {
    /// The distant lights with an angular radius (suns) that a ray leaving the scene along
    /// `ray` sees: each one's index in `lights` and the radiance it sends back along the ray
    /// (its disc's radiance when the direction lies in its cone). Nothing for a ray that ends
    /// (`t_max` finite: a shadow ray) or a direction outside every disc. Integrators add these
    /// to what [`RenderScene::escape`] resolves (the background or the environment), with the
    /// MIS weight of [`Light::pdf_li`] against their light samples.
    #[inline]
    pub fn suns_seen<'s>(&'s self, ray: &Ray) -> impl Iterator<Item = (usize, glam::Vec3)> + 's {
        let dir = if ray.t_max == f32::INFINITY {
            ray.dir.try_normalize()
        } else {
            None
        };
        self.lights
            .iter()
            .enumerate()
            .filter_map(move |(i, l)| match (l, dir) {
                (Light::Distant(d), Some(w)) => {
                    let le = d.le(w);
                    (le != glam::Vec3::ZERO).then_some((i, le))
                }
                _ => None,
            })
    }
}
