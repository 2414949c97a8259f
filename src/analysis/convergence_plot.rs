//! Log-log plots of error against time for `caustic converge`, drawn with `plotters` once as
//! SVG (text as `<text>`, so no font is needed) and once into an RGB buffer saved as PNG, whose
//! text is drawn with the 8×8 bitmap font ([`super::pixel_font`]) by a thin backend wrapper:
//! plotters is built without its font features (font-kit and system fonts). Every text is 18 px:
//! plotters lays text out with its font-less estimate of 0.7 em per character (em = size / 1.24²),
//! which at 18 px is the bitmap font's 8 px advance, so boxes fit the PNG's text.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::render::output::{OutputError, write_atomic};

use super::error_image::write_png;
use super::plot_backend::PixelFontBackend;

/// Size of both plots, in pixels.
pub const SIZE: (u32, u32) = (800, 560);

/// One curve: an integrator's points.
#[derive(Debug, Clone)]
pub struct Curve {
    /// The legend's text (name and fitted slope).
    pub label: String,
    /// (wall time in seconds, RMSE), both positive.
    pub points: Vec<(f64, f64)>,
}

/// A plot: title, axis names and curves.
#[derive(Debug, Clone)]
pub struct Plot {
    /// Caption above the chart.
    pub title: String,
    /// X axis name.
    pub x_desc: String,
    /// Y axis name.
    pub y_desc: String,
    /// The curves; points that are not positive and finite are left out.
    pub curves: Vec<Curve>,
}

/// Writes the plot as `<stem>.svg` and `<stem>.png` (each atomically).
pub fn write(plot: &Plot, svg: &Path, png: &Path) -> Result<(), OutputError> {
    let fail = |path: &Path, e: String| OutputError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    };
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, SIZE).into_drawing_area();
        draw(&root, plot).map_err(|e| fail(svg, e.to_string()))?;
    }
    write_atomic(svg, text.as_bytes())?;
    let mut buffer = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let inner = BitMapBackend::with_buffer(&mut buffer, SIZE);
        let root = PixelFontBackend { inner }.into_drawing_area();
        draw(&root, plot).map_err(|e| fail(png, e.to_string()))?;
    }
    let img = image::RgbImage::from_raw(SIZE.0, SIZE.1, buffer)
        .ok_or_else(|| fail(png, "plot buffer has the wrong size".into()))?;
    write_png(&img, png)
}

/// The range of positive finite values of `v`, widened to whole decades (plotters labels a log
/// axis from its first power of ten on).
fn log_range(v: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = v
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold((f64::MAX, f64::MIN_POSITIVE), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    if lo > hi {
        return 0.1..1.0;
    }
    let (a, b) = (lo.log10().floor(), hi.log10().ceil());
    // Just below the lower decade, so that plotters' own rounding of log10 still starts there.
    10f64.powf(a) * 0.999..10f64.powf(b.max(a + 1.0))
}

/// A log axis' tick label: 1, 2 and 5 times a power of ten are labelled (only powers of ten on
/// an axis of more than four decades), the other grid lines (3, 4, 6, …) are left blank so
/// labels do not crowd near the top of each decade. Shortest decimal form: `0.002`, `50`.
fn tick(v: f64, decades: f64) -> String {
    let exponent = v.log10().floor();
    let mantissa = v / 10f64.powf(exponent);
    let marks: &[f64] = if decades > 4.5 {
        &[1.0, 10.0]
    } else {
        &[1.0, 2.0, 5.0, 10.0]
    };
    if !marks.iter().any(|m| (mantissa - m).abs() < 1e-6 * m) {
        return String::new();
    }
    let digits = (-exponent).max(0.0) as usize;
    if digits > 6 || exponent > 6.0 {
        format!("{v:.0e}")
    } else {
        format!("{v:.digits$}")
    }
}

/// Decades a log range spans.
fn decades(r: &std::ops::Range<f64>) -> f64 {
    (r.end / r.start).log10()
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &Plot,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let ok = |p: &&(f64, f64)| p.0.is_finite() && p.0 > 0.0 && p.1.is_finite() && p.1 > 0.0;
    let all = || plot.curves.iter().flat_map(|c| c.points.iter().filter(ok));
    let xs = log_range(all().map(|p| p.0));
    let ys = log_range(all().map(|p| p.1));
    let (x_decades, y_decades) = (decades(&xs), decades(&ys));
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(root)
        .caption(&plot.title, ("sans-serif", 18))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(80)
        .build_cartesian_2d(xs.clone().log_scale(), ys.log_scale())?;
    chart
        .configure_mesh()
        .x_desc(&plot.x_desc)
        .y_desc(&plot.y_desc)
        .label_style(("sans-serif", 18))
        .x_labels(40)
        .y_labels(40)
        .bold_line_style(BLACK.mix(0.12))
        .light_line_style(BLACK.mix(0.04))
        .axis_desc_style(("sans-serif", 18))
        .x_label_formatter(&|v| tick(*v, x_decades))
        .y_label_formatter(&|v| tick(*v, y_decades))
        .draw()?;
    for (i, curve) in plot.curves.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        let points: Vec<(f64, f64)> = curve.points.iter().filter(ok).copied().collect();
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(curve.label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart.draw_series(points.iter().map(|p| Circle::new(*p, 3, colour.filled())))?;
    }
    // A guide of slope −1/2 (Monte Carlo's rate) through the first curve's first point.
    if let Some(&(t0, e0)) = plot.curves.first().and_then(|c| c.points.iter().find(ok)) {
        let t1 = xs.end;
        let guide = vec![(t0, e0), (t1, e0 * (t1 / t0).powf(-0.5))];
        let grey = RGBColor(150, 150, 150);
        chart
            .draw_series(LineSeries::new(guide, grey.stroke_width(1)))?
            .label("slope -1/2")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
    }
    chart
        .configure_series_labels()
        .label_font(("sans-serif", 18))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    root.present()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_label_one_two_five_in_short_form() {
        assert_eq!(tick(0.001, 3.0), "0.001");
        assert_eq!(tick(0.002, 3.0), "0.002");
        assert_eq!(tick(0.003, 3.0), "");
        assert_eq!(tick(50.0, 3.0), "50");
        assert_eq!(tick(50.0, 6.0), "");
        assert_eq!(tick(100.0, 6.0), "100");
        assert_eq!(tick(1e-9, 12.0), "1e-9");
    }

    #[test]
    fn both_plots_are_written_and_the_png_has_text_and_curves() {
        let dir = tempfile::tempdir().expect("tmp");
        let plot = Plot {
            title: "test".into(),
            x_desc: "time (s)".into(),
            y_desc: "RMSE".into(),
            curves: vec![Curve {
                label: "path".into(),
                points: vec![(0.1, 1.0), (0.4, 0.5), (1.6, 0.25), (0.0, 9.0)],
            }],
        };
        let (svg, png) = (dir.path().join("p.svg"), dir.path().join("p.png"));
        write(&plot, &svg, &png).expect("written");
        let text = std::fs::read_to_string(&svg).expect("svg");
        assert!(text.starts_with("<svg") && text.contains("\npath\n") && text.contains("\nRMSE\n"));
        let img = image::open(&png).expect("png").into_rgb8();
        assert_eq!((img.width(), img.height()), SIZE);
        // The first curve is drawn in Palette99's first colour; black text is somewhere.
        let first = Palette99::pick(0).to_rgba();
        let has = |c: [u8; 3]| img.pixels().any(|p| p.0 == c);
        assert!(has([first.0, first.1, first.2]));
        assert!(has([0, 0, 0]));
    }
}
