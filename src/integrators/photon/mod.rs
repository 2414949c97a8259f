//! Photon mapping (Jensen, "Realistic Image Synthesis Using Photon Mapping", 2001): the report's
//! two passes, done with the one material model.
//!
//! Pass 1 ([`maps::build_maps`], once per render): photons leave the lights in proportion to
//! their power and are traced in importance mode; a caustic map holds light → specular⁺ →
//! diffuse landings of photons aimed at the specular objects, a global map every diffuse
//! landing after `min_bounces` diffuse bounces.
//!
//! Pass 2 ([`PhotonMapper::li`]): camera paths follow mirror and glass chains; at each vertex
//! with a diffuse part, the radiance is split without overlap into
//! - direct light, by a shadow ray to a light chosen by power (as the path tracer's next-event
//!   estimation, without MIS: emitters hit after a diffuse bounce are never counted);
//! - caustics (light → specular⁺ → here), from the caustic map;
//! - the rest of the indirect light (≥ 1 diffuse bounce before here), from the global map read
//!   directly, or by final gathering: rays sampled from the BSDF, whose landing points report
//!   their direct light, caustics and global-map radiance.

pub mod aim;
pub mod cache;
pub mod discs;
pub mod emit;
pub mod estimate;
pub mod maps;
pub mod passes;
pub mod potential_walls;
pub mod radius_field;
pub mod trace;
pub mod volume;
pub mod wall_grid;
pub mod wall_list;
pub mod walls;

pub use estimate::{Estimate, IrradianceCache, Kernel, PhotonMap};
pub use maps::{MapSet, PhotonMaps, PhotonSummary, build_maps};
pub use passes::{PassTotals, ProgressivePhotons, RadiusSchedule};
pub use volume::{BeamEstimate, VolumeMap, VolumePhoton};

use glam::Vec3;

use super::context::{Context, PathObserver};
use super::light_guide::LightGuide;
use super::shadow::{RayCone, connect_light};
use super::trace_log::RayKind;
use super::{Counters, LightPath, Radiance};
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::{Interaction, Medium, RenderScene, SurfaceHit, SurfacePoint};
use crate::sampling::Sampler;
use crate::shading::{Bsdf, ShadingFrame, TransportMode};
use walls::Walls;

/// Bounces after which Russian roulette may end a camera path's specular chain.
const ROULETTE_DEPTH: u32 = 3;

/// Delta bounces at which a camera path follows both Fresnel reflection and refraction (at
/// purely specular surfaces: glass, water, chrome; a glazed diffuse surface samples its mirror
/// part instead of paying a second diffuse estimate for a few per cent of the light).
const SPLIT_DEPTH: u32 = 2;

/// Final gathering is done only at vertices whose path weight is at least this; dimmer ones
/// (seen in a faint reflection) read the precomputed irradiance instead.
const FINAL_GATHER_MIN_WEIGHT: f32 = 0.25;

/// Pending branches of one camera sample (a split adds one; deeper chains sample one lobe).
const STACK: usize = 8;

/// A camera-path branch waiting to be traced.
#[derive(Debug, Clone, Copy)]
struct Branch {
    ray: Ray,
    beta: Vec3,
    eta_scale: f32,
    depth: u32,
    cone: RayCone,
    kind: RayKind,
    parent: Option<usize>,
    /// The absorbing medium the branch's ray travels in.
    medium: Medium,
}

impl Default for Branch {
    fn default() -> Self {
        Self {
            ray: Ray::new(Vec3::ZERO, Vec3::Z),
            beta: Vec3::ZERO,
            eta_scale: 1.0,
            depth: 0,
            cone: RayCone::camera(0.0),
            kind: RayKind::Camera,
            parent: None,
            medium: Medium::OUTSIDE,
        }
    }
}

/// Most mirror or glass bounces a final-gather ray follows before reading the maps.
const GATHER_SPECULAR_DEPTH: u32 = 4;

