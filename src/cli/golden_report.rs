//! What `caustic golden check` prints about one scene and the error image it writes; the
//! words and the statistics are the library's ([`caustic::render::golden::report`],
//! [`caustic::render::golden::batch_means`]).

use std::path::Path;

use image::Rgb;

use caustic::Error;
use caustic::render::golden::pixel_variance::pixel_z;
use caustic::render::golden::report;
use caustic::render::golden::{
    BatchBlocks, BatchVerdict, GoldenImage, GoldenMeta, GoldenTest, PixelEstimates,
};

use caustic::analysis::error_image::{self, ErrorScale};

/// A scene's verdict.
pub enum Outcome {
    /// The same scene within noise.
    Same,
    /// Changed beyond its noise (or no longer the golden's size).
    Changed,
}

/// The check's render of a scene.
pub struct Now<'a> {
    /// Per-pixel estimates (for the error image).
    pub estimates: &'a PixelEstimates,
    /// Block means per batch (for the test).
    pub batches: &'a BatchBlocks,
    /// Cell means per batch (for the structure test).
    pub cells: &'a BatchBlocks,
    /// What it was rendered from.
    pub meta: &'a GoldenMeta,
    /// Its settings hash computed with the golden's seed.
    pub hash_at_golden_seed: u64,
}

/// |z| drawn in the top colour of the error image.
const Z_MAX: f32 = 5.0;
/// Outline colour of the blocks that changed.
const OUTLINE: [u8; 3] = [255, 40, 40];
/// Blocks listed in the report.
const LISTED: usize = 8;
/// Changed settings listed in the report.
const SETTINGS_LISTED: usize = 12;

/// Prints the verdict for the scene at `path` and, for a changed one, writes its error image
/// into `error_dir`.
pub fn report(
    path: &Path,
    golden: &GoldenImage,
    now: &Now<'_>,
    test: &GoldenTest,
    error_dir: &Path,
) -> Result<Outcome, Error> {
    let name = path.display();
    if now.hash_at_golden_seed != golden.meta.hash {
        let diff = report::settings_diff_normalized(&golden.meta.settings, &now.meta.settings);
        if diff.is_empty() {
            println!(
                "{name}: the settings hash differs from the golden's but no scene field does: an asset file (mesh, texture) or the caustic version changed; comparing the pixels"
            );
        } else {
            println!(
                "{name}: {} since the golden was written (comparing the pixels all the same):",
                if diff.len() == 1 {
                    "1 setting changed".to_string()
                } else {
                    format!("{} settings changed", diff.len())
                }
            );
            for d in diff.iter().take(SETTINGS_LISTED) {
                println!("  {d}");
            }
            if diff.len() > SETTINGS_LISTED {
                println!("  … and {} more", diff.len() - SETTINGS_LISTED);
            }
        }
    }
    let g = &golden.estimates;
    if (g.width, g.height) != (now.estimates.width, now.estimates.height) {
        println!(
            "{name}: CHANGED: the golden is {}×{} but the render is {}×{}; the pixels cannot be compared (give --width/--height, or run `caustic golden update` again)",
            g.width, g.height, now.estimates.width, now.estimates.height
        );
        return Ok(Outcome::Changed);
    }
    let verdict = test
        .compare((&golden.batches, &golden.cells), (now.batches, now.cells))
        .map_err(|e| Error::Usage(format!("{name}: {e}")))?;
    let v = &verdict.blocks;
    let seeds = format!("seed {}, golden's {}", now.meta.seed, golden.meta.seed);
    if !verdict.changed() {
        println!(
            "{name}: same within noise ({}; {}; {seeds})",
            report::summary(v),
            report::structure_summary(&verdict.structure)
        );
        return Ok(Outcome::Same);
    }
    let changed = v.changed_blocks();
    let image = error_dir.join(format!(
        "{}.error.png",
        path.file_name()
            .map_or_else(|| "scene".into(), |n| n.to_string_lossy().into_owned())
    ));
    write_error_image(g, now.estimates, v, &image)?;
    let structure = verdict.structure.as_ref().ok().filter(|s| s.changed());
    let what = match (changed.len(), structure.is_some()) {
        (0, _) => "the pattern of light is beyond its noise".to_string(),
        (1, false) => "1 block is beyond its noise".to_string(),
        (n, false) => format!("{n} blocks are beyond their noise"),
        (1, true) => "1 block and the pattern of light are beyond their noise".to_string(),
        (n, true) => format!("{n} blocks and the pattern of light are beyond their noise"),
    };
    println!(
        "{name}: CHANGED: {what} ({seeds}); error image `{}`",
        image.display()
    );
    for line in report::changed_lines(v, LISTED) {
        println!("{line}");
    }
    if let Some(s) = structure {
        for line in report::structure_lines(s) {
            println!("{line}");
        }
    }
    Ok(Outcome::Changed)
}

/// The error image: each pixel's |z| in false colour (0 to 5), the changed blocks of the
/// finest scale outlined in red (a coarser block when only a coarser scale saw the change).
fn write_error_image(
    g: &PixelEstimates,
    now: &PixelEstimates,
    v: &BatchVerdict,
    path: &Path,
) -> Result<(), Error> {
    let z = pixel_z(g, now);
    let scale = ErrorScale {
        max: Z_MAX,
        source: "fixed",
    };
    let mut img = error_image::render_named(
        &z,
        g.width,
        g.height,
        scale,
        "|z| per pixel; red: changed blocks",
    );
    let k = error_image::zoom(g.width);
    let changed = v.changed_blocks();
    let finest = changed.iter().map(|(s, _)| *s).min().unwrap_or(0);
    for (_, b) in changed.iter().filter(|(s, _)| *s == finest) {
        let (x0, y0) = (b.x * k, b.y * k);
        let (x1, y1) = ((b.x + b.width) * k - 1, (b.y + b.height) * k - 1);
        for x in x0..=x1 {
            img.put_pixel(x, y0, Rgb(OUTLINE));
            img.put_pixel(x, y1, Rgb(OUTLINE));
        }
        for y in y0..=y1 {
            img.put_pixel(x0, y, Rgb(OUTLINE));
            img.put_pixel(x1, y, Rgb(OUTLINE));
        }
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::Usage(format!("cannot create `{}`: {e}", dir.display())))?;
    }
    error_image::write_png(&img, path)?;
    Ok(())
}
