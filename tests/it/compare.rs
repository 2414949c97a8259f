//! `caustic compare` (figures per channel, regions, JSON, the error image) and the golden-image
//! check `caustic render --compare REF --max-rmse X`. Expected figures are worked out by hand in
//! the comments.

use std::path::{Path, PathBuf};

use crate::common::caustic;

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Writes a linear EXR of `pixels` (row-major RGB).
fn exr(dir: &Path, name: &str, width: u32, pixels: &[[f32; 3]]) -> String {
    let height = pixels.len() as u32 / width;
    let flat: Vec<f32> = pixels.iter().flatten().copied().collect();
    let img = image::Rgb32FImage::from_raw(width, height, flat).expect("sizes agree");
    let path = dir.join(name);
    img.save(&path).expect("writes EXR");
    path.to_str().expect("utf8").to_string()
}

fn close(v: &serde_json::Value, expected: f64) -> bool {
    v.as_f64().is_some_and(|x| (x - expected).abs() < 1e-6)
}

/// A 3×1 test image and reference: differences (0.5, 0, −0.1), (0.2, −0.2, 0), (0, 0, 0).
fn pair(dir: &Path) -> (String, String) {
    let a = exr(
        dir,
        "a.exr",
        3,
        &[[1.0, 0.5, 0.0], [0.2, 0.2, 0.2], [3.0, 3.0, 3.0]],
    );
    let b = exr(
        dir,
        "b.exr",
        3,
        &[[0.5, 0.5, 0.1], [0.0, 0.4, 0.2], [3.0, 3.0, 3.0]],
    );
    (a, b)
}

