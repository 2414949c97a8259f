//! `caustic plot`: the log-log plot and slopes of `caustic converge`, for curves read from CSV
//! files — another renderer's (Mitsuba 3's, in `scripts/convergence_slopes.sh`) beside ours.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use serde_json::json;

use caustic::Error;
use caustic::render::output::write_atomic;

use caustic::analysis::convergence_plot::{Curve, Plot};
use caustic::analysis::slope::{fmt_slope, log_log_slope};

/// `caustic plot` arguments.
#[derive(Args, Debug)]
pub struct PlotArgs {
    /// Curves as `LABEL=FILE.csv`: each CSV has a header row naming at least the columns
    /// `seconds` and `rmse`, then one point per row.
    #[arg(required = true, value_name = "LABEL=CSV")]
    curves: Vec<String>,
    /// Writes OUT.svg and OUT.png (and OUT.json: the points and slopes).
    #[arg(long, short, value_name = "OUT")]
    output: PathBuf,
    /// Caption above the chart.
    #[arg(long, default_value = "RMSE against render time")]
    title: String,
    /// RMSE of the reference's own noise σ: also fits the slope of √(RMSE² − σ²), the error
    /// against the exact image (a reference's noise adds σ² to every point's expected MSE and
    /// flattens a curve's far end).
    #[arg(long, value_name = "SIGMA", default_value_t = 0.0)]
    ref_noise: f64,
}

/// The `(seconds, rmse)` points of the CSV file `path` (`text` its contents), sorted by time.
fn points(path: &Path, text: &str) -> Result<Vec<(f64, f64)>, Error> {
    let bad =
        |line: usize, what: String| Error::Usage(format!("{}:{line}: {what}", path.display()));
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(bad(
            1,
            "empty: want a header row with `seconds` and `rmse`".into(),
        ));
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let column = |name: &str| {
        names.iter().position(|n| *n == name).ok_or_else(|| {
            bad(
                1,
                format!(
                    "no `{name}` column in the header (it has {})",
                    names.join(", ")
                ),
            )
        })
    };
    let (s, r) = (column("seconds")?, column("rmse")?);
    let mut out = Vec::new();
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let number = |c: usize, name: &str| {
            cells
                .get(c)
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| bad(i + 1, format!("`{name}` must be a positive number")))
        };
        out.push((number(s, "seconds")?, number(r, "rmse")?));
    }
    if out.is_empty() {
        return Err(bad(2, "no points below the header".into()));
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(out)
}

/// Runs `caustic plot`.
pub fn run(args: &PlotArgs) -> Result<(), Error> {
    let sigma = args.ref_noise;
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(Error::Usage(format!(
            "--ref-noise {sigma}: want a number ≥ 0"
        )));
    }
    let mut curves = Vec::new();
    let mut doc = Vec::new();
    for spec in &args.curves {
        let Some((label, file)) = spec.split_once('=') else {
            return Err(Error::Usage(format!("`{spec}`: want LABEL=FILE.csv")));
        };
        let path = Path::new(file);
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::Usage(format!("{}: {e}", path.display())))?;
        let pts = points(path, &text)?;
        let slope = log_log_slope(pts.iter().copied());
        let net = (sigma > 0.0).then(|| {
            log_log_slope(
                pts.iter()
                    .filter(|p| p.1 > sigma)
                    .map(|&(x, y)| (x, (y * y - sigma * sigma).sqrt())),
            )
        });
        let mut line = format!(
            "{label}: {} points, {:.2}–{:.2} s, RMSE {:.5} → {:.5}; slope {}",
            pts.len(),
            pts[0].0,
            pts[pts.len() - 1].0,
            pts[0].1,
            pts[pts.len() - 1].1,
            fmt_slope(slope)
        );
        let mut legend = format!("{label} (slope {}", fmt_slope(slope));
        if let Some(net) = net {
            let _ = write!(
                line,
                ", {} with the reference's noise ({sigma:.5}) taken out",
                fmt_slope(net)
            );
            let _ = write!(legend, "; net {}", fmt_slope(net));
        }
        legend.push(')');
        println!("{line}");
        doc.push(
            json!({"label": label, "csv": file, "points": pts, "slope": slope,
            "ref_noise": (sigma > 0.0).then_some(sigma), "slope_without_ref_noise": net.flatten()}),
        );
        curves.push(Curve {
            label: legend,
            points: pts,
        });
    }
    let plot = Plot {
        title: args.title.clone(),
        x_desc: "render time (s)".into(),
        y_desc: "RMSE".into(),
        curves,
    };
    let with = |ext: &str| args.output.with_extension(ext);
    caustic::analysis::convergence_plot::write(&plot, &with("svg"), &with("png"))?;
    let doc = json!({"title": args.title, "curves": doc});
    write_atomic(&with("json"), format!("{doc:#}\n").as_bytes())?;
    println!("wrote {}.{{svg,png,json}}", args.output.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_points_are_read_by_column_name_and_bad_rows_name_their_line() {
        let p = Path::new("m.csv");
        let pts = points(p, "rmse,seconds,spp\n0.02,8,512\n0.04,2,128\n").expect("points");
        assert_eq!(pts, vec![(2.0, 0.04), (8.0, 0.02)]);
        let e = points(p, "seconds,rmse\n1,0.1\n2,oops\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.csv:3") && e.contains("rmse"), "{e}");
        let e = points(p, "time,rmse\n1,0.1\n").unwrap_err().to_string();
        assert!(e.contains("m.csv:1") && e.contains("seconds"), "{e}");
        assert!(points(p, "seconds,rmse\n").is_err());
    }
}
