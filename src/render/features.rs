//! Feature buffers (`--layers albedo,normal,depth`, and the guide of `--denoise`): per pixel,
//! the albedo, shading normal and depth of the first non-specular surface each camera sample
//! sees, with their per-pixel variance, for every integrator. Defined as Intel Open Image
//! Denoise and Cycles define their denoising albedo and normal: a camera path is followed
//! through mirrors and glass (delta lobes) and near-specular surfaces
//! ([`Bsdf::is_near_specular`] at [`NEAR_SPECULAR_ALPHA`]), its throughput tinting what it
//! finds, and the features are read at the first surface with a diffuse or glossy part.
//!
//! A cheap camera-path tracer of its own (one intersection per bounce, no light sampling):
//! it starts each sample exactly as the render does ([`camera_sample`]: the same pixel and
//! lens positions, the sampler's first dimensions), then draws its own numbers to choose a
//! branch at glass. No integrator is involved, so the features exist for all of them.
//! Each pixel's samples are summed in index order into per-pixel `f64` sums, so the result
//! is the same for any thread count. The samples are kept in two halves (those before the
//! split index and the rest), the half-buffers the denoiser cross-validates with.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::Vec3;
use rayon::prelude::*;

use super::options::{Region, RenderError, check_region};
use super::tiles::camera_sample;
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::{Interaction, RenderScene};
use crate::sampling::Sampler;
use crate::shading::{NEAR_SPECULAR_ALPHA, TransportMode};

#[cfg(doc)]
use crate::shading::Bsdf;

/// Feature values per sample: albedo RGB, normal XYZ, depth.
pub const FEATURE_CHANNELS: usize = 7;
/// Most specular bounces followed before a path's features are read where it is.
const MAX_SPECULAR_BOUNCES: u32 = 16;

/// What one camera sample sees at its first non-specular surface.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FeatureSample {
    /// The surface's colour (its BSDF's tint, in [0, 1]) times the throughput of the mirrors
    /// and glass on the way (their tint and Fresnel weights); black for an emitter or the
    /// background.
    pub albedo: Vec3,
    /// Unit shading normal (world space, on the side the path arrived from); for an emitter
    /// or the background, the direction back along the ray.
    pub normal: Vec3,
    /// Distance travelled from the camera to that surface along the followed path (scene
    /// units; through a mirror, the distance to the reflected object, as a virtual image's);
    /// 0 when the path escaped.
    pub depth: f32,
}

impl FeatureSample {
    fn to_array(self) -> [f64; FEATURE_CHANNELS] {
        let (a, n) = (self.albedo.as_dvec3(), self.normal.as_dvec3());
        [a.x, a.y, a.z, n.x, n.y, n.z, f64::from(self.depth)]
    }

    fn from_array(v: [f64; FEATURE_CHANNELS]) -> Self {
        Self {
            albedo: Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32),
            normal: Vec3::new(v[3] as f32, v[4] as f32, v[5] as f32),
            depth: v[6] as f32,
        }
    }
}

/// One half's per-pixel sums of feature samples and their squares, and sample counts.
#[derive(Debug, Clone, PartialEq)]
struct HalfSums {
    sums: Vec<[f64; FEATURE_CHANNELS]>,
    squares: Vec<[f64; FEATURE_CHANNELS]>,
    counts: Vec<u32>,
}

impl HalfSums {
    fn new(n: usize) -> Self {
        Self {
            sums: vec![[0.0; FEATURE_CHANNELS]; n],
            squares: vec![[0.0; FEATURE_CHANNELS]; n],
            counts: vec![0; n],
        }
    }
}

/// The feature buffers of a render (or region): per-pixel sums of [`FeatureSample`]s in two
/// halves of the sample indices.
#[derive(Debug, Clone, PartialEq)]
pub struct Features {
    /// Width in pixels (of the region).
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples with an index below this are in half 0, the others in half 1.
    pub split: u32,
    halves: [HalfSums; 2],
}

