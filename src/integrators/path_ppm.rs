//! Path tracing with progressive photon-mapped caustics (`path-ppm`): the split of the report's
//! two maps made consistent. Paths light → specular⁺ → diffuse, which a path tracer finds only
//! when a BSDF sample happens to hit a small emitter through glass or water (and never for
//! point lights), come from a caustic photon map at every diffuse vertex of the camera path;
//! everything else comes from the path tracer with next-event estimation and MIS
//! ([`PathTracer::li_with_maps`]). With global photons (`photons.global` > 0) the path stops
//! gathering the emitters' light after one diffuse bounce and reads the global map there
//! instead (final gathering with one ray per sample: far less noise in indirect light); that
//! map stores photons after any first bounce, caustics included, so one estimate there reads
//! all the light that has bounced.
//! Sample index `i` of every pixel is pass `i`, with fresh photons read within a radius that
//! shrinks by Knaus & Zwicker's schedule ([`ProgressivePhotons`]), so the image converges to
//! the path tracer's expectation.

use super::path::PathMaps;
use super::photon::{MapSet, ProgressivePhotons};
use super::{Counters, PathTracer, Radiance, TraceLog};
use crate::geometry::Ray;
use crate::render_scene::RenderScene;
use crate::sampling::Sampler;

/// The path tracer with the current pass's caustic map.
#[derive(Debug)]
pub struct PathPpm<'a> {
    photons: ProgressivePhotons<'a>,
    path: PathTracer<'a>,
}

impl<'a> PathPpm<'a> {
    /// Builds pass 0's caustic map (which fixes the first radius).
    #[must_use]
    pub fn new(scene: &'a RenderScene) -> Self {
        Self {
            photons: ProgressivePhotons::new(
                scene,
                MapSet {
                    caustic: true,
                    global: scene.params.photons.global > 0,
                    global_any_bounce: true,
                },
            ),
            path: PathTracer::new(scene),
        }
    }

    /// The passes' photon maps.
    #[must_use]
    pub fn photons(&self) -> &ProgressivePhotons<'a> {
        &self.photons
    }

    /// Makes the caustic map that of pass `pass` (the sample index about to be taken).
    pub fn begin_pass(&mut self, pass: u32) {
        self.photons.begin_pass(pass);
    }

    /// Radiance along camera ray `ray`.
    pub fn li(
        &self,
        ray: Ray,
        sampler: &mut Sampler,
        counters: &mut Counters,
        log: Option<&mut TraceLog>,
    ) -> Radiance {
        let m = self.photons.maps();
        let maps = PathMaps {
            caustic: m.caustic.as_ref(),
            global: m.global.as_ref(),
            global_at: 1,
            global_has_caustics: true,
        };
        self.path.li_with_maps(maps, ray, sampler, counters, log)
    }
}
