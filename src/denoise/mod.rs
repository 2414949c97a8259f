//! The denoiser of `--denoise`: a feature-guided, non-learned filter for Monte Carlo renders
//! that keeps caustics (docs/denoise.md).
//!
//! The method is joint non-local means with cross-bilateral feature weights, after Rousselle,
//! Manzi and Zwicker, "Robust Denoising using Feature and Color Information" (Pacific Graphics
//! 2013), with the dual-buffer variance cancellation of Rousselle, Knaus and Zwicker, "Adaptive
//! Rendering with Non-Local Means Filtering" (SIGGRAPH Asia 2012), and the two-buffer
//! cross-filtering and cross-validated choice among candidate filters of Bitterli et al.,
//! "Nonlinearly Weighted First-order Regression for Denoising Monte Carlo Renderings" (EGSR
//! 2016, NFOR): each half of the samples is filtered with weights computed from the other
//! half, and per pixel the candidate whose output is closest to the other half (less that
//! half's variance: an unbiased estimate of the squared error) is kept. Texture is kept by
//! filtering the light divided by the albedo feature and multiplying back (as in Schied et al.,
//! "Spatiotemporal Variance-Guided Filtering", HPG 2017). Unlike NFOR it is a zero-order
//! (weighted-average) filter and the features are not prefiltered: they are traced without
//! light sampling and are nearly noise-free ([`input::Guide`]).
//!
//! Caustics: the light the renderer marks as caustic (through mirrors or glass onto a diffuse
//! surface), and the specular light (emitters seen through mirrors and glass: highlights), are
//! given separately ([`DenoiseInput::unguided`]) and filtered with their own variance and
//! colour weights only, never guided by albedo or normal, which they follow neither; the rest
//! of the light is filtered with the feature guidance. Their sum is the image. Last, what a
//! filter removed is given back where the two halves agree it was structure rather than noise
//! (a Wiener gain on the box-averaged residuals of both halves, [`select`]): a caustic's or a
//! shadow's local mean survives even where no feature marks it.
//!
//! Each layer's candidates are at two scales: the fine ones, and a coarse one filtered on the
//! image halved (2×2 means), whose low band replaces the fine candidate's ([`scales`], after
//! the scale composition of Vogels et al. 2018): noise whose grains are as wide as the fine
//! window (a photon map's discs, a dark wall's few indirect samples) is left to it, and the
//! cross-validation decides per pixel which scale fits.
//!
//! Before any filtering, fireflies are rejected by the two halves' independence ([`outliers`]:
//! a value one half holds and the other half's neighbourhood does not confirm is held to a
//! bound; Zirr et al. 2018, DeCoro et al. 2010), and at few samples per half the guided light's
//! per-pixel variance is prefiltered over the neighbours on the same surface.
//!
//! The module knows nothing of scenes or renders: plain arrays in, an image out. Every pixel's
//! arithmetic runs in a fixed order in bands of rows whose split does not depend on the thread
//! count, so the output is the same bytes for any number of threads.

pub mod cross_filter;
pub mod error;
pub mod fast_exp;
pub mod input;
pub mod outliers;
pub mod planes;
pub mod scales;
pub mod select;

#[cfg(test)]
mod tests;

use glam::Vec3;

pub use error::DenoiseError;
pub use input::{DenoiseInput, Guide, HalfBuffers};

use cross_filter::{Candidates, Deltas, GuidePlanes, LayerPlanes, cross_filter};
use outliers::{OutlierParams, reject_outliers};
use select::{Change, select};

