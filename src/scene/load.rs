//! Reading a scene file: RON or TOML by extension, deserialised into the schema with the field
//! path and file position of any error.

use std::cell::OnceCell;
use std::path::{Path, PathBuf};

use super::diagnostic::{Diagnostic, SourcePoint};
use super::locate::{SourceFormat, SourceIndex};
use super::schema::SceneFile;

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

/// A parsed (not yet validated) scene with its source.
#[derive(Debug)]
pub struct LoadedScene {
    /// Where it came from.
    pub source: SourceFile,
    /// The typed scene.
    pub scene: SceneFile,
}

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

    /// Deserialises the text into the schema.
    pub fn parse(&self) -> Result<SceneFile, SceneError> {
        let result = if self.text.trim().is_empty() {
            Err(Box::new(Diagnostic::error(
                "",
                format!(
                    "`{}` is empty; a scene needs at least `camera`, `materials` and `nodes`",
                    self.path.display()
                ),
            )))
        } else {
            match self.format {
                SourceFormat::Ron => super::parse::parse_ron(self),
                SourceFormat::Toml => super::parse::parse_toml(self),
            }
        };
        result.map_err(|d| SceneError::Invalid(vec![*d]))
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

/// Reads and parses a scene file (no validation).
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    let source = SourceFile::read(path)?;
    let scene = source.parse()?;
    Ok(LoadedScene { source, scene })
}
