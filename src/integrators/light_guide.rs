//! Next-event estimation's light choice, made per region of space from what each light
//! actually delivers there, learned once per render from a pilot. Used by every integrator
//! that samples one light per shading point (`path` and so `path-ppm`, `ppm` and the default
//! estimator; `photon`'s direct light); Whitted lights every point from every light.
//!
//! Choosing lights by power alone ([`LightSampler`]) spends most shadow rays on the brightest
//! light even where it is hidden: in the bathroom the sun and the sky (whose power counts over
//! the whole scene's bounding disc) took 84 % of next-event samples, although the walls hide
//! them from almost every point, and the ceiling panel that lights the room got 16 % — grain on
//! every wall. Following the idea of learning a per-region light-selection distribution
//! (Vévoda, Kondapaneni & Křivánek, "Bayesian online regression for adaptive direct illumination
//! sampling", ACM ToG 37(4), 2018; Wang et al., "Real-time stochastic lightcuts", 2020, cluster
//! lights by estimated contribution), but with a fixed pilot instead of online updates (so every
//! render, shard and thread count sees the same distribution):
//!
//! 1. **Pilot.** Camera rays on a coarse grid of the image ([`PILOT_PIXELS`] of them) are
//!    followed for a few bounces by BSDF sampling (fixed random streams). At every vertex with a
//!    non-delta part, each light is sampled [`PILOT_SAMPLES`] times by next-event estimation's
//!    own step and its unoccluded contribution `f·L·|cos θ|/pdf` (shadow rays traced) is added
//!    to the vertex's voxel
//!    (a [`VoxelTable`] voxel of side [`VOXELS_PER_DIAGONAL`]⁻¹ of the scene's diagonal).
//! 2. **Distribution.** In a voxel the pilot reached, light `l` is chosen with probability
//!    `(1 − δ)·Eₗ/ΣE + δ·dₗ` (`Eₗ` its mean pilot contribution, δ = [`POWER_SHARE`], `dₗ`
//!    the default choice: half `Φₗ/ΣΦ` by power, half uniform over the lights that emit);
//!    elsewhere by power. The default share keeps every light that emits selectable everywhere
//!    with a bounded weight, so the estimator stays unbiased whatever the pilot missed.
//! 3. **MIS.** The probability of a light is looked up in the voxel of the point the light was
//!    sampled from (for a BSDF-sampled ray that hits the light: the point the ray left), the
//!    same table next-event estimation used there, so the power heuristic stays exact.
//!
//! Scenes with one light have nothing to choose; with more than [`MAX_GUIDED_LIGHTS`] lights
//! the table would be large, and the plain power sampler is used.

use glam::Vec3;

use super::Counters;
use super::shadow::connect_light;
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::{Interaction, LightSampler, RenderScene};
use crate::sampling::Rng;
use crate::shading::TransportMode;
use crate::spatial::VoxelTable;

/// Camera rays of the pilot (on a grid of about this many pixels, the image's aspect ratio).
pub const PILOT_PIXELS: u32 = 96 * 72;
/// Bounces each pilot path makes (vertices with a non-delta part are recorded).
pub const PILOT_BOUNCES: u32 = 3;
/// Light samples per light at each pilot vertex.
pub const PILOT_SAMPLES: u32 = 4;
/// Voxel side: the scene's bounding-box diagonal over this.
pub const VOXELS_PER_DIAGONAL: f32 = 32.0;
/// Share of every voxel's distribution given to the default choice (δ): half by power, half
/// uniform over the lights that emit, so that a light the pilot missed where it does reach
/// (a few samples cannot see every light everywhere) keeps at least `δ/(2n)` of the samples
/// and cannot turn into rare, huge next-event estimates.
pub const POWER_SHARE: f32 = 0.5;

/// Fewest pilot vertices a voxel needs for a learned distribution (fewer: chosen by power).
pub const MIN_PILOT_VERTICES: usize = 4;
/// Most lights a guide is built for.
pub const MAX_GUIDED_LIGHTS: usize = 16;

