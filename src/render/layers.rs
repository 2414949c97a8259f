//! EXR layers beside the combined image (`--layers`): the radiance split by how light reached
//! the camera ([`LightPath`]: specular, direct, caustic, indirect), the per-pixel variance of
//! the pixel's mean and the sample count, so a user sees which part of an image is wrong (or
//! still noisy) without rendering it again. Written as one EXR part whose channels are named
//! `R, G, B` (the combined image, what viewers show first) and `<layer>.R/G/B` (or
//! `samples.Y`), the OpenEXR convention for layers in one part.

use std::io::Cursor;
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer as ExrLayer, LayerAttributes,
    SmallVec, Vec2, WritableImage,
};

use super::PixelSums;
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
    encode_channels(w, h, channels, path)
}

/// Encodes a `width` × `height` RGB image (`value(i)` for pixel `i`, row-major) as EXR bytes:
/// 32-bit float channels `R, G, B`, lossless compression, written on one thread so that the
/// same image always gives the same bytes (parallel compression writes its blocks in whatever
/// order they finish).
///
/// # Errors
/// [`OutputError::Layers`] when the encoder fails.
pub fn encode_rgb_exr(
    width: usize,
    height: usize,
    value: &dyn Fn(usize) -> glam::Vec3,
    path: &Path,
) -> Result<Vec<u8>, OutputError> {
    let channels = rgb_channels(width * height, "", value).into();
    encode_channels(width, height, channels, path)
}

/// Three float channels `<name>.R/G/B` (`R, G, B` for an empty name) of `n` pixels.
fn rgb_channels(
    n: usize,
    name: &str,
    value: &dyn Fn(usize) -> glam::Vec3,
) -> [AnyChannel<FlatSamples>; 3] {
    let mut c = [
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    ];
    for v in (0..n).map(value) {
        c[0].push(v.x);
        c[1].push(v.y);
        c[2].push(v.z);
    }
    let prefix = if name.is_empty() {
        String::new()
    } else {
        format!("{name}.")
    };
    let [r, g, b] = c;
    [
        AnyChannel::new(format!("{prefix}R").as_str(), FlatSamples::F32(r)),
        AnyChannel::new(format!("{prefix}G").as_str(), FlatSamples::F32(g)),
        AnyChannel::new(format!("{prefix}B").as_str(), FlatSamples::F32(b)),
    ]
}

/// One EXR part holding `channels`, encoded on one thread (deterministic bytes).
fn encode_channels(
    width: usize,
    height: usize,
    channels: Vec<AnyChannel<FlatSamples>>,
    path: &Path,
) -> Result<Vec<u8>, OutputError> {
    let layer = ExrLayer::new(
        Vec2(width, height),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut bytes = Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .map_err(|e| OutputError::Layers {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
    Ok(bytes.into_inner())
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use glam::Vec3;

    use super::encode_rgb_exr;

    #[test]
    fn the_same_image_always_encodes_to_the_same_bytes() {
        // Large enough for many compressed blocks: a parallel encoder wrote them in whatever
        // order they finished, so repeated encodings differed.
        let value = |i: usize| Vec3::new(i as f32 * 1e-3, (i % 97) as f32, (i % 13) as f32 * 0.5);
        let first = encode_rgb_exr(320, 200, &value, Path::new("x.exr")).expect("encodes");
        for _ in 0..8 {
            let again = encode_rgb_exr(320, 200, &value, Path::new("x.exr")).expect("encodes");
            assert!(again == first, "EXR bytes differ between two encodings");
        }
        let image = image::load_from_memory(&first)
            .expect("decodes")
            .into_rgb32f();
        assert_eq!(image.get_pixel(5, 1).0, value(325).to_array());
    }
}
