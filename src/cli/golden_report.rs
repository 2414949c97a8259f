//! What `caustic golden check` says about one scene: which settings changed since the golden
//! was written, the verdict of the block test with its figures, the blocks that moved, and the
//! error image of a changed scene.

use std::path::Path;

use image::Rgb;
use serde_json::Value;

use caustic::Error;
use caustic::render::golden::block_test::pixel_z;
use caustic::render::golden::{BlockTest, GoldenImage, GoldenMeta, PixelEstimates, Verdict};
use caustic::scene::SceneFile;

use super::error_image::{self, ErrorScale};

/// A scene's verdict.
pub enum Outcome {
    /// The same scene within noise.
    Same,
    /// Changed beyond its noise (or no longer the golden's size).
    Changed,
}

/// |z| drawn in the top colour of the error image.
const Z_MAX: f32 = 5.0;
/// Outline colour of the blocks that moved.
const OUTLINE: [u8; 3] = [255, 40, 40];
/// Blocks listed in the report.
const LISTED: usize = 8;
/// Changed settings listed in the report.
const SETTINGS_LISTED: usize = 12;

/// The scene's settings as sorted `(path, value)` pairs: every field of the scene file after
/// overrides, arrays of numbers kept whole (`materials.red.color = [0.7,0.12,0.1]`), the seed
/// left out (a check renders with another one on purpose).
#[must_use]
pub fn settings(scene: &SceneFile) -> Vec<(String, String)> {
    let mut out = Vec::new();
    if let Ok(v) = serde_json::to_value(scene) {
        flatten(&v, String::new(), &mut out);
    }
    out.retain(|(k, _)| k != "render.seed");
    out.sort();
    out
}

fn flatten(v: &Value, path: String, out: &mut Vec<(String, String)>) {
    match v {
        Value::Object(map) => {
            for (k, x) in map {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                flatten(x, p, out);
            }
        }
        Value::Array(items) if items.iter().any(|x| x.is_object() || x.is_array()) => {
            for (i, x) in items.iter().enumerate() {
                flatten(x, format!("{path}[{i}]"), out);
            }
        }
        leaf => out.push((path, leaf.to_string())),
    }
}

/// The settings that differ: `path: golden → now` (or added/removed), sorted by path.
#[must_use]
pub fn settings_diff(golden: &[(String, String)], now: &[(String, String)]) -> Vec<String> {
    let find = |list: &[(String, String)], k: &str| {
        list.iter().find(|(p, _)| p == k).map(|(_, v)| v.clone())
    };
    let mut keys: Vec<&String> = golden.iter().chain(now).map(|(k, _)| k).collect();
    keys.sort();
    keys.dedup();
    keys.into_iter()
        .filter_map(|k| match (find(golden, k), find(now, k)) {
            (Some(a), Some(b)) if a != b => Some(format!("{k}: {a} → {b}")),
            (Some(a), None) => Some(format!("{k}: {a} → (none)")),
            (None, Some(b)) => Some(format!("{k}: (none) → {b}")),
            _ => None,
        })
        .collect()
}

/// Prints the verdict for the scene at `path` and, for a changed one, writes its error image
/// into `error_dir`.
pub fn report(
    path: &Path,
    golden: &GoldenImage,
    now: &PixelEstimates,
    meta: &GoldenMeta,
    hash_at_golden_seed: u64,
    test: &BlockTest,
    error_dir: &Path,
) -> Result<Outcome, Error> {
    let name = path.display();
    if hash_at_golden_seed != golden.meta.hash {
        let diff = settings_diff(&golden.meta.settings, &meta.settings);
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
    if (g.width, g.height) != (now.width, now.height) {
        println!(
            "{name}: CHANGED: the golden is {}×{} but the render is {}×{}; the pixels cannot be compared (give --width/--height, or run `caustic golden update` again)",
            g.width, g.height, now.width, now.height
        );
        return Ok(Outcome::Changed);
    }
    let v = test
        .compare(g, now)
        .map_err(|e| Error::Usage(format!("{name}: {e}")))?;
    let figures = figures(&v, golden.meta.seed, meta.seed);
    if !v.changed() {
        println!("{name}: same within noise ({figures})");
        return Ok(Outcome::Same);
    }
    let moved = v.moved();
    let image = error_dir.join(format!(
        "{}.error.png",
        path.file_name()
            .map_or_else(|| "scene".into(), |n| n.to_string_lossy().into_owned())
    ));
    write_error_image(g, now, &v, &image)?;
    println!(
        "{name}: CHANGED ({figures}); {} of {} blocks moved; error image `{}`",
        moved.len(),
        v.blocks.len(),
        image.display()
    );
    let listed = if moved.is_empty() {
        println!(
            "  no single block beyond the limit (the χ² or whole-image test saw a change spread over the image); the largest:"
        );
        v.largest(LISTED)
    } else {
        moved.into_iter().take(LISTED).collect()
    };
    for b in listed {
        println!(
            "  block at {},{} ({}×{}): z {:+.1} {:+.1} {:+.1}; golden {} → now {}",
            b.x,
            b.y,
            b.width,
            b.height,
            b.z[0],
            b.z[1],
            b.z[2],
            rgb(b.golden),
            rgb(b.test)
        );
    }
    Ok(Outcome::Changed)
}

fn rgb(c: [f64; 3]) -> String {
    format!("({:.4}, {:.4}, {:.4})", c[0], c[1], c[2])
}

/// The verdict's figures: the largest |z| against its limit, Σz² per channel against theirs.
fn figures(v: &Verdict, golden_seed: u64, seed: u64) -> String {
    let chi = (0..3)
        .map(|c| format!("{:.0}/{:.0}", v.chi2[c], v.chi2_limit[c]))
        .collect::<Vec<_>>()
        .join(" ");
    let image = v
        .image_z
        .iter()
        .map(|z| format!("{z:+.1}"))
        .collect::<Vec<_>>()
        .join(" ");
    format!(
        "max block |z| {:.2} of limit {:.2}; Σz² r g b {chi}; image z {image} of ±{:.2} ({} blocks of {}², α {}); seed {seed}, golden's {golden_seed}",
        v.max_abs_z(),
        v.z_limit,
        v.image_z_limit,
        v.blocks.len(),
        v.test.block,
        v.test.alpha
    )
}

/// The error image: each pixel's |z| in false colour (0 to 5), the blocks that moved outlined
/// in red.
fn write_error_image(
    g: &PixelEstimates,
    now: &PixelEstimates,
    v: &Verdict,
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
        "|z| per pixel; red: moved blocks",
    );
    let k = error_image::zoom(g.width);
    for b in v.moved() {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_flatten_to_paths_and_the_diff_names_what_changed() {
        let v: Value = serde_json::json!({
            "render": {"width": 64, "seed": 3},
            "lights": [{"Sphere": {"power": [45, 43, 39]}}],
        });
        let mut out = Vec::new();
        flatten(&v, String::new(), &mut out);
        out.sort();
        assert_eq!(
            out,
            vec![
                (
                    "lights[0].Sphere.power".to_string(),
                    "[45,43,39]".to_string()
                ),
                ("render.seed".into(), "3".into()),
                ("render.width".into(), "64".into()),
            ]
        );
        let mut now = out.clone();
        now[0].1 = "[40,43,39]".into();
        now.remove(1);
        now.push(("render.height".into(), "48".into()));
        assert_eq!(
            settings_diff(&out, &now),
            vec![
                "lights[0].Sphere.power: [45,43,39] → [40,43,39]".to_string(),
                "render.height: (none) → 48".into(),
                "render.seed: 3 → (none)".into(),
            ]
        );
    }
}
