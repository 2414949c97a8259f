//! The recursive ray tracer of the report: direct light with shadow rays (Phong highlight
//! included), mirror reflection and Fresnel-weighted refraction, limited by depth and weight.
//!
//! Beer–Lambert absorption ([`Medium`], the same rule as the path tracer's): every ray carries
//! the medium it travels in, entered or left where it refracts or reflects at a surface whose
//! material absorbs; the radiance it brings back is scaled by `exp(−σ t)` over its length.
//! Shadow rays, which cross dielectrics in a straight line, start in the medium the shaded
//! point's side is in and are attenuated over each stretch inside a medium too.

use glam::Vec3;

use super::context::{Context, PathObserver};
use super::shadow::{RayCone, shadow_ray};
use super::trace_log::{RayKind, ShadowRecord, TraceHit};
use super::{Counters, LightPath, Radiance};
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::{Interaction, Medium, RenderScene, SurfaceHit};
use crate::shading::{LobeFlags, ShadingFrame};

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
    /// The absorbing medium the ray travels in.
    medium: Medium,
}

impl<'a> Whitted<'a> {
    /// An integrator for `scene`.
    #[must_use]
    pub fn new(scene: &'a RenderScene) -> Self {
        Self {
            scene,
            pixel_spread: scene.pixel_spread(),
            transmissive: scene
                .materials
                .iter()
                .any(|m| m.bsdf.flags().contains(LobeFlags::TRANSMISSION)),
        }
    }

    /// Radiance arriving along a camera ray.
    pub fn li<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
        let path = Path {
            ray,
            depth: 0,
            weight: Vec3::ONE,
            kind: RayKind::Camera,
            cone: RayCone::camera(self.pixel_spread),
            medium: Medium::OUTSIDE,
        };
        self.trace(path, cx, None)
    }

    fn trace<O: PathObserver>(
        &self,
        path: Path,
        cx: &mut Context<'_, O>,
        parent: Option<usize>,
    ) -> Radiance {
        let me = cx
            .observer
            .ray(path.depth, path.kind, &path.ray, path.weight, parent);
        let (l, hit_info) = self.shade(&path, cx, me);
        if O::ACTIVE {
            cx.observer.set_radiance(me, l.total());
            if let Some(h) = hit_info {
                cx.observer.set_hit(me, h);
            }
        }
        l
    }

    fn shade<O: PathObserver>(
        &self,
        path: &Path,
        cx: &mut Context<'_, O>,
        me: Option<usize>,
    ) -> (Radiance, Option<TraceHit>) {
        let scene = self.scene;
        cx.counters.rays += 1;
        let ray = &path.ray;
        let mut textured = None;
        let it = scene.interact(ray, |t| path.cone.width_at(ray, t), &mut textured);
        // Beer–Lambert absorption along this ray (exactly 1 outside media).
        let tr = path.medium.transmittance(ray, &it);
        let v = match it {
            // Leaving the scene: the background and the lights at infinity the ray sees.
            Interaction::Escaped => {
                let mut le = scene.params.background;
                for (_, e) in scene.lights_escaped(ray) {
                    le += e.le;
                }
                let info = scene
                    .escape_record(ray)
                    .filter(|_| O::ACTIVE)
                    .map(|e| TraceHit {
                        t: e.hit.t,
                        point: e.sp.p,
                        normal: e.sp.ns,
                        object: scene.objects[e.sp.object as usize].name.clone(),
                        material: "light".into(),
                        entering: true,
                    });
                return (seen(le * tr), info);
            }
            Interaction::Emitter(e) => {
                let entering = e.wo.dot(e.sp.ng) > 0.0;
                let info = O::ACTIVE.then(|| TraceHit {
                    t: e.hit.t,
                    point: e.sp.p,
                    normal: if entering { e.sp.ns } else { -e.sp.ns },
                    object: scene.objects[e.sp.object as usize].name.clone(),
                    material: "light".into(),
                    entering,
                });
                // An emitter: its radiance is seen from outside only.
                return (seen(e.le(scene) * tr), info);
            }
            Interaction::Surface(v) => v,
        };
        let (hit, sp, wo) = (v.hit, v.sp, v.wo);
        let ShadingFrame { ns, ng, entering } = v.frame;
        let material = v.bsdf;
        let info = O::ACTIVE.then(|| TraceHit {
            t: hit.t,
            point: sp.p,
            normal: ns,
            object: scene.objects[sp.object as usize].name.clone(),
            material: scene.material_names[v.material as usize].clone(),
            entering: wo.dot(sp.ng) > 0.0,
        });
        let mut l = Radiance::default();
        if material.has_local() {
            let direct = self.direct(&v, path.medium, cx, me);
            l.add(LightPath::Direct, direct);
        }
        if !material.has_delta() {
            return (l.scaled(tr), info);
        }
        if path.depth >= scene.params.max_depth {
            cx.observer
                .note(me, "max depth reached: specular rays not traced");
            return (l.scaled(tr), info);
        }
        let lobes = material.delta_lobes(wo, ns, ng, entering);
        let min = scene.params.min_contribution;
        let curvature = scene.geometry.curvature(&hit);
        let mut spawn = |dir: Vec3, w: Vec3, kind: RayKind, cx: &mut Context<'_, O>| {
            let weight = path.weight * tr * w;
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
                medium: path.medium.after(scene, &v, dir),
            };
            let seen = self.trace(child, cx, me);
            l.add_scaled(&seen, w);
        };
        spawn(
            lobes.reflect_dir,
            lobes.reflect_weight,
            RayKind::Reflect,
            cx,
        );
        if let Some((dir, w)) = lobes.refract {
            spawn(dir, w, RayKind::Refract, cx);
        }
        (l.scaled(tr), info)
    }

    /// Light arriving directly from every light source at the hit `v`, through the non-delta
    /// part of its BSDF; `medium` is the one the ray that found `v` travelled in (a shadow ray
    /// starts in it, or in `v`'s own medium when it leaves into an absorbing object).
    fn direct<O: PathObserver>(
        &self,
        v: &SurfaceHit,
        medium: Medium,
        cx: &mut Context<'_, O>,
        me: Option<usize>,
    ) -> Vec3 {
        let (sp, material, wo) = (&v.sp, v.bsdf, v.wo);
        let ShadingFrame { ns, ng, .. } = v.frame;
        let mut total = Vec3::ZERO;
        for (index, light) in self.scene.lights.iter().enumerate() {
            let n = light.shadow_samples(self.scene.params.light_samples);
            let mut sum = Vec3::ZERO;
            for _ in 0..n {
                let u = cx.sampler.next_2d();
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
                let start = medium.after(self.scene, v, ls.wi);
                let transmittance = self.transmittance(&shadow, start, cx.counters);
                let occluded = transmittance == Vec3::ZERO;
                let c = f * ls.weight * cos_s * transmittance;
                sum += c;
                if O::ACTIVE {
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
                    cx.observer.shadow(me, record);
                }
            }
            total += sum / n as f32;
        }
        total
    }
}

