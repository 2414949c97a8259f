//! The candidate filters: joint non-local means with cross-bilateral feature weights
//! (Rousselle, Manzi & Zwicker 2013), applied to one half of the samples with weights computed
//! from the other half (the cross-filtering of Bitterli et al. 2016), in albedo-divided units.
//!
//! For pixels `p`, `q = p + o` in the search window, the colour distance of the guiding half
//! `Y` per channel is Rousselle et al. (2012)'s variance-cancelled
//! `((Y_p − Y_q)² − (V_p + min(V_p, V_q))) / (ε + V_p + V_q)`, averaged over the channels and
//! over a `(2f+1)²` patch; a feature's distance is the same form with a bandwidth σ in the
//! denominator (albedo and normal; depth with σ relative to the depth plus the surface's own
//! slope times |o|), its variance subtracted only by the share
//! [`DenoiseParams::feature_variance_cancel`] (by default none: a feature's variance is a
//! pixel's coverage of several surfaces, and only widens the bandwidth). The weight of candidate `k` is `exp(−max(d_colour / k², d_features))`
//! (Rousselle 2013 take the smaller of the colour and feature weights), and the filtered value
//! `X_p + Σ w (X_q − X_p) / Σ w`: exactly `X_p` where every neighbour with weight agrees.

use rayon::prelude::*;

use super::DenoiseParams;
use super::fast_exp::exp_neg;
use super::input::{Guide, HalfBuffers};
use super::planes::{box_filter, box_rows};
use super::scales;

/// Rows per work item: a fixed split (not by thread count), so any thread count gives the same
/// bytes.
const BAND: usize = 16;
/// Keeps the colour distance finite where both variances are zero (a noise-free pixel): any
/// real difference then gives a distance far beyond the weights' range.
const EPS: f32 = 1e-30;

/// The candidate filters of one layer: their colour bandwidths, the window and patch radii.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidates {
    /// Colour bandwidth `k` of each candidate.
    pub k: Vec<f32>,
    /// Search window radius.
    pub radius: usize,
    /// Patch radius.
    pub patch: usize,
}

/// One layer's halves divided by the albedo (plus ε), as planes: `c[half][channel]`, and the
/// variances divided by its square, box-filtered.
#[derive(Debug, Clone)]
pub struct LayerPlanes {
    c: [[Vec<f32>; 3]; 2],
    v: [[Vec<f32>; 3]; 2],
}

impl LayerPlanes {
    /// The planes of `layer` divided by `demodulate` (per channel), for a `w`-wide image. The
    /// variances are box-filtered over `(2·variance_radius + 1)²` pixels (0: as they are): a
    /// pixel's variance from a few samples is itself very noisy — with two samples that agree
    /// by chance (both zero, say) it is 0, and the colour distance would then refuse every
    /// neighbour — so it is prefiltered, as Rousselle, Knaus and Zwicker (2012) and Bitterli et
    /// al. (2016) prefilter theirs. With `same_surface` (of that radius), only over the
    /// neighbours on the centre's surface; without, over the whole box.
    #[must_use]
    pub fn new(
        layer: &HalfBuffers,
        demodulate: &[Vec<f32>; 3],
        w: usize,
        variance_radius: usize,
        same_surface: Option<&SameSurface>,
    ) -> Self {
        let plane = |values: &[glam::Vec3], ch: usize, power: i32| -> Vec<f32> {
            values
                .iter()
                .zip(&demodulate[ch])
                .map(|(v, a)| v[ch] / a.powi(power))
                .collect()
        };
        let half =
            |values: &[glam::Vec3], power| std::array::from_fn(|ch| plane(values, ch, power));
        let h = layer.mean[0].len() / w.max(1);
        let smooth = |plane: Vec<f32>| {
            if variance_radius == 0 || w == 0 {
                plane
            } else if let Some(g) = same_surface.filter(|g| g.r == variance_radius) {
                g.mean(&plane)
            } else {
                box_filter(&plane, w, h, variance_radius)
            }
        };
        Self {
            c: std::array::from_fn(|h| half(&layer.mean[h], 1)),
            v: std::array::from_fn(|hf| half(&layer.variance[hf], 2).map(smooth)),
        }
    }

