//! Light-transport algorithms over the compiled scene, each prepared once per render and then
//! asked for the radiance of camera samples by every worker.
//!
//! The contract is the [`Estimator`] trait: `li_parts` with one [`Context`] argument (sampler,
//! counters and a [`PathObserver`], generic so that the no-op observer of normal renders
//! compiles away), plus optional photon-map and pass hooks. The set of integrators is closed and
//! dispatched through the [`Integrator`] enum, which the `integrators!` registration below
//! generates: no virtual call per sample (pbrt-v4's CPU integrators are virtual classes; it
//! keeps tagged-pointer dispatch for lights, BxDFs and materials — here it is an enum with
//! exhaustive matches). Adding an integrator: its file, implementing [`Estimator`], and one
//! line in `integrators!` (plus its `IntegratorKind` variant).

pub mod context;
pub mod light_guide;
pub mod path;
pub mod photon;
pub mod progressive_path;
pub mod shadow;
pub mod splat;
pub mod trace_log;
pub mod whitted;

pub use context::{Context, NoTrace, PathObserver};
pub use path::PathTracer;
pub use photon::PhotonMapper;
pub use progressive_path::ProgressivePath;
pub use trace_log::TraceLog;
pub use whitted::Whitted;

use glam::Vec3;

use crate::geometry::Ray;
use crate::render_scene::{IntegratorKind, RenderScene};

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

    /// Every part scaled by `w` (e.g. the transmittance of the segment the light came along).
    #[inline]
    #[must_use]
    pub fn scaled(mut self, w: Vec3) -> Self {
        for a in &mut self.parts {
            *a *= w;
        }
        self
    }

    /// Adds every part of `other` scaled by `w`.
    #[inline]
    pub fn add_scaled(&mut self, other: &Radiance, w: Vec3) {
        for (a, b) in self.parts.iter_mut().zip(&other.parts) {
            *a += *b * w;
        }
    }
}

/// What every integrator provides (the written contract). Implemented by each integrator type
/// and dispatched statically through [`Integrator`].
pub trait Estimator<'a> {
    /// Radiance arriving at the camera along `ray` (W·m⁻²·sr⁻¹ per channel) split by how the
    /// light reached the camera ([`LightPath`]), drawing random numbers from `cx.sampler`
    /// (already started on this pixel sample), counting rays in `cx.counters` and telling
    /// `cx.observer` about its paths.
    fn li_parts<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance;

    /// The photon maps it reads and how they were built, if it has any.
    fn photon_maps(&self) -> Option<&photon::PhotonMaps> {
        None
    }

    /// True if it adds to other pixels than the one sampled ([`Context::splat`]): the render
    /// job then keeps splat buffers and merges them into the film after every sweep.
    fn splats(&self) -> bool {
        false
    }

    /// The per-pass photon maps of a progressive integrator.
    fn progressive(&self) -> Option<&photon::ProgressivePhotons<'a>> {
        None
    }

    /// Sets up the shared state of pass `sample` (progressive integrators); nothing otherwise.
    fn begin_pass(&mut self, _sample: u32) {}
}

