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
//! The module knows nothing of scenes or renders: plain arrays in, an image out. Every pixel's
//! arithmetic runs in a fixed order in bands of rows whose split does not depend on the thread
//! count, so the output is the same bytes for any number of threads.

pub mod cross_filter;
pub mod error;
pub mod fast_exp;
pub mod input;
pub mod planes;
pub mod select;

#[cfg(test)]
mod tests;

use glam::Vec3;

pub use error::DenoiseError;
pub use input::{DenoiseInput, Guide, HalfBuffers};

use cross_filter::{Candidates, GuidePlanes, LayerPlanes, cross_filter};
use select::select;

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
    /// Normal difference (Euclidean between unit normals; 0.2 ≈ 11.5°) at which it is 1/e.
    pub sigma_normal: f32,
    /// Relative depth difference at which it is 1/e (beyond the surface's own slope).
    pub sigma_depth: f32,
    /// Radius of the box filter that smooths the error estimates before the per-pixel choice.
    pub select_radius: usize,
    /// Radius of the box filter that prefilters each half's per-pixel variance of the guided
    /// light before the colour distances use it (0: not prefiltered). At very few samples a
    /// pixel's variance is itself noisy (two samples that are both 0 give 0, and the colour
    /// distance then refuses every neighbour): 1 lowers the glass of water's relMSE at 4 spp
    /// from 0.0149 to 0.0043 but raises the caustic Cornell box's at 16 spp from 0.00196 to
    /// 0.00205 (docs/denoise.md), so it is off by default.
    pub variance_radius: usize,
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
            sigma_normal: 0.2,
            sigma_depth: 0.02,
            select_radius: 2,
            variance_radius: 0,
            unguided_variance_radius: 0,
            residual_radius: 4,
            albedo_epsilon: 0.01,
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
    let guided = LayerPlanes::new(&input.guided, albedo, w, params.variance_radius);
    let shares = input.half_shares();
    let candidates = Candidates {
        k: params.guided_k,
        radius: params.radius,
        patch: params.patch,
    };
    let filtered = cross_filter(&guided, Some(&guide_planes), &candidates, w, h);
    let mut out = select(&input.guided, &filtered, albedo, shares, params, w, h);
    if let Some(unguided) = &input.unguided {
        let planes = LayerPlanes::new(unguided, albedo, w, params.unguided_variance_radius);
        let candidates = Candidates {
            k: params.unguided_k,
            radius: params.unguided_radius,
            patch: params.patch,
        };
        let filtered = cross_filter(&planes, None, &candidates, w, h);
        let c = select(unguided, &filtered, albedo, shares, params, w, h);
        for (o, c) in out.iter_mut().zip(c) {
            *o += c;
        }
    }
    Ok(out)
}
