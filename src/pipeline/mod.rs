//! The whole front half of a run: read → override → validate → compile, with every diagnostic
//! located in the file (or attributed to the command line); and, on top of every other layer,
//! the library halves of the binary's commands, which a program using caustic as a crate can
//! call: [`render`] (a render request through its phases to the written output, which
//! [`rendered`] reports), [`golden`]
//! (golden images rendered, searched for a detection floor, checked), [`farm_plan`] (a farm
//! plan's scene and its resolved copy), and [`flags`] (the dedicated flags an override set
//! states, for the records that apply them again).

pub mod farm_plan;
pub mod flags;
pub mod golden;
pub mod render;
pub mod rendered;

use std::path::Path;

use crate::Error;
use crate::compile::{CompileStats, compile_with};
use crate::render_scene::RenderScene;
use crate::scene::load::SourceFile;
use crate::scene::overrides::apply_overrides;
use crate::scene::schema::{PhotonSettings, RenderSettings};
use crate::scene::validate::validate;
use crate::scene::{Diagnostic, SceneError, SceneFile};

/// Command-line changes to a scene: `--set` assignments and the dedicated render flags, the
/// latter as layers of the scene's own settings structs (only the fields the command line
/// states are `Some`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneOverrides {
    /// `path=value` assignments, applied first.
    pub sets: Vec<String>,
    /// `render` fields the flags state (`--width`, `--spp`, `--integrator`, …).
    pub render: RenderSettings,
    /// `photons` fields the flags state. A stated `caustic` (`--caustic-photons`) is shared by
    /// power among all lights: their own `caustic_photons` are dropped.
    pub photons: PhotonSettings,
}

impl SceneOverrides {
    /// Applies the overrides to a parsed scene: the assignments, then the flags' layers over
    /// the file's settings.
    pub fn apply(&self, scene: &SceneFile) -> Result<SceneFile, SceneError> {
        let mut s = apply_overrides(scene, &self.sets)?;
        s.render = self.render.or(&s.render);
        s.photons = self.photons.or(&s.photons);
        if self.photons.caustic.is_some() {
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
        p.extend(self.render.stated().iter().map(|f| format!("render.{f}")));
        p.extend(self.photons.stated().iter().map(|f| format!("photons.{f}")));
        p
    }

    /// The photon settings the command line stated, read from `applied` (the scene's photon
    /// settings after [`SceneOverrides::apply`]): the fields named by a flag or a
    /// `--set photons.FIELD=…`.
    #[must_use]
    pub fn stated_photons(&self, applied: &PhotonSettings) -> PhotonSettings {
        let paths = self.paths();
        applied.only(|field| paths.iter().any(|p| *p == format!("photons.{field}")))
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
    let command_line = overrides.stated_photons(&scene.photons);
    let (render_scene, mut stats) = compile_with(&scene, &command_line, &source.base_dir())
        .map_err(|errs| SceneError::Invalid(locate(&source, errs, overrides)))?;
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
