//! Every scene in `scenes/` rendered small (64×64, 4 spp) and compared with its reviewed image
//! (`tests/it/snapshots/render/<scene>_<ext>.png`) **within a tolerance**, not byte for byte:
//! these are stochastic renders, and a harmless change of random streams (a new sampler, a
//! different lobe choice) changes every pixel's noise but not what the image shows. The test
//! compares the means of 8×8-pixel blocks (256 samples each), which noise barely moves but
//! a change of light transport (a missing η², a leak, a black object) does. Exact bytes are
//! still asserted elsewhere: across thread counts, regions and passes (determinism.rs).
//!
//! On failure the new render is written beside the old as `<scene>_<ext>.new.png` for review;
//! `UPDATE_SNAPSHOTS=1 cargo test --release --test it render_snapshots` accepts all.

use std::path::PathBuf;

use glam::Vec3;

use crate::common;

use caustic::analysis::metrics::read_film;
use caustic::render::output::write_image;
use caustic::render::{Film, RenderOptions};

/// Block size in pixels.
const BLOCK: u32 = 8;

/// Largest allowed difference of a block's mean per channel: absolute plus relative to the
/// reference (linear radiance). Measured: switching the camera's sampler (independent to
/// Owen-scrambled Sobol) moves block means by at most ~0.01 + 3%.
fn tolerance(reference: f32) -> f32 {
    0.015 + 0.06 * reference
}

fn block_means(f: &Film) -> Vec<Vec3> {
    let mut out = Vec::new();
    for by in 0..f.height / BLOCK {
        for bx in 0..f.width / BLOCK {
            let mut s = Vec3::ZERO;
            for y in 0..BLOCK {
                for x in 0..BLOCK {
                    s += f.get(bx * BLOCK + x, by * BLOCK + y).min(Vec3::ONE);
                }
            }
            out.push(s / (BLOCK * BLOCK) as f32);
        }
    }
    out
}

/// The worst block difference beyond tolerance (≤ 0 when within), and where.
fn worst_block(film: &Film, reference: &Film) -> (f32, usize) {
    let (a, b) = (block_means(film), block_means(reference));
    let mut worst = (f32::MIN, 0);
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        for c in 0..3 {
            let excess = (x[c] - y[c]).abs() - tolerance(y[c]);
            if excess > worst.0 {
                worst = (excess, i);
            }
        }
    }
    worst
}

#[test]
fn every_scene_matches_its_snapshot_within_noise() {
    let update = std::env::var_os("UPDATE_SNAPSHOTS").is_some();
    let dir = common::root().join("tests/it/snapshots/render");
    let mut failures = Vec::new();
    for path in common::scene_files() {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("scene")
            .replace('.', "_");
        let options = RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        };
        let (film, stats) = common::render_file(&path, &common::small(64, 64, 4), &options);
        assert_eq!(stats.nan_samples, 0, "{}: NaN/Inf samples", path.display());
        assert!(
            film.mean().max_element() > 0.01,
            "{}: image is black",
            path.display()
        );
        let snap: PathBuf = dir.join(format!("{name}.png"));
        if update {
            write_image(&film, &snap, 1.0).expect("snapshot written");
            continue;
        }
        let reference = read_film(&snap).unwrap_or_else(|e| {
            panic!(
                "{}: no snapshot ({e}); run with UPDATE_SNAPSHOTS=1",
                snap.display()
            )
        });
        // Compare against what an 8-bit PNG of this render would hold, like with like.
        let tmp = dir.join(format!("{name}.new.png"));
        write_image(&film, &tmp, 1.0).expect("png written");
        let ours = read_film(&tmp).expect("png reads");
        let (excess, block) = worst_block(&ours, &reference);
        if excess > 0.0 {
            failures.push(format!(
                "{name}: block {block} off by {excess} beyond tolerance (new image: {})",
                tmp.display()
            ));
        } else {
            let _ = std::fs::remove_file(&tmp);
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn the_snapshot_comparison_catches_a_change_of_light_transport() {
    // Control: the same scene with its light 15% dimmer, or with one object gone, fails.
    let path = common::root().join("scenes/cornell.ron");
    let opts = RenderOptions::default();
    let (a, _) = common::render_file(&path, &common::small(64, 64, 4), &opts);
    let mut dim = common::small(64, 64, 4);
    dim.sets = vec!["lights[0].power=[38.0, 36.5, 33.0]".into()];
    let (b, _) = common::render_file(&path, &dim, &opts);
    assert!(worst_block(&b, &a).0 > 0.0, "a 15% dimmer light passed");
    let mut other_seed = common::small(64, 64, 4);
    other_seed.seed = Some(12345);
    let (c, _) = common::render_file(&path, &other_seed, &opts);
    assert!(
        worst_block(&c, &a).0 <= 0.0,
        "another seed failed: {:?}",
        worst_block(&c, &a)
    );
}
