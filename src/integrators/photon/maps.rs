//! Building the caustic and global photon maps: emission budgets per light, photon paths traced
//! in parallel batches with rayon, and the kd-trees. Deterministic: every photon draws from the
//! sampler stream keyed by (seed, map, light, photon index), and batches are concatenated in
//! index order, so the maps are the same for any thread count. A raised cancel flag
//! ([`MapScene::cancel`], the render's Ctrl-C flag) stops tracing within a photon and skips
//! the kd-trees and the irradiance; the maps are then marked [`PhotonSummary::cancelled`].

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::Vec3;
use rayon::prelude::*;

use super::aim::CausticTargets;
use super::emit::{LightEmitter, split_by_power};
use super::estimate::{IrradianceCache, Kernel, PhotonMap};
use super::trace::{MapKind, TraceCounts, TraceSettings, trace_photon_into};
use super::volume::{VolumeMap, VolumePhoton};
use super::walls::Walls;
use crate::render_scene::RenderScene;
use crate::sampling::Sampler;
use crate::sampling::rng::mix64;
use crate::spatial::{KdTree, Photon};

/// The pass number whose photon streams make the pilot maps of the radius fields (`passes.rs`). Sample
/// indices are below the `u32` sample count, so no pass of a render is ever this one.
pub const PILOT_PASS: u32 = u32::MAX;

/// Photons per parallel work item.
const BATCH: u64 = 2048;

/// How the maps of one render were built, for the summary.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PhotonSummary {
    /// Per light: caustic-map counts.
    pub caustic: Vec<TraceCounts>,
    /// Per light: global-map counts.
    pub global: Vec<TraceCounts>,
    /// Why a map was not built (`None`: built).
    pub caustic_skipped: Option<String>,
    /// Why the global map was not built.
    pub global_skipped: Option<String>,
    /// Specular objects caustic photons were aimed at.
    pub targets: usize,
    /// Largest estimate radius of each map (scene units; 0 when not built).
    pub caustic_radius: f32,
    /// Largest estimate radius of the global map.
    pub global_radius: f32,
    /// True when the radii were chosen from the scene (no `photons.max_radius`).
    pub auto_radius: bool,
    /// Time spent tracing photons.
    pub trace_time: Duration,
    /// Time spent building kd-trees.
    pub build_time: Duration,
    /// Time spent precomputing irradiance for final gathering.
    pub irradiance_time: Duration,
    /// Irradiance points precomputed.
    pub irradiance_points: usize,
    /// Bytes of both maps.
    pub memory: usize,
    /// What the photon-map cache did (`--photon-cache`), as the summary's last line.
    pub cache: Option<String>,
    /// The cancel flag stopped the build: the maps are incomplete and must not be used or
    /// saved.
    pub cancelled: bool,
}

impl PhotonSummary {
    /// Sum over lights of one map's counts.
    #[must_use]
    pub fn total(per_light: &[TraceCounts]) -> TraceCounts {
        let mut t = TraceCounts::default();
        for c in per_light {
            t.add(c);
        }
        t
    }
}

