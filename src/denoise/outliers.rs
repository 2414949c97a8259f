//! Firefly rejection before the filter, by the two halves' independence.
//!
//! A firefly is one sample far beyond what its pixel's light should be (a path that found the
//! sun through a glossy chrome lobe by chance): it lands in one half of the samples only, and
//! the other half, whose samples are independent of it, sees nothing like it there or around.
//! A real highlight — the sun's image in the water, a lamp seen through glass, a caustic's hot
//! spot — is in both halves. So half A's value at a pixel is held to what half B's
//! neighbourhood confirms (and the other way round): to `τ` times the larger of B's brightest
//! value in the 3×3 around the pixel and B's mean over a `(2r+1)²` window, plus a small floor;
//! a value above that is scaled down to it (all channels alike, keeping its hue, and its
//! variance by the square of the same factor).
//!
//! This is the confirmation principle of Zirr, Hanika and Dachsbacher, "Re-weighting Firefly
//! Samples for Improved Finite-Sample Monte Carlo Estimates" (Computer Graphics Forum 2018):
//! a sample's magnitude is trusted as far as neighbouring estimates reach it, with the
//! independent half-buffer (Rousselle, Knaus and Zwicker 2012) as the neighbour that cannot
//! share the outlier. Like the density-based rejection of DeCoro, Weyrich and Rusinkiewicz
//! ("Density-based Outlier Rejection in Monte Carlo Rendering", Pacific Graphics 2010), it
//! removes energy that no neighbourhood supports: the image is biased downwards by the
//! rejected part of the fireflies (Zirr et al.'s re-weighting would give their expected share
//! back; here it is dropped, as clamping renderers do), and unbiased wherever both halves agree.

use glam::Vec3;

use super::input::HalfBuffers;
use super::planes::box_filter;

/// How far a half may exceed what the other half confirms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutlierParams {
    /// `τ`: a half's brightness may be this many times the other half's confirmation (≤ 0:
    /// no rejection).
    pub factor: f32,
    /// Radius of the window whose mean (of the other half) also confirms a value, besides the
    /// 3×3 maximum.
    pub window: usize,
    /// The floor, as a share of the layer's mean brightness over the image: a value this dim
    /// is never rejected (dark regions where the other half happens to be 0).
    pub floor: f32,
}

/// The brightness a value is judged by: its channels' mean.
fn brightness(v: Vec3) -> f32 {
    v.element_sum() / 3.0
}

/// Holds each half of `layer` (`w × h`) to what the other half confirms (module docs); returns
/// how many half-pixels were scaled down. Values at or below the bound are left bit for bit,
/// so a noise-free image (both halves equal) is unchanged.
pub fn reject_outliers(
    layer: &mut HalfBuffers,
    params: &OutlierParams,
    w: usize,
    h: usize,
) -> usize {
    if params.factor <= 0.0 || w == 0 || h == 0 {
        return 0;
    }
    let n = w * h;
    let lum: [Vec<f32>; 2] = std::array::from_fn(|half| {
        layer.mean[half]
            .iter()
            .map(|&v| brightness(v).max(0.0))
            .collect()
    });
    let total: f64 = lum.iter().flatten().map(|&v| f64::from(v)).sum();
    let floor = params.floor * (total / (2 * n) as f64) as f32;
    let mut rejected = 0;
    // Both bounds from the unchanged halves: A's test does not see B's rejections.
    let bounds: [Vec<f32>; 2] = std::array::from_fn(|half| {
        let other = &lum[1 - half];
        let mean = box_filter(other, w, h, params.window);
        (0..n)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let mut peak = 0.0f32;
                for yy in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                    for xx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                        peak = peak.max(other[yy * w + xx]);
                    }
                }
                params.factor * peak.max(mean[i]) + floor
            })
            .collect()
    });
    for (half, bound) in bounds.iter().enumerate() {
        for (i, &b) in bound.iter().enumerate() {
            let v = lum[half][i];
            if v > b {
                let s = b / v;
                layer.mean[half][i] *= s;
                layer.variance[half][i] *= s * s;
                rejected += 1;
            }
        }
    }
    rejected
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::{OutlierParams, reject_outliers};
    use crate::denoise::input::HalfBuffers;

    const PARAMS: OutlierParams = OutlierParams {
        factor: 4.0,
        window: 3,
        floor: 0.05,
    };

    /// A 9×9 layer of 0.3 in both halves (variance 0.01), with `a` and `b` put at the centre of
    /// half A and half B.
    fn layer(a: Vec3, b: Vec3) -> HalfBuffers {
        let n = 81;
        let mut l = HalfBuffers {
            mean: [vec![Vec3::splat(0.3); n], vec![Vec3::splat(0.3); n]],
            variance: [vec![Vec3::splat(0.01); n], vec![Vec3::splat(0.01); n]],
        };
        l.mean[0][40] = a;
        l.mean[1][40] = b;
        l
    }

    /// The bath's firefly: 119 in one half where the light is 0.3 (the other half has 0.3):
    /// brought down to 4 × 0.3 plus the floor, hue kept, variance scaled by the same factor
    /// squared; nothing else touched.
    #[test]
    fn a_spike_in_one_half_is_brought_down_to_what_the_other_confirms() {
        let spike = Vec3::new(119.0, 110.0, 100.0);
        let mut l = layer(spike, Vec3::splat(0.3));
        let before = l.clone();
        assert_eq!(reject_outliers(&mut l, &PARAMS, 9, 9), 1);
        let mean = (0.3 * 80.0 * 2.0 + 0.3 + spike.element_sum() / 3.0) / 162.0;
        let bound = 4.0 * 0.3 + 0.05 * mean;
        let got = l.mean[0][40];
        assert!((got.element_sum() / 3.0 - bound).abs() < 1e-4, "{got}");
        let s = bound / (spike.element_sum() / 3.0);
        assert!(
            (got - spike * s).abs().max_element() < 1e-4,
            "hue kept: {got}"
        );
        assert!((l.variance[0][40].x - 0.01 * s * s).abs() < 1e-9);
        for i in (0..81).filter(|&i| i != 40) {
            assert_eq!(l.mean[0][i], before.mean[0][i]);
        }
        assert_eq!(l.mean[1], before.mean[1]);
    }

    /// A real one-pixel highlight, in both halves (at different noisy levels): kept bit for
    /// bit, and so is every other pixel.
    #[test]
    fn a_one_pixel_highlight_in_both_halves_is_kept() {
        let mut l = layer(Vec3::splat(119.0), Vec3::splat(60.0));
        let before = l.clone();
        assert_eq!(reject_outliers(&mut l, &PARAMS, 9, 9), 0);
        assert_eq!(l, before);
    }

    /// A highlight that moves by one pixel between the halves (a thin line both halves see, at
    /// neighbouring pixels) is kept too.
    #[test]
    fn a_highlight_a_pixel_off_in_the_other_half_is_kept() {
        let mut l = layer(Vec3::splat(50.0), Vec3::splat(0.3));
        l.mean[1][41] = Vec3::splat(40.0);
        let before = l.clone();
        assert_eq!(reject_outliers(&mut l, &PARAMS, 9, 9), 0);
        assert_eq!(l, before);
    }
}
