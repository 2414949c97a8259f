//! A scene file's text with its path and format, kept so diagnostics can quote it and find
//! positions in it (the type every stage of the front end passes around).

use std::cell::OnceCell;
use std::path::{Path, PathBuf};

use super::diagnostic::{Diagnostic, SourcePoint};
use super::error::SceneError;
use super::locate::{SourceFormat, SourceIndex};

/// A scene file's text, remembered so diagnostics can quote it.
#[derive(Debug)]
pub struct SourceFile {
    /// Path as given by the user.
    pub path: PathBuf,
    /// Full text.
    pub text: String,
    /// RON or TOML.
    pub format: SourceFormat,
    index: OnceCell<SourceIndex>,
}

impl SourceFile {
    /// Wraps already-read text; the format comes from the path's extension.
    pub fn new(path: &Path, text: String) -> Result<Self, SceneError> {
        let format = match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("ron") => SourceFormat::Ron,
            Some("toml") => SourceFormat::Toml,
            _ => {
                return Err(SceneError::UnknownFormat {
                    path: path.to_path_buf(),
                });
            }
        };
        Ok(Self {
            path: path.to_path_buf(),
            text,
            format,
            index: OnceCell::new(),
        })
    }

    /// Reads a file from disk.
    pub fn read(path: &Path) -> Result<Self, SceneError> {
        let bytes = std::fs::read(path).map_err(|source| SceneError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        match String::from_utf8(bytes) {
            Ok(text) => Self::new(path, text),
            Err(e) => Err(SceneError::Invalid(vec![not_utf8(
                path,
                e.as_bytes(),
                e.utf8_error(),
            )])),
        }
    }

    /// The path-to-position index of this text (built on first use).
    pub fn index(&self) -> &SourceIndex {
        self.index
            .get_or_init(|| SourceIndex::build(&self.text, self.format))
    }

    /// Attaches file positions to diagnostics that have a field path.
    #[must_use]
    pub fn locate(&self, diags: Vec<Diagnostic>) -> Vec<Diagnostic> {
        diags
            .into_iter()
            .map(|d| d.located(&self.path, &self.text, self.index()))
            .collect()
    }

    /// The directory asset paths are relative to.
    #[must_use]
    pub fn base_dir(&self) -> PathBuf {
        self.path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    }
}

/// A located diagnostic for a file that is not UTF-8 text.
fn not_utf8(path: &Path, bytes: &[u8], e: std::str::Utf8Error) -> Diagnostic {
    let at = e.valid_up_to();
    let before = String::from_utf8_lossy(&bytes[..at]);
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    let line_text = String::from_utf8_lossy(bytes)
        .lines()
        .nth(line - 1)
        .unwrap_or("")
        .to_string();
    let byte = bytes.get(at).copied().unwrap_or(0);
    Diagnostic {
        location: Some(SourcePoint {
            file: path.to_path_buf(),
            line,
            column,
            line_text,
            width: 1,
        }),
        ..Diagnostic::error(
            "",
            format!("the file is not UTF-8 text (byte 0x{byte:02X})"),
        )
        .with_help("save the scene file as UTF-8")
    }
}
