//! `--target-error X` (issue #43): the render stops by itself once its estimated relMSE is at
//! most X, and the image it stops with is scored against an independent long render of the
//! same scene: its true relMSE must be within a factor of X (the estimate ignores the
//! Sobol sampler's stratification, which makes it pessimistic, so the true error is expected
//! below X; the bound checked is [X / 4, 1.3 X]).

use caustic::analysis::metrics::{compare, read_film};
use caustic::render::{RenderOptions, render};

use crate::common;

#[test]
fn a_target_error_render_stops_and_its_true_error_is_near_the_target() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().join("t.exr");
    // `scenes/lights.ron` is path traced (the scene names `path`): every light kind at once.
    let (w, h, target) = (40u32, 30u32, 0.02f64);
    let o = common::caustic(&[
        "render",
        "scenes/lights.ron",
        "--width",
        &w.to_string(),
        "--height",
        &h.to_string(),
        "--threads",
        "2",
        "--target-error",
        &target.to_string(),
        "-o",
        out.to_str().expect("utf8"),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let line = stderr
        .lines()
        .find(|l| l.starts_with("target error 0.02: reached"))
        .unwrap_or_else(|| panic!("no stop line: {stderr}"));
    let spp: u32 = line
        .split(" at ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    // It stopped by itself, long before the sample cap (2²⁰).
    assert!((4..4096).contains(&spp), "{line}");
    let test = read_film(&out).expect("the EXR");

    // The reference: 4096 samples per pixel of the same scene, another seed.
    let mut overrides = common::small(w, h, 4096);
    overrides.render.seed = Some(99);
    let prepared =
        caustic::pipeline::prepare(&common::root().join("scenes/lights.ron"), &overrides)
            .expect("lights prepares");
    let reference = render(
        &prepared.render_scene,
        &RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        },
    )
    .expect("reference")
    .film;
    let true_rel = compare(&test, &reference)
        .expect("same size")
        .overall()
        .rel_mse;
    assert!(
        true_rel <= 1.3 * target && true_rel >= target / 4.0,
        "true relMSE {true_rel} against the target {target} ({line})"
    );
}
