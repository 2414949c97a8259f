//! `caustic compare`: error figures of an image against a reference.

use std::path::{Path, PathBuf};

use clap::Args;

use caustic::Error;
use caustic::render::metrics::{compare, read_film};

/// Arguments of `caustic compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// The image under test.
    image: PathBuf,
    /// The converged reference.
    reference: PathBuf,
}

/// Prints RMSE, relMSE, the largest difference and the mean bias.
pub fn run(args: &CompareArgs) -> Result<(), Error> {
    let (image, reference) = (&args.image, &args.reference);
    let read = |p: &Path| {
        read_film(p).map_err(|e| Error::Usage(format!("error: cannot read `{}`: {e}", p.display())))
    };
    let (a, b) = (read(image)?, read(reference)?);
    let e = compare(&a, &b).ok_or_else(|| {
        Error::Usage(format!(
            "error: `{}` is {}×{} but `{}` is {}×{}",
            image.display(),
            a.width,
            a.height,
            reference.display(),
            b.width,
            b.height
        ))
    })?;
    println!(
        "rmse {:.6}  relMSE {:.6}  max |diff| {:.6}  mean bias {:+.6}",
        e.rmse, e.rel_mse, e.max_abs, e.mean_bias
    );
    Ok(())
}