/// The denoiser's settings; [`DenoiseParams::default`] is what `--denoise` uses.
#[derive(Debug, Clone, PartialEq)]
pub struct DenoiseParams {
    /// Search window radius in pixels for the guided light ((2r+1)² neighbours).
    pub radius: usize,
    /// Search window radius for the unguided (caustic and specular) light.
    pub unguided_radius: usize,
    /// Patch radius of the colour distance (non-local means).
    pub patch: usize,
    /// Candidate colour bandwidths `k` of the guided light (larger: smoother), from which the
    /// cross-validation picks per pixel.
    pub guided_k: [f32; 3],
    /// Candidate colour bandwidths of the unguided light.
    pub unguided_k: [f32; 3],
    /// Albedo difference (Euclidean, RGB) at which the feature weight is 1/e.
    pub sigma_albedo: f32,
    /// Normal difference (Euclidean between unit normals; 0.1 ≈ 5.7°) at which it is 1/e.
    /// From 0.2 to 0.1 the bath's relMSE at 8 spp fell by 12 % over 8 seeds (0.0176 → 0.0155:
    /// its tiles' bevels and grout, whose normals turn within a pixel or two, were averaged
    /// into the tiles), the pool's by 0.4 %; the glass of water's is unchanged and the caustic
    /// Cornell box's rose by 1 % (4 seeds). 0.07 and 0.05 lowered the bath's bias further but
    /// raised its variance more (docs/denoise.md).
    pub sigma_normal: f32,
    /// Relative depth difference at which it is 1/e (beyond the surface's own slope).
    pub sigma_depth: f32,
    /// Radius of the box filter that smooths the error estimates before the per-pixel choice.
    pub select_radius: usize,
    /// Radius of the window that prefilters each half's per-pixel variance of the guided
    /// light before the colour distances use it, when the halves have at most
    /// `variance_max_samples` samples (0: never prefiltered). From a few samples a pixel's
    /// variance is itself very noisy (two samples that are both 0 give 0, and the colour
    /// distance then refuses every neighbour). With 1 (and `variance_same_surface`) the glass
    /// of water's relMSE at 4 spp falls from 0.0083 to 0.0044 and the pool's rises from 0.0131
    /// to 0.0141 (docs/denoise.md); on the caustic Cornell box at 16 spp (8 samples a half)
    /// a plain 3×3 box raised it from 0.00196 to 0.00205, hence the sample limit.
    pub variance_radius: usize,
    /// The variance prefilter runs only when a half has at most this many samples: the
    /// relative spread of a variance estimated from `n` samples is about `√(2/(n−1))`, 1.4 at
    /// 2 samples, 0.8 at 4.
    pub variance_max_samples: u32,
    /// Whether the guided light's variance prefilter averages only over the neighbours the
    /// feature guide counts as the same surface ([`GuidePlanes::same_surface`]) rather
    /// than over the whole box.
    pub variance_same_surface: bool,
    /// The same for the unguided (caustic and specular) light. A smoothed variance spreads a
    /// caustic's noise onto the dark beside it, whose pixels then average across the caustic's
    /// edge (with 1 for both layers the glass of water's caustic lost a further 8 % of its mean).
    pub unguided_variance_radius: usize,
    /// Radius of the box over which the residual is averaged before the structure the halves
    /// agree on is given back ([`select`]'s last step).
    pub residual_radius: usize,
    /// Added to the albedo before the light is divided by it (keeps black surfaces and
    /// emitters, of albedo 0, filtered as plain radiance).
    pub albedo_epsilon: f32,
    /// Firefly rejection before the filter, each half held to what the other confirms
    /// ([`outliers`]).
    pub outliers: OutlierParams,
    /// Search window radius, in coarse pixels, of the guided light's coarse candidates
    /// ([`scales`]: the image halved, so radius 3 reaches 7 fine pixels out; 0: none). On 8
    /// or 16 seeds of each (docs/denoise.md), with `unguided_coarse_radius` 3, one coarse
    /// candidate (`coarse_candidates: [0]`) and `coarse_patch` 1: relMSE −5 % on the glass
    /// of water, −4 % on the pool, −3 % on the bath, ±0.3 % on the caustic Cornell box; with
    /// radius 5, or all three bandwidths at the coarse scale, no better for more work.
    pub coarse_radius: usize,
    /// The same for the unguided (caustic and specular) light.
    pub unguided_coarse_radius: usize,
    /// Patch radius of the coarse candidates' colour distance (in coarse pixels).
    pub coarse_patch: usize,
    /// Which candidates (indices into `guided_k` / `unguided_k`) are also run at the coarse
    /// scale, each composed with the fine candidate of the same bandwidth (an index beyond
    /// the bandwidths is ignored). The narrowest alone did best: the coarse scale has already
    /// averaged four pixels' noise.
    pub coarse_candidates: Vec<usize>,
    /// Share of a feature's variance subtracted from its squared difference in the feature
    /// distance (1: the variance cancellation of Rousselle, Manzi and Zwicker 2013; 0: the
    /// variance only widens the bandwidth). The features are traced without light sampling:
    /// their variance is a pixel's coverage of several surfaces (an edge, a floor seen through
    /// waves), not noise, and cancelling it let a pixel half sky and half deck count as the
    /// same surface as the sky (the pool's horizon row). At 0 the pool's relMSE falls by 5 %
    /// more, the others within ±1 %.
    pub feature_variance_cancel: f32,
}

impl Default for DenoiseParams {
    fn default() -> Self {
        Self {
            radius: 5,
            unguided_radius: 5,
            patch: 3,
            guided_k: [0.5, 1.0, 2.0],
            unguided_k: [0.35, 0.7, 1.4],
            sigma_albedo: 0.05,
            sigma_normal: 0.1,
            sigma_depth: 0.02,
            select_radius: 2,
            variance_radius: 1,
            variance_max_samples: 3,
            variance_same_surface: true,
            unguided_variance_radius: 0,
            residual_radius: 4,
            albedo_epsilon: 0.01,
            outliers: OutlierParams {
                factor: 4.0,
                window: 3,
                floor: 0.05,
            },
            coarse_radius: 3,
            unguided_coarse_radius: 3,
            coarse_patch: 1,
            coarse_candidates: vec![0],
            feature_variance_cancel: 0.0,
        }
    }
}