/// A final-gather ray shorter than this many times the radius of the estimate where it lands
/// is "short": its end is so near the gathering point that the estimate's disc there reaches
/// past the corner between them, where the other surface's photons are rejected and the disc
/// is partly empty (−5 % 1 cm from a wall; issue 29, corner-final-gather). A short ray does
/// not read that estimate: it gathers one more diffuse bounce instead (Jensen 2001, §9.3's
/// path-traced step for short gather rays), whose own landing is usually far. `path-ppm`'s
/// final gathering from its global map follows the same rule.
pub const SHORT_GATHER: f32 = 2.0;

/// Most short-ray bounces one final-gather ray takes (deep in a corner, each may land near the
/// corner again); after them the estimate is read as it is.
pub const SHORT_GATHER_BOUNCES: u32 = 3;

/// The photon-mapping integrator: the maps, built once, and the camera-side estimator.
#[derive(Debug)]
pub struct PhotonMapper<'a> {
    scene: &'a RenderScene,
    /// Next-event estimation's light choice, the path tracer's ([`LightGuide`]).
    lights: LightGuide,
    pixel_spread: f32,
    /// Final-gather rays per camera hit (0: read the global map directly).
    final_gather: u32,
    maps: PhotonMaps,
}

impl<'a> PhotonMapper<'a> {
    /// Traces the photons and builds the maps (`scene.params.photons`), or reads them from the
    /// photon-map cache folder `cache` ([`cache::build_or_load`]). A raised `cancel` (the
    /// render's Ctrl-C flag) stops the build soon: the maps are then empty and
    /// [`PhotonSummary::cancelled`], and the render must not go on.
    #[must_use]
    pub fn new(
        scene: &'a RenderScene,
        cache: Option<&std::path::Path>,
        cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    ) -> Self {
        Self {
            scene,
            lights: LightGuide::learn(scene),
            pixel_spread: scene.pixel_spread(),
            final_gather: scene.params.photons.final_gather,
            maps: cache::build_or_load(scene, cache, cancel),
        }
    }

    /// The maps and how they were built.
    #[must_use]
    pub fn maps(&self) -> &PhotonMaps {
        &self.maps
    }

