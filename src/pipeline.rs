//! The whole front half of a run: read → override → validate → compile, with every diagnostic
//! located in the file (or attributed to the command line).

use std::path::Path;

use crate::compile::{CompileStats, compile};
use crate::error::Error;
use crate::render_scene::RenderScene;
use crate::scene::load::SourceFile;
use crate::scene::overrides::apply_overrides;
use crate::scene::validate::validate;
use crate::scene::{Diagnostic, SceneError, SceneFile};
use crate::settings::{IntegratorKind, SamplerKind};

/// Command-line changes to a scene: `--set` assignments and the dedicated render flags.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneOverrides {
    /// `path=value` assignments, applied first.
    pub sets: Vec<String>,
    /// `render.width`.
    pub width: Option<u32>,
    /// `render.height`.
    pub height: Option<u32>,
    /// `render.samples_per_pixel`.
    pub samples_per_pixel: Option<u32>,
    /// `render.max_depth`.
    pub max_depth: Option<u32>,
    /// `render.seed`.
    pub seed: Option<u64>,
    /// `render.integrator`.
    pub integrator: Option<IntegratorKind>,
    /// `render.sampler`.
    pub sampler: Option<SamplerKind>,
    /// `photons.caustic`, shared by power among all lights (their own `caustic_photons` are
    /// dropped).
    pub caustic_photons: Option<u32>,
}

impl SceneOverrides {
    /// Applies the overrides to a parsed scene.
    pub fn apply(&self, scene: &SceneFile) -> Result<SceneFile, SceneError> {
        let mut s = apply_overrides(scene, &self.sets)?;
        let r = &mut s.render;
        r.width = self.width.unwrap_or(r.width);
        r.height = self.height.unwrap_or(r.height);
        r.samples_per_pixel = self.samples_per_pixel.unwrap_or(r.samples_per_pixel);
        r.max_depth = self.max_depth.unwrap_or(r.max_depth);
        r.seed = self.seed.unwrap_or(r.seed);
        r.integrator = self.integrator.or(r.integrator);
        r.sampler = self.sampler.unwrap_or(r.sampler);
        if let Some(n) = self.caustic_photons {
            s.photons.caustic = n;
            for l in &mut s.lights {
                *l.caustic_photons_mut() = None;
            }
        }
        Ok(s)
    }

    /// Field paths these overrides change (diagnostics on them point at the command line).
    #[must_use]
    pub fn paths(&self) -> Vec<String> {
        let mut p: Vec<String> = self
            .sets
            .iter()
            .filter_map(|s| s.split_once('='))
            .map(|(k, _)| k.trim().to_string())
            .collect();
        for (flag, set) in [
            ("render.width", self.width.is_some()),
            ("render.height", self.height.is_some()),
            ("render.samples_per_pixel", self.samples_per_pixel.is_some()),
            ("render.max_depth", self.max_depth.is_some()),
            ("render.seed", self.seed.is_some()),
            ("render.integrator", self.integrator.is_some()),
            ("render.sampler", self.sampler.is_some()),
            ("photons.caustic", self.caustic_photons.is_some()),
        ] {
            if set {
                p.push(flag.to_string());
            }
        }
        p
    }
}

/// A scene ready to render.
#[derive(Debug)]
pub struct Prepared {
    /// The source file (for later diagnostics).
    pub source: SourceFile,
    /// The scene after overrides.
    pub scene: SceneFile,
    /// The compiled scene.
    pub render_scene: RenderScene,
    /// Compilation figures.
    pub stats: CompileStats,
    /// Warnings found on the way.
    pub warnings: Vec<Diagnostic>,
}

/// Reads, overrides and validates; returns the scene and its warnings, or all errors.
pub fn check(
    path: &Path,
    overrides: &SceneOverrides,
) -> Result<(SourceFile, SceneFile, Vec<Diagnostic>), Error> {
    let source = SourceFile::read(path)?;
    let parsed = source.parse()?;
    let scene = overrides.apply(&parsed)?;
    let diags = locate(&source, validate(&scene), overrides);
    if diags.iter().any(Diagnostic::is_error) {
        return Err(SceneError::Invalid(diags).into());
    }
    Ok((source, scene, diags))
}

/// Reads, overrides, validates and compiles a scene file.
pub fn prepare(path: &Path, overrides: &SceneOverrides) -> Result<Prepared, Error> {
    let (source, scene, warnings) = check(path, overrides)?;
    let (mut render_scene, mut stats) = compile(&scene, &source.base_dir())
        .map_err(|errs| SceneError::Invalid(locate(&source, errs, overrides)))?;
    keep_stated_photons(&mut render_scene, &scene, overrides);
    let mut warnings = warnings;
    warnings.extend(locate(
        &source,
        std::mem::take(&mut stats.warnings),
        overrides,
    ));
    Ok(Prepared {
        source,
        scene,
        render_scene,
        stats,
        warnings,
    })
}

/// The default estimator chooses its per-pass photon counts itself, but counts stated on the
/// command line (`--set photons.caustic=…`, `--caustic-photons`, `--photons`, `--gather`) are
/// per pass and win: they replace the chosen ones, and the summary says so.
fn keep_stated_photons(rs: &mut RenderScene, scene: &SceneFile, overrides: &SceneOverrides) {
    let Some(choice) = rs.params.default_estimator.as_mut() else {
        return;
    };
    if choice.photons.is_none() {
        return;
    }
    let stated = overrides.paths();
    let is_stated = |field: &str| stated.iter().any(|p| p == &format!("photons.{field}"));
    let p = &mut rs.params.photons;
    let mut any = false;
    for (field, value, from) in [
        ("caustic", &mut p.caustic, scene.photons.caustic),
        ("global", &mut p.global, scene.photons.global),
        (
            "caustic_gather",
            &mut p.caustic_gather,
            scene.photons.caustic_gather,
        ),
        ("gather", &mut p.gather, scene.photons.gather),
    ] {
        if is_stated(field) {
            *value = from;
            any = true;
        }
    }
    if any {
        choice.photons = None;
    }
}

fn locate(
    source: &SourceFile,
    diags: Vec<Diagnostic>,
    overrides: &SceneOverrides,
) -> Vec<Diagnostic> {
    let overridden = overrides.paths();
    let (from_cli, from_file): (Vec<_>, Vec<_>) = diags.into_iter().partition(|d| {
        overridden
            .iter()
            .any(|p| d.path == *p || d.path.starts_with(&format!("{p}.")))
    });
    let mut out = source.locate(from_file);
    out.extend(from_cli.into_iter().map(|mut d| {
        d.message.push_str(" (value set on the command line)");
        d
    }));
    out
}
