//! Progressive photon mapping (`ppm`), in the probabilistic, independent-pass form of Knaus &
//! Zwicker ("Progressive Photon Mapping: A Probabilistic Approach", ACM ToG 30(3), 2011; the
//! progressive idea is Hachisuka, Ogaki & Jensen, "Progressive Photon Mapping", SIGGRAPH Asia
//! 2008). Sample index `i` of every pixel is pass `i`: fresh caustic and global maps
//! ([`ProgressivePhotons`]) read at the camera path's first diffuse vertex within the pass's
//! shrinking radius, with direct light by shadow rays; mirror and glass chains are followed
//! before it, and light of the background is path traced after it (photons carry only the
//! emitters' light). The image, the mean of the passes, converges to the exact one, caustics
//! of point lights included.

use super::path::PathMaps;
use super::photon::{MapSet, ProgressivePhotons};
use super::{Counters, PathTracer, Radiance, TraceLog};
use crate::geometry::Ray;
use crate::render_scene::RenderScene;
use crate::sampling::Sampler;

/// The progressive photon mapper: the current pass's maps and the camera paths that read them.
#[derive(Debug)]
pub struct Ppm<'a> {
    photons: ProgressivePhotons<'a>,
    path: PathTracer<'a>,
}

impl<'a> Ppm<'a> {
    /// No maps yet: [`Ppm::begin_pass`] builds each pass's.
    #[must_use]
    pub fn new(scene: &'a RenderScene) -> Self {
        Self {
            photons: ProgressivePhotons::new(
                scene,
                MapSet {
                    caustic: true,
                    global: true,
                    global_any_bounce: false,
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

    /// Makes the maps those of pass `pass` (the sample index about to be taken).
    pub fn begin_pass(&mut self, pass: u32) {
        self.photons.begin_pass(pass);
    }

    /// Radiance along camera ray `ray` from the current pass's maps.
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
            global_at: 0,
            global_has_caustics: false,
        };
        self.path.li_with_maps(maps, ray, sampler, counters, log)
    }
}
