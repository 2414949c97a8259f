//! `--denoise` for a render: the bridge from a render's sums to the denoiser
//! ([`crate::denoise`]). The render is taken in two halves of its sample indices (the job
//! renders the first half, the caller keeps a copy of its sums, then the job takes the rest:
//! the finished film is the same bytes as without the stop, [`super::RenderJob`]), so the
//! second half is the whole less the first, worked out from the means, variances and counts
//! in `f64`. With the light-path layers kept, the caustic and specular light is handed to the
//! denoiser on its own (filtered without feature guidance: the features follow neither) and
//! the direct and indirect light as the guided part.
//! The features ([`Features`]) are traced over the same samples and split at the same index.

use glam::{DVec3, Vec3};

use super::features::Features;
use super::{Film, PixelSums};
use crate::denoise::{DenoiseError, DenoiseInput, DenoiseParams, Guide, HalfBuffers, denoise};
use crate::integrators::LightPath;

/// The sums of a render's first half of samples, kept when the job has taken them.
#[derive(Debug, Clone)]
pub struct FirstHalf {
    /// The image's sums over the first half.
    pub sums: PixelSums,
    /// The light-path layers' sums over the first half, when the job keeps them.
    pub parts: Option<Vec<PixelSums>>,
}

/// Why a render could not be denoised.
#[derive(Debug, thiserror::Error)]
pub enum DenoiseRenderError {
    /// The buffers do not fit each other.
    #[error("cannot denoise: {0}")]
    Mismatch(String),
    /// The denoiser refused its input.
    #[error("cannot denoise: {0}")]
    Denoise(#[from] DenoiseError),
    /// The worker pool could not start.
    #[error("cannot start {0} denoising threads: {1}")]
    Threads(usize, String),
}

/// Denoises a finished render: `all` (and `all_parts`) over every sample, `first` over the
/// samples below the features' split, on `threads` workers (`None`: all cores). The same
/// bytes for any thread count.
///
/// # Errors
/// [`DenoiseRenderError::Mismatch`] when the sizes differ or only one of the two has the
/// light-path layers; the denoiser's errors (e.g. a half without samples).
pub fn denoise_render(
    all: &PixelSums,
    all_parts: Option<&[PixelSums]>,
    first: &FirstHalf,
    features: &Features,
    params: &DenoiseParams,
    threads: Option<usize>,
) -> Result<Film, DenoiseRenderError> {
    let (w, h) = (all.width, all.height);
    for (what, size) in [
        ("the first half", (first.sums.width, first.sums.height)),
        ("the feature buffers", (features.width, features.height)),
    ] {
        if size != (w, h) {
            return Err(DenoiseRenderError::Mismatch(format!(
                "{what} is {}×{}, the render {w}×{h}",
                size.0, size.1
            )));
        }
    }
    let n = w as usize * h as usize;
    let (guided, unguided) = match (all_parts, first.parts.as_deref()) {
        (Some(all_parts), Some(first_parts)) => {
            let (mut unguided, mut others) = (Vec::new(), Vec::new());
            for (p, &kind) in LightPath::ALL.iter().enumerate().take(all_parts.len()) {
                match kind {
                    LightPath::Caustic | LightPath::Specular => unguided.push(p),
                    LightPath::Direct | LightPath::Indirect => others.push(p),
                }
            }
            let layer = |which: &[usize]| {
                halves_of(n, |i, into| {
                    for &p in which {
                        into.add(split(&all_parts[p], &first_parts[p], i));
                    }
                })
            };
            let guided = layer(&others);
            let c = layer(&unguided);
            (guided, Some(c))
        }
        (None, None) => (
            halves_of(n, |i, into| into.add(split(all, &first.sums, i))),
            None,
        ),
        _ => {
            return Err(DenoiseRenderError::Mismatch(
                "the light-path layers were kept for only one of the two halves".into(),
            ));
        }
    };
    let counts = (0..n).fold([0u32; 2], |m, i| {
        let (a, t) = (first.sums.count(i), all.count(i));
        [m[0].max(a), m[1].max(t.saturating_sub(a))]
    });
    let input = DenoiseInput {
        width: w as usize,
        height: h as usize,
        half_samples: counts,
        guided,
        unguided,
        features: Some(guide(features)),
    };
    let threads = threads.unwrap_or_else(rayon::current_num_threads).max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| DenoiseRenderError::Threads(threads, e.to_string()))?;
    let pixels = pool.install(|| denoise(&input, params))?;
    Ok(Film {
        width: w,
        height: h,
        pixels,
    })
}

/// One pixel's two halves: each half's mean and the variance of that mean.
#[derive(Debug, Clone, Copy, Default)]
struct Split {
    mean: [Vec3; 2],
    variance: [Vec3; 2],
}

/// Two half-buffers built pixel by pixel, adding up [`Split`]s (of several light paths).
struct Accumulate<'a>(&'a mut HalfBuffers, usize);

impl Accumulate<'_> {
    fn add(&mut self, s: Split) {
        for h in 0..2 {
            self.0.mean[h][self.1] += s.mean[h];
            self.0.variance[h][self.1] += s.variance[h];
        }
    }
}

fn halves_of(n: usize, mut fill: impl FnMut(usize, &mut Accumulate<'_>)) -> HalfBuffers {
    let mut b = HalfBuffers {
        mean: [vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]],
        variance: [vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]],
    };
    for i in 0..n {
        fill(i, &mut Accumulate(&mut b, i));
    }
    b
}

/// Pixel `i`'s halves: the first from `first`, the second as `all` less `first`.
fn split(all: &PixelSums, first: &PixelSums, i: usize) -> Split {
    let (n, na) = (f64::from(all.count(i)), f64::from(first.count(i)));
    let nb = n - na;
    let (m, ma) = (all.mean(i).as_dvec3(), first.mean(i).as_dvec3());
    let va_samples = first.variance(i).as_dvec3();
    let va = if na > 0.0 {
        va_samples / na
    } else {
        DVec3::ZERO
    };
    if nb <= 0.0 {
        return Split {
            mean: [ma.as_vec3(); 2],
            variance: [va.as_vec3(); 2],
        };
    }
    let mb = (m * n - ma * na) / nb;
    // Sums of squares: (n − 1)·s² + n·m².
    let squares = |s2: DVec3, mean: DVec3, k: f64| s2 * (k - 1.0).max(0.0) + mean * mean * k;
    let q = squares(all.variance(i).as_dvec3(), m, n) - squares(va_samples, ma, na);
    let vb = if nb >= 2.0 {
        ((q - mb * mb * nb) / (nb - 1.0)).max(DVec3::ZERO) / nb
    } else {
        DVec3::ZERO
    };
    Split {
        mean: [ma.as_vec3(), mb.as_vec3()],
        variance: [va.as_vec3(), vb.as_vec3()],
    }
}

/// The denoiser's guide from the feature buffers (over all their samples).
fn guide(f: &Features) -> Guide {
    let n = f.len();
    let mut g = Guide {
        albedo: Vec::with_capacity(n),
        albedo_variance: Vec::with_capacity(n),
        normal: Vec::with_capacity(n),
        normal_variance: Vec::with_capacity(n),
        depth: Vec::with_capacity(n),
        depth_variance: Vec::with_capacity(n),
    };
    for i in 0..n {
        let (m, v) = (f.mean(i), f.variance(i));
        g.albedo.push(m.albedo);
        g.albedo_variance.push(v.albedo.element_sum());
        g.normal.push(m.normal);
        g.normal_variance.push(v.normal.element_sum());
        g.depth.push(m.depth);
        g.depth_variance.push(v.depth);
    }
    g
}
