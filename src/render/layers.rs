//! EXR layers beside the combined image (`--layers`): the radiance split by how light reached
//! the camera ([`LightPath`]: specular, direct, caustic, indirect), the per-pixel variance of
//! the pixel's mean and the sample count, so a user sees which part of an image is wrong (or
//! still noisy) without rendering it again. Written as one EXR part whose channels are named
//! `R, G, B` (the combined image, what viewers show first) and `<layer>.R/G/B` (or
//! `samples.Y`), the OpenEXR convention for layers in one part. Beside a PNG image the light
//! layers are pictures instead ([`super::layer_pictures`]).

use std::path::Path;

use exr::prelude::{AnyChannel, FlatSamples};

use super::PixelSums;
use super::exr::{encode_channels, rgb_channels};
use super::output::{OutputError, write_atomic};
use crate::integrators::LightPath;

/// One layer a render can write beside the combined image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layer {
    /// The radiance of one kind of light path (RGB).
    Part(LightPath),
    /// Variance of each pixel's mean (the samples' variance over their count; RGB).
    Variance,
    /// Samples taken per pixel (`samples.Y`).
    Samples,
}

/// Why a `--layers` name is not known.
#[derive(Debug, thiserror::Error)]
#[error(
    "unknown layer `{0}`: the layers are specular, direct, caustic, indirect, variance and samples"
)]
pub struct UnknownLayer(pub String);

impl Layer {
    /// Every layer, in the order they are written.
    pub const ALL: [Layer; 6] = [
        Layer::Part(LightPath::Specular),
        Layer::Part(LightPath::Direct),
        Layer::Part(LightPath::Caustic),
        Layer::Part(LightPath::Indirect),
        Layer::Variance,
        Layer::Samples,
    ];

    /// The layer's name (channel prefix).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Layer::Part(p) => p.name(),
            Layer::Variance => "variance",
            Layer::Samples => "samples",
        }
    }

    /// The layer called `name`.
    ///
    /// # Errors
    /// [`UnknownLayer`] naming the valid layers.
    pub fn parse(name: &str) -> Result<Self, UnknownLayer> {
        Self::ALL
            .into_iter()
            .find(|l| l.name().eq_ignore_ascii_case(name.trim()))
            .ok_or_else(|| UnknownLayer(name.to_string()))
    }
}

/// Encodes the combined image of `sums` and the `layers` asked for as an EXR file's bytes.
/// `parts` holds the per-[`LightPath`] sums (in `LightPath::ALL` order) when the render kept
/// them; a part layer without them is an error.
///
/// # Errors
/// [`OutputError::Layers`] when a part layer is asked for but `parts` is `None`, or when the
/// EXR encoder fails.
pub fn encode_layers(
    sums: &PixelSums,
    parts: Option<&[PixelSums]>,
    layers: &[Layer],
    path: &Path,
) -> Result<Vec<u8>, OutputError> {
    let fail = |reason: String| OutputError::Layers {
        path: path.to_path_buf(),
        reason,
    };
    let (w, h) = (sums.width as usize, sums.height as usize);
    let n = w * h;
    let rgb = |name: &str, value: &dyn Fn(usize) -> glam::Vec3| rgb_channels(n, name, value);
    let mut channels: Vec<AnyChannel<FlatSamples>> = rgb("", &|i| sums.mean(i)).into();
    for &layer in layers {
        match layer {
            Layer::Part(kind) => {
                let Some(part) = parts.and_then(|p| p.get(kind as usize)) else {
                    return Err(fail(format!(
                        "the `{}` layer was not kept by this render",
                        kind.name()
                    )));
                };
                channels.extend(rgb(kind.name(), &|i| part.mean(i)));
            }
            Layer::Variance => channels.extend(rgb("variance", &|i| {
                let count = sums.count(i).max(1) as f32;
                sums.variance(i) / count
            })),
            Layer::Samples => channels.push(AnyChannel::new(
                "samples.Y",
                FlatSamples::F32((0..n).map(|i| sums.count(i) as f32).collect()),
            )),
        }
    }
    encode_channels(w, h, channels).map_err(|e| fail(e.to_string()))
}

/// [`encode_layers`], written to `path` atomically.
///
/// # Errors
/// As [`encode_layers`], and when the file cannot be written.
pub fn write_layers(
    sums: &PixelSums,
    parts: Option<&[PixelSums]>,
    layers: &[Layer],
    path: &Path,
) -> Result<(), OutputError> {
    let bytes = encode_layers(sums, parts, layers, path)?;
    write_atomic(path, &bytes)
}
