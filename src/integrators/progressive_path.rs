//! The progressive integrators: camera paths of the path tracer reading per-pass photon maps
//! ([`ProgressivePhotons`]) whose radius shrinks by Knaus & Zwicker's schedule ("Progressive
//! Photon Mapping: A Probabilistic Approach", ACM ToG 30(3), 2011; the progressive idea is
//! Hachisuka, Ogaki & Jensen, "Progressive Photon Mapping", SIGGRAPH Asia 2008). Sample index
//! `i` of every pixel is pass `i`, so passes render anywhere and merge. Two integrators:
//!
//! - **`ppm`** (progressive photon mapping): mirror and glass chains are followed to the first
//!   diffuse vertex, which reads direct light by a shadow ray and the caustic and global maps
//!   (all the emitters' light); the path goes on only for the background's light (photons do
//!   not carry it). Caustics of point lights included, the image converges to the exact one.
//! - **`path-ppm`** (path tracing with progressive photon maps, the split of the report's two
//!   maps made consistent): the path tracer, with caustics (light → specular⁺ → diffuse) from
//!   the caustic map at every diffuse vertex instead of from emitters hit by chance through
//!   glass or water (the fireflies of path tracing; never for point lights), and, with global
//!   photons, all bounced light from the global map at the second diffuse vertex (final
//!   gathering with one ray per sample). That map stores photons after any first bounce,
//!   caustics included, so the vertex makes one estimate.
//!
//! Both are [`PathTracer::li_with_maps`] with different [`PathMaps`]; the parts are disjoint
//! and together make every path, so the images converge to the path tracer's.

use super::context::{Context, PathObserver};
use super::path::PathMaps;
use super::photon::{MapSet, ProgressivePhotons};
use super::{PathTracer, Radiance};
use crate::geometry::Ray;
use crate::render_scene::RenderScene;
use crate::shading::NEAR_SPECULAR_ALPHA;

/// Specular vertices at which the progressive integrators split their camera paths
/// ([`PathTracer::with_specular_splits`]): at most 4 branches per camera sample. Light reaching
/// the camera through water or glass (the light's image in it) is then followed along both
/// Fresnel branches instead of being found by one sample in ~1/F, the fireflies of issue #24.
pub const SPECULAR_SPLITS: u32 = 2;

/// A progressive integrator: the current pass's maps and the camera paths that read them.
#[derive(Debug)]
pub struct ProgressivePath<'a> {
    photons: ProgressivePhotons<'a>,
    path: PathTracer<'a>,
    /// Diffuse bounces before the vertex that reads the global map.
    global_at: u32,
    /// The global map holds caustics too (`path-ppm`).
    global_has_caustics: bool,
    /// The maps' near-specular width ([`MapSet::near_specular`]).
    near_specular: Option<f32>,
    /// Per light: the current pass's caustic map holds its photons.
    caustic_lights: Vec<bool>,
}

impl<'a> ProgressivePath<'a> {
    /// Progressive photon mapping (`ppm`): caustic and global maps read at the first diffuse
    /// vertex. No maps yet: [`ProgressivePath::begin_pass`] builds each pass's.
    #[must_use]
    pub fn ppm(scene: &'a RenderScene) -> Self {
        let set = MapSet {
            caustic: true,
            global: true,
            global_any_bounce: false,
            near_specular: Some(NEAR_SPECULAR_ALPHA),
            volume: scatters(scene),
        };
        Self::new(scene, set, 0)
    }

    /// Path tracing with progressive photon maps (`path-ppm`): the caustic map at every
    /// diffuse vertex, the global map (with `photons.global` > 0) after one diffuse bounce.
    #[must_use]
    pub fn path_ppm(scene: &'a RenderScene) -> Self {
        let set = MapSet {
            caustic: true,
            global: scene.params.photons.global > 0,
            global_any_bounce: true,
            near_specular: Some(NEAR_SPECULAR_ALPHA),
            volume: scatters(scene),
        };
        Self::new(scene, set, 1)
    }

    fn new(scene: &'a RenderScene, set: MapSet, global_at: u32) -> Self {
        Self {
            photons: ProgressivePhotons::new(scene, set),
            path: PathTracer::new(scene).with_specular_splits(SPECULAR_SPLITS),
            global_at,
            global_has_caustics: set.global_any_bounce,
            near_specular: set.near_specular,
            caustic_lights: Vec::new(),
        }
    }

    /// The passes' photon maps.
    #[must_use]
    pub fn photons(&self) -> &ProgressivePhotons<'a> {
        &self.photons
    }

    /// This integrator, whose every later pass's photon tracing stops soon after `cancel`
    /// (Ctrl-C) is raised.
    #[must_use]
    pub fn with_cancel(
        mut self,
        cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    ) -> Self {
        self.photons.set_cancel(cancel);
        self
    }

    /// Makes the maps those of pass `pass` (the sample index about to be taken).
    pub fn begin_pass(&mut self, pass: u32) {
        self.photons.begin_pass(pass);
        let m = self.photons.maps();
        self.caustic_lights.clear();
        self.caustic_lights
            .extend(m.summary.caustic.iter().map(|c| c.emitted > 0));
    }

    /// Radiance along camera ray `ray` from the current pass's maps.
    pub fn li<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
        let m = self.photons.maps();
        let maps = PathMaps {
            caustic: m.caustic.as_ref(),
            global: m.global.as_ref(),
            global_at: self.global_at,
            global_has_caustics: self.global_has_caustics,
            near_specular: self.near_specular,
            caustic_lights: &self.caustic_lights,
            volume: m.volume.as_ref(),
        };
        self.path.li_with_maps(maps, ray, cx)
    }
}

/// True if the scene has a medium that scatters: then caustic photons also store volume
/// photons (the volume caustic map, `photon/volume.rs`), and camera paths read it.
fn scatters(scene: &RenderScene) -> bool {
    scene.volumetric && scene.media.iter().any(|m| m.scatters())
}

impl<'a> super::Estimator<'a> for ProgressivePath<'a> {
    fn li_parts<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
        self.li(ray, cx)
    }

    fn photon_maps(&self) -> Option<&super::photon::PhotonMaps> {
        Some(self.photons.maps())
    }

    fn progressive(&self) -> Option<&ProgressivePhotons<'a>> {
        Some(&self.photons)
    }

    fn begin_pass(&mut self, sample: u32) {
        ProgressivePath::begin_pass(self, sample);
    }
}