    /// Radiance arriving along camera ray `ray` (module docs for the split). Mirror and glass
    /// chains are split into both branches for the first two delta bounces (as
    /// Whitted does: no noise from choosing between Fresnel reflection and refraction) and
    /// followed by sampling one delta lobe after that.
    pub fn li<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
        self.li_from(&self.maps, ray, cx)
    }

    /// [`PhotonMapper::li`] reading `maps` instead of the integrator's own.
    pub fn li_from<O: PathObserver>(
        &self,
        maps: &PhotonMaps,
        ray: Ray,
        cx: &mut Context<'_, O>,
    ) -> Radiance {
        let scene = self.scene;
        let params = &scene.params;
        let mut l = Radiance::default();
        let mut stack = [Branch::default(); STACK];
        stack[0] = Branch {
            ray,
            beta: Vec3::ONE,
            eta_scale: 1.0,
            depth: 0,
            cone: RayCone::camera(self.pixel_spread),
            kind: RayKind::Camera,
            parent: None,
            medium: Medium::OUTSIDE,
        };
        let mut len = 1;
        let root = cx.observer.next_node();
        while len > 0 {
            len -= 1;
            let b = stack[len];
            let (ray, beta, depth) = (b.ray, b.beta, b.depth);
            cx.counters.rays += 1;
            let node = cx.observer.ray(depth, b.kind, &ray, beta, b.parent);
            let mut gathered = Vec3::ZERO;
            let mut textured = None;
            let it = scene.interact(&ray, |t| b.cone.width_at(&ray, t), &mut textured);
            // Beer–Lambert absorption along the segment just travelled (1 outside media).
            let beta = beta * b.medium.transmittance(&ray, &it);
            let v = match it {
                Interaction::Escaped => {
                    // Leaving the scene along a specular chain (or directly): the background and
                    // the lights at infinity the ray sees.
                    gathered = beta * params.background;
                    for (_, e) in scene.lights_escaped(&ray) {
                        gathered += beta * e.le;
                    }
                    l.add(LightPath::Specular, gathered);
                    if let Some(e) = scene.escape_record(&ray) {
                        cx.observer.hit(node, scene, &e.hit, &e.sp, "light");
                    }
                    cx.observer.set_radiance(node, gathered);
                    continue;
                }
                Interaction::Emitter(e) => {
                    // Reached along a specular chain (or directly): the emitter is seen.
                    if e.light.is_some() {
                        gathered = beta * e.le(scene);
                        l.add(LightPath::Specular, gathered);
                    }
                    cx.observer.hit(node, scene, &e.hit, &e.sp, "light");
                    cx.observer.set_radiance(node, gathered);
                    continue;
                }
                Interaction::Surface(v) => v,
            };
            let (hit, sp, wo) = (v.hit, v.sp, v.wo);
            let name = &scene.material_names[v.material as usize];
            cx.observer.hit(node, scene, &hit, &sp, name);
            if depth >= params.max_depth {
                cx.observer.note(node, "max depth reached");
                continue;
            }
            let (bsdf, fr) = (v.bsdf, v.frame);
            if bsdf.has_local() {
                let full = beta.max_element() >= FINAL_GATHER_MIN_WEIGHT;
                let (c, note) =
                    self.local(maps, &v, b.medium, full, cx.sampler, cx.counters, O::ACTIVE);
                gathered = beta * c.total();
                l.add_scaled(&c, beta);
                if let Some(text) = note {
                    cx.observer.note(node, &text);
                }
            }
            cx.observer.set_radiance(node, gathered);
            if !bsdf.has_delta() {
                continue;
            }
            let curvature = scene.geometry.curvature(&hit);
            let mut push = |dir: Vec3, weight: Vec3, transmitted: bool, eta_scale: f32| {
                let beta = beta * weight;
                if len >= STACK || !beta.is_finite() || beta.max_element() <= 0.0 {
                    return;
                }
                stack[len] = Branch {
                    ray: Ray::new(offset_ray_origin(sp.p, sp.p_error, fr.ng, dir), dir),
                    beta,
                    eta_scale: b.eta_scale * eta_scale,
                    depth: depth + 1,
                    cone: b.cone.bounce(
                        &ray,
                        hit.t,
                        curvature,
                        if transmitted { 1.0 } else { 2.0 },
                    ),
                    kind: if transmitted {
                        RayKind::Refract
                    } else {
                        RayKind::Reflect
                    },
                    parent: node,
                    medium: b.medium.after(scene, &v, dir),
                };
                len += 1;
            };
            if depth < SPLIT_DEPTH && !bsdf.has_local() {
                let lobes = bsdf.delta_lobes(wo, fr.ns, fr.ng, fr.entering);
                if let Some((dir, w)) = lobes.refract {
                    push(dir, w, true, lobes.eta_scale);
                }
                if lobes.reflect_weight.max_element() > 0.0 {
                    push(lobes.reflect_dir, lobes.reflect_weight, false, 1.0);
                }
                continue;
            }
            // Deeper: one delta lobe, sampled (the diffuse part was accounted for above).
            let u_lobe = cx.sampler.defer_1d();
            let u_dir = cx.sampler.next_2d();
            let u_rr = cx.sampler.next_1d();
            let u_lobe = bsdf.lobe_number(|| cx.sampler.get_1d(u_lobe));
            let Some(s) = bsdf.sample(wo, u_lobe, u_dir, &fr, TransportMode::Radiance) else {
                continue;
            };
            if !s.delta {
                continue;
            }
            let mut w = s.weight;
            if depth + 1 > ROULETTE_DEPTH {
                let eta_scale = b.eta_scale * if s.transmitted { s.eta_scale } else { 1.0 };
                let q = (beta * w / eta_scale).max_element().min(1.0);
                if !(q > 0.0) || u_rr >= q {
                    cx.observer.note(node, "ended by Russian roulette");
                    continue;
                }
                w /= q;
            }
            push(
                s.wi,
                w,
                s.transmitted,
                if s.transmitted { s.eta_scale } else { 1.0 },
            );
        }
        cx.observer.finish_tree(root);
        l
    }

    /// The radiance a camera-path vertex with a diffuse part sends towards `wo`: direct light,
    /// caustics and indirect light, at the hit `v` reached through `medium` (where final-gather
    /// rays start). With `describe`, also a line for `debug-pixel` naming each estimate's photon
    /// count and radius.
    #[allow(clippy::too_many_arguments)]
    fn local(
        &self,
        maps: &PhotonMaps,
        v: &SurfaceHit,
        medium: Medium,
        full: bool,
        sampler: &mut Sampler,
        counters: &mut Counters,
        describe: bool,
    ) -> (Radiance, Option<String>) {
        let (sp, fr, bsdf, wo) = (&v.sp, &v.frame, v.bsdf, v.wo);
        let direct = self.direct(sp, fr, bsdf, wo, sampler, counters);
        if !full
            && let Some(l) = cached_radiance(
                maps,
                Walls::of(self.scene, Some(sp.object)),
                sp,
                fr,
                bsdf,
                wo,
                counters,
            )
        {
            let note = describe.then(|| {
                format!(
                    "direct ({:.4}, {:.4}, {:.4}); caustic + indirect {} ({:.4}, {:.4}, {:.4}) (dim branch)",
                    direct.x,
                    direct.y,
                    direct.z,
                    if bsdf.is_diffuse_only() {
                        "from precomputed irradiance"
                    } else {
                        "from both maps (glossy)"
                    },
                    l.x,
                    l.y,
                    l.z
                )
            });
            let mut r = Radiance::default();
            r.add(LightPath::Direct, direct);
            r.add(LightPath::Indirect, l);
            return (r, note);
        }
        let caustic = maps.caustic.as_ref().map(|m| {
            counted(
                m,
                Walls::of(self.scene, Some(sp.object)),
                sp.p,
                wo,
                fr,
                bsdf,
                counters,
            )
        });
        let gather = self.final_gather;
        let (indirect, global) = if gather > 0 {
            (
                self.final_gather(maps, v, medium, gather, sampler, counters),
                None,
            )
        } else {
            let e = maps.global.as_ref().map(|m| {
                counted(
                    m,
                    Walls::of(self.scene, Some(sp.object)),
                    sp.p,
                    wo,
                    fr,
                    bsdf,
                    counters,
                )
            });
            (e.map_or(Vec3::ZERO, |e| e.radiance), e)
        };
        let caustic_l = caustic.map_or(Vec3::ZERO, |e| e.radiance);
        let note = describe.then(|| {
            let show = |name: &str, e: Option<Estimate>| match e {
                Some(e) => format!(
                    "{name}: {} photons within r = {:.4}{} → ({:.4}, {:.4}, {:.4})",
                    e.found,
                    e.radius,
                    if e.cut { " (radius-limited)" } else { "" },
                    e.radiance.x,
                    e.radiance.y,
                    e.radiance.z
                ),
                None => format!("{name}: no map"),
            };
            let global_text = if gather > 0 {
                format!(
                    "final gather ({gather} rays) → ({:.4}, {:.4}, {:.4})",
                    indirect.x, indirect.y, indirect.z
                )
            } else {
                show("global", global)
            };
            format!(
                "direct ({:.4}, {:.4}, {:.4}); {}; {}",
                direct.x,
                direct.y,
                direct.z,
                show("caustic", caustic),
                global_text
            )
        });
        let mut r = Radiance::default();
        r.add(LightPath::Direct, direct);
        r.add(LightPath::Caustic, caustic_l);
        r.add(LightPath::Indirect, indirect);
        (r, note)
    }

    /// Direct light at a vertex by one shadow ray to a light chosen as the path tracer chooses
    /// it (per voxel, learned by a pilot; by power where it learned nothing).
    fn direct(
        &self,
        sp: &SurfacePoint,
        fr: &ShadingFrame,
        bsdf: &Bsdf,
        wo: Vec3,
        sampler: &mut Sampler,
        counters: &mut Counters,
    ) -> Vec3 {
        let u_light = sampler.next_1d();
        let u_point = sampler.next_2d();
        let Some((index, pmf)) = self.lights.choose(sp.p, || u_light) else {
            return Vec3::ZERO;
        };
        match connect_light(self.scene, index, sp, &bsdf.at(wo, fr), u_point, counters) {
            // |cos θ|: through a rough dielectric the light lies below the shading normal.
            Some(c) if !c.occluded => c.f * c.ls.weight * (fr.ns.dot(c.ls.wi).abs() / pmf),
            _ => Vec3::ZERO,
        }
    }

    /// Indirect light at a vertex by `n` final-gather rays sampled from the BSDF's diffuse part:
    /// where each lands, its direct light, caustics and global-map radiance (following up to
    /// four mirror or glass bounces first; a ray shorter than [`SHORT_GATHER`] times the
    /// landing estimate's radius takes one more BSDF-sampled bounce instead of reading it).
    /// Each ray carries its absorbing [`Medium`], starting from `medium` (the one the camera ray
    /// reached the hit `v` through) and changing where it scatters, as camera paths do: what
    /// it brings back keeps `exp(−σ t)` of every segment inside.
    fn final_gather(
        &self,
        maps: &PhotonMaps,
        v: &SurfaceHit,
        medium: Medium,
        n: u32,
        sampler: &mut Sampler,
        counters: &mut Counters,
    ) -> Vec3 {
        let scene = self.scene;
        let (sp, fr) = (&v.sp, &v.frame);
        // The mixture worked out once for all `n` rays leaving this vertex.
        let at = v.bsdf.at(v.wo, fr);
        let mut sum = Vec3::ZERO;
        for _ in 0..n {
            let u_lobe = sampler.defer_1d();
            let u_dir = sampler.next_2d();
            let u_lobe = at.lobe_number(|| sampler.get_1d(u_lobe));
            let Some(s) = at.sample(u_lobe, u_dir, TransportMode::Radiance) else {
                continue;
            };
            if s.delta {
                continue; // The delta lobes are followed by the camera path itself.
            }
            let mut beta = s.weight;
            let mut ray = Ray::new(offset_ray_origin(sp.p, sp.p_error, fr.ng, s.wi), s.wi);
            let mut medium = medium.after(scene, v, s.wi);
            let (mut specular, mut shortcuts) = (0u32, 0u32);
            loop {
                counters.rays += 1;
                let mut textured = None;
                let it = scene.interact(&ray, |_| 0.0, &mut textured);
                // Beer–Lambert absorption along the segment just travelled (1 outside media).
                beta *= medium.transmittance(&ray, &it);
                let g = match it {
                    Interaction::Escaped => {
                        sum += beta * scene.params.background;
                        break;
                    }
                    Interaction::Emitter(_) => break, // Direct light is the shadow ray's.
                    Interaction::Surface(g) => g,
                };
                let (gp, gwo, gfr) = (g.sp, g.wo, g.frame);
                let mut short = false;
                if g.bsdf.has_local() {
                    let mut lo = self.direct(&gp, &gfr, g.bsdf, gwo, sampler, counters);
                    let near = maps.irradiance.as_ref().and_then(|c| {
                        c.lookup_with_radius(gp.p, gfr.ng, Walls::of(scene, Some(gp.object)))
                    });
                    short = shortcuts < SHORT_GATHER_BOUNCES
                        && near.is_some_and(|(_, r)| g.hit.t < SHORT_GATHER * r);
                    if short {
                        // The caustics here still come from their map; the rest of the light
                        // arriving here is gathered by the bounce below.
                        if let Some(map) = &maps.caustic {
                            lo += counted(
                                map,
                                Walls::of(scene, Some(gp.object)),
                                gp.p,
                                gwo,
                                &gfr,
                                g.bsdf,
                                counters,
                            )
                            .radiance;
                        }
                    } else if let Some((e, _)) = near.filter(|_| g.bsdf.is_diffuse_only()) {
                        lo += g.bsdf.eval(gwo, gfr.ns, &gfr, TransportMode::Radiance) * e;
                    } else {
                        for map in [&maps.caustic, &maps.global].into_iter().flatten() {
                            lo += counted(
                                map,
                                Walls::of(scene, Some(gp.object)),
                                gp.p,
                                gwo,
                                &gfr,
                                g.bsdf,
                                counters,
                            )
                            .radiance;
                        }
                    }
                    sum += beta * lo;
                }
                if !short && (specular == GATHER_SPECULAR_DEPTH || !g.bsdf.has_delta()) {
                    break;
                }
                let u_lobe = sampler.defer_1d();
                let u_dir = sampler.next_2d();
                let u_lobe = g.bsdf.lobe_number(|| sampler.get_1d(u_lobe));
                let Some(gs) = g
                    .bsdf
                    .sample(gwo, u_lobe, u_dir, &gfr, TransportMode::Radiance)
                else {
                    break;
                };
                if gs.delta {
                    if specular == GATHER_SPECULAR_DEPTH {
                        break;
                    }
                    specular += 1;
                } else if short {
                    shortcuts += 1;
                } else {
                    break;
                }
                beta *= gs.weight;
                if !beta.is_finite() || beta.max_element() <= 0.0 {
                    break;
                }
                medium = medium.after(scene, &g, gs.wi);
                ray = Ray::new(offset_ray_origin(gp.p, gp.p_error, gfr.ng, gs.wi), gs.wi);
            }
        }
        sum / n as f32
    }
}

