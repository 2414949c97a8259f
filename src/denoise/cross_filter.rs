//! The candidate filters: joint non-local means with cross-bilateral feature weights
//! (Rousselle, Manzi & Zwicker 2013), applied to one half of the samples with weights computed
//! from the other half (the cross-filtering of Bitterli et al. 2016), in albedo-divided units.
//!
//! For pixels `p`, `q = p + o` in the search window, the colour distance of the guiding half
//! `Y` per channel is Rousselle et al. (2012)'s variance-cancelled
//! `((Y_p − Y_q)² − (V_p + min(V_p, V_q))) / (ε + V_p + V_q)`, averaged over the channels and
//! over a `(2f+1)²` patch; a feature's distance is the same form with a bandwidth σ in the
//! denominator (albedo and normal; depth with σ relative to the depth plus the surface's own
//! slope times |o|). The weight of candidate `k` is `exp(−max(d_colour / k², d_features))`
//! (Rousselle 2013 take the smaller of the colour and feature weights), and the filtered value
//! `X_p + Σ w (X_q − X_p) / Σ w`: exactly `X_p` where every neighbour with weight agrees.

use rayon::prelude::*;

use super::DenoiseParams;
use super::fast_exp::exp_neg;
use super::input::{Guide, HalfBuffers};
use super::planes::box_rows;

/// Rows per work item: a fixed split (not by thread count), so any thread count gives the same
/// bytes.
const BAND: usize = 8;
/// Keeps the colour distance finite where both variances are zero (a noise-free pixel): any
/// real difference then gives a distance far beyond the weights' range.
const EPS: f32 = 1e-30;
/// Number of candidate filters.
pub const CANDIDATES: usize = 3;

/// The candidate filters of one layer: their colour bandwidths, the window and patch radii.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidates {
    /// Colour bandwidth `k` of each candidate.
    pub k: [f32; CANDIDATES],
    /// Search window radius.
    pub radius: usize,
    /// Patch radius.
    pub patch: usize,
}

/// One layer's halves divided by the albedo (plus ε), as planes: `c[half][channel]`, and the
/// variances divided by its square.
#[derive(Debug, Clone)]
pub struct LayerPlanes {
    c: [[Vec<f32>; 3]; 2],
    v: [[Vec<f32>; 3]; 2],
}

impl LayerPlanes {
    /// The planes of `layer` divided by `demodulate` (per channel).
    #[must_use]
    pub fn new(layer: &HalfBuffers, demodulate: &[Vec<f32>; 3]) -> Self {
        let plane = |values: &[glam::Vec3], ch: usize, power: i32| -> Vec<f32> {
            values
                .iter()
                .zip(&demodulate[ch])
                .map(|(v, a)| v[ch] / a.powi(power))
                .collect()
        };
        let half =
            |values: &[glam::Vec3], power| std::array::from_fn(|ch| plane(values, ch, power));
        Self {
            c: std::array::from_fn(|h| half(&layer.mean[h], 1)),
            v: std::array::from_fn(|h| half(&layer.variance[h], 2)),
        }
    }
}

/// The feature guide as planes, with the bandwidths folded in, and the demodulation factor.
#[derive(Debug, Clone)]
pub struct GuidePlanes {
    /// Albedo + ε per channel: what the light is divided by before filtering.
    pub demodulate: [Vec<f32>; 3],
    albedo: [Vec<f32>; 3],
    albedo_var: Vec<f32>,
    normal: [Vec<f32>; 3],
    normal_var: Vec<f32>,
    depth: Vec<f32>,
    depth_var: Vec<f32>,
    /// |∂depth/∂pixel|, the smaller one-sided difference along x or y, whichever is larger.
    slope: Vec<f32>,
    sigma_albedo2: f32,
    sigma_normal2: f32,
    sigma_depth: f32,
}

impl GuidePlanes {
    /// The planes of `guide` for a `w`-wide image.
    #[must_use]
    pub fn new(guide: &Guide, w: usize, params: &DenoiseParams) -> Self {
        let split = |v: &[glam::Vec3]| std::array::from_fn(|ch| v.iter().map(|x| x[ch]).collect());
        let albedo: [Vec<f32>; 3] = split(&guide.albedo);
        let demodulate = std::array::from_fn(|ch| {
            albedo[ch]
                .iter()
                .map(|a| a.max(0.0) + params.albedo_epsilon)
                .collect()
        });
        let d = &guide.depth;
        let h = d.len() / w.max(1);
        let slope = (0..d.len())
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let one_sided = |a: Option<usize>, b: Option<usize>| {
                    let diff = |j: Option<usize>| j.map_or(f32::INFINITY, |j| (d[j] - d[i]).abs());
                    let s = diff(a).min(diff(b));
                    if s.is_finite() { s } else { 0.0 }
                };
                let gx = one_sided(
                    x.checked_sub(1).map(|_| i - 1),
                    (x + 1 < w).then_some(i + 1),
                );
                let gy = one_sided(
                    y.checked_sub(1).map(|_| i - w),
                    (y + 1 < h).then_some(i + w),
                );
                gx.max(gy)
            })
            .collect();
        Self {
            demodulate,
            albedo,
            albedo_var: guide.albedo_variance.clone(),
            normal: split(&guide.normal),
            normal_var: guide.normal_variance.clone(),
            depth: guide.depth.clone(),
            depth_var: guide.depth_variance.clone(),
            slope,
            sigma_albedo2: params.sigma_albedo * params.sigma_albedo,
            sigma_normal2: params.sigma_normal * params.sigma_normal,
            sigma_depth: params.sigma_depth,
        }
    }

    /// The feature distance of pixels `p` and `q`, `steps` pixels apart (|dx| + |dy|).
    #[inline]
    fn distance(&self, p: usize, q: usize, steps: f32) -> f32 {
        let cancel = |a: f32, b: f32| a + a.min(b);
        let vec_d = |f: &[Vec<f32>; 3], v: &[f32], sigma2: f32| {
            let mut d2 = 0.0;
            for c in f {
                let t = c[p] - c[q];
                d2 += t * t;
            }
            (d2 - cancel(v[p], v[q])).max(0.0) / (sigma2 + v[p] + v[q])
        };
        let da = vec_d(&self.albedo, &self.albedo_var, self.sigma_albedo2);
        let dn = vec_d(&self.normal, &self.normal_var, self.sigma_normal2);
        let (dp, dq) = (self.depth[p], self.depth[q]);
        let s = self.sigma_depth * dp.abs() + self.slope[p] * steps + 1e-6;
        let (vp, vq) = (self.depth_var[p], self.depth_var[q]);
        let dd = ((dp - dq) * (dp - dq) - cancel(vp, vq)).max(0.0) / (s * s + vp + vq);
        da.max(dn).max(dd)
    }
}

