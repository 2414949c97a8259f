//! The passes of progressive photon mapping in its probabilistic form (Knaus & Zwicker,
//! "Progressive Photon Mapping: A Probabilistic Approach", ACM ToG 30(3), 2011): every pass
//! traces fresh, independent photon maps and reads them within a radius that shrinks from pass
//! to pass as `r²ᵢ₊₁ = r²ᵢ (i + α)/(i + 1)`. Each pass's image is a density estimate whose blur
//! (bias) and noise both vanish as passes are averaged: the mean converges to the exact image.
//!
//! The radius of pass `i` at a point `x` is `sᵢ·R(x)`, with `sᵢ = rᵢ/r₁` from the schedule and
//! `R(x)` a [`RadiusField`]: the k-nearest radius of a **pilot** map, traced once per render
//! from photon streams no pass uses (pass number [`PILOT_PASS`]), so `R` is independent of every
//! pass's photons and each pass's estimate is a plain fixed-disc density estimate (unbiased for
//! the disc-averaged radiance). The disc follows the photon density, sharp in a bright caustic
//! and wide where photons are sparse, as the k-nearest radius does, while each pass answers its
//! estimates from a hash grid of its photons (`PhotonMap::set_pass_lookup`) instead of a
//! k-nearest search per estimate.
//!
//! Pass `i` is sample index `i` of every pixel, and its photons come from streams keyed by the
//! pass, so any set of passes can be rendered anywhere, in any order, and the films merged
//! (farm shards) into the bytes of one render.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use super::maps::{MapScene, MapSet, PILOT_PASS, PhotonMaps, build_maps_with};
use super::radius_field::RadiusField;
use super::volume::{VolumeMap, volume_radius_field};
use super::walls::Walls;
use crate::render_scene::RenderScene;

/// Knaus & Zwicker's radius schedule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadiusSchedule {
    /// The shrink parameter α ∈ (0, 1).
    pub alpha: f64,
}

impl RadiusSchedule {
    /// `rᵢ / r₁` for 0-based pass `pass` (pass 0 is i = 1):
    /// `√(∏_{k=1}^{pass} (k + α)/(k + 1))`, which falls as `pass^((α−1)/2)`.
    #[must_use]
    pub fn scale(&self, pass: u32) -> f32 {
        let mut r2 = 1.0f64;
        for k in 1..=u64::from(pass) {
            let k = k as f64;
            r2 *= (k + self.alpha) / (k + 1.0);
        }
        r2.sqrt() as f32
    }
}

/// The radius fields of the caustic and global maps (`None`: that map has no pilot photons).
#[derive(Debug, Clone, Default)]
pub struct PassFields {
    /// `R(x)` of the caustic map.
    pub caustic: Option<Arc<RadiusField>>,
    /// `R(x)` of the global map.
    pub global: Option<Arc<RadiusField>>,
    /// `R(x)` of the volume caustic map's beam estimate (`volume.rs`).
    pub volume: Option<Arc<RadiusField>>,
}

/// Totals over the passes a progressive render has traced (for its summary).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PassTotals {
    /// Passes whose maps were built.
    pub passes: u64,
    /// Photons emitted over those passes.
    pub emitted: u64,
    /// Photons stored over those passes.
    pub stored: u64,
    /// Time spent tracing photons and building kd-trees.
    pub time: Duration,
}

/// The per-pass photon maps of a progressive render.
#[derive(Debug)]
pub struct ProgressivePhotons<'a> {
    scene: &'a RenderScene,
    /// The photon targets and diffuse area, found once for every pass.
    prepared: MapScene,
    set: MapSet,
    schedule: RadiusSchedule,
    /// The pass whose maps `maps` holds (`None` before the first).
    pass: Option<u32>,
    maps: PhotonMaps,
    totals: PassTotals,
    /// The radius fields, built from the pilot maps before the first pass (`None` until then).
    fields: Option<PassFields>,
}

impl<'a> ProgressivePhotons<'a> {
    /// No maps yet: [`ProgressivePhotons::begin_pass`] builds each pass's.
    #[must_use]
    pub fn new(scene: &'a RenderScene, set: MapSet) -> Self {
        Self {
            scene,
            prepared: MapScene::new(scene, set),
            set,
            schedule: RadiusSchedule {
                alpha: f64::from(scene.params.photons.alpha),
            },
            pass: None,
            maps: PhotonMaps::default(),
            totals: PassTotals::default(),
            fields: None,
        }
    }

    /// Makes every later pass's photon tracing stop soon after `cancel` (the render's Ctrl-C
    /// flag) is raised.
    pub fn set_cancel(&mut self, cancel: Option<Arc<AtomicBool>>) {
        self.prepared.cancel = cancel;
    }