/// The light choice of next-event estimation: per voxel where a pilot learned it, by power
/// elsewhere (see the module docs).
#[derive(Debug, Clone)]
pub struct LightGuide {
    power: LightSampler,
    /// The pilot's voxels (empty: no guidance), each with its row of the tables below.
    voxels: VoxelTable,
    /// Per voxel row, `lights` cumulative probabilities (the last is 1) …
    cdf: Vec<f32>,
    /// … and the probabilities themselves.
    pmf: Vec<f32>,
    lights: usize,
}

impl LightGuide {
    /// The power-proportional choice only (no pilot).
    #[must_use]
    pub fn by_power(scene: &RenderScene) -> Self {
        Self {
            power: LightSampler::new(&scene.lights),
            voxels: VoxelTable::default(),
            cdf: Vec::new(),
            pmf: Vec::new(),
            lights: scene.lights.len(),
        }
    }

    /// Learns the per-voxel choice for `scene` from its pilot (deterministic: fixed streams
    /// from the scene's seed, reduced in a fixed order). Falls back to [`LightGuide::by_power`]
    /// with fewer than 2 or more than [`MAX_GUIDED_LIGHTS`] lights, or when the pilot reaches
    /// nothing.
    #[must_use]
    pub fn learn(scene: &RenderScene) -> Self {
        use rayon::prelude::*;
        let guide = Self::by_power(scene);
        let n = scene.lights.len();
        if !(2..=MAX_GUIDED_LIGHTS).contains(&n) {
            return guide;
        }
        let b = scene.geometry.bvh.bounds;
        let side = (b.max - b.min).length() / VOXELS_PER_DIAGONAL;
        if !(side.is_finite() && side > 0.0) {
            return guide;
        }
        let (w, h) = (scene.params.width.max(1), scene.params.height.max(1));
        let aspect = w as f32 / h as f32;
        let gh = ((PILOT_PIXELS as f32 / aspect).sqrt().round() as u32).max(1);
        let gw = ((gh as f32 * aspect).round() as u32).max(1);
        // Each pilot path: its vertices' positions and per-light irradiance estimates.
        let records: Vec<Vec<([f32; 3], Vec<f32>)>> = (0..gw * gh)
            .into_par_iter()
            .map(|i| pilot_path(scene, i, gw, gh, w, h))
            .collect();
        if records.iter().all(Vec::is_empty) {
            return guide;
        }
        let power: Vec<f32> = (0..n).map(|l| guide.power.pmf(l)).collect();
        let emitting = power.iter().filter(|&&p| p > 0.0).count().max(1) as f32;
        let default: Vec<f32> = power
            .iter()
            .map(|&p| {
                if p > 0.0 {
                    0.5 * p + 0.5 / emitting
                } else {
                    0.0
                }
            })
            .collect();
        let vertices = records
            .iter()
            .flatten()
            .map(|(p, e)| (Vec3::from_array(*p), e.as_slice()));
        let Ok((voxels, rows)) = VoxelTable::build(side, vertices, |run| {
            if run.len() < MIN_PILOT_VERTICES {
                return None;
            }
            let mut e = vec![0.0f64; n];
            for est in run.iter() {
                for (s, v) in e.iter_mut().zip(est.iter()) {
                    *s += f64::from(*v);
                }
            }
            let total: f64 = e.iter().sum();
            let row: Vec<f32> = (0..n)
                .map(|l| {
                    let learned = if total > 0.0 {
                        (e[l] / total) as f32
                    } else {
                        default[l]
                    };
                    // A light of zero power is never chosen (as by power).
                    if power[l] > 0.0 {
                        (1.0 - POWER_SHARE) * learned + POWER_SHARE * default[l]
                    } else {
                        0.0
                    }
                })
                .collect();
            let sum: f32 = row.iter().sum();
            (sum > 0.0).then(|| row.into_iter().map(|p| p / sum).collect::<Vec<f32>>())
        }) else {
            return guide;
        };
        let mut cdf = Vec::with_capacity(rows.len() * n);
        for row in &rows {
            let mut acc = 0.0f32;
            for (l, p) in row.iter().enumerate() {
                acc += p;
                cdf.push(if l + 1 == n { 1.0 } else { acc });
            }
        }
        Self {
            voxels,
            cdf,
            pmf: rows.concat(),
            ..guide
        }
    }

