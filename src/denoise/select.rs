//! The per-pixel choice among the candidate filters by two-buffer cross-validation (Bitterli et
//! al. 2016, §5; Rousselle et al. 2012 use the two buffers the same way): candidate `k`'s
//! output of half A is compared with half B, whose noise is independent of it, so
//! `(F_A − B)² − Var(B)` estimates its squared error without a reference (and likewise for B
//! against A). The estimates, relative to the pixel's brightness, are averaged over a small
//! box and each pixel keeps the candidate with the least; its output is the two filtered
//! halves weighed by their shares of the samples.

use glam::Vec3;

use super::DenoiseParams;
use super::cross_filter::{CANDIDATES, Deltas};
use super::input::HalfBuffers;
use super::planes::box_filter;

/// The output of the candidate each pixel's cross-validated error picks: `layer`'s halves
/// plus the albedo (`demodulate`) times `deltas` (each half's [`super::cross_filter`]).
#[must_use]
pub fn select(
    layer: &HalfBuffers,
    deltas: &[Deltas; 2],
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
    let delta = |half: usize, k: usize, i: usize| {
        let d = &deltas[half][k];
        Vec3::new(d[0][i], d[1][i], d[2][i])
    };
    // The filtered halves of candidate k at pixel i.
    let filtered =
        |k: usize, i: usize| (ma[i] + a(i) * delta(0, k, i), mb[i] + a(i) * delta(1, k, i));
    let errors: [Vec<f32>; CANDIDATES] = std::array::from_fn(|k| {
        let raw: Vec<f32> = (0..n)
            .map(|i| {
                let (fa, fb) = filtered(k, i);
                let (da, db) = (fa - mb[i], fb - ma[i]);
                let e = (da * da - vb[i] + db * db - va[i]).element_sum() / 6.0;
                let m = (ma[i] * shares[0] + mb[i] * shares[1]).element_sum() / 3.0;
                e / (m * m + 1e-4)
            })
            .collect();
        box_filter(&raw, w, h, params.select_radius)
    });
    (0..n)
        .map(|i| {
            let mut best = 0;
            for k in 1..CANDIDATES {
                if errors[k][i] < errors[best][i] {
                    best = k;
                }
            }
            let (fa, fb) = filtered(best, i);
            fa + shares[1] * (fb - fa)
        })
        .collect()
}
