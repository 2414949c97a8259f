//! The recursive ray tracer of the report: direct light with shadow rays (Phong highlight
//! included), mirror reflection and Fresnel-weighted refraction, limited by depth and weight.

use glam::Vec3;

use super::shadow::{RayCone, shadow_ray};
use super::trace_log::{RayKind, ShadowRecord, TraceHit, TraceLog};
use super::{Counters, LightPath, Radiance};
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::{Light, RenderScene, ShadingPoint, SurfacePoint};
use crate::sampling::Sampler;
use crate::shading::Bsdf;

/// The Whitted-style integrator over a compiled scene.
#[derive(Debug)]
pub struct Whitted<'a> {
    scene: &'a RenderScene,
    pixel_spread: f32,
    /// Some material transmits, so shadow rays must look for what they pass through.
    transmissive: bool,
}

/// Most transmitting surfaces a shadow ray crosses; beyond them the rest is taken as clear.
const MAX_SHADOW_CROSSINGS: u32 = 64;

/// A ray to trace and how it contributes.
struct Path {
    ray: Ray,
    depth: u32,
    weight: Vec3,
    kind: RayKind,
    cone: RayCone,
}

impl<'a> Whitted<'a> {
    /// An integrator for `scene`.
    #[must_use]
    pub fn new(scene: &'a RenderScene) -> Self {
        Self {
            scene,
            pixel_spread: scene.pixel_spread(),
            transmissive: scene.materials.iter().any(|m| m.bsdf.transmit > 0.0),
        }
    }

    /// Radiance arriving along a camera ray.
    pub fn li(
        &self,
        ray: Ray,
        rng: &mut Sampler,
        counters: &mut Counters,
        log: Option<&mut TraceLog>,
    ) -> Radiance {
        let path = Path {
            ray,
            depth: 0,
            weight: Vec3::ONE,
            kind: RayKind::Camera,
            cone: RayCone::camera(self.pixel_spread),
        };
        self.trace(path, rng, counters, log, None)
    }

    fn trace(
        &self,
        path: Path,
        rng: &mut Sampler,
        counters: &mut Counters,
        mut log: Option<&mut TraceLog>,
        parent: Option<usize>,
    ) -> Radiance {
        let me = log
            .as_deref_mut()
            .map(|l| l.push(path.depth, path.kind, &path.ray, path.weight, parent));
        let (l, hit_info) = self.shade(&path, rng, counters, log.as_deref_mut(), me);
        if let (Some(log), Some(me)) = (log, me) {
            log.nodes[me].radiance = l.total();
            log.nodes[me].hit = hit_info;
        }
        l
    }

    fn shade(
        &self,
        path: &Path,
        rng: &mut Sampler,
        counters: &mut Counters,
        mut log: Option<&mut TraceLog>,
        me: Option<usize>,
    ) -> (Radiance, Option<TraceHit>) {
        let scene = self.scene;
        counters.rays += 1;
        let ray = &path.ray;
        let Some(hit) = scene.geometry.intersect(ray) else {
            return (seen(scene.params.background), None);
        };
        let sp = scene.geometry.surface(ray, &hit);
        let object = &scene.objects[sp.object as usize];
        let wo = -ray.dir.normalize();
        let entering = wo.dot(sp.ng) > 0.0;
        let shading = object.material.map(|m| {
            let width = path.cone.width_at(ray, hit.t);
            scene.shading_point(&scene.materials[m as usize], &sp, wo, width)
        });
        let info = log.is_some().then(|| TraceHit {
            t: hit.t,
            point: sp.p,
            normal: shading.map_or(if entering { sp.ns } else { -sp.ns }, |s| s.ns),
            object: object.name.clone(),
            material: object
                .material
                .map_or("light".into(), |m| scene.material_names[m as usize].clone()),
            entering,
        });
        let Some(ShadingPoint {
            bsdf: material,
            ng,
            ns,
            entering,
        }) = shading
        else {
            // An emitter: its radiance is seen from outside only.
            let l = match object.light.map(|i| scene.lights[i as usize]) {
                Some(Light::Sphere { radiance, .. }) if entering => radiance,
                _ => Vec3::ZERO,
            };
            return (seen(l), info);
        };
        let mut l = Radiance::default();
        if material.has_local() {
            let direct = self.direct(
                &sp,
                &material,
                wo,
                ng,
                ns,
                rng,
                counters,
                log.as_deref_mut(),
                me,
            );
            l.add(LightPath::Direct, direct);
        }
        if !material.has_delta() {
            return (l, info);
        }
        if path.depth >= scene.params.max_depth {
            TraceLog::note(log, me, "max depth reached: specular rays not traced");
            return (l, info);
        }
        let lobes = material.delta_lobes(wo, ns, ng, entering);
        let min = scene.params.min_contribution;
        let curvature = scene.geometry.curvature(&hit);
        let mut spawn = |dir: Vec3, w: Vec3, kind: RayKind, log: Option<&mut TraceLog>| {
            let weight = path.weight * w;
            if weight.max_element() < min || weight.max_element() <= 0.0 {
                return;
            }
            let origin = offset_ray_origin(sp.p, sp.p_error, ng, dir);
            let child = Path {
                ray: Ray::new(origin, dir),
                depth: path.depth + 1,
                weight,
                kind,
                cone: path.cone.bounce(
                    ray,
                    hit.t,
                    curvature,
                    if kind == RayKind::Reflect { 2.0 } else { 1.0 },
                ),
            };
            let seen = self.trace(child, rng, counters, log, me);
            l.add_scaled(&seen, w);
        };
        spawn(
            lobes.reflect_dir,
            lobes.reflect_weight,
            RayKind::Reflect,
            log.as_deref_mut(),
        );
        if let Some((dir, w)) = lobes.refract {
            spawn(dir, w, RayKind::Refract, log);
        }
        (l, info)
    }

