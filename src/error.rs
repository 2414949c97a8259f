//! The crate's top-level error and the process exit codes it maps to.

use crate::render::RenderError;
use crate::render::output::OutputError;
use crate::scene::SceneError;

/// Anything that can stop a command.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene file (or an override) is unreadable or invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The render could not run with the given options.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The image could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// A command-line value (or a file it names) is unusable. The message is bare: its
    /// `error: ` prefix is added here, in one place, by the error's text.
    #[error("error: {0}")]
    Usage(String),
    /// The run was interrupted (Ctrl-C); the message says what, if anything, was kept.
    #[error("{0}")]
    Interrupted(String),
    /// A golden-image check failed: the image is further from its reference than allowed
    /// (`render --compare REF --max-rmse X`); the image was still written. The message is bare,
    /// as [`Error::Usage`]'s.
    #[error("error: {0}")]
    Mismatch(String),
}

impl Error {
    /// Exit code: 2 for bad input (scene, assets, flags), 1 for failures while rendering or
    /// writing, 3 when a golden-image check fails, 130 (128 + SIGINT) when interrupted.
    #[must_use]
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Interrupted(_) | Error::Render(RenderError::Cancelled) => 130,
            Error::Scene(_) | Error::Usage(_) | Error::Render(_) => 2,
            Error::Output(OutputError::UnknownFormat { .. } | OutputError::Unwritable { .. }) => 2,
            Error::Output(_) => 1,
            Error::Mismatch(_) => 3,
        }
    }
}