/// Caustic and indirect radiance towards `wo` read without gathering again, where final
/// gathering built the precomputed irradiance (a gather ray's landing, a dim camera vertex):
/// - on a Lambert surface, `f · E` with `E` the irradiance of both maps at the nearest point on
///   the same surface (exact: `f` does not depend on the light's direction); `None` when no
///   such point lies near;
/// - on a surface with a Phong lobe, both maps read with the full BSDF, since the lobe weighs
///   each photon by its direction: `f(ωo, n) · E` (the lobe evaluated as if all light came
///   along the normal) made final gathering +8 / +22 / +45 % too bright on glossy walls of
///   shininess 1 / 10 / 50 (issue 29, glossy-final-gather).
fn cached_radiance(
    maps: &PhotonMaps,
    walls: Walls<'_>,
    sp: &SurfacePoint,
    fr: &ShadingFrame,
    bsdf: &Bsdf,
    wo: Vec3,
    counters: &mut Counters,
) -> Option<Vec3> {
    let cache = maps.irradiance.as_ref()?;
    if bsdf.is_diffuse_only() {
        let e = cache.lookup(sp.p, fr.ng, walls)?;
        return Some(bsdf.eval(wo, fr.ns, fr, TransportMode::Radiance) * e);
    }
    let mut l = Vec3::ZERO;
    for map in [&maps.caustic, &maps.global].into_iter().flatten() {
        l += counted(map, walls, sp.p, wo, fr, bsdf, counters).radiance;
    }
    Some(l)
}

/// `map`'s estimate at `p` towards `wo` through `bsdf` (photons one of `walls`
/// separates from `p` left out), counted in `counters` (estimates made, and those the largest
/// radius cut short).
#[inline]
fn counted(
    map: &PhotonMap,
    walls: Walls<'_>,
    p: Vec3,
    wo: Vec3,
    fr: &ShadingFrame,
    bsdf: &Bsdf,
    counters: &mut Counters,
) -> Estimate {
    let e = map.estimate(p, wo, fr, bsdf, walls);
    counters.photon_estimates += 1;
    counters.photon_radius_cut += u64::from(e.cut);
    e
}

impl<'a> super::Estimator<'a> for PhotonMapper<'a> {
    fn li_parts<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
        self.li(ray, cx)
    }

    fn photon_maps(&self) -> Option<&PhotonMaps> {
        Some(self.maps())
    }
}
