//! `caustic render --compare REF --max-rmse X`: a golden-image check for continuous
//! integration. The reference is read before rendering (a bad path fails at once, exit code 2);
//! after the image is written the render is compared with it, the figures are printed, and the
//! command fails with exit code 3 ([`Error::Mismatch`]) when the RMSE is above the limit.

use std::path::Path;

use caustic::Error;
use caustic::analysis::metrics::Reference;
use caustic::render::{Film, Region};

/// Reads the reference of `--compare`, if given.
pub fn load(path: Option<&Path>) -> Result<Option<Reference>, Error> {
    path.map(|p| Reference::read(p).map_err(|e| Error::Usage(format!("--compare: {e}"))))
        .transpose()
}

/// Refuses, before rendering, a reference whose size matches neither the image (`width`×
/// `height`) nor the crop `region` of it.
pub fn check_size(
    reference: &Reference,
    width: u32,
    height: u32,
    region: Option<Region>,
) -> Result<(), Error> {
    let size = (reference.film.width, reference.film.height);
    if size == (width, height) || region.is_some_and(|r| size == (r.width, r.height)) {
        return Ok(());
    }
    let crop = region.map_or_else(String::new, |r| {
        format!(" or the {}×{} of --region", r.width, r.height)
    });
    Err(Error::Usage(format!(
        "--compare: the reference `{}` is {}×{} but the image is {width}×{height}{crop}; \
         give --width/--height to match it",
        reference.path.display(),
        size.0,
        size.1
    )))
}

/// Compares the rendered `film` (written to `output`; a crop at `region` if given) with the
/// reference, prints the figures on one line, and fails when the RMSE exceeds `max_rmse`.
pub fn check(
    reference: &Reference,
    film: &Film,
    output: &Path,
    exposure: f32,
    region: Option<Region>,
    max_rmse: Option<f64>,
) -> Result<(), Error> {
    let c = reference
        .compare(film, output, exposure, region)
        .map_err(|e| Error::Usage(format!("--compare: {e}")))?;
    if let Some(note) = &c.note {
        eprintln!("{note}");
    }
    let e = c.error;
    // NaN figures (an image of NaNs) fail too.
    let fails = max_rmse.is_some_and(|max| e.rmse > max || e.rmse.is_nan());
    let verdict = match max_rmse {
        Some(_) if fails => " > --max-rmse: FAIL",
        Some(_) => " <= --max-rmse: pass",
        None => "",
    };
    println!(
        "against `{}`: rmse {:.6}{verdict}  relMSE {:.6}  mae {:.6}  mean bias {:+.6}  max |diff| {:.6}",
        reference.path.display(),
        e.rmse,
        e.rel_mse,
        e.mae,
        e.mean_bias,
        e.max_abs
    );
    match max_rmse {
        Some(max) if fails => Err(Error::Mismatch(format!(
            "`{}` is further from the reference `{}` than allowed: RMSE {:.6} > \
             --max-rmse {max} (the image was written; exit code 3)",
            output.display(),
            reference.path.display(),
            e.rmse
        ))),
        _ => Ok(()),
    }
}
