//! Unidirectional path tracing (Kajiya 1986) with next-event estimation and multiple importance
//! sampling by the power heuristic (Veach & Guibas 1995; Veach's thesis ch. 9), Russian
//! roulette after a few bounces (Arvo & Kirk 1990). Iterative, no allocation per sample. The
//! reference every other integrator is checked against.

use glam::Vec3;

use super::context::{Context, PathObserver};
use super::light_guide::LightGuide;
use super::photon::walls::Walls;
use super::photon::{PhotonMap, SHORT_GATHER, SHORT_GATHER_BOUNCES, VolumeMap};
use super::shadow::{LightConnection, RayCone, SHADOW_EPSILON, connect_light, shadow_ray};
use super::trace_log::{RayKind, ShadowRecord};
use super::whitted::shadow_transmittance;
use super::{LightPath, Radiance};
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::participating::FreeFlight;
use crate::render_scene::{
    HomogeneousMedium, Interaction, Medium, RenderScene, SurfaceHit, SurfacePoint,
};
use crate::shading::{BsdfAt, TransportMode};

mod equiangular;
use equiangular::MediumSegment;

/// Bounces after which Russian roulette may end a path.
const ROULETTE_DEPTH: u32 = 3;

/// Most surfaces a branch may cross straight on (interfaces, false hits of nested volumes)
/// before it is dropped: a guard against a ray caught on one surface by rounding.
const MAX_SKIPPED: u32 = 1024;

/// Photon maps a camera path reads ([`PathTracer::li_with_maps`]); none by default.
#[derive(Debug, Clone, Copy, Default)]
pub struct PathMaps<'m> {
    /// Light → specular⁺ → diffuse photons.
    pub caustic: Option<&'m PhotonMap>,
    /// Photons after at least one diffuse bounce.
    pub global: Option<&'m PhotonMap>,
    /// Diffuse bounces a path makes before the vertex that reads `global` (0: the first
    /// diffuse hit, as progressive photon mapping; 1: after one bounce, as final gathering).
    pub global_at: u32,
    /// `global` holds caustic photons too (landings after any first bounce): the vertex that
    /// reads it does not read `caustic`.
    pub global_has_caustics: bool,
    /// The maps were traced with near-specular surfaces as specular ones (GGX α up to this,
    /// [`crate::integrators::photon::MapSet::near_specular`]): such a vertex reads no
    /// map and is not a diffuse bounce; it samples lights as any glossy vertex does, unless a
    /// vertex before it read the caustic map with only specular and near-specular bounces
    /// between (then the map holds that light).
    pub near_specular: Option<f32>,
    /// Per light: whether `caustic` holds its caustic photons (a light given no caustic photons
    /// this pass leaves its caustics to the camera paths). Empty: none.
    pub caustic_lights: &'m [bool],
    /// Light → specular⁺ → medium photons (the volume caustic map, traced with the caustic
    /// photons of the lights in `caustic_lights`): read by the beam estimate along every
    /// camera segment in a scattering medium where the path may still scatter.
    pub volume: Option<&'m VolumeMap>,
}

impl PathMaps<'_> {
    /// True if the caustic map carries light `index`'s caustics.
    #[inline]
    fn carries(&self, index: usize) -> bool {
        self.caustic.is_some() && self.caustic_lights.get(index).copied().unwrap_or(false)
    }

    /// True if the volume caustic map carries light `index`'s light → specular⁺ → medium paths.
    #[inline]
    fn carries_volume(&self, index: usize) -> bool {
        self.volume.is_some() && self.caustic_lights.get(index).copied().unwrap_or(false)
    }

    /// True if a path whose last non-specular vertex read the caustic map (`map_read`) or was a
    /// medium vertex under a volume caustic map (`volume_read`) reaches light `index` through
    /// `since_local` specular bounces with light the maps already hold.
    #[inline]
    fn holds(
        &self,
        index: usize,
        since_local: Option<u32>,
        map_read: bool,
        volume_read: bool,
    ) -> bool {
        since_local.is_some_and(|n| n > 0)
            && ((map_read && self.carries(index)) || (volume_read && self.carries_volume(index)))
    }
}

