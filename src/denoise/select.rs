//! The per-pixel choice among the candidate filters by two-buffer cross-validation (Bitterli et
//! al. 2016, §5; Rousselle et al. 2012 use the two buffers the same way): candidate `k`'s
//! output of half A is compared with half B, whose noise is independent of it, so
//! `(F_A − B)² − Var(B)` estimates its squared error without a reference (and likewise for B
//! against A). The estimates, relative to the pixel's brightness, are averaged over a small
//! box and each pixel keeps the candidate with the least; its output is the two filtered
//! halves weighed by their shares of the samples.

use glam::Vec3;

use super::DenoiseParams;
use super::input::HalfBuffers;
use super::planes::box_filter;

/// One candidate filter's change to each half (filtered less input, in albedo-divided units):
/// `[half][channel][pixel]`.
pub type Change = [[Vec<f32>; 3]; 2];

/// The output of the candidate each pixel's cross-validated error picks: `layer`'s halves
/// plus the albedo (`demodulate`) times the candidate's [`Change`].
#[must_use]
pub fn select(
    layer: &HalfBuffers,
    changes: &[Change],
    demodulate: &[Vec<f32>; 3],
    shares: [f32; 2],
    params: &DenoiseParams,
    w: usize,
    h: usize,
) -> Vec<Vec3> {
    let n = w * h;
    let [ma, mb] = &layer.mean;
    let [va, vb] = &layer.variance;
    let a = |i: usize| Vec3::new(demodulate[0][i], demodulate[1][i], demodulate[2][i]);
    let change = |c: &Change, half: usize, i: usize| {
        let d = &c[half];
        Vec3::new(d[0][i], d[1][i], d[2][i])
    };
    // The filtered halves of candidate `k` at pixel i.
    let filtered = |k: usize, i: usize| {
        (
            ma[i] + a(i) * change(&changes[k], 0, i),
            mb[i] + a(i) * change(&changes[k], 1, i),
        )
    };
    // Each pixel's squared brightness (plus a floor), the errors' scale: once for all
    // candidates.
    let scale: Vec<f32> = (0..n)
        .map(|i| {
            let m = (ma[i] * shares[0] + mb[i] * shares[1]).element_sum() / 3.0;
            m * m + 1e-4
        })
        .collect();
    let errors: Vec<Vec<f32>> = (0..changes.len())
        .map(|k| {
            let raw: Vec<f32> = (0..n)
                .map(|i| {
                    let (fa, fb) = filtered(k, i);
                    let (da, db) = (fa - mb[i], fb - ma[i]);
                    let e = (da * da - vb[i] + db * db - va[i]).element_sum() / 6.0;
                    e / scale[i]
                })
                .collect();
            box_filter(&raw, w, h, params.select_radius)
        })
        .collect();
    let out: Vec<Vec3> = (0..n)
        .map(|i| {
            let mut best = 0;
            for k in 1..changes.len() {
                if errors[k][i] < errors[best][i] {
                    best = k;
                }
            }
            let (fa, fb) = filtered(best, i);
            fa + shares[1] * (fb - fa)
        })
        .collect();
    restore_structure(out, layer, shares, params.residual_radius, w, h)
}

/// Gives back what the filter removed where the two halves agree it was structure, not noise:
/// the residuals `A − F` and `B − F`, box-averaged, have independent noise, so the product of
/// the two averages estimates the squared bias of the output (the structure it smoothed away)
/// and their mean's square that plus the noise; their ratio is a Wiener gain in [0, 1] by which
/// the averaged residual is added back. Where the filter removed only noise the gain is near 0;
/// a smoothed caustic or shadow edge gets its local mean back. Exactly `out` where the
/// residuals are zero (a noise-free or constant image).
fn restore_structure(
    mut out: Vec<Vec3>,
    layer: &HalfBuffers,
    shares: [f32; 2],
    radius: usize,
    w: usize,
    h: usize,
) -> Vec<Vec3> {
    let [ma, mb] = &layer.mean;
    let [va, vb] = &layer.variance;
    for ch in 0..3 {
        let ra: Vec<f32> = (0..out.len()).map(|i| ma[i][ch] - out[i][ch]).collect();
        let rb: Vec<f32> = (0..out.len()).map(|i| mb[i][ch] - out[i][ch]).collect();
        // A tent (a box twice): a box's square edges would show around a bright residual.
        let tent = |r: &[f32]| box_filter(&box_filter(r, w, h, radius), w, h, radius);
        let (ba, bb) = (tent(&ra), tent(&rb));
        for (i, o) in out.iter_mut().enumerate() {
            let (a, b) = (ba[i], bb[i]);
            let mean = shares[0] * a + shares[1] * b;
            let m2 = mean * mean;
            if m2 > 0.0 {
                let gain = ((a * b).max(0.0) / m2).min(1.0);
                // Never beyond the pixel's own halves and their noise (two standard
                // deviations), unless the filter already was: the box average reaches across
                // edges, and a noise-free pixel (halves equal, no variance) beside a smoothed
                // edge must not take the edge's residual.
                let (pa, pb) = (ma[i][ch], mb[i][ch]);
                let noise = 2.0 * va[i][ch].max(vb[i][ch]).sqrt();
                let (lo, hi) = (pa.min(pb) - noise, pa.max(pb) + noise);
                let restored = o[ch] + gain * mean;
                o[ch] = restored.clamp(o[ch].min(lo), o[ch].max(hi));
            }
        }
    }
    out
}
