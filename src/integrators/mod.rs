//! Light-transport algorithms over the compiled scene: a closed set dispatched through an enum
//! (no virtual calls per sample, as pbrt-v4's tagged integrators), each prepared once per render
//! and then asked for the radiance of camera samples by every worker.

pub mod path;
pub mod photon;
pub mod progressive;
pub mod shadow;
pub mod splat;
pub mod trace_log;
pub mod whitted;

pub use path::PathTracer;
pub use photon::PhotonMapper;
pub use progressive::ProgressivePath;
pub use trace_log::TraceLog;
pub use whitted::Whitted;

use glam::Vec3;

use crate::geometry::Ray;
use crate::render_scene::{IntegratorKind, RenderScene};
use crate::sampling::Sampler;

/// Rays an integrator traced; each render worker owns one and the renderer sums them (samples
/// and NaN/Inf counts are the renderer's own).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Rays traced (camera, scattered and shadow).
    pub rays: u64,
    /// Photon-map density estimates made.
    pub photon_estimates: u64,
    /// Estimates whose k-nearest search the largest radius cut short.
    pub photon_radius_cut: u64,
}

impl Counters {
    /// Adds `other` into `self`.
    pub fn add(&mut self, other: &Counters) {
        self.rays += other.rays;
        self.photon_estimates += other.photon_estimates;
        self.photon_radius_cut += other.photon_radius_cut;
    }
}

/// How the light of a camera sample reached the camera, by the non-delta (diffuse or glossy)
/// scattering events on its way, counted from the camera: the EXR layers of `--layers`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightPath {
    /// None: emitters and the background seen directly or through mirrors and glass.
    Specular = 0,
    /// One, lit straight from an emitter or the background (seen directly or in a mirror).
    Direct = 1,
    /// One, lit through mirrors or glass (light → specular⁺ → diffuse: caustics).
    Caustic = 2,
    /// Two or more.
    Indirect = 3,
}

impl LightPath {
    /// Every kind, in layer order.
    pub const ALL: [LightPath; 4] = [
        LightPath::Specular,
        LightPath::Direct,
        LightPath::Caustic,
        LightPath::Indirect,
    ];

    /// The kind of light that reached the camera after `k` non-delta scattering events,
    /// `via_specular` when it arrived at the first of them through a mirror or glass.
    #[inline]
    #[must_use]
    pub fn classify(k: u32, via_specular: bool) -> Self {
        match k {
            0 => LightPath::Specular,
            1 if via_specular => LightPath::Caustic,
            1 => LightPath::Direct,
            _ => LightPath::Indirect,
        }
    }

    /// The layer's name (`--layers` and the EXR channel prefix).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            LightPath::Specular => "specular",
            LightPath::Direct => "direct",
            LightPath::Caustic => "caustic",
            LightPath::Indirect => "indirect",
        }
    }
}

/// A camera sample's radiance (W·m⁻²·sr⁻¹ per channel) split by [`LightPath`]; the parts sum
/// to the sample's value.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Radiance {
    /// Indexed by `LightPath as usize`.
    pub parts: [Vec3; 4],
}

impl Radiance {
    /// Adds `v` to the part `kind`.
    #[inline]
    pub fn add(&mut self, kind: LightPath, v: Vec3) {
        self.parts[kind as usize] += v;
    }

    /// The sum of the parts.
    #[inline]
    #[must_use]
    pub fn total(&self) -> Vec3 {
        self.parts[0] + self.parts[1] + self.parts[2] + self.parts[3]
    }

    /// Adds every part of `other` scaled by `w`.
    #[inline]
    pub fn add_scaled(&mut self, other: &Radiance, w: Vec3) {
        for (a, b) in self.parts.iter_mut().zip(&other.parts) {
            *a += *b * w;
        }
    }
}