impl Whitted<'_> {
    /// [`shadow_transmittance`] in this integrator's scene.
    fn transmittance(&self, shadow: &Ray, start: Medium, counters: &mut Counters) -> Vec3 {
        shadow_transmittance(self.scene, self.transmissive, shadow, start, counters)
    }
}

/// How much of the light travelling along `shadow` (up to its `t_max`) arrives: 0 when an
/// opaque surface is in the way, else the product of the straight-line transmittances of
/// the dielectric surfaces crossed (`Bsdf::straight_transmittance`) and of Beer–Lambert's
/// `exp(−σ t)` over each stretch inside an absorbing medium, the first in `start`.
/// `transmissive` false says no material of `scene` transmits (then any hit blocks). Whitted's
/// shadow rays, and the path tracer's where its diffuse depth ends (`diffuse_depth`: there it
/// computes Whitted's transport).
pub(super) fn shadow_transmittance(
    scene: &RenderScene,
    transmissive: bool,
    shadow: &Ray,
    start: Medium,
    counters: &mut Counters,
) -> Vec3 {
    counters.rays += 1;
    // Most shadow rays are unblocked, or blocked by something opaque: any-hit queries
    // settle them; only rays that meet nothing but transmitters walk their crossings.
    if !scene.geometry.occluded(shadow) {
        return start.transmittance_over(shadow.dir.length() * shadow.t_max);
    }
    if !transmissive
        || scene.geometry.occluded_by(shadow, |prim| {
            scene.is_opaque(scene.geometry.object_of(prim))
        })
    {
        return Vec3::ZERO;
    }
    let end = shadow.origin + shadow.dir * shadow.t_max;
    let mut ray = *shadow;
    let mut t = Vec3::ONE;
    let mut medium = start;
    for _ in 0..MAX_SHADOW_CROSSINGS {
        let mut textured = None;
        let v = match scene.interact(&ray, |_| 0.0, &mut textured) {
            // Nothing more before the light: the last stretch, in the current medium.
            Interaction::Escaped => {
                return t * medium.transmittance_over(ray.dir.length() * ray.t_max);
            }
            Interaction::Surface(v) if !scene.is_opaque(v.sp.object) => v,
            Interaction::Surface(_) | Interaction::Emitter(_) => return Vec3::ZERO,
        };
        t *= medium.transmittance_over(v.hit.t * ray.dir.length());
        t *= v
            .bsdf
            .straight_transmittance(v.frame.ns.dot(v.wo), v.frame.entering);
        medium = medium.after(scene, &v, ray.dir);
        if t.max_element() <= 0.0 {
            return Vec3::ZERO;
        }
        let origin = offset_ray_origin(v.sp.p, v.sp.p_error, -v.frame.ng, ray.dir);
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

/// Radiance of an emitter or the background seen along a camera ray's mirror and glass chain.
fn seen(l: Vec3) -> Radiance {
    let mut r = Radiance::default();
    r.add(LightPath::Specular, l);
    r
}

impl<'a> super::Estimator<'a> for Whitted<'a> {
    fn li_parts<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
        self.li(ray, cx)
    }
}
