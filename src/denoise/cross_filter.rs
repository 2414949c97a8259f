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
                .map(|(v, a)| v[ch] / if power == 2 { a * a } else { *a })
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

/// Writes the colour distance of the pixels of `row` (`len` of them, from `p_at`) to those from
/// `q_at` on, in the guiding half's planes `c`, `v`: the sum over the channels.
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
        if ch == 0 {
            for i in 0..len {
                let (t, va, vb) = (yp[i] - yq[i], vp[i], vq[i]);
                row[i] = (t * t - (va + va.min(vb))) / (EPS + va + vb);
            }
        } else {
            for i in 0..len {
                let (t, va, vb) = (yp[i] - yq[i], vp[i], vq[i]);
                row[i] += (t * t - (va + va.min(vb))) / (EPS + va + vb);
            }
        }
    }
}

/// Candidates whose weights are computed together: `exp(−d/k²)` for a bandwidth `k` is
/// `exp(−d/(2k)²)` to the fourth power, so of three candidates `4k, 2k, k` only the widest
/// needs an exponential, the others two multiplies each.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Chain {
    /// One candidate, its own exponential.
    One(usize),
    /// Candidates of bandwidths `k, k/2, k/4` (exactly), the widest first.
    Three([usize; 3]),
}

/// The candidates of bandwidths `k` grouped into [`Chain`]s, from the widest.
fn chains(k: &[f32]) -> Vec<Chain> {
    let mut order: Vec<usize> = (0..k.len()).collect();
    order.sort_by(|&a, &b| k[b].total_cmp(&k[a]));
    let mut used = vec![false; k.len()];
    let mut out = Vec::new();
    for &top in &order {
        if used[top] {
            continue;
        }
        let half_of = |i: usize| (0..k.len()).find(|&j| !used[j] && j != i && 2.0 * k[j] == k[i]);
        let chain = half_of(top).and_then(|mid| {
            let low =
                (0..k.len()).find(|&j| !used[j] && j != top && j != mid && 2.0 * k[j] == k[mid]);
            low.map(|low| [top, mid, low])
        });
        match chain {
            Some(three) => {
                for i in three {
                    used[i] = true;
                }
                out.push(Chain::Three(three));
            }
            None => {
                used[top] = true;
                out.push(Chain::One(top));
            }
        }
    }
    out
}