impl Features {
    /// Traces the features of samples `samples` of every pixel of `region` (`None`: the whole
    /// image) on `threads` workers (`None`: all cores); samples below `split` go to half 0.
    /// The same for any thread count.
    ///
    /// # Errors
    /// [`RenderError::EmptyRegion`] / [`RenderError::RegionOutside`] for a bad region,
    /// [`RenderError::Threads`] when the pool cannot start, [`RenderError::Cancelled`] when
    /// `cancel` is raised (looked at before each row).
    pub fn trace(
        scene: &RenderScene,
        region: Option<Region>,
        samples: Range<u32>,
        split: u32,
        threads: Option<usize>,
        cancel: Option<&AtomicBool>,
    ) -> Result<Self, RenderError> {
        let p = &scene.params;
        let region = region.unwrap_or(Region {
            x: 0,
            y: 0,
            width: p.width,
            height: p.height,
        });
        check_region(region, p.width, p.height)?;
        let threads = threads.unwrap_or_else(rayon::current_num_threads).max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| RenderError::Threads(threads, e.to_string()))?;
        let w = region.width as usize;
        let rows: Option<Vec<[HalfSums; 2]>> = pool.install(|| {
            (0..region.height)
                .into_par_iter()
                .map(|row| {
                    if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                        return None;
                    }
                    let mut sampler = Sampler::new(p.sampler, p.seed, p.samples_per_pixel);
                    let mut halves = [HalfSums::new(w), HalfSums::new(w)];
                    for i in 0..w {
                        let (x, y) = (region.x + i as u32, region.y + row);
                        for s in samples.clone() {
                            let ray = camera_sample(scene, &mut sampler, x, y, s);
                            let f = trace_sample(scene, ray, &mut sampler).to_array();
                            let half = &mut halves[usize::from(s >= split)];
                            let (sums, squares) = (&mut half.sums[i], &mut half.squares[i]);
                            for ((s, q), v) in sums.iter_mut().zip(squares.iter_mut()).zip(f) {
                                *s += v;
                                *q += v * v;
                            }
                            half.counts[i] += 1;
                        }
                    }
                    Some(halves)
                })
                .collect()
        });
        let rows = rows.ok_or(RenderError::Cancelled)?;
        let n = w * region.height as usize;
        let mut halves = [HalfSums::new(n), HalfSums::new(n)];
        for (row, parts) in rows.into_iter().enumerate() {
            for (mine, part) in halves.iter_mut().zip(parts) {
                let at = row * w..(row + 1) * w;
                mine.sums[at.clone()].copy_from_slice(&part.sums);
                mine.squares[at.clone()].copy_from_slice(&part.squares);
                mine.counts[at].copy_from_slice(&part.counts);
            }
        }
        Ok(Self {
            width: region.width,
            height: region.height,
            split,
            halves,
        })
    }

    /// Pixels in the buffers.
    #[must_use]
    pub fn len(&self) -> usize {
        self.halves[0].counts.len()
    }

    /// Whether the buffers have no pixel.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Samples of pixel `i` in half `h` (0 or 1).
    #[must_use]
    pub fn half_count(&self, h: usize, i: usize) -> u32 {
        self.halves[h].counts[i]
    }

    /// Mean of pixel `i`'s samples in half `h` (0 or 1; all zero without samples).
    #[must_use]
    pub fn half_mean(&self, h: usize, i: usize) -> FeatureSample {
        let half = &self.halves[h];
        let n = f64::from(half.counts[i].max(1));
        FeatureSample::from_array(half.sums[i].map(|s| s / n))
    }

    /// Variance of the mean of pixel `i`'s samples in half `h`, per feature channel (the
    /// samples' unbiased variance over their count; 0 with fewer than two samples).
    #[must_use]
    pub fn half_variance(&self, h: usize, i: usize) -> FeatureSample {
        let half = &self.halves[h];
        variance_of_mean(half.sums[i], half.squares[i], half.counts[i])
    }

    /// Mean of all of pixel `i`'s samples.
    #[must_use]
    pub fn mean(&self, i: usize) -> FeatureSample {
        let (s, _, n) = self.total(i);
        let n = f64::from(n.max(1));
        FeatureSample::from_array(s.map(|s| s / n))
    }

    /// Variance of the mean of all of pixel `i`'s samples, per feature channel.
    #[must_use]
    pub fn variance(&self, i: usize) -> FeatureSample {
        let (s, q, n) = self.total(i);
        variance_of_mean(s, q, n)
    }

    fn total(&self, i: usize) -> ([f64; FEATURE_CHANNELS], [f64; FEATURE_CHANNELS], u32) {
        let [a, b] = &self.halves;
        let mut s = a.sums[i];
        let mut q = a.squares[i];
        for c in 0..FEATURE_CHANNELS {
            s[c] += b.sums[i][c];
            q[c] += b.squares[i][c];
        }
        (s, q, a.counts[i] + b.counts[i])
    }
}

