//! `caustic compare`: error figures of an image against a reference.

use std::path::PathBuf;

use clap::Args;

use caustic::Error;

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
    let c = caustic::render::metrics::compare_files(&args.image, &args.reference)
        .map_err(|e| Error::Usage(e.to_string()))?;
    if let Some(note) = &c.note {
        eprintln!("{note}");
    }
    let e = c.error;
    println!(
        "rmse {:.6}  relMSE {:.6}  max |diff| {:.6}  mean bias {:+.6}",
        e.rmse, e.rel_mse, e.max_abs, e.mean_bias
    );
    Ok(())
}
