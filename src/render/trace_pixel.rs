//! The debug single-pixel trace (`caustic debug-pixel`): one sample of one pixel traced exactly
//! as the renderer traces it, with its ray tree recorded.

use glam::Vec3;

use super::options::RenderError;
use super::tiles::camera_sample;
use crate::integrators::{Context, Counters, Integrator, TraceLog};
use crate::render_scene::RenderScene;
use crate::sampling::Sampler;

/// Traces sample `sample` of pixel `(x, y)` exactly as the renderer does, recording its ray tree.
pub fn trace_pixel(
    scene: &RenderScene,
    x: u32,
    y: u32,
    sample: u32,
) -> Result<(TraceLog, Vec3), RenderError> {
    trace_pixel_with(scene, x, y, sample, None)
}

/// [`trace_pixel`] with photon maps from the cache folder `photon_cache` (`--photon-cache`).
pub fn trace_pixel_with(
    scene: &RenderScene,
    x: u32,
    y: u32,
    sample: u32,
    photon_cache: Option<&std::path::Path>,
) -> Result<(TraceLog, Vec3), RenderError> {
    let p = &scene.params;
    if x >= p.width || y >= p.height {
        return Err(RenderError::PixelOutside(x, y, p.width, p.height));
    }
    let mut sampler = Sampler::new(p.sampler, p.seed, p.samples_per_pixel);
    let ray = camera_sample(scene, &mut sampler, x, y, sample);
    let mut log = TraceLog::default();
    let mut integrator = Integrator::prepare_with(scene, photon_cache);
    integrator.begin_pass(sample);
    let l = integrator.li(
        ray,
        &mut Context::new(&mut sampler, &mut Counters::default(), &mut log),
    );
    Ok((log, l))
}
