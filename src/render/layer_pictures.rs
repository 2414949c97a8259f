//! Layers as pictures (`--layers` with a PNG output): each kind of light path the render kept
//! ([`LightPath`]) written as its own 8-bit PNG beside the image, `out.png` → `out.direct.png`,
//! `out.caustic.png`, …, tone-mapped exactly as the image is (the same [`Display`] through
//! the same [`to_srgb8`]), so the pictures show side by side what each kind of light adds to
//! the image. The image and its pictures are written together: all are encoded and written to
//! temporary files before any is renamed into place. The statistics layers (variance, samples)
//! are numbers, not pictures: they go only into EXR files ([`super::layers`]), as do the
//! feature layers (albedo, normal, depth). A denoised render (`--denoise`) writes the denoised
//! image as the PNG; its layer pictures stay the noisy light layers.
//! [`write_with_layers`] picks between the two by the output's extension.

use std::path::{Path, PathBuf};

use super::layers::{Layer, LayerExtras, write_layers_with};
use super::output::{OutputError, OutputFormat, encode, write_atomic_all};
use super::tonemap::Display;
use super::{Film, PixelSums};
use crate::integrators::LightPath;

#[cfg(doc)]
use super::output::to_srgb8;

/// Why a layer cannot be a picture beside a PNG image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error(
    "the `{}` layer holds numbers, not a picture: it is written only into an EXR output (`-o out.exr`); beside a PNG output, --layers writes the light layers (specular, direct, caustic, indirect) as PNG pictures",
    .0.name()
)]
pub struct NotAPicture(pub Layer);

/// The light-path layers of `layers`, in the order given and each once: the layers a PNG
/// output writes as pictures.
///
/// # Errors
/// [`NotAPicture`] for the first statistics layer (variance, samples).
pub fn picture_layers(layers: &[Layer]) -> Result<Vec<LightPath>, NotAPicture> {
    let mut kinds = Vec::with_capacity(layers.len());
    for &layer in layers {
        match layer {
            Layer::Part(kind) if !kinds.contains(&kind) => kinds.push(kind),
            Layer::Part(_) => {}
            Layer::Variance | Layer::Samples | Layer::Albedo | Layer::Normal | Layer::Depth => {
                return Err(NotAPicture(layer));
            }
        }
    }
    Ok(kinds)
}

/// Where the picture of layer `kind` goes beside the image `output`: the layer's name between
/// the file's stem and its extension (`out.png` → `out.caustic.png`, in the same folder).
#[must_use]
pub fn layer_path(output: &Path, kind: LightPath) -> PathBuf {
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    let name = match output.extension() {
        Some(ext) => format!("{stem}.{}.{}", kind.name(), ext.to_string_lossy()),
        None => format!("{stem}.{}", kind.name()),
    };
    output.with_file_name(name)
}

/// Encodes the image of `sums` for `output` and the picture of each light-path layer of
/// `layers` for its [`layer_path`], every one through `display`: the files to write, the image
/// first. `parts` holds the per-[`LightPath`] sums (in `LightPath::ALL` order) when the render
/// kept them.
///
/// # Errors
/// [`OutputError::Pictures`] for a statistics layer or a light-path layer the render did not
/// keep; the encoder's error.
pub fn encode_layer_pictures(
    sums: &PixelSums,
    parts: Option<&[PixelSums]>,
    layers: &[Layer],
    output: &Path,
    display: Display,
) -> Result<Vec<(PathBuf, Vec<u8>)>, OutputError> {
    encode_pictures_of(&sums.to_film(), parts, layers, output, display)
}

/// [`encode_layer_pictures`] with the image `image` (e.g. the denoised one) instead of the
/// sums' mean.
fn encode_pictures_of(
    image: &Film,
    parts: Option<&[PixelSums]>,
    layers: &[Layer],
    output: &Path,
    display: Display,
) -> Result<Vec<(PathBuf, Vec<u8>)>, OutputError> {
    let fail = |reason: String| OutputError::Pictures {
        path: output.to_path_buf(),
        reason,
    };
    let kinds = picture_layers(layers).map_err(|e| fail(e.to_string()))?;
    let mut files = vec![(output.to_path_buf(), encode(image, output, display)?)];
    for kind in kinds {
        let Some(part) = parts.and_then(|p| p.get(kind as usize)) else {
            return Err(fail(format!(
                "the `{}` layer was not kept by this render",
                kind.name()
            )));
        };
        let path = layer_path(output, kind);
        let bytes = encode(&part.to_film(), &path, display)?;
        files.push((path, bytes));
    }
    Ok(files)
}

/// Writes the image of `sums` with its `layers` to `output`, by its extension: an EXR holds
/// the layers as channels ([`super::layers::write_layers`]; linear, `display` unused), a PNG gets each
/// light-path layer as a picture beside it ([`encode_layer_pictures`]), all written
/// atomically.
///
/// # Errors
/// As [`super::layers::write_layers`] or [`encode_layer_pictures`], [`OutputError::UnknownFormat`] for
/// another extension, and when a file cannot be written.
pub fn write_with_layers(
    sums: &PixelSums,
    parts: Option<&[PixelSums]>,
    layers: &[Layer],
    output: &Path,
    display: Display,
) -> Result<(), OutputError> {
    write_with_extras(sums, parts, LayerExtras::default(), layers, output, display)
}

