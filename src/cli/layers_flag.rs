//! `--layers` (of `render` and `preview`) checked against the output before any work: the
//! layers the user listed, and whether the output can hold them (an EXR holds any layer as
//! channels; a PNG gets each light layer as a picture beside it, which must be writable and
//! not the checkpoint file).

use std::path::{Path, PathBuf};

use caustic::Error;
use caustic::render::output::{OutputFormat, check_writable};
use caustic::render::{Layer, layer_path, picture_layers};

use super::same_file::same_file;

/// The layers of every `--layers` flag, in order, each once.
pub(super) fn listed(flags: &[Vec<Layer>]) -> Vec<Layer> {
    let mut layers: Vec<Layer> = Vec::new();
    for &layer in flags.iter().flatten() {
        if !layers.contains(&layer) {
            layers.push(layer);
        }
    }
    layers
}

/// Refuses `layers` the output cannot hold, and a layer picture that cannot be written; the
/// picture files a PNG output will get (none for an EXR output, or without layers).
///
/// # Errors
/// [`Error::Usage`] for an output that is neither `.exr` nor `.png`, a statistics layer with a
/// PNG output, or a picture that would overwrite the checkpoint; the output error of a picture
/// that cannot be written.
pub(super) fn check(
    output: &Path,
    layers: &[Layer],
    checkpoint: Option<&Path>,
) -> Result<Vec<PathBuf>, Error> {
    if layers.is_empty() {
        return Ok(Vec::new());
    }
    match OutputFormat::for_path(output) {
        Ok(OutputFormat::Exr) => Ok(Vec::new()),
        Ok(OutputFormat::Png) => {
            let kinds =
                picture_layers(layers).map_err(|e| Error::Usage(format!("--layers: {e}")))?;
            let pictures: Vec<PathBuf> = kinds.iter().map(|&k| layer_path(output, k)).collect();
            for picture in &pictures {
                if let Some(cp) = checkpoint
                    && same_file(cp, picture)
                {
                    return Err(Error::Usage(format!(
                        "--checkpoint `{}` is where --layers writes a layer picture; give it another name",
                        cp.display()
                    )));
                }
                check_writable(picture)?;
            }
            Ok(pictures)
        }
        Err(_) => Err(Error::Usage(format!(
            "--layers are written into an EXR output as channels, or beside a PNG output as pictures: the output `{}` must end in `.exr` or `.png`",
            output.display()
        ))),
    }
}
