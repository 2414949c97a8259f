//! The default estimator: what renders a scene that names no integrator (issue #24), and the
//! per-pass photon budget it chooses for itself. The choice is part of resolving the settings
//! ([`super::settings::resolve`], where the integrator is chosen); the record of it,
//! [`DefaultEstimator`] with its [`PassPhotons`], is kept in the render parameters for the
//! summary.
//!
//! The choice is made once, when the scene is compiled, from what the scene can do:
//!
//! - A **specular caster** is an object whose material has a delta (mirror or smooth
//!   dielectric) part of non-zero weight, or is near-specular (a glossy metal or glass at most
//!   [`NEAR_SPECULAR_ALPHA`] wide), asked through `Bsdf::focusing_share` — exactly the objects
//!   the progressive integrators' caustic photons are aimed at (`integrators::photon::aim`), so
//!   "no caster" means "an empty caustic map". Only such an object can focus light onto a
//!   diffuse surface (a caustic: light → specular⁺ → diffuse), the paths a path tracer finds
//!   only by chance.
//! - With at least one caster the default is `path-ppm` (path tracing whose caustics come from
//!   a progressive caustic photon map, Knaus & Zwicker 2011): consistent, and free of the
//!   caustic fireflies of path tracing.
//! - With none it is `path`: no photon pass is traced, and the image is the path tracer's, byte
//!   for byte (`path-ppm` with an empty caustic map would trace the same camera paths, but
//!   would still pay for the empty passes).
//!
//! A scene's `photons` counts are sized for the `photon` integrator, which traces its maps once
//! per render (hundreds of thousands of photons); `path-ppm` traces fresh maps every pass, so
//! the default chooses its per-pass counts itself ([`PassPhotons::for_image`]) unless the command
//! line states them (`--set photons.caustic=…`, `--caustic-photons`, …), which then win.

use crate::render_scene::{
    DefaultEstimator, IntegratorKind, ObjectInfo, PassPhotons, SurfaceMaterial,
};
use crate::shading::NEAR_SPECULAR_ALPHA;

/// Caustic photons emitted per pass per image pixel. The measurement on the caustic
/// Cornell box (256 × 256 pixels) found 20 000 per pass (≈ 0.3 per pixel) the best of the
/// counts tried at equal time; the count scales with the pixel count so that photon tracing
/// stays the same fraction of a pass (a pass traces one camera sample per pixel).
pub const CAUSTIC_PHOTONS_PER_PIXEL: f64 = 0.3;
/// Fewest caustic photons per pass (small images still get a usable map).
pub const MIN_PASS_PHOTONS: u32 = 1_000;
/// Most caustic photons per pass (large images: photon tracing is kept a bounded cost and the
/// passes frequent, so the radius keeps shrinking).
pub const MAX_PASS_PHOTONS: u32 = 100_000;
/// Nearest photons whose distance sets the caustic map's initial radius `R(x)` (the k of the
/// pilot map's k-nearest radius, `integrators::photon::radius_field`). Measured at equal time
/// (5 December 2026, 2-vCPU EPYC): on the bath (800×600, 20 s, two seeds, relMSE against the
/// 256-pass default reference with each image's 100 worst pixels left out) k = 20: 0.038,
/// k = 10: 0.031–0.033, k = 7: 0.032, k = 5: 0.033 — an estimate costs in proportion to the
/// photons in its disc (k = 10 reaches 15–16 spp where k = 20 reaches 13); on the caustic
/// Cornell box (`scripts/mitsuba_equal_time.sh 1 256`, 6 s) relMSE 0.00526 (k = 20), 0.00475
/// (10), 0.00455 (7), RMSE within 3 %, z8 1.15 for all three. A smaller disc also blurs less.
pub const PASS_CAUSTIC_GATHER: u32 = 10;

impl PassPhotons {
    /// The per-pass budget for an image of `width` × `height` pixels:
    /// [`CAUSTIC_PHOTONS_PER_PIXEL`] per pixel, rounded to a thousand and clamped to
    /// [[`MIN_PASS_PHOTONS`], [`MAX_PASS_PHOTONS`]] (256 × 256 gives 20 000).
    #[must_use]
    pub fn for_image(width: u32, height: u32) -> Self {
        let pixels = f64::from(width) * f64::from(height);
        let thousands = (pixels * CAUSTIC_PHOTONS_PER_PIXEL / 1000.0).round();
        let caustic = (thousands * 1000.0)
            .clamp(f64::from(MIN_PASS_PHOTONS), f64::from(MAX_PASS_PHOTONS))
            as u32;
        Self {
            caustic,
            caustic_gather: PASS_CAUSTIC_GATHER,
            global: 0,
        }
    }
}

impl DefaultEstimator {
    /// The default for a scene with these objects (`material(i)` is material `i`) rendered at
    /// `width` × `height` pixels: the integrator and why.
    #[must_use]
    pub fn choose<'m>(
        objects: &[ObjectInfo],
        material: impl Fn(usize) -> Option<&'m SurfaceMaterial>,
        width: u32,
        height: u32,
    ) -> (IntegratorKind, Self) {
        let specular_casters = objects
            .iter()
            .filter_map(|o| o.material)
            .filter(|&m| {
                // An interface (no surface, docs/media.md) focuses nothing.
                material(m as usize).is_some_and(|m| {
                    !m.interior.interface && m.bsdf.focusing_share(Some(NEAR_SPECULAR_ALPHA)) > 0.0
                })
            })
            .count();
        if specular_casters == 0 {
            let choice = Self {
                specular_casters,
                photons: None,
            };
            (IntegratorKind::Path, choice)
        } else {
            let choice = Self {
                specular_casters,
                photons: Some(PassPhotons::for_image(width, height)),
            };
            (IntegratorKind::PathPpm, choice)
        }
    }

    /// The summary's reason, e.g. `path-ppm: 2 specular casters, per pass 20000 caustic
    /// photons, k = 10 (0.3 per pixel)` or `path: no specular caster, no photon pass`.
    #[must_use]
    pub fn describe(&self, chosen: IntegratorKind) -> String {
        let casters = match self.specular_casters {
            0 => "no specular caster".to_string(),
            1 => "1 specular caster".to_string(),
            n => format!("{n} specular casters"),
        };
        match (chosen, self.photons) {
            (IntegratorKind::Path, _) => format!("{chosen}: {casters}, no photon pass"),
            (_, Some(p)) => format!(
                "{chosen}: {casters}; per pass {} caustic photons, k = {}, no global map \
                 (chosen for the image size: {CAUSTIC_PHOTONS_PER_PIXEL} per pixel, {}–{})",
                p.caustic, p.caustic_gather, MIN_PASS_PHOTONS, MAX_PASS_PHOTONS
            ),
            (_, None) => {
                format!("{chosen}: {casters}; per-pass photons as set on the command line")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_per_pass_budget_follows_the_pixel_count_within_its_bounds() {
        // The best row: 20 000 per pass on the 256² Cornell box.
        assert_eq!(PassPhotons::for_image(256, 256).caustic, 20_000);
        // 320 × 240 × 0.3 = 23 040 → 23 000.
        assert_eq!(PassPhotons::for_image(320, 240).caustic, 23_000);
        assert_eq!(PassPhotons::for_image(16, 16).caustic, MIN_PASS_PHOTONS);
        assert_eq!(PassPhotons::for_image(4096, 4096).caustic, MAX_PASS_PHOTONS);
        assert_eq!(PassPhotons::for_image(0, 0).caustic, MIN_PASS_PHOTONS);
        assert_eq!(PassPhotons::for_image(256, 256).global, 0);
    }
}
