//! Light-transport algorithms over the compiled scene: a closed set dispatched through an enum
//! (no virtual calls per sample, as pbrt-v4's tagged integrators), each prepared once per render
//! and then asked for the radiance of camera samples by every worker.

pub mod path;
pub mod shadow;
pub mod trace_log;
pub mod whitted;

pub use path::PathTracer;
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
}

/// A prepared integrator: shared, immutable state built once per render (light selection
/// tables today; photon maps later), read by every worker.
#[derive(Debug)]
pub enum Integrator<'a> {
    /// Recursive ray tracing ([`Whitted`]).
    Whitted(Whitted<'a>),
    /// Unidirectional path tracing with next-event estimation ([`PathTracer`]).
    Path(PathTracer<'a>),
}

impl<'a> Integrator<'a> {
    /// Prepares the integrator the scene asks for (`render.integrator`).
    #[must_use]
    pub fn prepare(scene: &'a RenderScene) -> Self {
        match scene.params.integrator {
            IntegratorKind::Whitted => Integrator::Whitted(Whitted::new(scene)),
            IntegratorKind::Path => Integrator::Path(PathTracer::new(scene)),
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
        match self {
            Integrator::Whitted(w) => w.li(ray, sampler, counters, log),
            Integrator::Path(p) => p.li(ray, sampler, counters, log),
        }
    }
}
