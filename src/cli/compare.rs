//! `caustic compare`: error figures of an image against a reference, per channel and overall,
//! optionally over a region, as text or JSON, and optionally a false-colour error image.

use std::path::PathBuf;

use clap::Args;
use serde_json::json;

use caustic::Error;
use caustic::analysis::metrics::{
    ChannelError, ImageError, compare_region, pixel_errors, read_pair,
};
use caustic::render::Region;

use super::render::parse_region;
use caustic::analysis::error_image::{self, ErrorScale};

/// Arguments of `caustic compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// The image under test.
    image: PathBuf,
    /// The converged reference.
    reference: PathBuf,
    /// Compare only the crop X,Y,W,H (pixels from the top-left, as `render --region`).
    #[arg(long, value_name = "X,Y,W,H")]
    region: Option<String>,
    /// Write a false-colour PNG of each pixel's RMS error over its channels (viridis), with a
    /// colour bar labelled with its scale; the summary repeats the scale.
    #[arg(long, value_name = "FILE.png")]
    error_image: Option<PathBuf>,
    /// The error drawn in the colour bar's top colour (default: the 99th percentile of the
    /// pixels' errors). Give the same value to compare several error images.
    #[arg(long, value_name = "ERROR", requires = "error_image", value_parser = parse_positive)]
    error_max: Option<f32>,
    /// Print the figures as one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

fn parse_positive(text: &str) -> Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("expected a positive number, found `{text}`"))
}

/// Prints RMSE, relMSE, mean absolute error, bias and the largest difference, overall and per
/// channel, and writes the error image if asked.
pub fn run(args: &CompareArgs) -> Result<(), Error> {
    if let Some(path) = &args.error_image {
        let png = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !png {
            return Err(Error::Usage(format!(
                "--error-image `{}`: the error image must end in `.png`",
                path.display()
            )));
        }
        caustic::render::output::check_writable(path)?;
    }
    let region = args.region.as_deref().map(parse_region).transpose()?;
    let pair = read_pair(&args.image, &args.reference).map_err(|e| Error::Usage(e.to_string()))?;
    let (w, h) = (pair.test.width, pair.test.height);
    let region = region.unwrap_or(Region {
        x: 0,
        y: 0,
        width: w,
        height: h,
    });
    let outside = || {
        Error::Usage(format!(
            "--region {},{},{},{} does not fit in the {w}×{h} images (X + W ≤ {w}, \
             Y + H ≤ {h}, W and H at least 1)",
            region.x, region.y, region.width, region.height
        ))
    };
    let e = compare_region(&pair.test, &pair.reference, region).ok_or_else(outside)?;
    if let Some(note) = &pair.note {
        eprintln!("{note}");
    }
    let scale = match &args.error_image {
        Some(path) => {
            let errors = pixel_errors(&pair.test, &pair.reference, region).ok_or_else(outside)?;
            let scale = args.error_max.map_or_else(
                || error_image::default_scale(&errors),
                |max| ErrorScale {
                    max,
                    source: "--error-max",
                },
            );
            let img = error_image::render(&errors, region.width, region.height, scale);
            error_image::write_png(&img, path)?;
            Some((path, scale))
        }
        None => None,
    };
    if args.json {
        let error_image = scale.map(|(path, s)| {
            json!({"path": path.display().to_string(), "max": s.max, "scale_from": s.source})
        });
        let whole = (region.x, region.y, region.width, region.height) == (0, 0, w, h);
        let value = json!({
            "image": args.image.display().to_string(),
            "reference": args.reference.display().to_string(),
            "width": w,
            "height": h,
            "region": (!whole).then_some([region.x, region.y, region.width, region.height]),
            "note": pair.note,
            "error_image": error_image,
            "figures": figures_json(&e),
        });
        println!("{value:#}");
        return Ok(());
    }
    println!(
        "rmse {:.6}  relMSE {:.6}  max |diff| {:.6}  mean bias {:+.6}  mae {:.6}",
        e.rmse, e.rel_mse, e.max_abs, e.mean_bias, e.mae
    );
    println!(
        "{:<8}{:>12}{:>12}{:>12}{:>13}{:>12}",
        "channel", "rmse", "relMSE", "mae", "bias", "max |diff|"
    );
    for (name, c) in ["red", "green", "blue"].iter().zip(e.channels) {
        println!(
            "{name:<8}{:>12.6}{:>12.6}{:>12.6}{:>+13.6}{:>12.6}",
            c.rmse, c.rel_mse, c.mae, c.bias, c.max_abs
        );
    }
    if (region.x, region.y, region.width, region.height) != (0, 0, w, h) {
        println!(
            "over the region {},{},{},{} ({} pixels of {w}×{h})",
            region.x, region.y, region.width, region.height, e.pixels
        );
    }
    if let Some((path, s)) = scale {
        let z = error_image::zoom(region.width);
        let zoomed = if z > 1 {
            format!(", each pixel drawn {z}×{z}")
        } else {
            String::new()
        };
        println!(
            "error image `{}`: per-pixel RMS error over the channels, viridis from 0 to {} ({}){zoomed}",
            path.display(),
            error_image::label(s.max),
            s.source
        );
    }
    Ok(())
}

/// The figures of one channel (or of all pooled) as JSON.
pub fn channel_json(c: &ChannelError) -> serde_json::Value {
    json!({"rmse": c.rmse, "rel_mse": c.rel_mse, "mae": c.mae, "bias": c.bias, "max_abs": c.max_abs})
}

/// All the figures of a comparison as JSON: overall, then per channel.
pub fn figures_json(e: &ImageError) -> serde_json::Value {
    let [r, g, b] = e.channels.map(|c| channel_json(&c));
    json!({
        "pixels": e.pixels,
        "overall": channel_json(&e.overall()),
        "red": r,
        "green": g,
        "blue": b,
    })
}