/// The registration of every integrator: variant, type, the `IntegratorKind` that selects it
/// and how it is prepared from the scene and the photon-cache folder. Generates [`Integrator`]
/// and its dispatch (exhaustive matches: a new variant cannot be forgotten anywhere).
macro_rules! integrators {
    ($(
        $(#[$doc:meta])*
        $variant:ident($ty:ty) = $kind:ident, |$scene:ident, $cache:ident, $cancel:ident| $make:expr;
    )*) => {
        /// A prepared integrator: shared, immutable state built once per render (light
        /// selection tables, photon maps), read by every worker.
        #[derive(Debug)]
        pub enum Integrator<'a> {
            $($(#[$doc])* $variant($ty),)*
        }

        impl<'a> Integrator<'a> {
            /// [`Integrator::prepare`], with photon maps read from and saved to the cache folder
            /// `photon_cache` (`--photon-cache`; see [`photon::cache`]).
            #[must_use]
            pub fn prepare_with(
                scene: &'a RenderScene,
                photon_cache: Option<&std::path::Path>,
            ) -> Self {
                Self::prepare_cancellable(scene, photon_cache, None)
            }

            /// [`Integrator::prepare_with`], whose photon tracing (the photon integrator's maps
            /// here, a progressive one's in every [`Integrator::begin_pass`]) stops soon after
            /// `cancel` is raised; check the flag before rendering with the result.
            #[must_use]
            pub fn prepare_cancellable(
                scene: &'a RenderScene,
                photon_cache: Option<&std::path::Path>,
                cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
            ) -> Self {
                match scene.params.integrator {
                    $(IntegratorKind::$kind => {
                        let ($scene, $cache, $cancel) = (scene, photon_cache, cancel);
                        let _ = (&$cache, &$cancel);
                        Integrator::$variant($make)
                    })*
                }
            }

            /// The photon maps and how they were built: the photon integrator's, or the current
            /// pass's of a progressive one.
            #[must_use]
            pub fn photon_maps(&self) -> Option<&photon::PhotonMaps> {
                match self {
                    $(Integrator::$variant(x) => x.photon_maps(),)*
                }
            }

            /// True if the integrator splats to other pixels ([`Estimator::splats`]).
            #[must_use]
            pub fn splats(&self) -> bool {
                match self {
                    $(Integrator::$variant(x) => x.splats(),)*
                }
            }

            /// The per-pass photon maps of a progressive integrator (`None` for the others).
            #[must_use]
            pub fn progressive(&self) -> Option<&photon::ProgressivePhotons<'a>> {
                match self {
                    $(Integrator::$variant(x) => x.progressive(),)*
                }
            }

            /// Sets up the shared state of pass `sample` (progressive integrators: that pass's
            /// photon maps, built in parallel on the calling thread pool); a no-op for the others.
            pub fn begin_pass(&mut self, sample: u32) {
                match self {
                    $(Integrator::$variant(x) => x.begin_pass(sample),)*
                }
            }

            /// [`Integrator::li`] split by how the light reached the camera ([`LightPath`]).
            #[inline]
            pub fn li_parts<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Radiance {
                match self {
                    $(Integrator::$variant(x) => x.li_parts(ray, cx),)*
                }
            }
        }
    };
}

integrators! {
    /// Recursive ray tracing ([`Whitted`]).
    Whitted(Whitted<'a>) = Whitted, |scene, _cache, _cancel| Whitted::new(scene);
    /// Unidirectional path tracing with next-event estimation ([`PathTracer`]).
    Path(PathTracer<'a>) = Path, |scene, _cache, _cancel| PathTracer::new(scene);
    /// Photon mapping ([`PhotonMapper`]); its maps are built by `prepare`.
    Photon(Box<PhotonMapper<'a>>) = Photon, |scene, cache, cancel| {
        Box::new(PhotonMapper::new(scene, cache, cancel))
    };
    /// Progressive photon mapping ([`ProgressivePath::ppm`]); fresh maps every pass.
    Ppm(Box<ProgressivePath<'a>>) = Ppm, |scene, _cache, cancel| {
        Box::new(ProgressivePath::ppm(scene).with_cancel(cancel))
    };
    /// Path tracing with progressive photon maps ([`ProgressivePath::path_ppm`]).
    PathPpm(Box<ProgressivePath<'a>>) = PathPpm, |scene, _cache, cancel| {
        Box::new(ProgressivePath::path_ppm(scene).with_cancel(cancel))
    };
}

impl<'a> Integrator<'a> {
    /// Prepares the integrator the scene asks for (`render.integrator`).
    #[must_use]
    pub fn prepare(scene: &'a RenderScene) -> Self {
        Self::prepare_with(scene, None)
    }

    /// True when every sample index is a pass with its own shared state (photon maps), which
    /// [`Integrator::begin_pass`] must set up before that sample of any pixel is taken.
    #[must_use]
    pub fn is_progressive(&self) -> bool {
        self.progressive().is_some()
    }

    /// Radiance arriving at the camera along `ray` (W·m⁻²·sr⁻¹ per channel), with the sampler,
    /// counters and path observer of `cx` ([`Estimator::li_parts`]).
    #[inline]
    pub fn li<O: PathObserver>(&self, ray: Ray, cx: &mut Context<'_, O>) -> Vec3 {
        self.li_parts(ray, cx).total()
    }
}