impl std::fmt::Display for PhotonSummary {
    /// The summary a render prints: per map, per light, photons emitted, (caustic) reaching a
    /// specular object, stored, and the stored flux; each map's radius, memory and timings.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let map_line = |f: &mut std::fmt::Formatter<'_>,
                        name: &str,
                        per_light: &[TraceCounts],
                        skipped: &Option<String>,
                        radius: f32|
         -> std::fmt::Result {
            if let Some(why) = skipped {
                return writeln!(f, "photons: no {name} map ({why})");
            }
            let t = PhotonSummary::total(per_light);
            writeln!(
                f,
                "photons: {name} map: {} stored of {} emitted, max radius {radius:.4}{}; {}",
                t.stored,
                t.emitted,
                if self.auto_radius {
                    " (from the scene's size)"
                } else {
                    ""
                },
                if name == "caustic" {
                    "only photons that reach a diffuse surface through mirrors or glass are stored, and they alone draw the caustics: few stored means blotchy caustics (raise --caustic-photons)"
                } else {
                    "stored photons carry the indirect light: few stored means blotchy indirect light (raise --photons)"
                }
            )?;
            for (i, c) in per_light.iter().enumerate() {
                if c.emitted == 0 {
                    continue;
                }
                write!(f, "  lights[{i}]: {} emitted", c.emitted)?;
                if name == "caustic" {
                    write!(f, ", {} reached a specular object", c.reached_specular)?;
                }
                writeln!(
                    f,
                    ", {} stored ({:.4} W stored{})",
                    c.stored,
                    mean_flux(c.stored_flux),
                    if c.lost_at_depth > 0 {
                        format!(
                            ", {} cut by max_bounces, which would have stored {:.4} W more, {:.2} % of the flux stored",
                            c.lost_at_depth,
                            mean_flux(c.lost_flux),
                            100.0 * mean_flux(c.lost_flux)
                                / mean_flux(c.stored_flux).max(f32::MIN_POSITIVE)
                        )
                    } else {
                        String::new()
                    }
                )?;
            }
            Ok(())
        };
        map_line(
            f,
            "caustic",
            &self.caustic,
            &self.caustic_skipped,
            self.caustic_radius,
        )?;
        map_line(
            f,
            "global",
            &self.global,
            &self.global_skipped,
            self.global_radius,
        )?;
        let volume = PhotonSummary::total(&self.caustic).volume_stored;
        if volume > 0 {
            writeln!(
                f,
                "photons: volume caustic map: {volume} stored where caustic paths scatter in a medium (light → specular⁺ → medium)"
            )?;
        }
        if self.irradiance_points > 0 {
            writeln!(
                f,
                "photons: irradiance precomputed at {} points in {:.3} s (final gathering)",
                self.irradiance_points,
                self.irradiance_time.as_secs_f64()
            )?;
        }
        write!(
            f,
            "photons: traced in {:.3} s, kd-trees built in {:.3} s, {:.1} MB ({} targets for caustic photons)",
            self.trace_time.as_secs_f64(),
            self.build_time.as_secs_f64(),
            self.memory as f64 / 1e6,
            self.targets
        )?;
        match &self.cache {
            Some(line) => write!(f, "\n{line}"),
            None => Ok(()),
        }
    }
}

/// Stream keys of photon paths: distinct per map, light and progressive pass, never shared
/// with pixels.
fn stream(kind: MapKind, light: usize, pass: Option<u32>) -> u64 {
    let k = match kind {
        MapKind::Caustic => 1u64,
        MapKind::Global => 2,
    };
    let key = (k << 40) | light as u64;
    match pass {
        None => key,
        Some(p) => key ^ mix64(u64::from(p).wrapping_add(0x9E37_79B9_7F4A_7C15)) & !(1 << 48),
    }
}

/// Stream key of the per-(map, light, pass) lattice rotation.
fn rotation_stream(kind: MapKind, light: usize, pass: Option<u32>) -> u64 {
    stream(kind, light, pass) | (1 << 48)
}

/// Traces `emitters`' photons (light `l`'s from stream (settings' map, `l`), caustic ones aimed
/// at `targets`) into one flat list in (light, index) order, with per-light counts. Parallel
/// batches; the same result for any thread count. When `cancel` is raised, every batch stops
/// before its next photon and the list is incomplete (the caller checks the flag).
pub fn trace_map(
    scene: &RenderScene,
    emitters: &[LightEmitter],
    targets: &CausticTargets,
    settings: TraceSettings,
    cancel: Option<&AtomicBool>,
) -> (Vec<Photon>, Vec<TraceCounts>) {
    let (photons, _, counts) = trace_map_with_volume(
        scene,
        emitters,
        targets,
        settings,
        scene.params.seed,
        false,
        cancel,
    );
    (photons, counts)
}

