//! Why a scene could not be used: the file could not be read, its format is unknown, or it has
//! errors (every diagnostic found).

use std::path::PathBuf;

use super::diagnostic::Diagnostic;

/// Why a scene could not be loaded, validated or compiled.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read scene file `{}`: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The extension is neither `.ron` nor `.toml`.
    #[error("cannot tell the format of `{}`: the scene file must end in `.ron` or `.toml`", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// Syntax, type or semantic errors, all of them.
    #[error("{}", render_all(.0))]
    Invalid(Vec<Diagnostic>),
}

fn render_all(diags: &[Diagnostic]) -> String {
    let errors = diags.iter().filter(|d| d.is_error()).count();
    let mut s: String = diags.iter().map(|d| format!("{d}\n")).collect();
    s.push_str(&format!(
        "{errors} error{} found",
        if errors == 1 { "" } else { "s" }
    ));
    s
}
