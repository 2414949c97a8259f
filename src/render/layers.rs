//! EXR layers beside the combined image (`--layers`): the radiance split by how light reached
//! the camera ([`LightPath`]: specular, direct, caustic, indirect), the per-pixel variance of
//! the pixel's mean and the sample count, so a user sees which part of an image is wrong (or
//! still noisy) without rendering it again. Written as one EXR part whose channels are named
//! `R, G, B` (the combined image, what viewers show first) and `<layer>.R/G/B` (or
//! `samples.Y`), the OpenEXR convention for layers in one part. Beside a PNG image the light
//! layers are pictures instead ([`super::layer_pictures`]). The feature layers (albedo, normal,
//! depth: [`super::features`]) come with their per-pixel variance (`albedo.variance.R/G/B`,
//! `normal.variance.X/Y/Z`, `depth.Z` and `depth.variance.Z`); a denoised render
//! (`--denoise`) writes the denoised image as `R, G, B` and the noisy one as `noisy.R/G/B`.

use std::path::Path;

use exr::prelude::{AnyChannel, FlatSamples};

use super::exr::{encode_channels, rgb_channels};
use super::features::{FeatureSample, Features};
use super::output::{OutputError, write_atomic};
use super::{Film, PixelSums};
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
    /// Albedo at the first non-specular surface (RGB) and its variance
    /// ([`FeatureSample::albedo`]).
    Albedo,
    /// Shading normal there (`normal.X/Y/Z`, world space) and its variance.
    Normal,
    /// Distance to that surface along the path (`depth.Z`, scene units) and its variance.
    Depth,
}

/// What a render made besides its sums that the layers and the image may come from: the
/// feature buffers (for the feature layers) and the denoised image (`--denoise`: it becomes the
/// file's image and the noisy one a layer).
#[derive(Debug, Clone, Copy, Default)]
pub struct LayerExtras<'a> {
    /// The feature buffers, when traced.
    pub features: Option<&'a Features>,
    /// The denoised image, of the sums' size.
    pub denoised: Option<&'a Film>,
}

/// Why a `--layers` name is not known.
#[derive(Debug, thiserror::Error)]
#[error(
    "unknown layer `{0}`: the layers are specular, direct, caustic, indirect, variance, samples, albedo, normal and depth"
)]
pub struct UnknownLayer(pub String);

impl Layer {
    /// Every light and statistics layer, in the order they are written (`--layers all`); the
    /// feature layers ([`Layer::FEATURES`]) are asked for by name, as they take a pass of
    /// their own.
    pub const ALL: [Layer; 6] = [
        Layer::Part(LightPath::Specular),
        Layer::Part(LightPath::Direct),
        Layer::Part(LightPath::Caustic),
        Layer::Part(LightPath::Indirect),
        Layer::Variance,
        Layer::Samples,
    ];

    /// The feature layers.
    pub const FEATURES: [Layer; 3] = [Layer::Albedo, Layer::Normal, Layer::Depth];

    /// Whether this is a feature layer (traced by [`Features::trace`]).
    #[must_use]
    pub fn is_feature(self) -> bool {
        Self::FEATURES.contains(&self)
    }

    /// The layer's name (channel prefix).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Layer::Part(p) => p.name(),
            Layer::Variance => "variance",
            Layer::Samples => "samples",
            Layer::Albedo => "albedo",
            Layer::Normal => "normal",
            Layer::Depth => "depth",
        }
    }

    /// The layer called `name`.
    ///
    /// # Errors
    /// [`UnknownLayer`] naming the valid layers.
    pub fn parse(name: &str) -> Result<Self, UnknownLayer> {
        Self::ALL
            .into_iter()
            .chain(Self::FEATURES)
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
    encode_layers_with(sums, parts, LayerExtras::default(), layers, path)
}

/// [`encode_layers`] with the feature buffers and the denoised image: with `extras.denoised`
/// the file's image (`R, G, B`) is the denoised one and the noisy mean of `sums` is written
/// as the `noisy` layer; a feature layer needs `extras.features`.
///
/// # Errors
/// As [`encode_layers`], and [`OutputError::Layers`] for a feature layer without features or
/// a denoised image or features of another size than `sums`.
pub fn encode_layers_with(
    sums: &PixelSums,
    parts: Option<&[PixelSums]>,
    extras: LayerExtras<'_>,
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
    let mut channels: Vec<AnyChannel<FlatSamples>> = match extras.denoised {
        Some(film) if (film.width, film.height) != (sums.width, sums.height) => {
            return Err(fail(format!(
                "the denoised image is {}×{}, the render {}×{}",
                film.width, film.height, sums.width, sums.height
            )));
        }
        Some(film) => {
            let mut c: Vec<_> = rgb("", &|i| film.pixels[i]).into();
            c.extend(rgb("noisy", &|i| sums.mean(i)));
            c
        }
        None => rgb("", &|i| sums.mean(i)).into(),
    };
    let features = || match extras.features {
        Some(f) if (f.width, f.height) == (sums.width, sums.height) => Ok(f),
        Some(f) => Err(fail(format!(
            "the feature buffers are {}×{}, the render {}×{}",
            f.width, f.height, sums.width, sums.height
        ))),
        None => Err(fail(
            "the feature layers (albedo, normal, depth) were not traced by this render".into(),
        )),
    };
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
            Layer::Albedo | Layer::Normal => {
                let f = features()?;
                let (value, names): (fn(FeatureSample) -> glam::Vec3, [&str; 3]) =
                    if layer == Layer::Albedo {
                        (|s| s.albedo, ["R", "G", "B"])
                    } else {
                        (|s| s.normal, ["X", "Y", "Z"])
                    };
                let name = layer.name();
                channels.extend(named3(n, name, names, &|i| value(f.mean(i))));
                let variance = format!("{name}.variance");
                channels.extend(named3(n, &variance, names, &|i| value(f.variance(i))));
            }
            Layer::Depth => {
                let f = features()?;
                let depth = |name: &str, v: &dyn Fn(usize) -> f32| {
                    AnyChannel::new(name, FlatSamples::F32((0..n).map(v).collect()))
                };
                channels.push(depth("depth.Z", &|i| f.mean(i).depth));
                channels.push(depth("depth.variance.Z", &|i| f.variance(i).depth));
            }
        }
    }
    encode_channels(w, h, channels).map_err(|e| fail(e.to_string()))
}

/// Three float channels `<name>.<c>` for the three channel names `names`.
fn named3(
    n: usize,
    name: &str,
    names: [&str; 3],
    value: &dyn Fn(usize) -> glam::Vec3,
) -> [AnyChannel<FlatSamples>; 3] {
    let [x, y, z] = rgb_channels(n, "", value);
    let rename = |c: AnyChannel<FlatSamples>, to: &str| {
        AnyChannel::new(format!("{name}.{to}").as_str(), c.sample_data)
    };
    [
        rename(x, names[0]),
        rename(y, names[1]),
        rename(z, names[2]),
    ]
}

/// [`encode_layers_with`], written to `path` atomically.
///
/// # Errors
/// As [`encode_layers_with`], and when the file cannot be written.
pub fn write_layers_with(
    sums: &PixelSums,
    parts: Option<&[PixelSums]>,
    extras: LayerExtras<'_>,
    layers: &[Layer],
    path: &Path,
) -> Result<(), OutputError> {
    let bytes = encode_layers_with(sums, parts, extras, layers, path)?;
    write_atomic(path, &bytes)
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
