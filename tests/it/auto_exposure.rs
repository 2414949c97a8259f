//! The automatic exposure of 8-bit images (issue #43): at the defaults at most 1 % of the
//! pixels clip, on a sunlit outdoor scene (which clipped 82 % at today's exposure 1) and on a
//! dim one (which it brightens); a stated exposure passes through exactly as before. The
//! clipped pixels are counted in the PNG `caustic render` wrote (decoded by the `image` crate),
//! not by the code that chose the exposure.

use std::path::Path;

use caustic::render::output::to_srgb8;
use caustic::render::tonemap::{Display, Tonemap};

use crate::common;

/// The share of pixels with some channel at 255, and the median 8-bit luminance-ish value (the
/// median of each pixel's green channel), of a PNG file.
fn clipped_and_median(path: &Path) -> (f64, u8) {
    let img = image::open(path).expect("a readable PNG").into_rgb8();
    let n = (img.width() * img.height()) as usize;
    let clipped = img.pixels().filter(|p| p.0.contains(&255)).count();
    let mut green: Vec<u8> = img.pixels().map(|p| p.0[1]).collect();
    green.sort_unstable();
    (clipped as f64 / n as f64, green[n / 2])
}

/// Renders `scene` small with the given extra flags to `name` in `dir`; returns the PNG's path
/// and the command's stderr.
fn render(dir: &Path, scene: &str, name: &str, extra: &[&str]) -> (std::path::PathBuf, String) {
    let out = dir.join(name);
    let mut args = vec![
        "render",
        scene,
        "--width",
        "96",
        "--height",
        "72",
        "--spp",
        "2",
        "--threads",
        "2",
        "-o",
        out.to_str().expect("utf8"),
    ];
    args.extend_from_slice(extra);
    let o = common::caustic(&args);
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{scene}: {stderr}");
    (out, stderr)
}

#[test]
fn a_sunlit_pool_clips_at_most_one_percent_by_default() {
    let dir = tempfile::tempdir().expect("tmp");
    let scene = "benches/scenes/user/pool_noon.ron";
    let (auto, stderr) = render(dir.path(), scene, "auto.png", &[]);
    assert!(stderr.contains("(automatic: key 0.18"), "{stderr}");
    let (clipped, median) = clipped_and_median(&auto);
    assert!(clipped <= 0.01, "{clipped}");
    // Not made dark to get there: the middle pixel is a mid-tone.
    assert!((60..=220).contains(&median), "{median}");
    // Today's exposure 1 with the linear clip: most of the picture is white.
    let (today, _) = render(dir.path(), scene, "one.png", &["--exposure", "1"]);
    let (clipped_today, _) = clipped_and_median(&today);
    assert!(clipped_today > 0.5, "{clipped_today}");
}

#[test]
fn a_dim_scene_is_brightened_and_still_clips_at_most_one_percent() {
    let dir = tempfile::tempdir().expect("tmp");
    let scene = "benches/scenes/user/jewel.ron";
    let (auto, stderr) = render(dir.path(), scene, "auto.png", &[]);
    assert!(stderr.contains("(automatic: key 0.18"), "{stderr}");
    let (clipped, median) = clipped_and_median(&auto);
    assert!(clipped <= 0.01, "{clipped}");
    let (today, _) = render(dir.path(), scene, "one.png", &["--exposure", "1"]);
    let (_, median_today) = clipped_and_median(&today);
    assert!(
        median > median_today.saturating_add(30),
        "automatic {median}, exposure 1: {median_today}"
    );
}

/// A stated exposure (flag or scene) is today's display exactly: the PNG is the EXR of the same
/// render through exposure × the linear clip, byte for byte, and no automatic line is printed.
#[test]
fn a_stated_exposure_passes_through_exactly() {
    let dir = tempfile::tempdir().expect("tmp");
    let scene = "scenes/cornell.ron";
    // The raw estimate (`--no-denoise`), which the EXR holds.
    let (flag, stderr) = render(
        dir.path(),
        scene,
        "flag.png",
        &["--exposure", "0.7", "--no-denoise"],
    );
    assert!(!stderr.contains("automatic"), "{stderr}");
    let (set, _) = render(
        dir.path(),
        scene,
        "set.png",
        &["--set", "render.exposure=0.7", "--no-denoise"],
    );
    let (exr, _) = render(dir.path(), scene, "linear.exr", &[]);
    let film = caustic::analysis::metrics::read_film(&exr).expect("the EXR");
    let expected = to_srgb8(
        &film,
        Display {
            exposure: 0.7,
            tonemap: Tonemap::Linear,
        },
    );
    for png in [flag, set] {
        let got = image::open(&png).expect("PNG").into_rgb8();
        assert_eq!(
            got.into_raw(),
            expected.clone().into_raw(),
            "{}",
            png.display()
        );
    }
}