    /// Makes the maps those of pass `pass` (building them unless they already are), reading
    /// within the pass's share of the k-nearest radius. A build stopped by the cancel flag
    /// leaves no pass current (its maps are empty), so it is rebuilt if asked for again.
    pub fn begin_pass(&mut self, pass: u32) {
        if self.pass == Some(pass) {
            return;
        }
        let t = Instant::now();
        let fields = match self.fields.clone() {
            Some(f) => f,
            None => {
                let pilot = build_maps_with(self.scene, &self.prepared, Some(PILOT_PASS), self.set);
                if pilot.summary.cancelled {
                    self.pass = None;
                    return;
                }
                let field = |m: &Option<super::PhotonMap>| {
                    m.as_ref()
                        .and_then(super::PhotonMap::radius_field)
                        .map(Arc::new)
                };
                let f = PassFields {
                    caustic: field(&pilot.caustic),
                    global: field(&pilot.global),
                    volume: volume_radius_field(&pilot.volume_photons).map(Arc::new),
                };
                self.totals.time += t.elapsed();
                self.fields = Some(f.clone());
                f
            }
        };
        let t = Instant::now();
        self.maps = build_maps_with(self.scene, &self.prepared, Some(pass), self.set);
        if self.maps.summary.cancelled {
            self.pass = None;
            return;
        }
        self.pass = Some(pass);
        let shrink = self.shrink(pass);
        for (m, field) in [
            (self.maps.caustic.as_mut(), &fields.caustic),
            (self.maps.global.as_mut(), &fields.global),
        ] {
            let Some(m) = m else { continue };
            match field {
                Some(f) => m.set_pass_lookup(shrink, Arc::clone(f), Walls::of(self.scene, None)),
                // No pilot photon although this pass stored some (a rare light path): the
                // pass's own k-nearest radius, shrunk (its photons marked for it).
                None => {
                    m.mark_walls(Walls::of(self.scene, None));
                    m.set_shrink(shrink);
                }
            }
        }
        // The volume photons' spheres: radius `shrink · R(x)` (2-D kernel across the ray, so the
        // surface maps' schedule); without pilot volume photons, the pass's own field.
        let volume = std::mem::take(&mut self.maps.volume_photons);
        self.maps.volume = match &fields.volume {
            Some(f) => VolumeMap::build(volume, |p| shrink * f.radius(p)),
            None => match volume_radius_field(&volume) {
                Some(f) => VolumeMap::build(volume, |p| shrink * f.radius(p)),
                None => None,
            },
        };
        let s = &self.maps.summary;
        for c in s.caustic.iter().chain(&s.global) {
            self.totals.emitted += c.emitted;
            self.totals.stored += c.stored;
        }
        self.totals.passes += 1;
        self.totals.time += t.elapsed();
    }

    /// The current pass's maps.
    #[must_use]
    pub fn maps(&self) -> &PhotonMaps {
        &self.maps
    }

    /// The radius fields (after the first pass has begun).
    #[must_use]
    pub fn fields(&self) -> Option<&PassFields> {
        self.fields.as_ref()
    }

    /// The fraction `sᵢ = rᵢ/r₁` of the initial radius `R(x)` that pass `pass` reads.
    #[must_use]
    pub fn shrink(&self, pass: u32) -> f32 {
        self.schedule.scale(pass)
    }

    /// The pass whose maps are current, if any.
    #[must_use]
    pub fn pass(&self) -> Option<u32> {
        self.pass
    }

    /// Totals over the passes built so far.
    #[must_use]
    pub fn totals(&self) -> PassTotals {
        self.totals
    }
}

#[cfg(test)]
mod tests {
    use super::RadiusSchedule;

    #[test]
    fn schedule_matches_the_recurrence_and_its_asymptotic_rate() {
        let s = RadiusSchedule { alpha: 2.0 / 3.0 };
        assert_eq!(s.scale(0), 1.0);
        // By hand: r₂² = r₁² (1 + α)/2.
        let r2 = ((1.0 + 2.0 / 3.0) / 2.0f64).sqrt() as f32;
        assert!((s.scale(1) - r2).abs() < 1e-7);
        // r² ∝ i^(α−1) for large i: doubling the pass scales r by 2^((α−1)/2).
        let ratio = f64::from(s.scale(20_000) / s.scale(10_000));
        let expected = 2f64.powf((2.0 / 3.0 - 1.0) / 2.0);
        assert!((ratio - expected).abs() < 1e-4, "{ratio} vs {expected}");
    }
}
