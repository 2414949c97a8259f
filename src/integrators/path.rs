//! Unidirectional path tracing (Kajiya 1986) with next-event estimation and multiple importance
//! sampling by the power heuristic (Veach & Guibas 1995; Veach's thesis ch. 9), Russian
//! roulette after a few bounces (Arvo & Kirk 1990). Iterative, no allocation per sample. The
//! reference every other integrator is checked against.

use glam::Vec3;

use super::Counters;
use super::shadow::{LightConnection, RayCone, connect_light};
use super::trace_log::{RayKind, ShadowRecord, TraceLog};
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::{Light, LightSampler, RenderScene, SurfacePoint};
use crate::sampling::Sampler;
use crate::shading::{Bsdf, ShadingFrame, TransportMode};

/// Bounces after which Russian roulette may end a path.
const ROULETTE_DEPTH: u32 = 3;

/// The path tracer over a compiled scene.
#[derive(Debug)]
pub struct PathTracer<'a> {
    scene: &'a RenderScene,
    lights: LightSampler,
    pixel_spread: f32,
}

/// The power heuristic with β = 2 for one sample from each of two strategies.
#[inline]
fn power_heuristic(pdf: f32, other: f32) -> f32 {
    let (a, b) = (pdf * pdf, other * other);
    if a + b > 0.0 && a.is_finite() {
        a / (a + b)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

impl<'a> PathTracer<'a> {
    /// Prepares the light-selection table (lights chosen in proportion to their power).
    #[must_use]
    pub fn new(scene: &'a RenderScene) -> Self {
        Self {
            scene,
            lights: LightSampler::new(&scene.lights),
            pixel_spread: scene.pixel_spread(),
        }
    }

    /// Radiance arriving along camera ray `ray`. Paths have at most `render.max_depth` bounces
    /// and at most `render.diffuse_depth` non-delta ones (0: direct light and delta chains only,
    /// Whitted's light transport); the background is an environment that escaping rays see.
    pub fn li(
        &self,
        ray: Ray,
        sampler: &mut Sampler,
        counters: &mut Counters,
        mut log: Option<&mut TraceLog>,
    ) -> Vec3 {
        let scene = self.scene;
        let params = &scene.params;
        let mut ray = ray;
        let mut cone = RayCone::camera(self.pixel_spread);
        let mut l = Vec3::ZERO;
        let mut beta = Vec3::ONE;
        // Radiance scale from refraction so far, undone for Russian roulette (pbrt's etaScale).
        let mut eta_scale = 1.0f32;
        // The last bounce was a delta lobe (or the camera): emitters hit next count fully.
        let mut specular = true;
        let mut prev_pdf = 0.0f32;
        let mut prev_p = ray.origin;
        let mut diffuse_bounces = 0u32;
        let mut kind = RayKind::Camera;
        let mut parent: Option<usize> = None;
        let mut depth = 0u32;
        // Debug logs only: each node holds the radiance gathered before it until the path ends.
        let mut root: Option<usize> = None;
        loop {
            counters.rays += 1;
            let node = log.as_deref_mut().map(|lg| {
                let id = lg.push(depth, kind, &ray, beta, parent);
                lg.nodes[id].radiance = l;
                id
            });
            root = root.or(node);
            let Some(hit) = scene.geometry.intersect(&ray) else {
                l += beta * params.background;
                break;
            };
            let sp = scene.geometry.surface(&ray, &hit);
            let object = &scene.objects[sp.object as usize];
            let wo = -ray.dir.normalize();
            let Some(m) = object.material else {
                // An emitter (seen from outside only); it absorbs what reaches it.
                let le = match object.light.map(|i| (i, scene.lights[i as usize])) {
                    Some((i, Light::Sphere { radiance, .. })) if wo.dot(sp.ng) > 0.0 => {
                        let w = if specular {
                            1.0
                        } else {
                            let light_pdf = self.lights.pmf(i as usize)
                                * scene.lights[i as usize].pdf_li(prev_p, -wo);
                            power_heuristic(prev_pdf, light_pdf)
                        };
                        radiance * w
                    }
                    _ => Vec3::ZERO,
                };
                l += beta * le;
                if let Some(lg) = log.as_deref_mut() {
                    lg.record_hit(node, scene, &hit, &sp, "light");
                }
                break;
            };
            let sh = scene.shading_point(
                &scene.materials[m as usize],
                &sp,
                wo,
                cone.width_at(&ray, hit.t),
            );
            if let Some(lg) = log.as_deref_mut() {
                let name = scene.material_names[m as usize].clone();
                lg.record_hit(node, scene, &hit, &sp, &name);
            }
            if depth >= params.max_depth {
                TraceLog::note(log.as_deref_mut(), node, "max depth reached");
                break;
            }
            let fr = ShadingFrame {
                ns: sh.ns,
                ng: sh.ng,
                entering: sh.entering,
            };
            let bsdf = sh.bsdf;
            let may_scatter = diffuse_bounces < params.diffuse_depth;
            // Next-event estimation through the non-delta part.
            let u_light = sampler.next_1d();
            let u_point = sampler.next_2d();
            if bsdf.has_local()
                && let Some((index, pmf)) = self.lights.sample(u_light)
            {
                let c = self.direct(
                    &sp,
                    wo,
                    &fr,
                    &bsdf,
                    index,
                    pmf,
                    u_point,
                    may_scatter,
                    counters,
                    log.as_deref_mut(),
                    node,
                );
                l += beta * c;
            }
            // Continue the path by sampling the BSDF.
            let u_lobe = sampler.next_1d();
            let u_dir = sampler.next_2d();
            let u_rr = sampler.next_1d();
            let Some(s) = bsdf.sample(wo, u_lobe, u_dir, &fr, TransportMode::Radiance) else {
                break;
            };
            if !s.delta {
                if !may_scatter {
                    TraceLog::note(log.as_deref_mut(), node, "diffuse depth reached");
                    break;
                }
                diffuse_bounces += 1;
            }
            beta *= s.weight;
            if s.transmitted {
                eta_scale *= s.eta_scale;
            }
            if !beta.is_finite() || beta.max_element() <= 0.0 {
                break;
            }
            depth += 1;
            if depth > ROULETTE_DEPTH {
                let q = (beta / eta_scale).max_element().min(1.0);
                if u_rr >= q {
                    TraceLog::note(log.as_deref_mut(), node, "ended by Russian roulette");
                    break;
                }
                beta /= q;
            }
            let curvature = scene.geometry.curvature(&hit);
            cone = if s.delta {
                cone.bounce(
                    &ray,
                    hit.t,
                    curvature,
                    if s.transmitted { 1.0 } else { 2.0 },
                )
            } else {
                cone.scatter(&ray, hit.t, s.pdf)
            };
            specular = s.delta;
            prev_pdf = s.pdf;
            prev_p = sp.p;
            kind = match (s.delta, s.transmitted) {
                (_, true) => RayKind::Refract,
                (true, false) => RayKind::Reflect,
                (false, false) => RayKind::Scatter,
            };
            parent = node;
            let origin = offset_ray_origin(sp.p, sp.p_error, fr.ng, s.wi);
            ray = Ray::new(origin, s.wi);
        }
        if let (Some(lg), Some(root)) = (log, root) {
            // The radiance each logged ray brought back: what the path gathered from it on,
            // divided by the path weight it carried.
            for n in &mut lg.nodes[root..] {
                let gathered = l - n.radiance;
                n.radiance =
                    Vec3::select(n.weight.cmpgt(Vec3::ZERO), gathered / n.weight, Vec3::ZERO);
            }
        }
        l
    }
}

impl PathTracer<'_> {
    /// Next-event estimation at `sp` towards light `index` (chosen with probability `pmf`):
    /// the radiance it sends through the non-delta part of the BSDF, MIS-weighted against BSDF
    /// sampling when the path may still scatter diffusely (else the light sample alone stands
    /// for direct light). Logged as a shadow record.
    #[allow(clippy::too_many_arguments)]
    fn direct(
        &self,
        sp: &SurfacePoint,
        wo: Vec3,
        fr: &ShadingFrame,
        bsdf: &Bsdf,
        index: usize,
        pmf: f32,
        u: (f32, f32),
        may_scatter: bool,
        counters: &mut Counters,
        log: Option<&mut TraceLog>,
        node: Option<usize>,
    ) -> Vec3 {
        let Some(LightConnection {
            ls,
            f,
            occluded: blocked,
        }) = connect_light(self.scene, index, sp, wo, fr, bsdf, u, counters)
        else {
            return Vec3::ZERO;
        };
        let w = if ls.delta || !may_scatter {
            1.0
        } else {
            power_heuristic(ls.pdf * pmf, bsdf.pdf(wo, ls.wi, fr))
        };
        let c = if blocked {
            Vec3::ZERO
        } else {
            f * (fr.ns.dot(ls.wi) * w / (ls.pdf * pmf)) * ls.radiance
        };
        if let (Some(lg), Some(me)) = (log, node) {
            lg.nodes[me].shadows.push(ShadowRecord {
                light: index,
                dir: ls.wi,
                occluded: blocked,
                contribution: c,
                blocker: None,
            });
        }
        c
    }
}