    /// These planes (`w × h`) at half the size ([`scales::downsample`]: 2×2 means, and the
    /// variances of those means), for the coarse candidates.
    #[must_use]
    pub fn downsampled(&self, w: usize, h: usize) -> Self {
        let down = |planes: &[[Vec<f32>; 3]; 2], variance: bool| {
            std::array::from_fn(|half| {
                std::array::from_fn(|ch| scales::downsample(&planes[half][ch], w, h, variance))
            })
        };
        Self {
            c: down(&self.c, false),
            v: down(&self.v, true),
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
    /// Share of a feature's variance subtracted from its squared difference (1: Rousselle et
    /// al. 2013's variance cancellation; 0: the variance only widens the bandwidth).
    cancel: f32,
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
            cancel: params.feature_variance_cancel,
        }
    }

    /// Which pixels of each `(2r+1)²` window (`w × h` image) the guide counts as the same
    /// surface as the centre (feature distance at most 1: a feature weight of at least 1/e),
    /// for averaging noisy per-pixel values over one surface only ([`SameSurface::mean`]).
    #[must_use]
    pub fn same_surface(&self, w: usize, h: usize, r: usize) -> SameSurface {
        let side = 2 * r + 1;
        let mut mask = vec![false; w * h * side * side];
        let mut d = vec![0.0f32; w];
        let r = r as isize;
        // Offset by offset, a row at a time (the distances of a row's pixels in one call).
        for dy in -r..=r {
            for dx in -r..=r {
                let (x0, x1) = (
                    (-dx).max(0) as usize,
                    (w as isize - dx.max(0)).max(0) as usize,
                );
                if x1 <= x0 {
                    continue;
                }
                let slot = ((dy + r) as usize) * side + (dx + r) as usize;
                let steps = (dx.abs() + dy.abs()) as f32;
                for y in 0..h {
                    let qy = y as isize + dy;
                    if qy < 0 || qy >= h as isize {
                        continue;
                    }
                    let p_at = y * w + x0;
                    let q_at = ((qy as usize * w + x0) as isize + dx) as usize;
                    let d = &mut d[..x1 - x0];
                    self.distances(p_at, q_at, steps, d);
                    for (j, &dist) in d.iter().enumerate() {
                        mask[(p_at + j) * side * side + slot] = dist <= 1.0;
                    }
                }
            }
        }
        SameSurface {
            w,
            h,
            r: r as usize,
            mask,
        }
    }

    /// The feature distances of the pixels from `p_at` on to those from `q_at` on, `steps`
    /// pixels apart (|dx| + |dy|), into `out` (one per pixel).
    fn distances(&self, p_at: usize, q_at: usize, steps: f32, out: &mut [f32]) {
        let len = out.len();
        let (ps, qs) = (p_at..p_at + len, q_at..q_at + len);
        // Depth first: it sets every distance.
        let (dp, dq) = (&self.depth[ps.clone()], &self.depth[qs.clone()]);
        let (vp, vq) = (&self.depth_var[ps.clone()], &self.depth_var[qs.clone()]);
        let slope = &self.slope[ps.clone()];
        for (((((o, &a), &b), &va), &vb), &g) in
            out.iter_mut().zip(dp).zip(dq).zip(vp).zip(vq).zip(slope)
        {
            let s = self.sigma_depth * a.abs() + g * steps + 1e-6;
            let t = a - b;
            *o = (t * t - self.cancel * (va + va.min(vb))).max(0.0) / (s * s + va + vb);
        }
        let features = [
            (&self.albedo, &self.albedo_var, self.sigma_albedo2),
            (&self.normal, &self.normal_var, self.sigma_normal2),
        ];
        for (f, v, sigma2) in features {
            let (f0p, f0q) = (&f[0][ps.clone()], &f[0][qs.clone()]);
            let (f1p, f1q) = (&f[1][ps.clone()], &f[1][qs.clone()]);
            let (f2p, f2q) = (&f[2][ps.clone()], &f[2][qs.clone()]);
            let (vp, vq) = (&v[ps.clone()], &v[qs.clone()]);
            for i in 0..len {
                let (t0, t1, t2) = (f0p[i] - f0q[i], f1p[i] - f1q[i], f2p[i] - f2q[i]);
                let (va, vb) = (vp[i], vq[i]);
                let d2 = t0 * t0 + t1 * t1 + t2 * t2;
                let d = (d2 - self.cancel * (va + va.min(vb))).max(0.0) / (sigma2 + va + vb);
                out[i] = out[i].max(d);
            }
        }
    }
}

