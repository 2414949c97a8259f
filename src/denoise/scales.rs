//! Candidates at a coarser scale: the layer and the guide halved in each dimension (2×2 means),
//! filtered there by the same cross-filter, and the coarse result's low frequencies put in
//! place of the fine candidate's.
//!
//! The fine filter's window (11×11) cannot remove noise whose grains are about as wide as the
//! window: the blotches a caustic photon map's discs leave (a photon's disc covers several
//! pixels, so neighbouring pixels share its noise), or a dark wall lit by a few indirect
//! samples. Halving the image makes the same window cover 22×22 pixels for a quarter of the
//! work. As in the scale composition of Vogels et al., "Denoising with Kernel Prediction and
//! Asymmetric Loss Functions" (SIGGRAPH 2018, §4.3), the composite keeps the fine candidate's
//! details and takes the coarse one's low band: `F = F_fine + U(F_coarse − D(F_fine))`, with
//! `D` the 2×2 mean and `U` bilinear upsampling. Whether a pixel takes the composite or the
//! fine candidate alone is left to the two-buffer cross-validation ([`super::select`]), the
//! per-pixel choice among filter scales of Rousselle, Knaus and Zwicker, "Adaptive Sampling
//! and Reconstruction using Greedy Error Minimization" (SIGGRAPH Asia 2011) and of NFOR
//! (Bitterli et al. 2016) among bandwidths.

use glam::Vec3;

use super::input::Guide;

/// The coarse image's size: `w × h` halved, rounded up.
#[must_use]
pub fn coarse_size(w: usize, h: usize) -> (usize, usize) {
    (w.div_ceil(2), h.div_ceil(2))
}

/// `plane` (`w × h`) at half the size: each coarse pixel the mean of its 2×2 block (of the
/// 1, 2 or 4 fine pixels there at an odd edge); with `variance`, the variance of that mean
/// (the sum over the block over the count squared: the block's pixels are independent).
#[must_use]
pub fn downsample(plane: &[f32], w: usize, h: usize, variance: bool) -> Vec<f32> {
    let (wc, hc) = coarse_size(w, h);
    let mut out = Vec::with_capacity(wc * hc);
    for y in 0..hc {
        // Full 2×2 blocks: the same sums in the same order as the general loop below.
        if 2 * y + 1 < h {
            let (top, bottom) = (&plane[2 * y * w..][..w], &plane[(2 * y + 1) * w..][..w]);
            let scale = if variance { 1.0 / 16.0 } else { 0.25 };
            out.extend(
                top.chunks_exact(2)
                    .zip(bottom.chunks_exact(2))
                    .map(|(t, b)| (0.0 + t[0] + t[1] + b[0] + b[1]) * scale),
            );
            if w.is_multiple_of(2) {
                continue;
            }
        }
        for x in out.len() - y * wc..wc {
            let (mut sum, mut count) = (0.0f32, 0.0f32);
            for yy in 2 * y..(2 * y + 2).min(h) {
                for xx in 2 * x..(2 * x + 2).min(w) {
                    sum += plane[yy * w + xx];
                    count += 1.0;
                }
            }
            out.push(if variance {
                sum / (count * count)
            } else {
                sum / count
            });
        }
    }
    out
}

/// `coarse` (`coarse_size(w, h)`) bilinearly interpolated at the centres of the `w × h` fine
/// pixels (a fine pixel's centre is a quarter of a coarse pixel from its block's centre),
/// clamped at the edges.
#[must_use]
pub fn upsample(coarse: &[f32], w: usize, h: usize) -> Vec<f32> {
    let (wc, hc) = coarse_size(w, h);
    // The two coarse neighbours of fine index `i` along an axis of `n` coarse pixels and the
    // weight of the second.
    let taps = |i: usize, n: usize| {
        let c = i / 2;
        if i.is_multiple_of(2) {
            (c.saturating_sub(1), c, 0.75)
        } else {
            (c, (c + 1).min(n - 1), 0.25)
        }
    };
    let columns: Vec<(usize, usize, f32)> = (0..w).map(|x| taps(x, wc)).collect();
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        let (y0, y1, fy) = taps(y, hc);
        let (top, bottom) = (
            &coarse[y0 * wc..(y0 + 1) * wc],
            &coarse[y1 * wc..(y1 + 1) * wc],
        );
        out.extend(columns.iter().map(|&(x0, x1, fx)| {
            let t = top[x0] + (top[x1] - top[x0]) * fx;
            let b = bottom[x0] + (bottom[x1] - bottom[x0]) * fx;
            t + (b - t) * fy
        }));
    }
    out
}

