//! A finished render as `caustic render` reports it ([`RenderedImage`]): the film written, and
//! its summaries in the command's words — the summary line, the target error reached, what an
//! adaptive render spent, what the photon passes did.

use std::ops::Range;
use std::path::PathBuf;

use crate::render::adaptive::AdaptivePlan;
use crate::render::auto_exposure::AutoExposure;
use crate::render::error_estimate::ErrorEstimate;
use crate::render::tonemap::Display;
use crate::render::{Film, PixelSums, RenderOutput};
use crate::settings::{IntegratorKind, SamplerKind};

/// A finished render, written: the film and what the command says of it.
#[derive(Debug)]
pub struct RenderedImage {
    /// The file written.
    pub output: PathBuf,
    /// The render's film, sums and figures.
    pub out: RenderOutput,
    /// The denoised image (`--denoise`).
    pub denoised: Option<Film>,
    /// The display the 8-bit outputs were written with.
    pub display: Display,
    /// The exposure chosen from the film, for an 8-bit output without a stated exposure.
    pub auto_exposure: Option<AutoExposure>,
    /// The image's estimated error when the render stopped, and whether it reached the target.
    pub error: Option<(ErrorEstimate, bool)>,
    /// The target error of the render (`render.target_error`), if any.
    pub(super) target_error: Option<f32>,
    /// Whether the render was adaptive.
    pub(super) adaptive: bool,
    /// The sample range a shard or `--samples` took (`None`: all).
    pub(super) samples: Option<Range<u32>>,
    /// Samples per pixel of the whole render.
    pub(super) spp: u32,
    /// The integrator that rendered.
    pub(super) integrator: IntegratorKind,
    /// Whether it was the default estimator's choice.
    pub(super) default_estimator: bool,
    /// The sampler.
    pub(super) sampler: SamplerKind,
}

/// Samples per pixel a render output holds.
pub(super) fn reached_spp(out: &RenderOutput) -> u64 {
    out.stats.samples / (u64::from(out.film.width) * u64::from(out.film.height)).max(1)
}

impl RenderedImage {
    /// The image the output shows: the denoised one, else the film.
    #[must_use]
    pub fn image(&self) -> &Film {
        self.denoised.as_ref().unwrap_or(&self.out.film)
    }

    /// Samples per pixel the render took.
    #[must_use]
    pub fn reached_spp(&self) -> u64 {
        reached_spp(&self.out)
    }

    /// The summary line: the output, size, samples (and which of the render's a shard or
    /// `--samples` range took), integrator, sampler, rays and speed.
    #[must_use]
    pub fn summary(&self) -> String {
        let (out, spp) = (&self.out, self.spp);
        let st = &out.stats;
        let secs = st.elapsed.as_secs_f64();
        let reached = self.reached_spp();
        // A shard or `--samples` range says which samples of the render's it took.
        let range = match &self.samples {
            Some(r) if reached > 0 => format!(
                " (samples {}..{} of {spp})",
                r.start,
                r.start + reached as u32
            ),
            Some(r) => format!(" (none of samples {}..{} of {spp})", r.start, r.end),
            None => String::new(),
        };
        format!(
            "{}: {}×{}, {} spp{range}, {:?} integrator{}, {:?} sampler, {} rays in {:.2} s ({:.2} Mrays/s, {} thread{})",
            self.output.display(),
            out.film.width,
            out.film.height,
            reached,
            self.integrator,
            if self.default_estimator {
                " (default)"
            } else {
                ""
            },
            self.sampler,
            st.rays,
            secs,
            st.rays as f64 / secs.max(1e-9) / 1e6,
            st.threads,
            if st.threads == 1 { "" } else { "s" }
        )
    }

    /// Whether the target error was reached, and the estimate (a render with a target).
    #[must_use]
    pub fn target_error_summary(&self) -> Option<String> {
        let ((e, reached), target) = (self.error?, self.target_error?);
        Some(format!(
            "target error {target}: {} — estimated relMSE {:.5} (its worst 1 % of pixels: {:.4}) at {reached_spp} spp in {secs:.2} s",
            if reached {
                "reached"
            } else {
                "not reached (the time or samples ran out)"
            },
            e.image,
            e.worst,
            reached_spp = self.reached_spp(),
            secs = self.out.stats.elapsed.as_secs_f64(),
        ))
    }

    /// What an adaptive render spent (an adaptive render).
    #[must_use]
    pub fn adaptive_summary(&self) -> Option<String> {
        self.adaptive
            .then(|| adaptive_summary(&self.out.sums, self.target_error))
    }

    /// What the photon passes did: the progressive integrators' passes and radii, or the
    /// share of estimates cut short by the largest radius (integrators with photon maps).
    #[must_use]
    pub fn photons_summary(&self) -> Option<String> {
        let st = &self.out.stats;
        if let Some(pr) = &st.progressive {
            let t = &pr.totals;
            Some(format!(
                "photons: {} passes of fresh maps, {} photons emitted and {} stored in all ({:.2} s), {} estimates; the last pass read {:.3} of each initial radius{}",
                t.passes,
                t.emitted,
                t.stored,
                t.time.as_secs_f64(),
                st.photon_estimates,
                pr.last_shrink,
                match pr.caustic_radius {
                    Some((typical, empty)) => format!(
                        " (caustic map: R = {typical:.4} for a typical photon, {empty:.4} where the pilot map found none)"
                    ),
                    None => String::new(),
                }
            ))
        } else if st.photon_estimates > 0 {
            Some(format!(
                "photons: {} estimates, {:.1}% cut short by the largest radius (photons.max_radius): those found fewer than the photons they ask for (photons.gather) within it, so they average fewer photons and are noisier; if the image looks blotchy, trace more photons (--photons, --caustic-photons) or raise --max-radius (which blurs more)",
                st.photon_estimates,
                100.0 * st.photon_radius_cut as f64 / st.photon_estimates as f64
            ))
        } else {
            None
        }
    }
}

/// What an adaptive render spent: samples per pixel (mean, fewest, most) and the estimated
/// relMSE of the image and of its worst 1 % of pixels.
fn adaptive_summary(sums: &PixelSums, target: Option<f32>) -> String {
    let n = sums.width as usize * sums.height as usize;
    let counts = (0..n).map(|i| sums.count(i));
    let total: u64 = counts.clone().map(u64::from).sum();
    let e = ErrorEstimate::of_sums(sums);
    format!(
        "adaptive: {:.2} samples per pixel on average ({} to {}), each pixel until its estimated relMSE is at most {}; estimated relMSE {:.5}, worst 1 % of pixels {:.4}",
        total as f64 / n.max(1) as f64,
        counts.clone().min().unwrap_or(0),
        counts.max().unwrap_or(0),
        AdaptivePlan::new(target.map(f64::from), 1).pixel_target as f32,
        e.image,
        e.worst
    )
}
