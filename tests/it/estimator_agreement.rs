//! `path-ppm` (the default estimator on scenes with a specular caster) and `path` (the
//! reference) render the same image within noise on every scene in `scenes/` (issue #24).
//!
//! The statistic is the golden test's block z-test (`caustic::render::golden::BlockTest`,
//! documented there): 8 × 8-pixel blocks, each block's mean difference over its standard error
//! from both films' per-pixel variances (their sums of squares), rejected at false-alarm rate
//! α = 0.01 by any of: the largest |z| over blocks and channels (Bonferroni), a channel's χ²
//! over blocks, or the whole image's mean z. `path-ppm` is consistent, not unbiased: its
//! caustic radius shrinks pass by pass, so what is checked is that its bias at these pass
//! counts is below the noise of a 64² image at 16 samples per pixel. `path` takes 128: its
//! per-pixel variance is estimated from its samples, and where it sees a small light through
//! water (a glint found once in ~1/F ≈ 30 samples) too few samples make that estimate far too
//! small (zero where no sample found it), which would reject the null on `path`'s account.
//!
//! `path-ppm` runs with the default estimator's per-pass budget for a 64² image (1 000 caustic
//! photons per pass, k = 10, no global map), not the scene's counts (sized for `photon`, which
//! traces once). Point, spot and distant lights emit no caustic photons here
//! (`caustic_photons: 0`), and distant lights are made delta (`angular_radius: 0`): the path
//! tracer never hits a point or a spot, and a sun's 0.27° disc (which escaping rays do see) so
//! rarely that 128 samples cannot estimate its caustics (light → water → floor from the bath's
//! sun would be missing from most of `path`'s pixels, present in `path-ppm`'s), so the test
//! compares the light both can carry. `tests/it/sun_caustic.rs` checks the sun's caustics of
//! both against a closed form, with a disc wide enough for `path`.

use std::path::Path;

use caustic::compile::compile;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::golden::{BlockTest, PixelEstimates};
use caustic::render::{RenderOptions, render};
use caustic::scene::schema::LightSpec;
use caustic::settings::IntegratorKind;

use crate::common::scene_files;

/// Scenes where the test does not hold today, each with what was measured (issue #24, open):
/// they are rendered and their figures printed, but not asserted. Every other scene must agree.
const KNOWN_DISAGREEMENTS: [(&str, &str); 1] = [(
    "blob.ron",
    "path-ppm's image mean is ~2.4 % below path's (image z ≈ −4) with 1 000 caustic photons \
     per pass. Located (5 December, path 2048 spp against path-ppm at 64², k = 10): the dark \
     8×8 blocks are the blobs' undersides, lit by the mirror-flecked floor, and the floor in \
     their contact shadows (0.85–0.90 of path at 256 passes). The image mean is 0.975 at 16 \
     passes, 0.982 at 256, 0.992 at 256 passes of 20 000 photons: the bias falls with the \
     radius as about r^0.6 (the pass radius shrinks by 1.6× from pass 16 to 256, the pilot's \
     by ~4.5× with 20× the photons), as a boundary bias does (discs reaching over the edges \
     of the lit region), not a blur (r²). Consistent, but slow at the default's fewest photons \
     per pass. Unresolved",
)];

#[test]
fn path_ppm_and_path_agree_within_noise_on_every_scene() {
    let mut failures = Vec::new();
    for file in scene_files() {
        let estimates = |integrator: IntegratorKind, spp: u32, seed: u64| {
            let overrides = SceneOverrides {
                render: caustic::scene::schema::RenderSettings {
                    width: Some(64),
                    height: Some(64),
                    samples_per_pixel: Some(spp),
                    seed: Some(seed),
                    integrator: Some(integrator),
                    ..Default::default()
                },
                ..SceneOverrides::default()
            };
            let p =
                prepare(&file, &overrides).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
            let mut scene = p.scene.clone();
            scene.photons.caustic = Some(1000);
            scene.photons.caustic_gather = Some(10);
            scene.photons.global = Some(0);
            for light in &mut scene.lights {
                match light {
                    LightSpec::Point {
                        caustic_photons, ..
                    }
                    | LightSpec::Spot {
                        caustic_photons, ..
                    }
                    | LightSpec::Distant {
                        caustic_photons, ..
                    } => *caustic_photons = Some(0),
                    LightSpec::Sphere { .. }
                    | LightSpec::Environment { .. }
                    | LightSpec::Sky { .. } => {}
                }
                if let LightSpec::Distant { angular_radius, .. } = light {
                    *angular_radius = 0.0;
                }
            }
            let base: &Path = &p.source.base_dir();
            let (render_scene, _) =
                compile(&scene, base).unwrap_or_else(|e| panic!("{}: {e:?}", file.display()));
            let out = render(&render_scene, &RenderOptions::default())
                .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
            PixelEstimates::from_sums(&out.sums)
        };
        let path = estimates(IntegratorKind::Path, 128, 101);
        let ppm = estimates(IntegratorKind::PathPpm, 16, 202);
        let v = BlockTest::default()
            .compare(&path, &ppm)
            .expect("same size");
        eprintln!(
            "{}: max |z| {:.2} (limit {:.2}), χ² {:.1?} / {:?} dof (limit {:.1?}), image z {:.2?}",
            file.display(),
            v.max_abs_z(),
            v.z_limit,
            v.chi2,
            v.dof,
            v.chi2_limit,
            v.image_z
        );
        let name = file
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        if let Some((_, why)) = KNOWN_DISAGREEMENTS.iter().find(|(n, _)| *n == name) {
            eprintln!("  known disagreement, not asserted: {why}");
        } else if v.changed() {
            failures.push(file.display().to_string());
        }
    }
    assert!(
        failures.is_empty(),
        "path-ppm differs from path on {failures:?}"
    );
}