/// Denoises `input` (on the current rayon pool): the guided light filtered with the feature
/// weights plus the unguided (caustic and specular) light filtered by its colour alone, each by the candidate the two
/// halves' cross-validation picks per pixel. Row-major RGB, `width × height`.
///
/// # Errors
/// [`DenoiseError`] for a missing guide, buffers of the wrong size, an image smaller than
/// 2×2, or a NaN, infinite or negative-variance value (naming the buffer and the pixel).
pub fn denoise(input: &DenoiseInput, params: &DenoiseParams) -> Result<Vec<Vec3>, DenoiseError> {
    input.check()?;
    let guide = input
        .features
        .as_ref()
        .ok_or(DenoiseError::MissingFeatures)?;
    let (w, h) = (input.width, input.height);
    let guide_planes = GuidePlanes::new(guide, w, params);
    let albedo = &guide_planes.demodulate;
    let mut guided_layer = input.guided.clone();
    reject_outliers(&mut guided_layer, &params.outliers, w, h);
    let few = input.half_samples.iter().min().copied().unwrap_or(0) <= params.variance_max_samples;
    let variance_radius = if few { params.variance_radius } else { 0 };
    let same_surface = (variance_radius > 0 && params.variance_same_surface)
        .then(|| guide_planes.same_surface(w, h, variance_radius));
    let guided = LayerPlanes::new(
        &guided_layer,
        albedo,
        w,
        variance_radius,
        same_surface.as_ref(),
    );
    let shares = input.half_shares();
    let candidates = Candidates {
        k: params.guided_k.to_vec(),
        radius: params.radius,
        patch: params.patch,
    };
    let fine = cross_filter(&guided, Some(&guide_planes), &candidates, w, h);
    let coarse = (params.coarse_radius > 0).then(|| {
        let (wc, hc) = scales::coarse_size(w, h);
        let coarse_guide = GuidePlanes::new(&scales::downsample_guide(guide, w, h), wc, params);
        let candidates = Candidates {
            k: pick(&params.guided_k, &params.coarse_candidates),
            radius: params.coarse_radius,
            patch: params.coarse_patch,
        };
        cross_filter(
            &guided.downsampled(w, h),
            Some(&coarse_guide),
            &candidates,
            wc,
            hc,
        )
    });
    let changes = candidate_changes(fine, coarse, &params.coarse_candidates, w, h);
    let mut out = select(&guided_layer, &changes, albedo, shares, params, w, h);
    if let Some(unguided) = &input.unguided {
        let mut unguided = unguided.clone();
        reject_outliers(&mut unguided, &params.outliers, w, h);
        let unguided = &unguided;
        let planes = LayerPlanes::new(unguided, albedo, w, params.unguided_variance_radius, None);
        let candidates = Candidates {
            k: params.unguided_k.to_vec(),
            radius: params.unguided_radius,
            patch: params.patch,
        };
        let fine = cross_filter(&planes, None, &candidates, w, h);
        let coarse = (params.unguided_coarse_radius > 0).then(|| {
            let (wc, hc) = scales::coarse_size(w, h);
            let candidates = Candidates {
                k: pick(&params.unguided_k, &params.coarse_candidates),
                radius: params.unguided_coarse_radius,
                patch: params.coarse_patch,
            };
            cross_filter(&planes.downsampled(w, h), None, &candidates, wc, hc)
        });
        let changes = candidate_changes(fine, coarse, &params.coarse_candidates, w, h);
        let c = select(unguided, &changes, albedo, shares, params, w, h);
        for (o, c) in out.iter_mut().zip(c) {
            *o += c;
        }
    }
    Ok(out)
}

/// The bandwidths `k[i]` for each `i` of `which`.
fn pick(k: &[f32], which: &[usize]) -> Vec<f32> {
    which.iter().filter_map(|&i| k.get(i).copied()).collect()
}

/// The candidates' changes to each half: the fine ones (`[half][candidate][channel]`), then,
/// when given, each coarse one composed with the fine one of the same bandwidth
/// (`which`: the fine candidates' indices, [`scales::compose`]).
fn candidate_changes(
    fine: [Deltas; 2],
    coarse: Option<[Deltas; 2]>,
    which: &[usize],
    w: usize,
    h: usize,
) -> Vec<Change> {
    let composites: Vec<Change> = coarse
        .map(|coarse| {
            which
                .iter()
                .filter(|&&k| k < fine[0].len())
                .enumerate()
                .map(|(j, &k)| {
                    std::array::from_fn(|half| {
                        std::array::from_fn(|ch| {
                            scales::compose(&fine[half][k][ch], &coarse[half][j][ch], w, h)
                        })
                    })
                })
                .collect()
        })
        .unwrap_or_default();
    let [fa, fb] = fine;
    let mut out: Vec<Change> = fa.into_iter().zip(fb).map(|(a, b)| [a, b]).collect();
    out.extend(composites);
    out
}