/// One row's inputs to the weighted sums of one half: the patch colour distances, the feature
/// weights, the centre pixels' and the neighbours' values per channel (all of one length).
struct Row<'a> {
    dc: &'a [f32],
    ef: &'a [f32],
    cp: [&'a [f32]; 3],
    cq: [&'a [f32]; 3],
}

/// One candidate's running sums over a row: of the weights, and of the weighted differences
/// per channel.
struct Sums<'a> {
    w: &'a mut [f32],
    a: [&'a mut [f32]; 3],
}

impl Row<'_> {
    /// Adds the row's weights `min(exp(−d_c·inv), e_f)` and weighted differences to `s`.
    #[inline]
    fn add_one(&self, inv: f32, s: Sums<'_>) {
        let [a0, a1, a2] = s.a;
        let [p0, p1, p2] = self.cp;
        let [q0, q1, q2] = self.cq;
        add_one(
            inv,
            [self.dc, self.ef, p0, p1, p2, q0, q1, q2],
            s.w,
            a0,
            a1,
            a2,
        );
    }

    /// [`Row::add_one`] for three candidates of `inv`, `4·inv` and `16·inv` at once (a
    /// [`Chain::Three`]), the narrower weights by squaring the wider twice.
    #[inline]
    fn add_three(&self, inv: f32, s: [Sums<'_>; 3]) {
        let [s0, s1, s2] = s;
        let [a00, a01, a02] = s0.a;
        let [a10, a11, a12] = s1.a;
        let [a20, a21, a22] = s2.a;
        let [p0, p1, p2] = self.cp;
        let [q0, q1, q2] = self.cq;
        add_three(
            inv,
            [self.dc, self.ef, p0, p1, p2, q0, q1, q2],
            s0.w,
            a00,
            a01,
            a02,
            s1.w,
            a10,
            a11,
            a12,
            s2.w,
            a20,
            a21,
            a22,
        );
    }
}

/// [`Row::add_one`]'s loop, every written plane a parameter of its own (see [`add_three`]).
#[inline]
fn add_one(
    inv: f32,
    r: [&[f32]; 8],
    w: &mut [f32],
    a0: &mut [f32],
    a1: &mut [f32],
    a2: &mut [f32],
) {
    let len = r[0].len();
    let [dc, ef, p0, p1, p2, q0, q1, q2] = r.map(|x| &x[..len]);
    let (w, a0, a1, a2) = (
        &mut w[..len],
        &mut a0[..len],
        &mut a1[..len],
        &mut a2[..len],
    );
    for i in 0..len {
        let wt = exp_neg(dc[i] * inv).min(ef[i]);
        w[i] += wt;
        a0[i] += wt * (q0[i] - p0[i]);
        a1[i] += wt * (q1[i] - p1[i]);
        a2[i] += wt * (q2[i] - p2[i]);
    }
}

/// [`Row::add_three`]'s loop, every plane a parameter of its own: `&mut` parameters are known
/// not to overlap (as fields of a struct they are not, and the loop, with its 20 planes, then
/// stayed scalar). `r`: the colour distances, the feature weights, the centre's and the
/// neighbour's three channels.
#[allow(
    clippy::too_many_arguments,
    reason = "one plane a parameter: see the doc comment"
)]
#[inline]
fn add_three(
    inv: f32,
    r: [&[f32]; 8],
    w0: &mut [f32],
    a00: &mut [f32],
    a01: &mut [f32],
    a02: &mut [f32],
    w1: &mut [f32],
    a10: &mut [f32],
    a11: &mut [f32],
    a12: &mut [f32],
    w2: &mut [f32],
    a20: &mut [f32],
    a21: &mut [f32],
    a22: &mut [f32],
) {
    let len = r[0].len();
    let [dc, ef, p0, p1, p2, q0, q1, q2] = r.map(|x| &x[..len]);
    let (w0, a00, a01, a02) = (
        &mut w0[..len],
        &mut a00[..len],
        &mut a01[..len],
        &mut a02[..len],
    );
    let (w1, a10, a11, a12) = (
        &mut w1[..len],
        &mut a10[..len],
        &mut a11[..len],
        &mut a12[..len],
    );
    let (w2, a20, a21, a22) = (
        &mut w2[..len],
        &mut a20[..len],
        &mut a21[..len],
        &mut a22[..len],
    );
    for i in 0..len {
        let x = dc[i] * inv;
        let e0 = exp_neg(x);
        let sq = e0 * e0;
        // 0 from 80 on, as exp_neg (and no subnormals).
        let e1 = if x < 20.0 { sq * sq } else { 0.0 };
        let sq = e1 * e1;
        let e2 = if x < 5.0 { sq * sq } else { 0.0 };
        let (d0, d1, d2) = (q0[i] - p0[i], q1[i] - p1[i], q2[i] - p2[i]);
        let f = ef[i];
        let (t0, t1, t2) = (e0.min(f), e1.min(f), e2.min(f));
        w0[i] += t0;
        a00[i] += t0 * d0;
        a01[i] += t0 * d1;
        a02[i] += t0 * d2;
        w1[i] += t1;
        a10[i] += t1 * d0;
        a11[i] += t1 * d1;
        a12[i] += t1 * d2;
        w2[i] += t2;
        a20[i] += t2 * d0;
        a21[i] += t2 * d1;
        a22[i] += t2 * d2;
    }
}