/// The path tracer over a compiled scene.
#[derive(Debug)]
pub struct PathTracer<'a> {
    scene: &'a RenderScene,
    lights: LightGuide,
    pixel_spread: f32,
    specular_splits: u32,
    /// Equiangular next-event estimation along medium segments ([`PathTracer::with_equiangular`]):
    /// on, and the scene has a light with a centre to aim at.
    equiangular: bool,
    /// Some material absorbs inside (Beer–Lambert): paths track the absorbing object they are
    /// in. False: the path loop without that bookkeeping ([`PathTracer::trace_paths`]).
    absorbing: bool,
}

/// Most branches waiting while one is followed ([`PathTracer::with_specular_splits`]); with
/// splits at most at the first 2 specular vertices no more than 2 ever wait.
const MAX_PENDING: usize = 4;

/// The state of one camera path (or one branch of it after a split at a specular vertex).
#[derive(Debug, Clone, Copy)]
struct Branch {
    ray: Ray,
    cone: RayCone,
    beta: Vec3,
    /// Radiance scale from refraction so far, undone for Russian roulette (pbrt's etaScale).
    eta_scale: f32,
    /// The last bounce was a delta lobe (or the camera): emitters hit next count fully.
    specular: bool,
    prev_pdf: f32,
    prev_p: Vec3,
    diffuse_bounces: u32,
    /// Delta (and near-specular, [`PathMaps::near_specular`]) bounces since the last other
    /// non-delta one (`None` before any): an emitter hit with at least one is a caustic path,
    /// which the caustic map accounts for when it was read at that non-delta vertex
    /// (`map_read`), or the volume caustic map when that vertex was in a medium
    /// (`volume_read`).
    since_local: Option<u32>,
    map_read: bool,
    volume_read: bool,
    /// After a non-delta bounce from a vertex that read the global map, the emitters' light is
    /// accounted for: only the background still counts.
    background_only: bool,
    /// Diffuse bounces before the vertex that reads the global map: `maps.global_at`, one more
    /// for each short gather ray ([`SHORT_GATHER`]) the path made.
    global_at: u32,
    kind: RayKind,
    parent: Option<usize>,
    depth: u32,
    medium: Medium,
    /// Specular vertices this branch was split at.
    splits: u32,
}

