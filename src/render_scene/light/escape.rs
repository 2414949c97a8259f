//! Rays that escape the scene and meet an environment light: the escape is resolved as a hit
//! on the environment, an emitter at infinity, so that every integrator sees the environment
//! (directly, through mirrors and glass, and as the MIS partner of its light samples) through
//! [`Interaction::Emitter`] and [`Light`]'s methods, with no case of its own.

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