/// [`trace_map`] with the photon streams of `seed` instead of the render's (a progressive
/// render's pilot maps with [`crate::render_scene::PhotonParams::pilot_seed`]), also storing
/// the caustic paths' volume photons when `volume` is true ([`trace_photon_into`]), in the same
/// (light, index) order: the same list for any thread count.
pub fn trace_map_with_volume(
    scene: &RenderScene,
    emitters: &[LightEmitter],
    targets: &CausticTargets,
    settings: TraceSettings,
    seed: u64,
    volume: bool,
    cancel: Option<&AtomicBool>,
) -> (Vec<Photon>, Vec<VolumePhoton>, Vec<TraceCounts>) {
    let jobs: Vec<(usize, u64, u64)> = emitters
        .iter()
        .enumerate()
        .flat_map(|(l, e)| {
            (0..e.count.div_ceil(BATCH))
                .map(move |b| (l, b * BATCH, ((b + 1) * BATCH).min(e.count)))
        })
        .collect();
    let params = &scene.params;
    let results: Vec<(usize, Vec<Photon>, Vec<VolumePhoton>, TraceCounts)> = jobs
        .par_iter()
        .map(|&(l, start, end)| {
            let mut sampler = Sampler::new(params.sampler, seed, 1);
            let mut out = Vec::new();
            let mut vol = Vec::new();
            let mut counts = TraceCounts::default();
            let mut cones = Vec::new();
            let e = &emitters[l];
            for i in start..end {
                if is_raised(cancel) {
                    break;
                }
                sampler.start_stream(stream(settings.kind, l, settings.pass), i);
                counts.emitted += 1;
                let emitted = match settings.kind {
                    MapKind::Global => e.global(i, &mut sampler),
                    MapKind::Caustic => e.caustic(targets, &mut sampler, &mut cones),
                };
                if let Some((ray, power)) = emitted {
                    trace_photon_into(
                        scene,
                        ray,
                        power,
                        settings,
                        &mut sampler,
                        &mut out,
                        volume.then_some(&mut vol),
                        &mut counts,
                    );
                }
            }
            (l, out, vol, counts)
        })
        .collect();
    let mut per_light = vec![TraceCounts::default(); emitters.len()];
    let total: usize = results.iter().map(|r| r.1.len()).sum();
    let total_volume: usize = results.iter().map(|r| r.2.len()).sum();
    let mut photons = Vec::with_capacity(total);
    let mut volume_photons = Vec::with_capacity(total_volume);
    for (l, out, vol, counts) in results {
        per_light[l].add(&counts);
        photons.extend_from_slice(&out);
        volume_photons.extend_from_slice(&vol);
    }
    (photons, volume_photons, per_light)
}

/// Whether the cancel flag `cancel` is raised.
#[inline]
pub(super) fn is_raised(cancel: Option<&AtomicBool>) -> bool {
    cancel.is_some_and(|c| c.load(Ordering::Relaxed))
}

/// The diffuse surface area (m²) photons can land on: triangles and spheres of objects whose
/// material has a diffuse part (ellipsoids by their bounding sphere's area, an upper bound).
pub(super) fn diffuse_area(scene: &RenderScene) -> f64 {
    let diffuse = |o: u32| {
        scene.objects[o as usize]
            .material
            .is_some_and(|m| scene.materials[m as usize].bsdf.has_local())
    };
    let g = &scene.geometry;
    let mut area = 0.0f64;
    for (t, a) in g.triangles.iter().zip(&g.tri_attrs) {
        if diffuse(a.object) {
            area += 0.5 * f64::from((t[1] - t[0]).cross(t[2] - t[0]).length());
        }
    }
    for s in &g.spheres {
        if diffuse(s.object) {
            area += 4.0 * std::f64::consts::PI * f64::from(s.radius).powi(2);
        }
    }
    for e in &g.ellipsoids {
        if diffuse(e.object) {
            let m = e.world_from_object.matrix3;
            let r = m
                .x_axis
                .length()
                .max(m.y_axis.length())
                .max(m.z_axis.length());
            area += 4.0 * std::f64::consts::PI * r * r;
        }
    }
    for q in &g.quadrics {
        if diffuse(q.object) {
            area += q.area();
        }
    }
    area
}

/// The largest radius of a `kind` map of `stored` photons gathered `k` at a time, from the
/// radius of the disc that holds `k` photons on average when they spread over `area`: twice
/// that for the global map (typical regions are never cut; sparse ones are, rather than
/// blurring a few photons over a wide disc), once for the caustic map, whose photons crowd
/// into the few places light is focused (elsewhere a wide search only finds stray photons and
/// costs time).
#[must_use]
pub fn auto_radius(area: f64, stored: u64, k: u32, kind: MapKind) -> f32 {
    if stored == 0 || !(area > 0.0) {
        return 0.0;
    }
    let factor = match kind {
        MapKind::Global => 2.0,
        MapKind::Caustic => 1.0,
    };
    (factor * (f64::from(k) * area / (std::f64::consts::PI * stored as f64)).sqrt()) as f32
}