/// A prepared integrator: shared, immutable state built once per render (light selection
/// tables today; photon maps later), read by every worker.
#[derive(Debug)]
pub enum Integrator<'a> {
    /// Recursive ray tracing ([`Whitted`]).
    Whitted(Whitted<'a>),
    /// Unidirectional path tracing with next-event estimation ([`PathTracer`]).
    Path(PathTracer<'a>),
    /// Photon mapping ([`PhotonMapper`]); its maps are built by `prepare`.
    Photon(Box<PhotonMapper<'a>>),
    /// Progressive photon mapping ([`ProgressivePath::ppm`]); fresh maps every pass.
    Ppm(Box<ProgressivePath<'a>>),
    /// Path tracing with progressive photon maps ([`ProgressivePath::path_ppm`]).
    PathPpm(Box<ProgressivePath<'a>>),
}

impl<'a> Integrator<'a> {
    /// Prepares the integrator the scene asks for (`render.integrator`).
    #[must_use]
    pub fn prepare(scene: &'a RenderScene) -> Self {
        Self::prepare_with(scene, None)
    }

    /// [`Integrator::prepare`], with photon maps read from and saved to the cache folder
    /// `photon_cache` (`--photon-cache`; see [`photon::cache`]).
    #[must_use]
    pub fn prepare_with(scene: &'a RenderScene, photon_cache: Option<&std::path::Path>) -> Self {
        Self::prepare_cancellable(scene, photon_cache, None)
    }

    /// [`Integrator::prepare_with`], whose photon tracing (the photon integrator's maps here,
    /// a progressive one's in every [`Integrator::begin_pass`]) stops soon after `cancel` is
    /// raised; check the flag before rendering with the result.
    #[must_use]
    pub fn prepare_cancellable(
        scene: &'a RenderScene,
        photon_cache: Option<&std::path::Path>,
        cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    ) -> Self {
        match scene.params.integrator {
            IntegratorKind::Whitted => Integrator::Whitted(Whitted::new(scene)),
            IntegratorKind::Path => Integrator::Path(PathTracer::new(scene)),
            IntegratorKind::Photon => {
                Integrator::Photon(Box::new(PhotonMapper::new(scene, photon_cache, cancel)))
            }
            IntegratorKind::Ppm => {
                let mut p = ProgressivePath::ppm(scene);
                p.set_cancel(cancel);
                Integrator::Ppm(Box::new(p))
            }
            IntegratorKind::PathPpm => {
                let mut p = ProgressivePath::path_ppm(scene);
                p.set_cancel(cancel);
                Integrator::PathPpm(Box::new(p))
            }
        }
    }

    /// The photon maps and how they were built: the photon integrator's, or the current pass's
    /// of a progressive one.
    #[must_use]
    pub fn photon_maps(&self) -> Option<&photon::PhotonMaps> {
        match self {
            Integrator::Photon(p) => Some(p.maps()),
            Integrator::Ppm(p) | Integrator::PathPpm(p) => Some(p.photons().maps()),
            _ => None,
        }
    }

    /// The per-pass photon maps of a progressive integrator (`None` for the others).
    #[must_use]
    pub fn progressive(&self) -> Option<&photon::ProgressivePhotons<'a>> {
        match self {
            Integrator::Ppm(p) | Integrator::PathPpm(p) => Some(p.photons()),
            _ => None,
        }
    }

    /// True when every sample index is a pass with its own shared state (photon maps), which
    /// [`Integrator::begin_pass`] must set up before that sample of any pixel is taken.
    #[must_use]
    pub fn is_progressive(&self) -> bool {
        self.progressive().is_some()
    }

    /// Sets up the shared state of pass `sample` (progressive integrators: that pass's photon
    /// maps, built in parallel on the calling thread pool); a no-op for the others.
    pub fn begin_pass(&mut self, sample: u32) {
        match self {
            Integrator::Ppm(p) | Integrator::PathPpm(p) => p.begin_pass(sample),
            _ => {}
        }
    }

    /// Radiance arriving at the camera along `ray` (W·m⁻²·sr⁻¹ per channel), drawing its
    /// random numbers from `sampler` (already started on this pixel sample), counting rays in
    /// `counters`; `log` records the ray tree for `caustic debug-pixel`.
    #[inline]
    pub fn li(
        &self,
        ray: Ray,
        sampler: &mut Sampler,
        counters: &mut Counters,
        log: Option<&mut TraceLog>,
    ) -> Vec3 {
        self.li_parts(ray, sampler, counters, log).total()
    }

    /// [`Integrator::li`] split by how the light reached the camera ([`LightPath`]).
    #[inline]
    pub fn li_parts(
        &self,
        ray: Ray,
        sampler: &mut Sampler,
        counters: &mut Counters,
        log: Option<&mut TraceLog>,
    ) -> Radiance {
        match self {
            Integrator::Whitted(w) => w.li(ray, sampler, counters, log),
            Integrator::Path(p) => p.li(ray, sampler, counters, log),
            Integrator::Photon(p) => p.li(ray, sampler, counters, log),
            Integrator::Ppm(p) | Integrator::PathPpm(p) => p.li(ray, sampler, counters, log),
        }
    }
}