/// For every pixel, which pixels of its `(2r+1)²` window are on its surface
/// ([`GuidePlanes::same_surface`]).
#[derive(Debug, Clone)]
pub struct SameSurface {
    w: usize,
    h: usize,
    r: usize,
    mask: Vec<bool>,
}

impl SameSurface {
    /// `plane` (`w × h`) averaged over each pixel's window, among the pixels on its surface:
    /// the prefilter of a noisy per-pixel variance that does not carry one surface's noise
    /// across an edge onto another (a noise-free background beside a noisy floor).
    #[must_use]
    pub fn mean(&self, plane: &[f32]) -> Vec<f32> {
        let (w, h, r) = (self.w, self.h, self.r);
        let side = 2 * r + 1;
        (0..plane.len())
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let (mut sum, mut count) = (0.0f32, 0.0f32);
                for yy in y.saturating_sub(r)..=(y + r).min(h - 1) {
                    for xx in x.saturating_sub(r)..=(x + r).min(w - 1) {
                        if self.mask[i * side * side + (yy + r - y) * side + (xx + r - x)] {
                            sum += plane[yy * w + xx];
                            count += 1.0;
                        }
                    }
                }
                // The centre is at distance 0 from itself: count ≥ 1.
                sum / count.max(1.0)
            })
            .collect()
    }
}

/// Per candidate and channel, the filtered half less that half (albedo-divided):
/// `[candidate][channel][pixel]`.
pub type Deltas = Vec<[Vec<f32>; 3]>;

/// Filters both halves of `layer` with each candidate: half 0 with weights from half 1 and the
/// other way round, with the feature guide when given. Runs on the current rayon pool in fixed
/// bands of rows.
#[must_use]
pub fn cross_filter(
    layer: &LayerPlanes,
    guide: Option<&GuidePlanes>,
    candidates: &Candidates,
    w: usize,
    h: usize,
) -> [Deltas; 2] {
    let bands: Vec<usize> = (0..h).step_by(BAND).collect();
    let parts: Vec<[Deltas; 2]> = bands
        .par_iter()
        .map(|&y0| filter_band(layer, guide, candidates, w, h, y0..(y0 + BAND).min(h)))
        .collect();
    std::array::from_fn(|half| {
        (0..candidates.k.len())
            .map(|k| {
                std::array::from_fn(|ch| {
                    parts
                        .iter()
                        .flat_map(|p| p[half][k][ch].iter().copied())
                        .collect()
                })
            })
            .collect()
    })
}

/// Adds the colour distance of the pixels of `row` (row `y`) to those `dx, dy` away, in the
/// guiding half's planes `c`, `v`, for the columns `xs` (all of whose neighbours are inside).
#[inline]
fn colour_distance(
    c: &[Vec<f32>; 3],
    v: &[Vec<f32>; 3],
    p_at: usize,
    q_at: usize,
    len: usize,
    row: &mut [f32],
) {
    for ch in 0..3 {
        let (yp, yq) = (&c[ch][p_at..p_at + len], &c[ch][q_at..q_at + len]);
        let (vp, vq) = (&v[ch][p_at..p_at + len], &v[ch][q_at..q_at + len]);
        // Indexed over slices of one length (no bounds checks): vectorises, where the
        // five-way zip ran scalar.
        let row = &mut row[..len];
        for i in 0..len {
            let (t, va, vb) = (yp[i] - yq[i], vp[i], vq[i]);
            row[i] += (t * t - (va + va.min(vb))) / (EPS + va + vb);
        }
    }
}