/// The [`Sums`] of one candidate's planes `acc` (per channel) and `w`, over `len` pixels from
/// `at`.
fn sums<'a>(acc: &'a mut [Vec<f32>; 3], w: &'a mut [f32], at: usize, len: usize) -> Sums<'a> {
    let [a0, a1, a2] = acc;
    Sums {
        w: &mut w[at..at + len],
        a: [
            &mut a0[at..at + len],
            &mut a1[at..at + len],
            &mut a2[at..at + len],
        ],
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
    let mut ef = vec![0.0f32; w];
    let chains = chains(&cand.k);
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
                let (c, v) = (&layer.c[1 - half], &layer.v[1 - half]);
                for y in p0..p1 {
                    // Zero where the neighbour is outside the image (the patch sums read it).
                    let full = &mut d[(y - p0) * w..(y - p0 + 1) * w];
                    let qy = y as isize + dy;
                    if qy < 0 || qy >= h as isize {
                        full.fill(0.0);
                        continue;
                    }
                    full[..x0].fill(0.0);
                    full[x1..].fill(0.0);
                    let p_at = y * w + x0;
                    let q_at = (qy as usize * w + x0) as isize + dx;
                    colour_distance(c, v, p_at, q_at as usize, len, &mut full[x0..x1]);
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
                let (df, ef) = (&mut df[..len], &mut ef[..len]);
                // The feature weight exp(−d_f), shared by both halves and every candidate:
                // exp(−max(a, b)) = min(exp(−a), exp(−b)).
                match guide {
                    Some(g) => {
                        g.distances(p_at, q_at, steps, df);
                        for i in 0..len {
                            ef[i] = exp_neg(df[i]);
                        }
                    }
                    None => ef.fill(1.0),
                }
                for half in 0..2 {
                    let c = &layer.c[half];
                    let row = Row {
                        dc: &patch[half][b_at..b_at + len],
                        ef,
                        cp: std::array::from_fn(|ch| &c[ch][p_at..p_at + len]),
                        cq: std::array::from_fn(|ch| &c[ch][q_at..q_at + len]),
                    };
                    let (acc, wsum) = (&mut acc[half], &mut wsum[half]);
                    for chain in &chains {
                        let (ks, n) = match *chain {
                            Chain::Three(ks) => {
                                if let (Ok([a0, a1, a2]), Ok([w0, w1, w2])) =
                                    (acc.get_disjoint_mut(ks), wsum.get_disjoint_mut(ks))
                                {
                                    row.add_three(
                                        inv_k2[ks[0]],
                                        [
                                            sums(a0, w0, b_at, len),
                                            sums(a1, w1, b_at, len),
                                            sums(a2, w2, b_at, len),
                                        ],
                                    );
                                    continue;
                                }
                                // (Not reached: a chain's candidates are distinct.)
                                (ks, 3)
                            }
                            Chain::One(k) => ([k; 3], 1),
                        };
                        for &k in &ks[..n] {
                            row.add_one(inv_k2[k], sums(&mut acc[k], &mut wsum[k], b_at, len));
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

#[cfg(test)]
mod tests {
    use super::{Chain, Row, chains, sums};

    /// Bandwidths in exact ratios of 2 are grouped in threes from the widest; the others
    /// (and what is left over) stay alone.
    #[test]
    fn candidates_are_chained_by_exact_halves() {
        assert_eq!(chains(&[0.5, 1.0, 2.0]), vec![Chain::Three([2, 1, 0])]);
        assert_eq!(chains(&[0.35, 0.7, 1.4]), vec![Chain::Three([2, 1, 0])]);
        assert_eq!(chains(&[0.5]), vec![Chain::One(0)]);
        assert_eq!(
            chains(&[0.5, 1.0, 3.0]),
            vec![Chain::One(2), Chain::One(1), Chain::One(0)]
        );
        assert_eq!(
            chains(&[0.25, 0.5, 1.0, 2.0]),
            vec![Chain::Three([3, 2, 1]), Chain::One(0)]
        );
    }

    /// The three chained weights against the library's exponential in f64:
    /// `min(exp(−d/k²), e_f)` for each candidate, summed with the weighted differences, over
    /// distances from negative (weight 1) to far beyond the weights' range (weight 0).
    #[test]
    fn chained_weights_match_the_exponential() {
        let n = 64;
        let dc: Vec<f32> = (0..n).map(|i| i as f32 * 0.9 - 3.0).collect();
        let ef: Vec<f32> = (0..n).map(|i| if i % 3 == 0 { 0.2 } else { 1.0 }).collect();
        let p: Vec<f32> = (0..n).map(|i| (i % 5) as f32 * 0.1).collect();
        let q: Vec<f32> = (0..n).map(|i| (i % 7) as f32 * 0.3).collect();
        let row = Row {
            dc: &dc,
            ef: &ef,
            cp: [&p, &p, &p],
            cq: [&q, &p, &q],
        };
        let inv = 1.0 / 12.0;
        let mut acc: Vec<[Vec<f32>; 3]> = (0..3)
            .map(|_| std::array::from_fn(|_| vec![0.0; n]))
            .collect();
        let mut w = vec![vec![0.0f32; n]; 3];
        let (a, rest) = acc.split_at_mut(1);
        let (b, c) = rest.split_at_mut(1);
        let (wa, wrest) = w.split_at_mut(1);
        let (wb, wc) = wrest.split_at_mut(1);
        row.add_three(
            inv,
            [
                sums(&mut a[0], &mut wa[0], 0, n),
                sums(&mut b[0], &mut wb[0], 0, n),
                sums(&mut c[0], &mut wc[0], 0, n),
            ],
        );
        for (j, scale) in [1.0f64, 4.0, 16.0].into_iter().enumerate() {
            for i in 0..n {
                let x = f64::from(dc[i]) * f64::from(inv) * scale;
                let want = (-x.max(0.0)).exp().min(f64::from(ef[i]));
                let got = f64::from(w[j][i]);
                assert!(
                    (got - want).abs() <= 5e-4 * want || (want < 2e-35 && got == 0.0),
                    "candidate {j}, d {}: {got} against {want}",
                    dc[i]
                );
                let d = f64::from(q[i] - p[i]);
                assert!((f64::from(acc[j][0][i]) - want * d).abs() <= 5e-4 * want * d.abs() + 1e-9);
                assert_eq!(acc[j][1][i], 0.0);
            }
        }
    }
}
