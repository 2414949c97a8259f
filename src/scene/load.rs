//! Reading a scene file: RON or TOML by extension, deserialised into the schema with the field
//! path and file position of any error.

use std::cell::OnceCell;
use std::path::{Path, PathBuf};

use super::diagnostic::{Diagnostic, SourcePoint, did_you_mean, humanize, quoted_list};
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

impl std::fmt::Debug for SourceIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SourceIndex")
    }
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
        let text = String::from_utf8(bytes).map_err(|e| SceneError::Read {
            path: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("not UTF-8 text ({e})"),
            ),
        })?;
        Self::new(path, text)
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
        let result = match self.format {
            SourceFormat::Ron => self.parse_ron(),
            SourceFormat::Toml => self.parse_toml(),
        };
        result.map_err(|d| SceneError::Invalid(vec![*d]))
    }

    fn parse_ron(&self) -> Result<SceneFile, Box<Diagnostic>> {
        use ron::extensions::Extensions;
        let options = ron::Options::default().with_default_extension(
            Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        let mut de =
            ron::Deserializer::from_str_with_options(&self.text, &options).map_err(|e| {
                Box::new(self.syntax_error(
                    e.span.start.line,
                    e.span.start.col,
                    &e.code.to_string(),
                ))
            })?;
        match serde_path_to_error::deserialize::<_, SceneFile>(&mut de) {
            Ok(scene) => match de.end() {
                Ok(()) => Ok(scene),
                Err(code) => {
                    let e = de.span_error(code);
                    Err(Box::new(self.syntax_error(
                        e.span.start.line,
                        e.span.start.col,
                        &e.code.to_string(),
                    )))
                }
            },
            Err(err) => {
                let path = user_path(&err.path().to_string());
                let code = err.into_inner();
                let spanned = de.span_error(code.clone());
                let diag = match &code {
                    ron::Error::NoSuchStructField {
                        expected, found, ..
                    } => unknown_name("field", found, expected),
                    ron::Error::NoSuchEnumVariant {
                        expected, found, ..
                    } => unknown_name("variant", found, expected),
                    ron::Error::MissingStructField { field, .. } => {
                        Diagnostic::error(&path, format!("missing required field `{field}`"))
                    }
                    other => Diagnostic::error(&path, humanize(&other.to_string())),
                };
                let diag = Diagnostic { path, ..diag };
                Err(Box::new(self.place(
                    diag,
                    Some((spanned.span.start.line, spanned.span.start.col)),
                )))
            }
        }
    }

    fn parse_toml(&self) -> Result<SceneFile, Box<Diagnostic>> {
        let de = toml::Deserializer::parse(&self.text)
            .map_err(|e| Box::new(self.toml_error(&e, String::new())))?;
        serde_path_to_error::deserialize::<_, SceneFile>(de).map_err(|err| {
            let path = user_path(&err.path().to_string());
            Box::new(self.toml_error(err.inner(), path))
        })
    }

    fn toml_error(&self, e: &toml::de::Error, path: String) -> Diagnostic {
        let msg = humanize(e.message().trim());
        let diag = parse_unknown_name(&msg).unwrap_or_else(|| Diagnostic::error("", msg));
        let diag = Diagnostic { path, ..diag };
        let at = e
            .span()
            .map(|s| self.index().location_of_offset(s.start))
            .map(|l| (l.line, l.column));
        self.place(diag, at)
    }

    fn syntax_error(&self, line: usize, col: usize, msg: &str) -> Diagnostic {
        self.place(
            Diagnostic::error("", format!("syntax error: {msg}")),
            Some((line, col)),
        )
    }

    /// Positions a parse diagnostic: at the parser's position when it has one, else at the path.
    fn place(&self, diag: Diagnostic, at: Option<(usize, usize)>) -> Diagnostic {
        match at {
            Some((line, column)) if line > 0 => {
                let offset = 0;
                let loc = super::locate::Location {
                    line,
                    column: column.max(1),
                    offset,
                };
                Diagnostic {
                    location: Some(SourcePoint::at(&self.path, &self.text, loc)),
                    ..diag
                }
            }
            _ => diag.located(&self.path, &self.text, self.index()),
        }
    }
}

/// `unknown field `x`, expected one of `a`, `b`` in any wording serde or a format produces.
fn parse_unknown_name(msg: &str) -> Option<Diagnostic> {
    let kind = if msg.starts_with("unknown field") {
        "field"
    } else if msg.starts_with("unknown variant") {
        "variant"
    } else {
        return None;
    };
    let names: Vec<&str> = msg.split('`').skip(1).step_by(2).collect();
    let (found, expected) = names.split_first()?;
    Some(unknown_name(kind, found, expected))
}

fn unknown_name(kind: &str, found: &str, expected: &[&str]) -> Diagnostic {
    let list = if expected.is_empty() {
        "none".to_string()
    } else {
        quoted_list(expected.iter().copied())
    };
    let diag = Diagnostic::error(
        "",
        format!("unknown {kind} `{found}`; valid {kind}s here: {list}"),
    );
    match did_you_mean(found, expected.iter().copied()) {
        Some(s) => diag.with_help(format!("did you mean `{s}`?")),
        None => diag,
    }
}

/// serde's path (`nodes[0].Sphere.radius`) with enum variant names removed (`nodes[0].radius`),
/// the form users write and the locator understands.
pub(crate) fn user_path(raw: &str) -> String {
    if raw == "." {
        return String::new();
    }
    const VARIANTS: [&str; 12] = [
        "Pinhole",
        "Point",
        "Sphere",
        "Group",
        "Cube",
        "Quad",
        "Mesh",
        "Translate",
        "RotateX",
        "RotateY",
        "RotateZ",
        "Scale",
    ];
    let mut out: Vec<&str> = Vec::new();
    for seg in raw.split('.') {
        let is_map_key = out.last().is_some_and(|prev| *prev == "materials");
        if seg == "?" || (!is_map_key && VARIANTS.contains(&seg)) {
            continue;
        }
        out.push(seg);
    }
    out.join(".")
}

/// Reads and parses a scene file (no validation).
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    let source = SourceFile::read(path)?;
    let scene = source.parse()?;
    Ok(LoadedScene { source, scene })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variant_names_are_dropped_from_paths() {
        assert_eq!(user_path("nodes[0].Sphere.radius"), "nodes[0].radius");
        assert_eq!(user_path("camera.Pinhole.fov_y"), "camera.fov_y");
        assert_eq!(user_path("materials.glass.ior"), "materials.glass.ior");
        assert_eq!(user_path("."), "");
    }

    #[test]
    fn unknown_field_messages_are_parsed() {
        let d =
            parse_unknown_name("unknown field `albdo`, expected one of `color`, `albedo`").unwrap();
        assert!(d.message.contains("`albdo`"));
        assert_eq!(d.help.as_deref(), Some("did you mean `albedo`?"));
    }
}
