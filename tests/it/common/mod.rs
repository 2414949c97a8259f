//! Helpers shared by the integration tests.

#![allow(dead_code)]

pub mod json_schema;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use caustic::compile::compile;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::{Film, RenderOptions, RenderStats, render};
use caustic::render_scene::RenderScene;
use caustic::scene::SourceFile;
use caustic::scene::validate::validate;

/// The crate root (tests run with it as the working directory, but be explicit).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every scene file in `scenes/`, sorted.
pub fn scene_files() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("scenes"))
        .expect("scenes/ exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("ron" | "toml")))
        .collect();
    v.sort();
    v
}

/// Overrides for a small test render.
pub fn small(width: u32, height: u32, spp: u32) -> SceneOverrides {
    SceneOverrides {
        render: caustic::scene::schema::RenderSettings {
            width: Some(width),
            height: Some(height),
            samples_per_pixel: Some(spp),
            ..Default::default()
        },
        ..SceneOverrides::default()
    }
}

/// Loads, compiles and renders a scene through the library.
pub fn render_file(
    path: &Path,
    overrides: &SceneOverrides,
    options: &RenderOptions,
) -> (Film, RenderStats) {
    let prepared = prepare(path, overrides).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let out = render(&prepared.render_scene, options)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    (out.film, out.stats)
}

/// Runs the `caustic` binary with `args` from the crate root.
pub fn caustic(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("caustic runs")
}

/// Parses, validates (no errors allowed) and compiles a RON scene given as text.
pub fn scene_from_text(text: &str) -> RenderScene {
    let src = SourceFile::new(Path::new("inline.ron"), text.to_string()).expect("ron");
    let file = src.parse().unwrap_or_else(|e| panic!("{e}\n{text}"));
    let diags = validate(&file);
    assert!(!diags.iter().any(|d| d.is_error()), "{diags:?}");
    compile(&file, Path::new(".")).expect("compiles").0
}

/// Mean and standard error of the mean of `n` radiance estimates along `ray` by the scene's
/// integrator, drawn from the renderer's own streams (sample indices 0..n of pixel (0, 0));
/// every sample must be finite.
pub fn estimate_along(
    scene: &caustic::render_scene::RenderScene,
    ray: caustic::geometry::Ray,
    n: u32,
) -> (glam::DVec3, glam::DVec3) {
    let integrator = caustic::integrators::Integrator::prepare(scene);
    let (mean, se, _) = estimate_by(scene, n, |cx| integrator.li(ray, cx).as_dvec3());
    (mean, se)
}

/// Mean, standard error of the mean and per-sample variance of `n` estimates `li` makes from
/// the renderer's own streams (the scene's sampler and seed, sample indices 0..n of pixel
/// (0, 0)); every sample must be finite.
pub fn estimate_by(
    scene: &caustic::render_scene::RenderScene,
    n: u32,
    mut li: impl FnMut(
        &mut caustic::integrators::Context<'_, caustic::integrators::NoTrace>,
    ) -> glam::DVec3,
) -> (glam::DVec3, glam::DVec3, glam::DVec3) {
    use caustic::integrators::{Context, Counters, NoTrace};
    let p = &scene.params;
    let mut sampler = caustic::sampling::Sampler::new(p.sampler, p.seed, n);
    let mut counters = Counters::default();
    let (mut sum, mut sq) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
    for i in 0..n {
        sampler.start_pixel_sample(0, 0, i);
        let _ = sampler.pixel_2d();
        let l = li(&mut Context::new(&mut sampler, &mut counters, &mut NoTrace));
        assert!(l.is_finite(), "sample {i}: {l}");
        sum += l;
        sq += l * l;
    }
    let mean = sum / f64::from(n);
    let var = (sq / f64::from(n) - mean * mean).max(glam::DVec3::ZERO);
    (mean, (var / f64::from(n)).sqrt(), var)
}