#[test]
fn compare_reports_hand_computed_figures_per_channel_overall_and_over_a_region() {
    let dir = tempfile::tempdir().expect("tmp");
    let (a, b) = pair(dir.path());
    let out = caustic(&["compare", &a, &b, "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("JSON");
    let f = &v["figures"];
    // Nine channel values; squared differences sum to 0.25 + 0.01 + 0.04 + 0.04 = 0.34.
    assert!(close(&f["overall"]["rmse"], (0.34f64 / 9.0).sqrt()), "{f}");
    // |d| sums to 1.0, d to 0.4.
    assert!(close(&f["overall"]["mae"], 1.0 / 9.0), "{f}");
    assert!(close(&f["overall"]["bias"], 0.4 / 9.0), "{f}");
    // relMSE: 0.25/(0.25+0.01) + 0.04/(0+0.01) + 0.04/(0.16+0.01) + 0.01/(0.01+0.01) over 9.
    let rel = (0.25 / 0.26 + 4.0 + 0.04 / 0.17 + 0.5) / 9.0;
    assert!(close(&f["overall"]["rel_mse"], rel), "{f}");
    assert!(close(&f["overall"]["max_abs"], 0.5), "{f}");
    // Red alone: differences 0.5, 0.2, 0 → RMSE √(0.29 / 3), bias 0.7 / 3.
    assert!(close(&f["red"]["rmse"], (0.29f64 / 3.0).sqrt()), "{f}");
    assert!(close(&f["red"]["bias"], 0.7 / 3.0), "{f}");
    // Green: 0, −0.2, 0 → bias −0.2 / 3; blue: −0.1, 0, 0 → MAE 0.1 / 3.
    assert!(close(&f["green"]["bias"], -0.2 / 3.0), "{f}");
    assert!(close(&f["blue"]["mae"], 0.1 / 3.0), "{f}");
    assert_eq!(f["pixels"], 3);
    assert!(v["region"].is_null());

    // The middle pixel only: (0.2, −0.2, 0) → RMSE √(0.08 / 3), bias 0.
    let out = caustic(&["compare", &a, &b, "--json", "--region", "1,0,1,1"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("JSON");
    assert!(close(
        &v["figures"]["overall"]["rmse"],
        (0.08f64 / 3.0).sqrt()
    ));
    assert!(close(&v["figures"]["overall"]["bias"], 0.0));
    assert_eq!(v["region"], serde_json::json!([1, 0, 1, 1]));

    // Text: the first line keeps its old layout (scripts read fields 2 and 4), then a table.
    let out = caustic(&["compare", &a, &b]);
    let text = stdout(&out);
    let first: Vec<&str> = text
        .lines()
        .next()
        .unwrap_or_default()
        .split_whitespace()
        .collect();
    assert_eq!((first[0], first[2]), ("rmse", "relMSE"), "{text}");
    let rmse: f64 = first[1].parse().expect("number");
    assert!((rmse - (0.34f64 / 9.0).sqrt()).abs() < 1e-6, "{text}");
    assert!(text.lines().any(|l| l.starts_with("green")), "{text}");

    // A region outside the images is a usage error naming the size.
    let out = caustic(&["compare", &a, &b, "--region", "2,0,2,1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("3×1"), "{}", stderr(&out));
}

#[test]
fn the_error_image_maps_errors_through_its_labelled_scale() {
    let dir = tempfile::tempdir().expect("tmp");
    let (a, b) = pair(dir.path());
    let png = dir.path().join("err.png");
    let p = png.to_str().expect("utf8");
    // Per-pixel RMS errors: √(0.26/3) = 0.294, √(0.08/3) = 0.163, 0. With the scale fixed at
    // 0.294392 the first pixel is viridis' top (yellow) and the last its bottom (purple).
    let out = caustic(&[
        "compare",
        &a,
        &b,
        "--error-image",
        p,
        "--error-max",
        "0.294392",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("viridis from 0 to 0.294 (--error-max)"),
        "{}",
        stdout(&out)
    );
    let img = image::open(&png).expect("PNG").into_rgb8();
    // A 3-pixel-wide image is drawn 16× larger (the cap), then the colour bar and labels.
    assert!(
        stdout(&out).contains("each pixel drawn 16×16"),
        "{}",
        stdout(&out)
    );
    assert!(img.width() >= 48 && img.height() > 16 + 20);
    let (top, mid, zero) = (
        img.get_pixel(0, 0).0,
        img.get_pixel(16, 0).0,
        img.get_pixel(47, 15).0,
    );
    assert!(top[0] > 200 && top[1] > 200 && top[2] < 100, "{top:?}");
    assert!(zero[2] > zero[1] && zero[0] < 100, "{zero:?}");
    assert!(mid != top && mid != zero);
    // The default scale is the 99th percentile: here the largest error, so the same picture.
    let png2 = dir.path().join("err2.png");
    let out = caustic(&[
        "compare",
        &a,
        &b,
        "--error-image",
        png2.to_str().expect("utf8"),
    ]);
    assert!(
        stdout(&out).contains("0.294 (99th percentile)"),
        "{}",
        stdout(&out)
    );
    // Only PNG error images.
    let out = caustic(&["compare", &a, &b, "--error-image", "e.exr"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}

fn render(dir: &Path, name: &str, seed: &str, extra: &[&str]) -> (std::process::Output, PathBuf) {
    let path = dir.join(name);
    let mut args = vec![
        "render",
        "scenes/cornell.ron",
        "-o",
        path.to_str().expect("utf8"),
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "2",
        "--seed",
        seed,
        "--quiet",
    ];
    args.extend_from_slice(extra);
    (caustic(&args), path)
}

/// The RMSE printed by `render --compare` ("against `REF`: rmse X ...").
fn printed_rmse(out: &std::process::Output) -> f64 {
    let text = stdout(out);
    text.lines()
        .find_map(|l| l.split_once(": rmse ").map(|(_, r)| r.to_string()))
        .and_then(|r| r.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("no rmse in {text}"))
}

#[test]
fn render_compare_is_a_golden_image_check_with_exit_code_3() {
    let dir = tempfile::tempdir().expect("tmp");
    let (out, reference) = render(dir.path(), "ref.exr", "5", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let r = reference.to_str().expect("utf8");
    // Same seed and settings: the same image, RMSE exactly 0, so even --max-rmse 0 passes.
    let (out, _) = render(
        dir.path(),
        "same.exr",
        "5",
        &["--compare", r, "--max-rmse", "0"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(printed_rmse(&out), 0.0);
    // Another seed: noisy at 2 spp, so a tiny limit fails with code 3, the image still written,
    // and the printed RMSE is the one `caustic compare` gives for the written EXR.
    let (out, other) = render(
        dir.path(),
        "other.exr",
        "6",
        &["--compare", r, "--max-rmse", "1e-6"],
    );
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    assert!(stderr(&out).starts_with("error:") && stderr(&out).contains("--max-rmse"));
    assert!(other.exists());
    let got = printed_rmse(&out);
    let cmp = caustic(&["compare", other.to_str().expect("utf8"), r]);
    let line = stdout(&cmp);
    let expected: f64 = line
        .split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .expect("rmse");
    assert!(
        got > 0.0 && (got - expected).abs() <= 1e-6,
        "{got} {expected}"
    );
    // A limit above it passes.
    let limit = format!("{}", got * 1.01);
    let (out, _) = render(
        dir.path(),
        "o2.exr",
        "6",
        &["--compare", r, "--max-rmse", &limit],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // A region render is checked against the same region of a whole-image reference.
    let (out, _) = render(
        dir.path(),
        "crop.exr",
        "5",
        &["--region", "4,4,8,8", "--compare", r, "--max-rmse", "0"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // A missing reference fails before rendering, as bad input (2), writing nothing.
    let (out, path) = render(dir.path(), "none.exr", "5", &["--compare", "no_such.exr"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(!path.exists());
    // A reference of another size fails before rendering (2), writing nothing.
    let big = dir.path().join("big.exr");
    let out = caustic(&[
        "render",
        "scenes/cornell.ron",
        "-o",
        big.to_str().expect("utf8"),
        "--width",
        "17",
        "--height",
        "16",
        "--compare",
        r,
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("16×16") && err.contains("17×16"), "{err}");
    assert!(!big.exists());
    // --max-rmse needs --compare.
    let (out, _) = render(dir.path(), "x.exr", "5", &["--max-rmse", "1"]);
    assert_eq!(out.status.code(), Some(2));
}
