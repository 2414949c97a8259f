//! Every scene in `scenes/` rendered small (64×64, 8 spp) and checked against its golden image
//! (`tests/golden/<scene file>.golden`) by `caustic golden check` — the very command README
//! shows for a user's CI — **within noise**, not byte for byte: these are stochastic renders,
//! and a harmless change of random streams changes every pixel's noise but not what the image
//! shows. The check renders with a seed other than the golden's and judges the difference of
//! block means at every scale against the spread of both renders' batch means (each pass an
//! independent estimate; docs/golden.md), so there is no tolerance to tune. Exact bytes are still asserted elsewhere: across thread counts, regions
//! and passes (determinism.rs).
//!
//! On failure the error images are written beside the goldens (`<scene>.error.png`);
//! `UPDATE_SNAPSHOTS=1 cargo test --release --test it render_snapshots` renders the goldens
//! again (review the change first).

use caustic::render::golden::GoldenImage;

use crate::common;

#[test]
fn every_scene_matches_its_golden_image_within_noise() {
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
        let out = common::caustic(&[
            "golden",
            "update",
            "scenes/",
            "-o",
            "tests/golden/",
            "--width",
            "64",
            "--height",
            "64",
            "--spp",
            "8",
            "--quiet",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    for path in common::scene_files() {
        let name = path.file_name().and_then(|n| n.to_str()).expect("name");
        let golden = common::root().join(format!("tests/golden/{name}.golden"));
        let g = GoldenImage::read(&golden).unwrap_or_else(|e| panic!("{e}"));
        let mean = g
            .estimates
            .mean
            .iter()
            .map(|p| p.max_element())
            .sum::<f32>()
            / g.estimates.mean.len() as f32;
        assert!(mean > 0.01, "{name}: the golden image is black");
    }
    let out = common::caustic(&["golden", "check", "scenes/", "--golden", "tests/golden/"]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(!stderr.contains("NaN"), "{stderr}");
    let scenes = common::scene_files().len();
    assert!(
        stdout.contains(&format!("{scenes} of {scenes} scenes the same")),
        "{stdout}"
    );
}

#[test]
fn the_snapshot_check_catches_a_change_of_light_transport() {
    // Control: the same scene with its light 15% dimmer fails against its golden.
    let dir = tempfile::tempdir().expect("temp dir");
    let out = common::caustic(&[
        "golden",
        "check",
        "scenes/cornell.ron",
        "--golden",
        "tests/golden/",
        "--error-dir",
        dir.path().to_str().expect("utf-8"),
        "--set",
        "lights[0].power=[38.0, 36.5, 33.0]",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(3),
        "a 15% dimmer light passed: {stdout}"
    );
    assert!(dir.path().join("cornell.ron.error.png").is_file());
}