/// Both maps of a render (each `None` when not built) and how they were built.
#[derive(Debug, Default)]
pub struct PhotonMaps {
    /// Light → specular⁺ → diffuse photons.
    pub caustic: Option<PhotonMap>,
    /// Photons after at least `min_bounces` diffuse bounces.
    pub global: Option<PhotonMap>,
    /// Both maps' irradiance at a subset of photons, for final gathering (built only when
    /// `final_gather > 0`).
    pub irradiance: Option<IrradianceCache>,
    /// The caustic paths' volume photons as traced (with [`MapSet::volume`]), before a
    /// progressive pass gives them radii and makes them [`PhotonMaps::volume`].
    pub volume_photons: Vec<VolumePhoton>,
    /// The volume caustic map the camera paths read (`volume.rs`; built by the progressive
    /// passes, `None` without volume photons).
    pub volume: Option<VolumeMap>,
    /// Counts, radii and timings.
    pub summary: PhotonSummary,
}

/// Traces and builds the maps the scene's `photons` settings ask for.
#[must_use]
pub fn build_maps(scene: &RenderScene) -> PhotonMaps {
    build_maps_cancellable(scene, None)
}

/// [`build_maps`], stopping soon after `cancel` is raised (the maps are then
/// [`PhotonSummary::cancelled`]).
#[must_use]
pub fn build_maps_cancellable(scene: &RenderScene, cancel: Option<Arc<AtomicBool>>) -> PhotonMaps {
    let all = MapSet {
        caustic: true,
        global: true,
        global_any_bounce: false,
        near_specular: None,
        volume: false,
    };
    let mut prepared = MapScene::new(scene, all);
    prepared.cancel = cancel;
    build_maps_with(scene, &prepared, None, all)
}

/// What every build of a scene's maps needs and no pass changes: where caustic photons are
/// aimed and the diffuse area the automatic radius spreads photons over. Made once per render
/// (progressive integrators build maps every pass).
#[derive(Debug, Clone)]
pub struct MapScene {
    /// Objects that reflect or transmit.
    pub targets: CausticTargets,
    /// Diffuse surface area, m² ([`diffuse_area`]).
    pub area: f64,
    /// The render's cancel flag (Ctrl-C): raised, it stops photon tracing within a photon.
    pub cancel: Option<Arc<AtomicBool>>,
}

impl MapScene {
    /// Finds the targets (with near-specular objects when `set` says so) and sums the diffuse
    /// area of `scene`.
    #[must_use]
    pub fn new(scene: &RenderScene, set: MapSet) -> Self {
        Self {
            targets: CausticTargets::new(scene, set.near_specular),
            area: diffuse_area(scene),
            cancel: None,
        }
    }
}

/// Which maps to build.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapSet {
    /// Light → specular⁺ → diffuse photons.
    pub caustic: bool,
    /// Diffuse landings after `min_bounces` diffuse bounces.
    pub global: bool,
    /// The global map stores every landing after a first bounce of any kind (mirror and glass
    /// ones too): it then also holds the caustics, and is read alone where all the light that
    /// arrives after a bounce is wanted (`path-ppm`'s second diffuse vertex).
    pub global_any_bounce: bool,
    /// Near-specular surfaces (GGX α up to this) are specular for photon paths
    /// ([`TraceSettings::near_specular`]); `None`: only delta lobes are.
    pub near_specular: Option<f32>,
    /// Caustic paths also store volume photons where they scatter in a medium (the volume
    /// caustic map of the progressive integrators, `volume.rs`).
    pub volume: bool,
}