/// [`Medium::after_in`] in the path loop's copy for `VOLUMETRIC` / `ABSORBING` scenes: where
/// no material absorbs and there are no media the path is always outside, unchanged.
#[inline(always)]
fn next_medium<const VOLUMETRIC: bool, const ABSORBING: bool>(
    medium: Medium,
    scene: &RenderScene,
    v: &SurfaceHit,
    wi: Vec3,
) -> Medium {
    if ABSORBING {
        medium.after_in::<VOLUMETRIC>(scene, v, wi)
    } else {
        medium
    }
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
    /// Prepares the light choice of next-event estimation: learned per region by a pilot
    /// ([`LightGuide::learn`]) when the scene has several lights, else by power.
    #[must_use]
    pub fn new(scene: &'a RenderScene) -> Self {
        Self {
            scene,
            lights: LightGuide::learn(scene),
            pixel_spread: scene.pixel_spread(),
            specular_splits: 0,
            equiangular: scene
                .lights
                .iter()
                .any(|l| equiangular::equiangular_center(l).is_some()),
            absorbing: scene.materials.iter().any(|m| !m.absorption.is_clear()),
        }
    }

    /// The same tracer with (`true`, the default) or without equiangular next-event estimation
    /// along medium segments (Kulla & Fajardo 2012; `path/equiangular.rs`). Without it, medium
    /// points are found by free-flight sampling alone, as before it existed: the tests measure
    /// its variance against that. A scene without a point, spot or sphere light never uses it
    /// (it draws no numbers for it either: such scenes render as before).
    #[must_use]
    pub fn with_equiangular(mut self, on: bool) -> Self {
        self.equiangular = on
            && self
                .scene
                .lights
                .iter()
                .any(|l| equiangular::equiangular_center(l).is_some());
        self
    }

    /// The same tracer splitting camera paths at their first `n` specular vertices: where a
    /// path that has made no diffuse or glossy bounce yet meets a purely specular surface
    /// (smooth glass or water, whose BSDF has only delta parts), it follows both the
    /// reflected and the refracted branch, weighted by the BSDF's delta weights (F and
    /// (1 − F)·(ηₒ/ηᵢ)², from [`crate::shading::Bsdf::delta_lobes`]), instead of choosing one with those
    /// probabilities. The expected value is unchanged (the sum of the two weighted branches is
    /// the expectation of the choice), so the estimator stays unbiased; the variance of light
    /// seen through specular chains (the light's image in water or glass, at F ≈ 0.04 chosen
    /// once in ~25 samples by the random choice) is removed at those vertices. Ray budget: at
    /// most 2ⁿ branches per camera sample, and only on pixels that see a specular surface. After
    /// `n` splits, or after a non-delta bounce, the branch chooses as before. 0 (the default):
    /// no splitting.
    #[must_use]
    pub fn with_specular_splits(mut self, n: u32) -> Self {
        self.specular_splits = n;
        self
    }

    /// Radiance arriving along camera ray `ray`. Paths have at most `render.max_depth` bounces
    /// and at most `render.diffuse_depth` non-delta ones (0: direct light and delta chains only,
    /// Whitted's light transport); the background is an environment that escaping rays see.
    pub fn li<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
        self.li_with_maps(PathMaps::default(), ray, cx)
    }

    /// [`PathTracer::li`] reading photon maps (the progressive integrators):
    /// - `maps.caustic` (light → specular⁺ → diffuse photons) at every vertex with a non-delta
    ///   part where the path may still scatter; an emitter reached by delta bounces after such
    ///   a vertex is then not counted, since the map holds exactly those paths (left to
    ///   chance hits, such paths through water or glass are the fireflies of path tracing).
    ///   With `maps.near_specular`, near-specular glossy vertices count as specular ones here:
    ///   they read no map, and after a vertex that read the caustic map they make no
    ///   next-event estimate of the lights it carries. Only lights the map carries
    ///   (`maps.caustic_lights`) are left out; the others' caustics stay in the camera path;
    /// - `maps.global` at the vertices after `maps.global_at` diffuse bounces (one more for
    ///   each short gather ray, at most [`SHORT_GATHER_BOUNCES`]: one shorter than
    ///   [`SHORT_GATHER`] times the global estimate's radius where it lands): there direct
    ///   light (next-event estimation, without MIS), caustics and the global map (light that
    ///   made at least one diffuse bounce; or any bounce, caustics included, with
    ///   `global_has_caustics`) account for all the light of the scene's emitters
    ///   leaving through the non-delta part, so a path that scatters on from there counts only
    ///   the background it escapes to (the maps hold no light from it).
    ///
    /// The parts are disjoint and together make every path, so the image converges to the
    /// path tracer's as the maps' radii shrink.
    pub fn li_with_maps<O: PathObserver>(
        &self,
        maps: PathMaps<'_>,
        ray: Ray,
        cx: &mut Context<'_, O>,
    ) -> Radiance {
        if self.scene.volumetric {
            self.trace_paths::<O, true, true>(maps, ray, cx)
        } else if self.absorbing {
            self.trace_paths::<O, false, true>(maps, ray, cx)
        } else {
            self.trace_paths::<O, false, false>(maps, ray, cx)
        }
    }

    /// [`PathTracer::li_with_maps`] with `VOLUMETRIC` = [`RenderScene::volumetric`] and
    /// `ABSORBING` = some material absorbs (always with `VOLUMETRIC`): one copy of the loop per
    /// kind of scene, so that scenes without media run a loop without the media's code (it
    /// made the path loop of every scene 1.6 % slower in instructions on cbox), and scenes
    /// where nothing absorbs one without the absorbing object's bookkeeping at every vertex
    /// (the path stays in clear air: its transmittance is exactly 1; 2.4 % of cbox's `path`
    /// instructions, docs/performance.md).
    fn trace_paths<O: PathObserver, const VOLUMETRIC: bool, const ABSORBING: bool>(
        &self,
        maps: PathMaps<'_>,
        ray: Ray,
        cx: &mut Context<'_, O>,
    ) -> Radiance {
        debug_assert_eq!(VOLUMETRIC, self.scene.volumetric);
        debug_assert!(ABSORBING || !(VOLUMETRIC || self.absorbing));
        let scene = self.scene;
        let params = &scene.params;
        let mut l = Radiance::default();
        // Debug logs only: each node holds the radiance gathered before it until the path ends.
        let mut root: Option<usize> = None;
        let mut pending = [None::<Branch>; MAX_PENDING];
        let mut waiting = 0usize;
        let mut next = Some(Branch {
            ray,
            cone: RayCone::camera(self.pixel_spread),
            beta: Vec3::ONE,
            eta_scale: 1.0,
            specular: true,
            prev_pdf: 0.0,
            prev_p: ray.origin,
            diffuse_bounces: 0,
            since_local: None,
            map_read: false,
            volume_read: false,
            background_only: false,
            global_at: maps.global_at,
            kind: RayKind::Camera,
            parent: None,
            depth: 0,
            medium: Medium::outside(scene),
            splits: 0,
        });
        while let Some(b) = next.take().or_else(|| {
            waiting = waiting.checked_sub(1)?;
            pending[waiting].take()
        }) {
            let Branch {
                mut ray,
                mut cone,
                mut beta,
                mut eta_scale,
                mut specular,
                mut prev_pdf,
                mut prev_p,
                mut diffuse_bounces,
                mut since_local,
                mut map_read,
                mut volume_read,
                mut background_only,
                mut global_at,
                mut kind,
                mut parent,
                mut depth,
                mut medium,
                splits,
            } = b;
            // Surfaces crossed straight on (interfaces, false hits) by this branch.
            let mut skipped = 0u32;
            loop {
                cx.counters.rays += 1;
                let node = cx.observer.ray(depth, kind, &ray, beta, parent);
                if O::ACTIVE {
                    cx.observer.set_radiance(node, l.total());
                }
                root = root.or(node);
                let mut textured = None;
                let mut nested = None;
                let mut it = scene.interact(&ray, |t| cone.width_at(&ray, t), &mut textured);
                if VOLUMETRIC {
                    // Participating media (docs/media.md): free-flight sampling along the
                    // segment; an event before the surface is a medium vertex.
                    if let Some(m) = medium.participating(scene) {
                        let len = ray.dir.length();
                        let t_hit = match &it {
                            Interaction::Escaped => f32::INFINITY,
                            Interaction::Emitter(e) => e.hit.t * len,
                            Interaction::Surface(v) => v.hit.t * len,
                        };
                        // Light → specular⁺ → here, scattered anywhere on the segment: the
                        // volume caustic map's beam estimate, where the path may still
                        // scatter (a medium vertex sampled below then counts none of it).
                        let mut beamed = false;
                        if let Some(vm) = maps.volume
                            && !background_only
                            && depth < params.max_depth
                            && diffuse_bounces < params.diffuse_depth
                            && let Some(id) = medium.participating_index()
                        {
                            let e = vm.beam(ray.origin, ray.dir / len, t_hit, id, m);
                            beamed = true;
                            cx.counters.photon_estimates += 1;
                            l.add(
                                LightPath::classify(diffuse_bounces + 1, true),
                                beta * e.radiance,
                            );
                            if O::ACTIVE {
                                let r = e.radiance;
                                let text = format!(
                                    "volume caustic map: {} photons along the segment → ({:.4}, {:.4}, {:.4})",
                                    e.found, r.x, r.y, r.z
                                );
                                cx.observer.note(node, &text);
                            }
                        }
                        // Equiangular next-event estimation along the segment, where a vertex
                        // sampled on it may scatter (path/equiangular.rs); the free-flight
                        // vertex's estimate below is MIS-weighted against it.
                        let seg = (self.equiangular
                            && !background_only
                            && depth < params.max_depth
                            && diffuse_bounces < params.diffuse_depth
                            && m.scatters())
                        .then(|| MediumSegment {
                            origin: ray.origin,
                            dir: ray.dir / len,
                            t_max: t_hit,
                            mean_free_path: 1.0 / m.sigma_t().min_element(),
                        });
                        if let Some(seg) = &seg {
                            let c = self.equiangular_direct(seg, m, medium, cx);
                            l.add(LightPath::classify(diffuse_bounces + 1, false), beta * c);
                        }
                        match m.sample_distance(t_hit, cx.sampler.next_2d()) {
                            FreeFlight::Pass { weight } => beta *= weight,
                            FreeFlight::Scatter { t, weight } => {
                                beta *= weight;
                                if depth >= params.max_depth
                                    || diffuse_bounces >= params.diffuse_depth
                                    || !beta.is_finite()
                                    || beta.max_element() <= 0.0
                                {
                                    cx.observer.note(node, "depth reached in a medium");
                                    break;
                                }
                                let p = ray.origin + ray.dir * (t / len);
                                let d_in = ray.dir / len;
                                let u_light = cx.sampler.next_1d();
                                let u_point = cx.sampler.next_2d();
                                if !background_only
                                    && let Some((index, pmf)) = self.lights.choose(p, || u_light)
                                {
                                    let mut c = self.direct_in_medium(
                                        p, d_in, m, medium, index, pmf, u_point, cx,
                                    );
                                    if let Some(seg) = &seg {
                                        c *= self.free_flight_weight(seg, m, t, index, pmf);
                                    }
                                    l.add(
                                        LightPath::classify(diffuse_bounces + 1, false),
                                        beta * c,
                                    );
                                }
                                let s = m.phase.sample(d_in, cx.sampler.next_2d());
                                let u_rr = cx.sampler.next_1d();
                                diffuse_bounces += 1;
                                depth += 1;
                                if depth > ROULETTE_DEPTH {
                                    let q = (beta / eta_scale).max_element().min(1.0);
                                    if u_rr >= q {
                                        cx.observer.note(node, "ended by Russian roulette");
                                        break;
                                    }
                                    beta /= q;
                                }
                                cone = cone.scatter(&ray, t / len, s.pdf);
                                specular = false;
                                since_local = Some(0);
                                map_read = false;
                                // The beam estimate above held this vertex's light → specular⁺
                                // (it is made wherever a vertex can follow, so always here).
                                volume_read = beamed;
                                prev_pdf = s.pdf;
                                prev_p = p;
                                kind = RayKind::Scatter;
                                parent = node;
                                ray = Ray::new(p, s.wi);
                                continue;
                            }
                        }
                    } else {
                        beta *= medium.transmittance(&ray, &it);
                    }
                    if let Interaction::Surface(v) = &mut it
                        // An interface or a surface inside a volume of higher priority: not
                        // there, the path goes straight on (not a bounce).
                        && let Some(next) = medium.surface_step(scene, &ray, v, &mut nested)
                    {
                        skipped += 1;
                        if skipped > MAX_SKIPPED {
                            break;
                        }
                        (ray, medium) = next;
                        continue;
                    }
                } else if ABSORBING {
                    // Beer–Lambert absorption along the segment just travelled (1 outside media).
                    beta *= medium.transmittance(&ray, &it);
                }
                // After a vertex that read the caustic map and at least one specular bounce, the
                // map holds the light of the lights it carries.
                let in_map = |i: usize| maps.holds(i, since_local, map_read, volume_read);
                let v = match &it {
                    Interaction::Escaped => {
                        // Leaving the scene: the lights at infinity the ray sees, each counted
                        // as an emitter hit is, then the background.
                        let via = since_local.is_some_and(|n| n > 0);
                        let class = LightPath::classify(diffuse_bounces, via);
                        if !background_only {
                            for (i, e) in scene.lights_escaped(&ray).filter(|&(i, _)| !in_map(i)) {
                                let w = if specular {
                                    1.0
                                } else {
                                    let light_pdf = self.lights.pmf(prev_p, i)
                                        * scene.lights[i].pdf_li(prev_p, e.wi);
                                    power_heuristic(prev_pdf, light_pdf)
                                };
                                l.add(class, beta * (e.le * w));
                            }
                        }
                        l.add(class, beta * params.background);
                        if O::ACTIVE
                            && let Some(e) = scene.escape_record(&ray)
                        {
                            cx.observer.hit(node, scene, &e.hit, &e.sp, "light");
                        }
                        break;
                    }
                    Interaction::Emitter(e) => {
                        // An emitter (seen from outside only); it absorbs what reaches it.
                        let le = match e.light {
                            None => Vec3::ZERO,
                            Some(_) if background_only => Vec3::ZERO,
                            Some(i) if in_map(i as usize) => Vec3::ZERO,
                            Some(i) => {
                                let le = e.le(scene);
                                if le == Vec3::ZERO {
                                    le
                                } else {
                                    let w = if specular {
                                        1.0
                                    } else {
                                        let light_pdf = self.lights.pmf(prev_p, i as usize)
                                            * scene.lights[i as usize]
                                                .pdf_li_hit(prev_p, -e.wo, e.sp.p, e.sp.ng);
                                        power_heuristic(prev_pdf, light_pdf)
                                    };
                                    le * w
                                }
                            }
                        };
                        let via = since_local.is_some_and(|n| n > 0);
                        l.add(LightPath::classify(diffuse_bounces, via), beta * le);
                        cx.observer.hit(node, scene, &e.hit, &e.sp, "light");
                        break;
                    }
                    Interaction::Surface(v) => v,
                };
                let (hit, sp, wo) = (&v.hit, &v.sp, v.wo);
                let name = &scene.material_names[v.material as usize];
                cx.observer.hit(node, scene, hit, sp, name);
                if depth >= params.max_depth {
                    cx.observer.note(node, "max depth reached");
                    break;
                }
                let fr = v.frame;
                let bsdf = v.bsdf;
                // The mixture worked out once for this vertex's light sample and next direction.
                let at = bsdf.at(wo, &fr);
                let may_scatter = diffuse_bounces < params.diffuse_depth;
                let local = bsdf.has_local() && !background_only;
                // A near-specular vertex is part of caustic paths: after a vertex that read the
                // caustic map, the light it passes on is in that map.
                let near = maps.near_specular.is_some_and(|a| bsdf.is_near_specular(a));
                let reads = local && !near;
                let at_global =
                    reads && may_scatter && maps.global.is_some() && diffuse_bounces == global_at;
                // A short gather ray (Jensen 2001, §9.3): its end is so near the vertex it left
                // that the global estimate's disc there reaches past the corner between them,
                // where it is partly empty (dark corners); the path takes one more diffuse bounce
                // and reads the global map after it instead (at most SHORT_GATHER_BOUNCES times).
                let short = at_global
                    && !specular
                    && global_at < maps.global_at + SHORT_GATHER_BOUNCES
                    && diffuse_bounces + 1 < params.diffuse_depth
                    && maps
                        .global
                        .is_some_and(|g| hit.t < SHORT_GATHER * g.radius_at(sp.p));
                if short {
                    global_at += 1;
                    cx.observer
                        .note(node, "short gather ray: global map read one bounce later");
                }
                let read_global = at_global && !short;
                // Next-event estimation through the non-delta part. Every bounce reserves the same
                // dimensions, whether or not it uses them, and computes only those it uses.
                let u_light = cx.sampler.defer_1d();
                let u_point = cx.sampler.defer_2d();
                if local
                    && let Some((index, pmf)) =
                        self.lights.choose(sp.p, || cx.sampler.get_1d(u_light))
                    && !(near
                        && (map_read && maps.carries(index)
                            || volume_read && maps.carries_volume(index)))
                {
                    let u = cx.sampler.get_2d(u_point);
                    let scatter = may_scatter && !read_global;
                    // At diffuse depth 0 direct light is Whitted's: through glass too.
                    let through = (params.diffuse_depth == 0 || VOLUMETRIC).then_some((v, medium));
                    let c = self.direct(sp, &at, index, pmf, u, scatter, through, cx, node);
                    l.add(LightPath::classify(diffuse_bounces + 1, false), beta * c);
                }
                let read_caustic = reads
                    && may_scatter
                    && maps.caustic.is_some()
                    && !(read_global && maps.global_has_caustics);
                if read_caustic || read_global {
                    let caustic = maps.caustic.filter(|_| read_caustic);
                    let global = maps.global.filter(|_| read_global);
                    let first = LightPath::classify(diffuse_bounces + 1, true);
                    for (name, map, kind) in [
                        ("caustic", caustic, first),
                        ("global", global, LightPath::Indirect),
                    ] {
                        let Some(map) = map else { continue };
                        let e =
                            map.estimate(sp.p, wo, &fr, bsdf, Walls::of(scene, Some(sp.object)));
                        cx.counters.photon_estimates += 1;
                        l.add(kind, beta * e.radiance);
                        if O::ACTIVE {
                            let text = format!(
                                "{name} map: {} photons within r = {:.4} → ({:.4}, {:.4}, {:.4})",
                                e.found, e.radius, e.radiance.x, e.radiance.y, e.radiance.z
                            );
                            cx.observer.note(node, &text);
                        }
                    }
                }
                // Split at the first specular vertices of a camera path (see
                // `with_specular_splits`): both delta branches wait on the stack with their weights.
                if splits < self.specular_splits
                    && diffuse_bounces == 0
                    && !bsdf.has_local()
                    && waiting + 2 <= MAX_PENDING
                {
                    let lobes = bsdf.delta_lobes(wo, fr.ns, fr.ng, fr.entering);
                    if let Some((t_dir, t_weight)) = lobes.refract
                        && t_weight.max_element() > 0.0
                        && lobes.reflect_weight.max_element() > 0.0
                    {
                        let curvature = scene.geometry.curvature(hit);
                        let branch = |dir: Vec3, weight: Vec3, transmitted: bool| Branch {
                            ray: Ray::new(offset_ray_origin(sp.p, sp.p_error, fr.ng, dir), dir),
                            cone: cone.bounce(
                                &ray,
                                hit.t,
                                curvature,
                                if transmitted { 1.0 } else { 2.0 },
                            ),
                            beta: beta * weight,
                            eta_scale: if transmitted {
                                eta_scale * lobes.eta_scale
                            } else {
                                eta_scale
                            },
                            specular: true,
                            prev_pdf: 0.0,
                            prev_p: sp.p,
                            diffuse_bounces,
                            since_local: since_local.map(|n| n + 1),
                            map_read,
                            volume_read,
                            background_only,
                            global_at,
                            kind: if transmitted {
                                RayKind::Refract
                            } else {
                                RayKind::Reflect
                            },
                            parent: node,
                            depth: depth + 1,
                            medium: next_medium::<VOLUMETRIC, ABSORBING>(medium, scene, v, dir),
                            splits: splits + 1,
                        };
                        // Russian roulette is not applied at a split vertex (optional per vertex,
                        // so the estimate stays unbiased); the branches' own later vertices apply it.
                        pending[waiting] = Some(branch(t_dir, t_weight, true));
                        pending[waiting + 1] =
                            Some(branch(lobes.reflect_dir, lobes.reflect_weight, false));
                        waiting += 2;
                        break;
                    }
                }
                // Continue the path by sampling the BSDF.
                let u_lobe = cx.sampler.defer_1d();
                let u_dir = cx.sampler.next_2d();
                let u_rr = cx.sampler.defer_1d();
                let u_lobe = at.lobe_number(|| cx.sampler.get_1d(u_lobe));
                let Some(s) = at.sample(u_lobe, u_dir, TransportMode::Radiance) else {
                    break;
                };
                if !s.delta {
                    if !may_scatter {
                        cx.observer.note(node, "diffuse depth reached");
                        break;
                    }
                    // A near-specular bounce is a specular one for the maps' parts.
                    diffuse_bounces += u32::from(!near);
                }
                let specular_like = s.delta || near;
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
                    if cx.sampler.get_1d(u_rr) >= q {
                        cx.observer.note(node, "ended by Russian roulette");
                        break;
                    }
                    beta /= q;
                }
                let curvature = scene.geometry.curvature(hit);
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
                since_local = if specular_like {
                    since_local.map(|n| n + 1)
                } else {
                    map_read = read_caustic;
                    volume_read = false;
                    background_only |= read_global;
                    Some(0)
                };
                prev_pdf = s.pdf;
                prev_p = sp.p;
                kind = match (s.delta, s.transmitted) {
                    (_, true) => RayKind::Refract,
                    (true, false) => RayKind::Reflect,
                    (false, false) => RayKind::Scatter,
                };
                parent = node;
                medium = next_medium::<VOLUMETRIC, ABSORBING>(medium, scene, v, s.wi);
                let origin = offset_ray_origin(sp.p, sp.p_error, fr.ng, s.wi);
                ray = Ray::new(origin, s.wi);
            }
        }
        if O::ACTIVE {
            // The radiance each logged ray brought back: what the path gathered from it on,
            // divided by the path weight it carried.
            cx.observer.finish_path(root, l.total());
        }
        l
    }
}

