//! The path-vertex step every integrator and photon path takes, written once: intersect a ray,
//! expand the hit into a surface point, and resolve what is there — nothing (the ray escaped),
//! an emitter, or a surface with its BSDF and shading frame (the role of pbrt-v4's
//! `SurfaceInteraction::GetBSDF` and Tungsten's `TraceBase`, our own code).

use glam::Vec3;

use super::{Hit, RenderScene, SurfacePoint};
use crate::geometry::Ray;
use crate::shading::{Bsdf, ShadingFrame};

/// What a ray found ([`RenderScene::interact`]); it borrows the scene's materials.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(
    clippy::large_enum_variant,
    reason = "one per path vertex, on the stack and matched at once: never stored in arrays, so boxing would only add an allocation per hit"
)]
pub enum Interaction<'s> {
    /// The ray left the scene: it sees the background and, if it is unbounded, the lights at
    /// infinity ([`RenderScene::lights_escaped`]).
    Escaped,
    /// The ray hit an emitter's surface (an object without a material: it absorbs what reaches
    /// it and emits [`EmitterHit::le`]).
    Emitter(EmitterHit),
    /// The ray hit a surface with a material.
    Surface(SurfaceHit<'s>),
}

/// A ray's hit on an emitter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitterHit {
    /// The hit (distance, primitive).
    pub hit: Hit,
    /// The surface point.
    pub sp: SurfacePoint,
    /// Unit direction back along the ray (from the surface towards the ray's origin).
    pub wo: Vec3,
    /// The light this surface emits as (`RenderScene::lights` index), if any.
    pub light: Option<u32>,
}

/// A ray's hit on a surface with a material, resolved for shading. It borrows the material's
/// BSDF, or the textured BSDF from the caller's slot where a texture changes it
/// ([`RenderScene::interact`]), so a path vertex copies no BSDF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit<'s> {
    /// The hit (distance, primitive).
    pub hit: Hit,
    /// The surface point.
    pub sp: SurfacePoint,
    /// Unit direction back along the ray (from the surface towards the ray's origin).
    pub wo: Vec3,
    /// Material index (`RenderScene::materials`, `material_names`).
    pub material: u32,
    /// The BSDF with textures applied.
    pub bsdf: &'s Bsdf,
    /// The shading frame on the side of `wo` (bumped, usable shading normal; geometric normal;
    /// which side `wo` is on).
    pub frame: ShadingFrame,
}

impl EmitterHit {
    /// Radiance the emitter sends back along the ray (W·m⁻²·sr⁻¹ per channel), through the
    /// light's own interface ([`super::Light::le`]): zero on the side it does not emit from and
    /// for an emitter surface that carries no light.
    #[inline]
    #[must_use]
    pub fn le(&self, scene: &RenderScene) -> Vec3 {
        self.light.map_or(Vec3::ZERO, |i| {
            scene.lights[i as usize].le(self.sp.ng, self.wo)
        })
    }
}

impl RenderScene {
    /// Traces `ray` to its first hit and resolves it: [`Interaction::Escaped`], an emitter, or a
    /// surface shaded by [`RenderScene::shade`] with the texture footprint
    /// `footprint(t)` world units wide at hit distance `t` (in `ray`'s parameter units; a ray
    /// cone's width there, or 0 for the sharpest lookup). This is the one vertex step of every
    /// integrator and of photon tracing.
    ///
    /// The surface's BSDF is borrowed from its material; where a colour or roughness texture
    /// changes it, the textured BSDF is written to `textured` and borrowed from there (the
    /// caller's storage, usually a `None` local of the loop body: the common untextured hit
    /// copies no BSDF).
    #[inline]
    #[must_use]
    pub fn interact<'s>(
        &'s self,
        ray: &Ray,
        footprint: impl FnOnce(f32) -> f32,
        textured: &'s mut Option<Bsdf>,
    ) -> Interaction<'s> {
        let Some(hit) = self.geometry.intersect(ray) else {
            return Interaction::Escaped;
        };
        let sp = self.geometry.surface(ray, &hit);
        let object = &self.objects[sp.object as usize];
        let wo = -ray.dir.normalize();
        match object.material {
            None => Interaction::Emitter(EmitterHit {
                hit,
                sp,
                wo,
                light: object.light,
            }),
            Some(m) => {
                let material = &self.materials[m as usize];
                let sh = self.shade(material, &sp, wo, footprint(hit.t), textured);
                Interaction::Surface(SurfaceHit {
                    hit,
                    sp,
                    wo,
                    material: m,
                    bsdf: sh.bsdf,
                    frame: ShadingFrame {
                        ns: sh.ns,
                        ng: sh.ng,
                        entering: sh.entering,
                    },
                })
            }
        }
    }
}