/// Traces and builds the caustic and/or global maps of the scene's `photons` settings from the
/// photon streams of progressive pass `pass` (`None`: the photon integrator's one set; only
/// then is irradiance precomputed for final gathering). Maps estimate from k nearest photons
/// within an automatic or given largest radius; progressive integrators then fix the radius.
#[must_use]
pub fn build_maps_with(
    scene: &RenderScene,
    prepared: &MapScene,
    pass: Option<u32>,
    set: MapSet,
) -> PhotonMaps {
    let p = &scene.params.photons;
    let mut summary = PhotonSummary::default();
    let weights: Vec<f64> = scene
        .lights
        .iter()
        .map(|l| {
            let w = l.power();
            f64::from((w.x + w.y + w.z) / 3.0)
        })
        .collect();
    let targets = &prepared.targets;
    let cancel = prepared.cancel.as_deref();
    summary.targets = targets.len();
    // The pilot maps of a progressive render may take their own seed (a golden check's).
    let seed = match (pass, p.pilot_seed) {
        (Some(PILOT_PASS), Some(pilot)) => pilot,
        _ => scene.params.seed,
    };
    let mut sampler = Sampler::new(scene.params.sampler, seed, 1);

    // Caustic budgets: lights with their own count keep it; the rest share `caustic` by power.
    let shared: Vec<f64> = weights
        .iter()
        .zip(&p.caustic_per_light)
        .map(|(&w, own)| if own.is_some() { 0.0 } else { w })
        .collect();
    let mut caustic_counts = split_by_power(u64::from(p.caustic), &shared);
    for (c, own) in caustic_counts.iter_mut().zip(&p.caustic_per_light) {
        if let Some(n) = own {
            *c = u64::from(*n);
        }
    }
    let global_counts = split_by_power(u64::from(p.global), &weights);
    let emitters = |kind: MapKind, counts: &[u64], sampler: &mut Sampler| -> Vec<LightEmitter> {
        scene
            .lights
            .iter()
            .zip(counts)
            .enumerate()
            .map(|(l, (light, &n))| {
                LightEmitter::new(light.clone(), n, sampler, rotation_stream(kind, l, pass))
            })
            .collect()
    };
    let area = prepared.area;
    summary.auto_radius = p.max_radius.is_none();

    let t0 = Instant::now();
    let mut volume_photons = Vec::new();
    let mut build_time = Duration::ZERO;
    let mut memory = 0;
    let caustic = if !set.caustic {
        summary.caustic_skipped = Some("not used by this integrator".into());
        None
    } else if targets.is_empty() {
        summary.caustic_skipped = Some("no object reflects or transmits".into());
        None
    } else if caustic_counts.iter().all(|&c| c == 0) {
        summary.caustic_skipped = Some("0 caustic photons".into());
        None
    } else {
        let e = emitters(MapKind::Caustic, &caustic_counts, &mut sampler);
        let settings = TraceSettings {
            kind: MapKind::Caustic,
            min_bounces: 0,
            any_bounce: false,
            max_bounces: p.max_bounces,
            pass,
            near_specular: set.near_specular,
        };
        let (photons, volume, counts) =
            trace_map_with_volume(scene, &e, targets, settings, seed, set.volume, cancel);
        volume_photons = volume;
        summary.caustic = counts;
        if is_raised(cancel) {
            return cancelled(summary);
        }
        finish_map(
            pass.is_none().then(|| Walls::of(scene, None)),
            photons,
            MapKind::Caustic,
            p.caustic_gather,
            p.max_radius,
            area,
            match p.caustic_cone {
                Some(k) => Kernel::Cone(k),
                None => Kernel::Box,
            },
            &mut summary.caustic_skipped,
            &mut summary.caustic_radius,
            &mut build_time,
            &mut memory,
        )
    };
    let global = if !set.global {
        summary.global_skipped = Some("not used by this integrator".into());
        None
    } else if global_counts.iter().all(|&c| c == 0) {
        summary.global_skipped = Some("0 global photons".into());
        None
    } else {
        let e = emitters(MapKind::Global, &global_counts, &mut sampler);
        let settings = TraceSettings {
            kind: MapKind::Global,
            // Progressive integrators read the global map for all light after a diffuse bounce.
            min_bounces: if pass.is_some() { 1 } else { p.min_bounces },
            any_bounce: set.global_any_bounce,
            max_bounces: p.max_bounces,
            pass,
            near_specular: set.near_specular,
        };
        let (photons, _, counts) =
            trace_map_with_volume(scene, &e, targets, settings, seed, false, cancel);
        summary.global = counts;
        if is_raised(cancel) {
            return cancelled(summary);
        }
        finish_map(
            pass.is_none().then(|| Walls::of(scene, None)),
            photons,
            MapKind::Global,
            p.gather,
            p.max_radius,
            area,
            Kernel::Box,
            &mut summary.global_skipped,
            &mut summary.global_radius,
            &mut build_time,
            &mut memory,
        )
    };
    summary.trace_time = t0.elapsed().saturating_sub(build_time);
    summary.build_time = build_time;
    summary.memory = memory;
    let (mut caustic, mut global) = (caustic, global);
    let irradiance = if pass.is_none() {
        use_photon_discs(scene, &mut caustic, &mut global, &mut summary);
        precompute_irradiance(scene, &caustic, &global, &mut summary, cancel)
    } else {
        None
    };
    if is_raised(cancel) {
        return cancelled(summary);
    }
    PhotonMaps {
        caustic,
        global,
        irradiance,
        volume_photons,
        volume: None,
        summary,
    }
}

