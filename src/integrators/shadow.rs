//! Shadow rays from a shaded point towards a sampled light point, shared by every integrator.

use glam::Vec3;

use super::Counters;
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::{LightSample, RenderScene, SurfacePoint};
use crate::shading::{BsdfAt, TransportMode};

/// Fraction of a shadow ray's length left unchecked at the light end (so the light's own
/// surface never occludes the point sampled on it).
pub const SHADOW_EPSILON: f32 = 1e-4;

/// The shadow ray from surface point `sp` towards `target` (a point on a light), leaving on the
/// side of `ng` (the geometric normal on the side the light is on). Rays leaving a smooth mesh
/// outward start from the smooth surface its vertex normals describe (`SurfacePoint::p_outside`,
/// against the shadow terminator), offset by the point's own error bound (pbrt's
/// `OffsetRayOrigin`). The ray's `dir` is the unnormalised segment and `t_max` stops just short
/// of `target`.
#[inline]
#[must_use]
pub fn shadow_ray(sp: &SurfacePoint, ng: Vec3, target: Vec3) -> Ray {
    let start = if ng.dot(sp.ng) > 0.0 {
        sp.p_outside
    } else {
        sp.p
    };
    let origin = offset_ray_origin(start, sp.p_error, ng, target - start);
    Ray {
        origin,
        dir: target - origin,
        t_max: 1.0 - SHADOW_EPSILON,
    }
}

/// A light sample connected to a shaded point by next-event estimation: the sample, the BSDF
/// value towards it, and whether its shadow ray was blocked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightConnection {
    /// The incident-light sample (direction, radiance, solid-angle pdf).
    pub ls: LightSample,
    /// The non-delta BSDF value `f(wo, wi)` in radiance mode (non-zero).
    pub f: Vec3,
    /// True when the shadow ray hit something before the light.
    pub occluded: bool,
}

/// Next-event estimation's shared step, for every integrator: samples light `light` of the
/// scene from surface point `sp` with `u`, evaluates the BSDF prepared at the point (`at`: its
/// frame and outgoing direction) towards it and, when that is non-zero, traces the shadow ray (counted in `counters`). `None` when the
/// light gives no sample or the BSDF is zero there (no ray is traced). The estimate itself
/// (`f · L · cos θ / pdf`, with or without an MIS weight) is the caller's.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn connect_light(
    scene: &RenderScene,
    light: usize,
    sp: &SurfacePoint,
    at: &BsdfAt<'_>,
    u: (f32, f32),
    counters: &mut Counters,
) -> Option<LightConnection> {
    let ls = scene.lights[light].sample_li(sp.p, u)?;
    let f = at.eval(ls.wi, TransportMode::Radiance);
    let fr = at.frame();
    if f == Vec3::ZERO || !(ls.pdf > 0.0) {
        return None;
    }
    counters.rays += 1;
    // The light's own surface is skipped: the sampled point is where the segment first meets
    // it (the near side of a sphere light), so it cannot block the segment, and the test would
    // cost a full quadric intersection on every shadow ray.
    // (A mesh light that is not convex can hide its sample behind itself: its own triangles
    // are tested, `Light::can_shadow_itself`.)
    let own = Some(light as u32);
    let self_shadowing = scene.lights[light].can_shadow_itself();
    let occluded = scene
        .geometry
        .occluded_by(&shadow_ray(sp, fr.ng, ls.point), |prim| {
            self_shadowing || scene.objects[scene.geometry.object_of(prim) as usize].light != own
        });
    Some(LightConnection { ls, f, occluded })
}

/// The pixel footprint carried along a path as a cone (Akenine-Möller et al., "Texture Level of
/// Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems ch. 20): its width at the
/// ray's origin and how fast it grows per unit distance (radians). Sizes texture filters at
/// every hit, including those seen in mirrors, through glass and after diffuse bounces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayCone {
    /// Width (world units) at the ray's origin.
    pub width: f32,
    /// Growth of the width per unit distance along the ray.
    pub spread: f32,
}

impl RayCone {
    /// The cone of a camera ray: zero width, `spread` radians.
    #[must_use]
    pub fn camera(spread: f32) -> Self {
        Self { width: 0.0, spread }
    }

    /// The cone's width where `ray` reaches parameter `t`.
    #[inline]
    #[must_use]
    pub fn width_at(self, ray: &Ray, t: f32) -> f32 {
        self.width + self.spread * t * ray.dir.length()
    }

    /// The cone leaving a hit at `t` (in ray-parameter units of `ray`) after a specular event at
    /// a surface of curvature `curvature`, bending rays by `bend` times the curvature (2 for a
    /// mirror, about |1 − 1/η| for refraction; taken as 1, conservatively).
    #[inline]
    #[must_use]
    pub fn bounce(self, ray: &Ray, t: f32, curvature: f32, bend: f32) -> Self {
        let width = self.width_at(ray, t);
        Self {
            width,
            spread: self.spread + bend * curvature * width,
        }
    }

    /// The cone leaving a hit at `t` after a non-delta bounce sampled with solid-angle density
    /// `pdf`: one sample stands for a solid angle of about 1/pdf, a cone of full angle
    /// 2·√(1/(π·pdf)), so textures seen after diffuse bounces are read at the scale a sample
    /// resolves.
    #[inline]
    #[must_use]
    pub fn scatter(self, ray: &Ray, t: f32, pdf: f32) -> Self {
        let width = self.width_at(ray, t);
        let angle = 2.0 * (1.0 / (std::f32::consts::PI * pdf.max(1e-4))).sqrt();
        Self {
            width,
            spread: self.spread.max(angle.min(std::f32::consts::PI)),
        }
    }
}