    /// Voxels with a learned distribution.
    #[must_use]
    pub fn voxels(&self) -> usize {
        self.voxels.len()
    }

    /// The table row of the voxel containing `p`, if the pilot learned one.
    #[inline]
    fn row(&self, p: Vec3) -> Option<usize> {
        self.voxels.get(p)
    }

    /// Chooses a light for next-event estimation at `p` (`u` drawn only when there is a choice):
    /// its index and the probability it was chosen with.
    #[inline]
    pub fn choose(&self, p: Vec3, u: impl FnOnce() -> f32) -> Option<(usize, f32)> {
        let Some(row) = self.row(p) else {
            return self.power.choose(u);
        };
        let n = self.lights;
        let cdf = &self.cdf[row * n..(row + 1) * n];
        let u = u();
        let i = cdf.iter().position(|&c| u < c).unwrap_or(n - 1);
        // Skip lights of zero probability that a u at a CDF step could land on.
        let i = (i..n)
            .find(|&j| self.pmf[row * n + j] > 0.0)
            .or_else(|| (0..i).rev().find(|&j| self.pmf[row * n + j] > 0.0))?;
        Some((i, self.pmf[row * n + i]))
    }

    /// Probability that [`LightGuide::choose`] at `p` picks light `i` (0 for out-of-range).
    #[inline]
    #[must_use]
    pub fn pmf(&self, p: Vec3, i: usize) -> f32 {
        match self.row(p) {
            Some(row) if i < self.lights => self.pmf[row * self.lights + i],
            Some(_) => 0.0,
            None => self.power.pmf(i),
        }
    }
}

/// One pilot path from grid pixel `i` of `gw × gh`: the positions of its vertices with a
/// non-delta part and, at each, every light's mean contribution `f·L·|cos|/pdf` over
/// [`PILOT_SAMPLES`] samples (0 when occluded).
fn pilot_path(
    scene: &RenderScene,
    i: u32,
    gw: u32,
    gh: u32,
    w: u32,
    h: u32,
) -> Vec<([f32; 3], Vec<f32>)> {
    let mut rng = Rng::new(scene.params.seed, 0x4C47_0000_0000 | u64::from(i));
    let (x, y) = (i % gw, i / gw);
    let fx = (x as f32 + rng.next_f32()) / gw as f32 * w as f32;
    let fy = (y as f32 + rng.next_f32()) / gh as f32 * h as f32;
    let mut ray = scene.camera.ray(fx, fy, w, h);
    let mut out = Vec::new();
    for _ in 0..=PILOT_BOUNCES {
        let mut textured = None;
        let Interaction::Surface(v) = scene.interact(&ray, |_| 0.0, &mut textured) else {
            break;
        };
        let (sp, fr) = (&v.sp, &v.frame);
        let at = v.bsdf.at(v.wo, fr);
        if v.bsdf.has_local() {
            let mut counters = Counters::default();
            let est: Vec<f32> = (0..scene.lights.len())
                .map(|light| {
                    let mut sum = 0.0f32;
                    for _ in 0..PILOT_SAMPLES {
                        let u = rng.next_2d();
                        // Next-event estimation's own step: the BSDF-weighted, unoccluded
                        // contribution `f·L·|cos|/pdf` is what the choice should follow.
                        let Some(c) = connect_light(scene, light, sp, &at, u, &mut counters) else {
                            continue;
                        };
                        if c.occluded {
                            continue;
                        }
                        let v = c.f * c.ls.radiance * (fr.ns.dot(c.ls.wi).abs() / c.ls.pdf);
                        let v = (v.x + v.y + v.z) / 3.0;
                        if v.is_finite() && v > 0.0 {
                            sum += v;
                        }
                    }
                    sum / PILOT_SAMPLES as f32
                })
                .collect();
            out.push((sp.p.to_array(), est));
        }
        let u_lobe = rng.next_f32();
        let Some(s) = at.sample(u_lobe, rng.next_2d(), TransportMode::Radiance) else {
            break;
        };
        let origin = offset_ray_origin(sp.p, sp.p_error, fr.ng, s.wi);
        ray = Ray::new(origin, s.wi);
    }
    out
}