fn variance_of_mean(
    s: [f64; FEATURE_CHANNELS],
    q: [f64; FEATURE_CHANNELS],
    n: u32,
) -> FeatureSample {
    if n < 2 {
        return FeatureSample::default();
    }
    let n = f64::from(n);
    let mut v = [0.0; FEATURE_CHANNELS];
    for c in 0..FEATURE_CHANNELS {
        let mean = s[c] / n;
        v[c] = ((q[c] - n * mean * mean) / (n - 1.0)).max(0.0) / n;
    }
    FeatureSample::from_array(v)
}

/// Follows one camera ray through specular surfaces to its first diffuse or glossy surface
/// and reads the features there.
fn trace_sample(scene: &RenderScene, mut ray: Ray, sampler: &mut Sampler) -> FeatureSample {
    let mut throughput = Vec3::ONE;
    let mut depth = 0.0f32;
    for _ in 0..MAX_SPECULAR_BOUNCES {
        let mut textured = None;
        let back = -ray.dir.normalize_or_zero();
        match scene.interact(&ray, |_| 0.0, &mut textured) {
            Interaction::Escaped => {
                return FeatureSample {
                    albedo: Vec3::ZERO,
                    normal: back,
                    depth: 0.0,
                };
            }
            Interaction::Emitter(e) => {
                return FeatureSample {
                    albedo: Vec3::ZERO,
                    normal: back,
                    depth: if e.hit.t.is_finite() {
                        depth + e.hit.t * ray.dir.length()
                    } else {
                        0.0
                    },
                };
            }
            Interaction::Surface(s) => {
                depth += s.hit.t * ray.dir.length();
                let bsdf = s.bsdf;
                let specular = !bsdf.has_local() || bsdf.is_near_specular(NEAR_SPECULAR_ALPHA);
                let here = FeatureSample {
                    albedo: throughput * bsdf.color().clamp(Vec3::ZERO, Vec3::ONE),
                    normal: s.frame.ns,
                    depth,
                };
                if !specular {
                    return here;
                }
                let u_lobe = sampler.next_1d();
                let u = sampler.next_2d();
                let Some(b) = bsdf.sample(s.wo, u_lobe, u, &s.frame, TransportMode::Radiance)
                else {
                    // Black or absorbed: the path ends on this surface.
                    return here;
                };
                // Without the η² radiance factor: an albedo stays in [0, 1] behind glass.
                throughput *= b.weight / b.eta_scale.max(f32::MIN_POSITIVE);
                if !throughput.is_finite() {
                    return here;
                }
                throughput = throughput.clamp(Vec3::ZERO, Vec3::ONE);
                let origin = offset_ray_origin(s.sp.p, s.sp.p_error, s.frame.ng, b.wi);
                ray = Ray::new(origin, b.wi);
            }
        }
    }
    FeatureSample {
        albedo: Vec3::ZERO,
        normal: -ray.dir.normalize_or_zero(),
        depth,
    }
}
