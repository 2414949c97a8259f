//! The page's save (`s`): writes the image so far the way `caustic render -o` writes its
//! output (PNG or EXR; with `--layers` EXR channels or PNG pictures beside the image; or the
//! mergeable `.part` film), atomically, and runs `--compare` on it. The bytes equal those of
//! `caustic render` for the same samples (`--samples 0..N`, N the samples per pixel taken when
//! saving), since passes add up exactly.

use std::time::Instant;

use caustic::farm::PartMeta;
use caustic::farm::part_meta::settings_hash;
use caustic::pipeline::Prepared;
use caustic::render::output::write_image;
use caustic::render::tonemap::Display;
use caustic::render::{RenderJob, write_with_layers};

use super::Settings;

/// Saves the samples `job` has taken so far; the message for the page, or why nothing (or not
/// all) was saved. `first` is the render's first sample index (`--samples`, `--shard`; else 0)
/// and `start` when its passes began.
pub fn save(
    settings: &Settings,
    prepared: &Prepared,
    job: &RenderJob<'_>,
    first: u32,
    start: Instant,
) -> Result<String, String> {
    let s = &settings.save;
    let output = &s.output;
    let sums = job.sums();
    let end = job.samples_done();
    if end == first {
        return Err("not saved: no pass has finished yet".into());
    }
    let p = &prepared.render_scene.params;
    let display = Display {
        exposure: p.exposure,
        tonemap: p.tonemap,
    };
    let written = if s.part {
        let scene = &prepared.render_scene;
        let meta = PartMeta {
            scene: settings.scene.display().to_string(),
            shard: settings.shard.map(|s| s.to_string()),
            seconds: start.elapsed().as_secs_f64(),
            ..PartMeta::of(
                scene,
                settings_hash(scene),
                first..end,
                p.samples_per_pixel,
                settings.region,
            )
        };
        sums.write(output, &meta.to_text())
    } else if !s.layers.is_empty() {
        write_with_layers(sums, job.parts(), &s.layers, output, display)
    } else {
        write_image(&job.snapshot(), output, display)
    };
    written.map_err(|e| format!("not saved: {e}"))?;
    let saved = |name: &dyn std::fmt::Display| {
        format!(
            "saved `{name}`: samples {first}..{end} ({} of {} per pixel)",
            end - first,
            p.samples_per_pixel
        )
    };
    eprintln!("{}", saved(&output.display()));
    // The page (and `/status`) shows the file's name, not the folder it is in.
    let name = output.file_name().map_or_else(
        || output.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let mut message = saved(&name);
    if let Some(reference) = &s.reference {
        let checked = super::super::max_rmse::check(
            reference,
            &job.snapshot(),
            output,
            p.exposure,
            settings.region,
            s.max_rmse,
        );
        if let Err(e) = checked {
            let text = crate::error_text(&e);
            eprintln!("{text}");
            message.push('\n');
            message.push_str(&text);
        }
    }
    Ok(message)
}