/// No maps, marked cancelled (what a build stopped by its cancel flag returns).
fn cancelled(mut summary: PhotonSummary) -> PhotonMaps {
    summary.cancelled = true;
    PhotonMaps {
        summary,
        ..PhotonMaps::default()
    }
}

/// Gives the photon integrator's maps (not a progressive pass's) their photons' discs
/// ([`PhotonMap::use_photon_discs`]: the sample-point estimate, which keeps each region's flux),
/// adding the time to `summary`'s build time and the bytes to its memory; each disc's wall mark
/// is made for its own radius against `scene`'s surfaces. Used by [`build_maps`] and by the
/// photon-map cache after loading the maps.
pub(super) fn use_photon_discs(
    scene: &RenderScene,
    caustic: &mut Option<PhotonMap>,
    global: &mut Option<PhotonMap>,
    summary: &mut PhotonSummary,
) {
    let t = Instant::now();
    for map in [caustic, global].into_iter().flatten() {
        let before = map.memory_bytes();
        map.use_photon_discs(Walls::of(scene, None));
        summary.memory += map.memory_bytes() - before;
    }
    summary.build_time += t.elapsed();
}

/// The irradiance final gathering reads, precomputed from the built (or cached) maps: `None`
/// when `final_gather` is 0, no map was built, or `cancel` was raised. Adds its time, points
/// and memory to `summary`. Used by [`build_maps`] and by the photon-map cache after loading
/// the maps.
pub(super) fn precompute_irradiance(
    scene: &RenderScene,
    caustic: &Option<PhotonMap>,
    global: &Option<PhotonMap>,
    summary: &mut PhotonSummary,
    cancel: Option<&AtomicBool>,
) -> Option<IrradianceCache> {
    let t1 = Instant::now();
    let irradiance = if scene.params.photons.final_gather > 0 {
        let maps: Vec<&PhotonMap> = [caustic, global].into_iter().flatten().collect();
        global
            .as_ref()
            .or(caustic.as_ref())
            .and_then(|sites| IrradianceCache::build(sites, &maps, Walls::of(scene, None), cancel))
    } else {
        None
    };
    summary.irradiance_time = t1.elapsed();
    summary.irradiance_points = irradiance.as_ref().map_or(0, IrradianceCache::len);
    summary.memory += irradiance.as_ref().map_or(0, IrradianceCache::memory_bytes);
    irradiance
}

/// Builds the kd-tree of one map's photons, or says why there is none; with `walls`, marks its
/// photons near walls ([`PhotonMap::mark_walls`]). A progressive pass's maps (and the pilot,
/// which makes no estimate) are marked later, for the pass's own radii
/// ([`PhotonMap::set_pass_lookup`]): marking them here for the largest radius first cost a
/// second BVH region query per photon for nothing.
#[allow(clippy::too_many_arguments)]
fn finish_map(
    walls: Option<Walls<'_>>,
    photons: Vec<Photon>,
    kind: MapKind,
    k: u32,
    max_radius: Option<f32>,
    area: f64,
    kernel: Kernel,
    skipped: &mut Option<String>,
    radius: &mut f32,
    build_time: &mut Duration,
    memory: &mut usize,
) -> Option<PhotonMap> {
    if photons.is_empty() {
        *skipped = Some("no photon was stored".into());
        return None;
    }
    let r = max_radius.unwrap_or_else(|| auto_radius(area, photons.len() as u64, k, kind));
    let t = Instant::now();
    let tree = match KdTree::build(photons) {
        Ok(t) => t,
        Err(e) => {
            *skipped = Some(e.to_string());
            return None;
        }
    };
    *memory += tree.memory_bytes();
    *radius = r;
    let mut map = PhotonMap::new(tree, k as usize, r, kernel);
    if let Some(walls) = walls {
        map.mark_walls(walls);
    }
    *build_time += t.elapsed();
    Some(map)
}

/// Mean of a flux's channels (W).
#[must_use]
pub fn mean_flux(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}