/// [`cross_filter`] for the rows `rows`.
fn filter_band(
    layer: &LayerPlanes,
    guide: Option<&GuidePlanes>,
    cand: &Candidates,
    w: usize,
    h: usize,
    rows: std::ops::Range<usize>,
) -> [Deltas; 2] {
    let (r, f) = (cand.radius as isize, cand.patch);
    let n = rows.len() * w;
    let inv_k2: Vec<f32> = cand
        .k
        .iter()
        .map(|k| 1.0 / (3.0 * (k * k).max(1e-12)))
        .collect();
    let nk = inv_k2.len();
    let (p0, p1) = (rows.start.saturating_sub(f), (rows.end + f).min(h));
    // Per half: the colour distance of its guide (the other half), and its patch average.
    let mut dist = [vec![0.0f32; (p1 - p0) * w], vec![0.0f32; (p1 - p0) * w]];
    let mut patch = [vec![0.0f32; n], vec![0.0f32; n]];
    let mut scratch = Vec::new();
    let mut df = vec![0.0f32; w];
    let mut wt = vec![0.0f32; w];
    let zero = || -> Deltas {
        (0..nk)
            .map(|_| std::array::from_fn(|_| vec![0.0; n]))
            .collect()
    };
    let mut acc = [zero(), zero()];
    let mut wsum: [Vec<Vec<f32>>; 2] = std::array::from_fn(|_| vec![vec![0.0; n]; nk]);
    for dy in -r..=r {
        for dx in -r..=r {
            let x0 = (-dx).max(0) as usize;
            let x1 = (w as isize - dx.max(0)).max(0) as usize;
            if x1 <= x0 {
                continue;
            }
            let len = x1 - x0;
            // The colour distance of every pixel the band's patches cover, for each half's
            // guide (the other half).
            for (half, d) in dist.iter_mut().enumerate() {
                d.fill(0.0);
                let (c, v) = (&layer.c[1 - half], &layer.v[1 - half]);
                for y in p0..p1 {
                    let qy = y as isize + dy;
                    if qy < 0 || qy >= h as isize {
                        continue;
                    }
                    let p_at = y * w + x0;
                    let q_at = (qy as usize * w + x0) as isize + dx;
                    let row = &mut d[(y - p0) * w + x0..(y - p0) * w + x1];
                    colour_distance(c, v, p_at, q_at as usize, len, row);
                }
                box_rows(d, p0, w, h, f, rows.clone(), &mut scratch, &mut patch[half]);
            }
            let steps = (dx.abs() + dy.abs()) as f32;
            for y in rows.clone() {
                let qy = y as isize + dy;
                if qy < 0 || qy >= h as isize {
                    continue;
                }
                let p_at = y * w + x0;
                let q_at = ((qy as usize * w + x0) as isize + dx) as usize;
                let b_at = (y - rows.start) * w + x0;
                let df = &mut df[..len];
                match guide {
                    Some(g) => g.distances(p_at, q_at, steps, df),
                    None => df.fill(0.0),
                }
                for half in 0..2 {
                    let cx = &layer.c[half];
                    let dc = &patch[half][b_at..b_at + len];
                    for k in 0..nk {
                        let (wt, df) = (&mut wt[..len], &df[..len]);
                        let inv = inv_k2[k];
                        for i in 0..len {
                            wt[i] = exp_neg((dc[i] * inv).max(df[i]));
                        }
                        let s = &mut wsum[half][k][b_at..b_at + len];
                        for i in 0..len {
                            s[i] += wt[i];
                        }
                        for ch in 0..3 {
                            let (cp, cq) = (&cx[ch][p_at..p_at + len], &cx[ch][q_at..q_at + len]);
                            let a = &mut acc[half][k][ch][b_at..b_at + len];
                            for i in 0..len {
                                a[i] += wt[i] * (cq[i] - cp[i]);
                            }
                        }
                    }
                }
            }
        }
    }
    for (acc, wsum) in acc.iter_mut().zip(&wsum) {
        for (acc, wsum) in acc.iter_mut().zip(wsum) {
            for plane in acc.iter_mut() {
                for (a, s) in plane.iter_mut().zip(wsum) {
                    // Σw ≥ 1: the pixel itself has weight 1.
                    *a /= s.max(1.0);
                }
            }
        }
    }
    acc
}
