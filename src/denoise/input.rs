//! What the denoiser is given: the noisy light in two half-buffers (each half's per-pixel mean
//! and the variance of that mean), split into the guided light and the caustic light, and the
//! feature guide; and the checks that refuse unusable input with a clear error.

use glam::Vec3;

use super::DenoiseError;

/// One noisy RGB quantity as two independent halves of the samples: per pixel, each half's
/// mean and the variance of that mean (the samples' variance over their count), row-major.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HalfBuffers {
    /// Per-pixel mean of each half.
    pub mean: [Vec<Vec3>; 2],
    /// Per-pixel, per-channel variance of each half's mean.
    pub variance: [Vec<Vec3>; 2],
}

/// The feature guide: per pixel, the albedo, shading normal and depth of the first
/// non-specular surface (over all samples), and the variance of each mean (summed over a
/// feature's channels).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Guide {
    /// Albedo, RGB in [0, 1].
    pub albedo: Vec<Vec3>,
    /// Variance of the albedo's mean, summed over RGB.
    pub albedo_variance: Vec<f32>,
    /// Shading normal (mean of unit vectors).
    pub normal: Vec<Vec3>,
    /// Variance of the normal's mean, summed over XYZ.
    pub normal_variance: Vec<f32>,
    /// Depth (scene units; 0 where nothing was hit).
    pub depth: Vec<f32>,
    /// Variance of the depth's mean.
    pub depth_variance: Vec<f32>,
}

/// Everything [`super::denoise`] reads.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DenoiseInput {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Samples in each half (all pixels alike), which weigh the halves in the output.
    pub half_samples: [u32; 2],
    /// The light the features guide: the image less its unguided light, or the whole image.
    pub guided: HalfBuffers,
    /// The light the features do not follow: caustic (through mirrors or glass onto a diffuse
    /// surface) and specular (emitters seen directly or through mirrors and glass), filtered by
    /// its own colour and variance only; `None` when the image is not split.
    pub unguided: Option<HalfBuffers>,
    /// The feature guide (required).
    pub features: Option<Guide>,
}

impl DenoiseInput {
    /// Each half's share of the samples (their weights in the output).
    #[must_use]
    pub fn half_shares(&self) -> [f32; 2] {
        let [a, b] = self.half_samples.map(f64::from);
        let total = (a + b).max(1.0);
        [(a / total) as f32, (b / total) as f32]
    }

    /// Checks sizes, halves and values.
    ///
    /// # Errors
    /// [`DenoiseError`] naming the first problem.
    pub fn check(&self) -> Result<(), DenoiseError> {
        let (w, h) = (self.width, self.height);
        if w < 2 || h < 2 {
            return Err(DenoiseError::TooSmall(w, h));
        }
        if let Some(half) = self.half_samples.iter().position(|&n| n == 0) {
            return Err(DenoiseError::EmptyHalf(half));
        }
        let n = w * h;
        let size = |buffer: &str, len: usize| {
            if len == n {
                Ok(())
            } else {
                Err(DenoiseError::Size {
                    buffer: buffer.to_string(),
                    len,
                    width: w,
                    height: h,
                    expected: n,
                })
            }
        };
        let bad = |buffer: &str, i: usize, what| DenoiseError::BadValue {
            buffer: buffer.to_string(),
            what,
            x: i % w,
            y: i / w,
        };
        let finite = |buffer: &str, values: &mut dyn Iterator<Item = f32>, variance: bool| {
            for (i, v) in values.enumerate() {
                if v.is_nan() {
                    return Err(bad(buffer, i, "NaN"));
                }
                if v.is_infinite() {
                    return Err(bad(buffer, i, "infinite"));
                }
                if variance && v < 0.0 {
                    return Err(bad(buffer, i, "negative"));
                }
            }
            Ok(())
        };
        let max3 = |v: &Vec3| {
            // The first non-finite channel, else the smallest (for the sign check).
            v.to_array()
                .into_iter()
                .find(|c| !c.is_finite())
                .unwrap_or(v.min_element())
        };
        let layers = std::iter::once(("light", &self.guided))
            .chain(self.unguided.as_ref().map(|c| ("unguided light", c)));
        for (name, layer) in layers {
            for half in 0..2 {
                let mean = format!("{name} (half {half} mean)");
                let var = format!("{name} (half {half} variance)");
                size(&mean, layer.mean[half].len())?;
                size(&var, layer.variance[half].len())?;
                finite(&mean, &mut layer.mean[half].iter().map(max3), false)?;
                finite(&var, &mut layer.variance[half].iter().map(max3), true)?;
            }
        }
        let g = self
            .features
            .as_ref()
            .ok_or(DenoiseError::MissingFeatures)?;
        let vectors = [("albedo", &g.albedo), ("normal", &g.normal)];
        for (name, v) in vectors {
            size(name, v.len())?;
            finite(name, &mut v.iter().map(max3), false)?;
        }
        let scalars = [
            ("albedo variance", &g.albedo_variance, true),
            ("normal variance", &g.normal_variance, true),
            ("depth", &g.depth, false),
            ("depth variance", &g.depth_variance, true),
        ];
        for (name, v, variance) in scalars {
            size(name, v.len())?;
            finite(name, &mut v.iter().copied(), variance)?;
        }
        Ok(())
    }
}