/// Per candidate and channel, the filtered half `half` less that half (albedo-divided):
/// `[candidate][channel][pixel]`.
pub type Deltas = [[Vec<f32>; 3]; CANDIDATES];

/// Filters half `half` of `layer` with each candidate, weights from the other half and, when
/// given, the feature guide. Runs on the current rayon pool in fixed bands of rows.
#[must_use]
pub fn cross_filter(
    layer: &LayerPlanes,
    half: usize,
    guide: Option<&GuidePlanes>,
    candidates: &Candidates,
    w: usize,
    h: usize,
) -> Deltas {
    let bands: Vec<usize> = (0..h).step_by(BAND).collect();
    let parts: Vec<Deltas> = bands
        .par_iter()
        .map(|&y0| filter_band(layer, half, guide, candidates, w, h, y0..(y0 + BAND).min(h)))
        .collect();
    std::array::from_fn(|k| {
        std::array::from_fn(|ch| {
            parts
                .iter()
                .flat_map(|p| p[k][ch].iter().copied())
                .collect()
        })
    })
}

/// [`cross_filter`] for the rows `rows`.
fn filter_band(
    layer: &LayerPlanes,
    half: usize,
    guide: Option<&GuidePlanes>,
    cand: &Candidates,
    w: usize,
    h: usize,
    rows: std::ops::Range<usize>,
) -> Deltas {
    let (r, f) = (cand.radius as isize, cand.patch);
    let n = rows.len() * w;
    let inv_k2 = cand.k.map(|k| 1.0 / (k * k).max(1e-12));
    let (cy, vy, cx) = (&layer.c[1 - half], &layer.v[1 - half], &layer.c[half]);
    let (p0, p1) = (rows.start.saturating_sub(f), (rows.end + f).min(h));
    let mut dist = vec![0.0f32; (p1 - p0) * w];
    let mut patch = vec![0.0f32; n];
    let mut scratch = Vec::new();
    let mut acc: Deltas = std::array::from_fn(|_| std::array::from_fn(|_| vec![0.0; n]));
    let mut wsum = [vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; n]];
    for dy in -r..=r {
        for dx in -r..=r {
            let xs = (-dx).max(0) as usize..(w as isize - dx.max(0)) as usize;
            if xs.is_empty() {
                continue;
            }
            // The colour distance of every pixel the band's patches cover.
            dist.fill(0.0);
            for y in p0..p1 {
                let qy = y as isize + dy;
                if qy < 0 || qy >= h as isize {
                    continue;
                }
                let (pr, qr) = (y * w, qy as usize * w);
                let row = &mut dist[(y - p0) * w..(y - p0 + 1) * w];
                for ch in 0..3 {
                    let (yp, yq) = (&cy[ch][pr..pr + w], &cy[ch][qr..qr + w]);
                    let (vp, vq) = (&vy[ch][pr..pr + w], &vy[ch][qr..qr + w]);
                    for x in xs.clone() {
                        let xq = (x as isize + dx) as usize;
                        let t = yp[x] - yq[xq];
                        let (a, b) = (vp[x], vq[xq]);
                        row[x] += (t * t - (a + a.min(b))) / (EPS + a + b);
                    }
                }
            }
            box_rows(&dist, p0, w, h, f, rows.clone(), &mut scratch, &mut patch);
            let steps = (dx.abs() + dy.abs()) as f32;
            for y in rows.clone() {
                let qy = y as isize + dy;
                if qy < 0 || qy >= h as isize {
                    continue;
                }
                let (pr, qr, br) = (y * w, qy as usize * w, (y - rows.start) * w);
                for x in xs.clone() {
                    let (p, q, i) = (pr + x, qr + (x as isize + dx) as usize, br + x);
                    let dc = (patch[i] * (1.0 / 3.0)).max(0.0);
                    let df = guide.map_or(0.0, |g| g.distance(p, q, steps));
                    let diff = [
                        cx[0][q] - cx[0][p],
                        cx[1][q] - cx[1][p],
                        cx[2][q] - cx[2][p],
                    ];
                    for k in 0..CANDIDATES {
                        let wt = exp_neg((dc * inv_k2[k]).max(df));
                        wsum[k][i] += wt;
                        for ch in 0..3 {
                            acc[k][ch][i] += wt * diff[ch];
                        }
                    }
                }
            }
        }
    }
    for k in 0..CANDIDATES {
        for ch in 0..3 {
            for (a, s) in acc[k][ch].iter_mut().zip(&wsum[k]) {
                // Σw ≥ 1: the pixel itself has weight 1.
                *a /= s.max(1.0);
            }
        }
    }
    acc
}