impl PathTracer<'_> {
    /// Next-event estimation at `sp` towards light `index` (chosen with probability `pmf`):
    /// the radiance it sends through the non-delta part of the BSDF, MIS-weighted against BSDF
    /// sampling when the path may still scatter diffusely (else the light sample alone stands
    /// for direct light). `through`: the vertex and the medium its ray travelled in when
    /// `diffuse_depth` is 0 (Whitted's transport, as documented): there a blocked shadow ray
    /// crosses transmitting surfaces in a straight line as Whitted's do
    /// ([`shadow_transmittance`]). At a deeper diffuse depth's last vertex it stays blocked: a
    /// straight line through a refracting surface is not a light path (it would add light that
    /// refraction sends elsewhere). In a volumetric scene `through` is always given and the
    /// shadow ray keeps the media's transmittance, crossing interfaces and false hits only
    /// ([`Medium::transmittance_through`]). Logged as a shadow record.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn direct<O: PathObserver>(
        &self,
        sp: &SurfacePoint,
        at: &BsdfAt<'_>,
        index: usize,
        pmf: f32,
        u: (f32, f32),
        may_scatter: bool,
        through: Option<(&SurfaceHit, Medium)>,
        cx: &mut Context<'_, O>,
        node: Option<usize>,
    ) -> Vec3 {
        let Some(LightConnection {
            ls,
            f,
            occluded: blocked,
        }) = connect_light(self.scene, index, sp, at, u, cx.counters)
        else {
            return Vec3::ZERO;
        };
        let transmittance = match through {
            // Scenes without media past diffuse depth 0 (the common case): visible or not.
            None if blocked => Vec3::ZERO,
            None => Vec3::ONE,
            // Volumetric scenes: the media's transmittance along the shadow ray, through
            // interfaces (docs/media.md).
            Some((v, medium)) if self.scene.volumetric => {
                let start = medium.after(self.scene, v, ls.wi);
                if blocked {
                    let shadow = shadow_ray(sp, at.frame().ng, ls.point);
                    let light = Some(index as u32);
                    start.transmittance_through(self.scene, &shadow, light, &mut cx.counters.rays)
                } else {
                    start.transmittance_in_scene(self.scene, ls.distance)
                }
            }
            Some(_) if !blocked => Vec3::ONE,
            Some((v, medium)) => {
                let shadow = shadow_ray(sp, at.frame().ng, ls.point);
                let start = medium.after(self.scene, v, ls.wi);
                shadow_transmittance(self.scene, true, &shadow, start, cx.counters)
            }
        };
        let blocked = transmittance == Vec3::ZERO;
        let c = if blocked {
            Vec3::ZERO
        } else {
            // MIS-weighted (the BSDF's pdf only for visible lights). |cos θ|: a light seen
            // through a transmitting non-delta lobe (rough glass) lies below the shading
            // normal, where the signed cosine would subtract its light.
            let w = if ls.delta || !may_scatter {
                1.0
            } else {
                power_heuristic(ls.pdf * pmf, at.pdf(ls.wi))
            };
            let c = f * (at.frame().ns.dot(ls.wi).abs() * w / (ls.pdf * pmf)) * ls.radiance;
            // Without `through` the transmittance is 1: the same bytes without the product.
            if through.is_some() {
                c * transmittance
            } else {
                c
            }
        };
        if O::ACTIVE {
            let record = ShadowRecord {
                light: index,
                dir: ls.wi,
                occluded: blocked,
                contribution: c,
                blocker: None,
            };
            cx.observer.shadow(node, record);
        }
        c
    }
}