    /// Light arriving directly from every light source, through the non-delta part of the BSDF.
    #[allow(clippy::too_many_arguments)]
    fn direct(
        &self,
        sp: &SurfacePoint,
        material: &Bsdf,
        wo: Vec3,
        ng: Vec3,
        ns: Vec3,
        rng: &mut Sampler,
        counters: &mut Counters,
        mut log: Option<&mut TraceLog>,
        me: Option<usize>,
    ) -> Vec3 {
        let mut total = Vec3::ZERO;
        for (index, light) in self.scene.lights.iter().enumerate() {
            let n = match light {
                Light::Point { .. } => 1,
                Light::Sphere { .. } => self.scene.params.light_samples,
            };
            let mut sum = Vec3::ZERO;
            for _ in 0..n {
                let u = rng.next_2d();
                let Some(ls) = light.sample_li(sp.p, u) else {
                    continue;
                };
                let cos_s = ns.dot(ls.wi);
                if cos_s <= 0.0 || ng.dot(ls.wi) <= 0.0 {
                    continue;
                }
                let f = material.f(wo, ls.wi, ns);
                if f == Vec3::ZERO {
                    continue;
                }
                // Aim at the sampled light point itself, stopping just short of it.
                let shadow = shadow_ray(sp, ng, ls.point);
                let transmittance = self.transmittance(&shadow, counters);
                let occluded = transmittance == Vec3::ZERO;
                let c = f * ls.weight * cos_s * transmittance;
                sum += c;
                if let (Some(log), Some(me)) = (log.as_deref_mut(), me) {
                    let contribution = c / n as f32;
                    let blocker = occluded
                        .then(|| self.scene.geometry.intersect(&shadow))
                        .flatten()
                        .map(|h| {
                            let object = self.scene.geometry.object_of(h.prim);
                            (self.scene.objects[object as usize].name.clone(), h.t)
                        });
                    let record = ShadowRecord {
                        light: index,
                        dir: ls.wi,
                        occluded,
                        contribution,
                        blocker,
                    };
                    log.nodes[me].shadows.push(record);
                }
            }
            total += sum / n as f32;
        }
        total
    }
}

impl Whitted<'_> {
    /// How much of the light travelling along `shadow` (up to its `t_max`) arrives: 0 when an
    /// opaque surface is in the way, else the product of the straight-line transmittances of
    /// the dielectric surfaces crossed (`Bsdf::straight_transmittance`).
    fn transmittance(&self, shadow: &Ray, counters: &mut Counters) -> Vec3 {
        counters.rays += 1;
        let scene = self.scene;
        // Most shadow rays are unblocked, or blocked by something opaque: any-hit queries
        // settle them; only rays that meet nothing but transmitters walk their crossings.
        if !scene.geometry.occluded(shadow) {
            return Vec3::ONE;
        }
        if !self.transmissive
            || scene.geometry.occluded_by(shadow, |prim| {
                scene.is_opaque(scene.geometry.object_of(prim))
            })
        {
            return Vec3::ZERO;
        }
        let end = shadow.origin + shadow.dir * shadow.t_max;
        let mut ray = *shadow;
        let mut t = Vec3::ONE;
        for _ in 0..MAX_SHADOW_CROSSINGS {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                return t;
            };
            let object = scene.geometry.object_of(hit.prim);
            let material = match scene.objects[object as usize].material {
                Some(m) if !scene.is_opaque(object) => &scene.materials[m as usize],
                _ => return Vec3::ZERO,
            };
            let sp = scene.geometry.surface(&ray, &hit);
            let wo = -ray.dir.normalize();
            let s = scene.shading_point(material, &sp, wo, 0.0);
            t *= s.bsdf.straight_transmittance(s.ns.dot(wo), s.entering);
            if t.max_element() <= 0.0 {
                return Vec3::ZERO;
            }
            let origin = offset_ray_origin(sp.p, sp.p_error, -s.ng, ray.dir);
            ray = Ray {
                origin,
                dir: end - origin,
                t_max: 1.0,
            };
            counters.rays += 1;
        }
        // Still crossing surfaces after the limit: keep what has come through so far.
        t
    }
}

/// Radiance of an emitter or the background seen along a camera ray's mirror and glass chain.
fn seen(l: Vec3) -> Radiance {
    let mut r = Radiance::default();
    r.add(LightPath::Specular, l);
    r
}