/// [`write_with_layers`] with the feature buffers and the denoised image of `extras`: an EXR
/// gets the denoised image as `R, G, B`, the noisy one as the `noisy` layer and any feature
/// layer ([`super::layers::encode_layers_with`]); a PNG is the denoised image, its layer
/// pictures the noisy light layers.
///
/// # Errors
/// As [`write_with_layers`]; a feature layer without features.
pub fn write_with_extras(
    sums: &PixelSums,
    parts: Option<&[PixelSums]>,
    extras: LayerExtras<'_>,
    layers: &[Layer],
    output: &Path,
    display: Display,
) -> Result<(), OutputError> {
    match OutputFormat::for_path(output)? {
        OutputFormat::Exr => write_layers_with(sums, parts, extras, layers, output),
        OutputFormat::Png => {
            let noisy;
            let image = match extras.denoised {
                Some(film) => film,
                None => {
                    noisy = sums.to_film();
                    &noisy
                }
            };
            write_atomic_all(&encode_pictures_of(image, parts, layers, output, display)?)
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::render::output::to_srgb8;
    use crate::render::tonemap::Tonemap;

    #[test]
    fn pictures_go_beside_the_image_named_by_their_layer() {
        let at = |p: &str, kind| layer_path(Path::new(p), kind);
        assert_eq!(
            at("docs/images/bath.png", LightPath::Caustic),
            PathBuf::from("docs/images/bath.caustic.png")
        );
        assert_eq!(
            at("out.PNG", LightPath::Direct),
            PathBuf::from("out.direct.PNG")
        );
        assert_eq!(
            at("a.b.png", LightPath::Indirect),
            PathBuf::from("a.b.indirect.png")
        );
    }

    #[test]
    fn only_light_layers_are_pictures_each_once() {
        let direct = Layer::Part(LightPath::Direct);
        let caustic = Layer::Part(LightPath::Caustic);
        assert_eq!(
            picture_layers(&[caustic, direct, caustic]),
            Ok(vec![LightPath::Caustic, LightPath::Direct])
        );
        assert_eq!(
            picture_layers(&[direct, Layer::Variance]),
            Err(NotAPicture(Layer::Variance))
        );
        let text = NotAPicture(Layer::Samples).to_string();
        assert!(text.contains("`samples`") && text.contains("EXR"), "{text}");
    }

    /// Two pixels, two samples each, split between the direct and caustic layers: each picture
    /// is its layer's mean through the image's display, and the image is the sum's.
    #[test]
    fn each_picture_is_its_layers_mean_through_the_images_display() {
        let mut sums = PixelSums::new(2, 1);
        let mut parts: Vec<PixelSums> = LightPath::ALL
            .iter()
            .map(|_| PixelSums::new(2, 1))
            .collect();
        let samples = [
            (0, Vec3::new(0.2, 0.1, 0.0), Vec3::new(0.5, 0.5, 0.5)),
            (0, Vec3::new(0.4, 0.3, 0.1), Vec3::ZERO),
            (1, Vec3::new(3.0, 0.0, 0.05), Vec3::new(0.01, 0.9, 2.0)),
            (1, Vec3::new(1.0, 0.2, 0.0), Vec3::new(0.03, 0.1, 0.0)),
        ];
        for (i, direct, caustic) in samples {
            sums.add(i, direct + caustic);
            parts[LightPath::Direct as usize].add(i, direct);
            parts[LightPath::Caustic as usize].add(i, caustic);
        }
        let display = Display {
            exposure: 0.7,
            tonemap: Tonemap::Aces,
        };
        let layers = [
            Layer::Part(LightPath::Direct),
            Layer::Part(LightPath::Caustic),
        ];
        let dir = tempfile::tempdir().expect("tmp");
        let out = dir.path().join("x.png");
        write_with_layers(&sums, Some(&parts), &layers, &out, display).expect("written");
        let read = |p: &Path| image::open(p).expect("a PNG").into_rgb8().into_raw();
        assert_eq!(read(&out), to_srgb8(&sums.to_film(), display).into_raw());
        for kind in [LightPath::Direct, LightPath::Caustic] {
            let film = parts[kind as usize].to_film();
            assert_eq!(
                read(&layer_path(&out, kind)),
                to_srgb8(&film, display).into_raw(),
                "{kind:?}"
            );
        }
        // Exactly the three files: no other layer, no temporary file.
        assert_eq!(std::fs::read_dir(dir.path()).expect("ls").count(), 3);
        // A layer the render did not keep is refused and nothing is written.
        let other = dir.path().join("y.png");
        let e = write_with_layers(&sums, None, &layers, &other, display)
            .expect_err("no parts kept")
            .to_string();
        assert!(e.contains("`direct` layer was not kept"), "{e}");
        assert!(!other.exists());
    }
}