impl PathTracer<'_> {
    /// Next-event estimation at a medium vertex `p` (light arrived travelling along unit
    /// `d_in`) in medium `m`, where the path's volumes are `medium`: light `index` (chosen with
    /// probability `pmf`) sampled from `u`, scattered by the phase function, attenuated by the
    /// media and interfaces on the way ([`Medium::transmittance_through`]) and MIS-weighted
    /// against phase sampling by the power heuristic.
    #[allow(clippy::too_many_arguments)]
    fn direct_in_medium<O: PathObserver>(
        &self,
        p: Vec3,
        d_in: Vec3,
        m: &HomogeneousMedium,
        medium: Medium,
        index: usize,
        pmf: f32,
        u: (f32, f32),
        cx: &mut Context<'_, O>,
    ) -> Vec3 {
        let scene = self.scene;
        let Some(ls) = scene.lights[index].sample_li(p, u) else {
            return Vec3::ZERO;
        };
        if !(ls.pdf > 0.0) {
            return Vec3::ZERO;
        }
        let phase = m.phase.p(d_in, ls.wi);
        let w = if ls.delta {
            1.0
        } else {
            power_heuristic(ls.pdf * pmf, phase)
        };
        let shadow = Ray {
            origin: p,
            dir: ls.point - p,
            t_max: 1.0 - SHADOW_EPSILON,
        };
        let light = Some(index as u32);
        let tr = medium.transmittance_through(scene, &shadow, light, &mut cx.counters.rays);
        ls.radiance * tr * (phase * w / (ls.pdf * pmf))
    }
}

impl<'a> super::Estimator<'a> for PathTracer<'a> {
    fn li_parts<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
        self.li(ray, cx)
    }
}