/// The composite candidate's change to the input: `fine + U(coarse − D(fine))`, where `fine`
/// is the fine candidate's change (filtered less input, `w × h`) and `coarse` the coarse
/// candidate's (of the halved input); since `D` of the input is the coarse input, this is the
/// module's `F_fine + U(F_coarse − D(F_fine))` less the input.
#[must_use]
pub fn compose(fine: &[f32], coarse: &[f32], w: usize, h: usize) -> Vec<f32> {
    let low = downsample(fine, w, h, false);
    let band: Vec<f32> = coarse.iter().zip(&low).map(|(c, l)| c - l).collect();
    let up = upsample(&band, w, h);
    fine.iter().zip(&up).map(|(f, u)| f + u).collect()
}

/// The feature guide at half the size: albedo, normal and depth as 2×2 means (a block across
/// an edge becomes a mixed pixel of its own, as a coarser render's would), their variances as
/// the variance of those means.
#[must_use]
pub fn downsample_guide(guide: &Guide, w: usize, h: usize) -> Guide {
    let vectors = |v: &[Vec3]| -> Vec<Vec3> {
        let planes: [Vec<f32>; 3] = std::array::from_fn(|ch| {
            let plane: Vec<f32> = v.iter().map(|x| x[ch]).collect();
            downsample(&plane, w, h, false)
        });
        (0..planes[0].len())
            .map(|i| Vec3::new(planes[0][i], planes[1][i], planes[2][i]))
            .collect()
    };
    Guide {
        albedo: vectors(&guide.albedo),
        albedo_variance: downsample(&guide.albedo_variance, w, h, true),
        normal: vectors(&guide.normal),
        normal_variance: downsample(&guide.normal_variance, w, h, true),
        depth: downsample(&guide.depth, w, h, false),
        depth_variance: downsample(&guide.depth_variance, w, h, true),
    }
}

#[cfg(test)]
mod tests {
    use super::{compose, downsample, upsample};

    /// 2×2 means by hand on a 3×3 plane (odd edges: blocks of 2 and 1), and the variance of
    /// those means.
    #[test]
    fn downsample_takes_block_means_and_their_variance() {
        let p = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
        assert_eq!(downsample(&p, 3, 3, false), vec![3.0, 4.5, 7.5, 9.0]);
        assert_eq!(
            downsample(&p, 3, 3, true),
            vec![12.0 / 16.0, 9.0 / 4.0, 15.0 / 4.0, 9.0]
        );
        // Even sizes: full blocks only.
        let q = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
        assert_eq!(downsample(&q, 4, 2, false), vec![3.5, 5.5]);
        assert_eq!(downsample(&q, 4, 2, true), vec![14.0 / 16.0, 22.0 / 16.0]);
    }

    /// A linear ramp along x (coarse centres at fine x = 0.5, 2.5, 4.5, …) is interpolated
    /// exactly inside, and held at the edges.
    #[test]
    fn upsample_is_bilinear_between_the_coarse_centres() {
        let coarse = [0.5, 2.5, 4.5, 0.5, 2.5, 4.5];
        let fine = upsample(&coarse, 6, 4);
        let want = [0.5, 1.0, 2.0, 3.0, 4.0, 4.5];
        for y in 0..4 {
            for x in 0..6 {
                assert!((fine[y * 6 + x] - want[x]).abs() < 1e-6, "({x}, {y})");
            }
        }
    }

    /// Where the coarse candidate changed nothing more than the fine one's block means, the
    /// composite is the fine candidate; a constant shift of the coarse one is added to every
    /// fine pixel.
    #[test]
    fn compose_replaces_only_the_low_band() {
        let fine: Vec<f32> = (0..16).map(|i| ((i * 7) % 5) as f32 - 2.0).collect();
        let coarse = downsample(&fine, 4, 4, false);
        let same = compose(&fine, &coarse, 4, 4);
        for (a, b) in same.iter().zip(&fine) {
            assert!((a - b).abs() < 1e-6);
        }
        let shifted: Vec<f32> = coarse.iter().map(|c| c + 0.5).collect();
        for (a, b) in compose(&fine, &shifted, 4, 4).iter().zip(&fine) {
            assert!((a - b - 0.5).abs() < 1e-6);
        }
    }
}
