//! Diagnostics: one problem in a scene file, with where it is and how to fix it, rendered like a
//! compiler message (file:line:column, the offending line, a caret under the value).

use std::fmt;
use std::path::{Path, PathBuf};

use super::lexer::{SourceFormat, lex};
use super::locate::{Location, SourceIndex};

/// How serious a diagnostic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Severity {
    /// The scene cannot be rendered.
    Error,
    /// The scene renders, but probably not as intended.
    Warning,
}

/// One problem found in a scene, before or after parsing.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// Field path such as `materials.water.ior` (empty when the problem is not tied to a field).
    pub path: String,
    /// What is wrong, including what was found and what is valid.
    pub message: String,
    /// An optional hint, such as a did-you-mean suggestion.
    pub help: Option<String>,
    /// Where in the file, when known.
    pub location: Option<SourcePoint>,
    /// How `path` is shown when it passes through named nodes (`nodes[2] "ball".radius`);
    /// `None`: as `path`.
    pub path_label: Option<String>,
}

/// A located excerpt of a source file.
#[derive(Debug, Clone, PartialEq)]
pub struct SourcePoint {
    /// The scene file.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column (characters).
    pub column: usize,
    /// The text of that line.
    pub line_text: String,
    /// How many characters the caret underlines.
    pub width: usize,
}

impl Diagnostic {
    /// An error at `path`.
    #[must_use]
    pub fn error(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            severity: Severity::Error,
            path: path.into(),
            message: message.into(),
            help: None,
            location: None,
            path_label: None,
        }
    }

    /// A warning at `path`.
    #[must_use]
    pub fn warning(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            severity: Severity::Warning,
            ..Self::error(path, message)
        }
    }

    /// Adds a hint.
    #[must_use]
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// True for errors.
    #[must_use]
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// Attaches the file position of `self.path`, found with `index` in `text`.
    #[must_use]
    pub fn located(mut self, file: &Path, text: &str, index: &SourceIndex) -> Self {
        if self.location.is_none()
            && !self.path.is_empty()
            && let Some(loc) = index.locate(&self.path)
        {
            self.location = Some(SourcePoint::at(file, text, loc));
        }
        self
    }
}

impl SourcePoint {
    /// The excerpt at `loc` in `text`, underlining the token that starts there.
    #[must_use]
    pub fn at(file: &Path, text: &str, loc: Location) -> Self {
        let line_text = text
            .lines()
            .nth(loc.line.saturating_sub(1))
            .unwrap_or("")
            .trim_end_matches('\r')
            .to_string();
        let rest: String = line_text
            .chars()
            .skip(loc.column.saturating_sub(1))
            .collect();
        Self {
            file: file.to_path_buf(),
            line: loc.line,
            column: loc.column,
            width: token_width(&rest),
            line_text,
        }
    }
}

/// Width of the value token at the start of `rest`: a bracketed group on one line, a string, or
/// a run of characters up to a delimiter.
pub(crate) fn token_width(rest: &str) -> usize {
    let mut chars = rest.chars();
    match chars.next() {
        None => 1,
        // A string, its escapes read by the lexer (the whole rest if it is never closed).
        Some('"') => lex(rest, SourceFormat::Ron)
            .first()
            .map_or(1, |t| rest[..t.end].chars().count()),
        Some(open @ ('(' | '[' | '{')) => {
            let close = match open {
                '(' => ')',
                '[' => ']',
                _ => '}',
            };
            let mut depth = 0usize;
            for (i, c) in rest.chars().enumerate() {
                if c == open {
                    depth += 1;
                } else if c == close {
                    depth -= 1;
                    if depth == 0 {
                        return i + 1;
                    }
                }
            }
            1
        }
        Some(_) => rest
            .chars()
            .take_while(|c| {
                !matches!(c, ',' | ')' | ']' | '}' | '(' | '[' | '{' | ':' | '=')
                    && !c.is_whitespace()
            })
            .count()
            .max(1),
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let label = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        if self.path.is_empty() {
            writeln!(f, "{label}: {}", self.message)?;
        } else {
            let path = self.path_label.as_deref().unwrap_or(&self.path);
            writeln!(f, "{label}: {}: {}", short_path(path), self.message)?;
        }
        if let Some(p) = &self.location {
            let num = p.line.to_string();
            let pad = " ".repeat(num.len());
            writeln!(f, "{pad}--> {}:{}:{}", p.file.display(), p.line, p.column)?;
            writeln!(f, "{pad} |")?;
            let (text, caret_col) = excerpt_window(&p.line_text, p.column);
            writeln!(f, "{num} | {text}")?;
            let lead: String = text
                .chars()
                .take(caret_col.saturating_sub(1))
                .map(|c| if c == '\t' { '\t' } else { ' ' })
                .collect();
            let room = text
                .chars()
                .count()
                .saturating_sub(caret_col.saturating_sub(1))
                .max(1);
            writeln!(f, "{pad} | {lead}{}", "^".repeat(p.width.clamp(1, room)))?;
        }
        if let Some(help) = &self.help {
            writeln!(f, "  = help: {help}")?;
        }
        Ok(())
    }
}

/// A field path shortened in the middle when it is very long (deeply nested groups).
fn short_path(path: &str) -> String {
    let chars: Vec<char> = path.chars().collect();
    if chars.len() <= 120 {
        return path.to_string();
    }
    let head: String = chars[..40].iter().collect();
    let tail: String = chars[chars.len() - 70..].iter().collect();
    format!("{head}…{tail}")
}

/// Longest excerpt shown; longer lines are cut to a window around the caret.
const EXCERPT_WIDTH: usize = 100;

/// A window of `line` around `column` no wider than [`EXCERPT_WIDTH`], and the column within it.
fn excerpt_window(line: &str, column: usize) -> (String, usize) {
    let chars: Vec<char> = line.chars().collect();
    if chars.len() <= EXCERPT_WIDTH + 20 {
        return (line.to_string(), column);
    }
    let start = column
        .saturating_sub(1)
        .saturating_sub(EXCERPT_WIDTH / 2)
        .min(chars.len());
    let end = (start + EXCERPT_WIDTH).min(chars.len());
    let mut text: String = chars[start..end].iter().collect();
    let mut col = column - start;
    if start > 0 {
        text.insert(0, '…');
        col += 1;
    }
    if end < chars.len() {
        text.push('…');
    }
    (text, col)
}

/// The closest of `candidates` to `found` by edit distance, if it is close enough to be a likely typo.
#[must_use]
pub fn did_you_mean<'a>(
    found: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    candidates
        .into_iter()
        .map(|c| (strsim::jaro_winkler(found, c), c))
        .filter(|(score, _)| *score > 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| c)
}

/// A file beside the missing `file` (in the folder it names, relative to `base_dir`) whose name
/// is close to its name by edit distance, written the way `file` is (its folder kept), if any.
#[must_use]
pub fn did_you_mean_file(base_dir: &Path, file: &str) -> Option<String> {
    let path = Path::new(file);
    let name = path.file_name()?.to_str()?;
    let folder = base_dir.join(path.parent().unwrap_or(Path::new("")));
    let mut names: Vec<String> = std::fs::read_dir(folder)
        .ok()?
        .filter_map(Result::ok)
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter_map(|e| e.file_name().into_string().ok())
        .collect();
    names.sort();
    let best = did_you_mean(name, names.iter().map(String::as_str))?;
    Some(match file.rfind(['/', '\\']) {
        Some(i) => format!("{}{best}", &file[..=i]),
        None => best.to_string(),
    })
}

/// Rewrites serde's Rust-flavoured wording (`expected f32`, `u32`, `a sequence`) for scene authors.
#[must_use]
pub fn humanize(msg: &str) -> String {
    [
        ("expected f32", "expected a number"),
        ("expected f64", "expected a number"),
        ("expected u32", "expected a whole number ≥ 0"),
        ("expected u64", "expected a whole number ≥ 0"),
        ("expected usize", "expected a whole number ≥ 0"),
        ("Expected float", "expected a number"),
        ("Expected integer", "expected a whole number"),
        ("a sequence", "a list"),
        ("missing field", "missing required field"),
    ]
    .iter()
    .fold(msg.to_string(), |m, (from, to)| m.replace(from, to))
}

/// Formats a list of names as `` `a`, `b`, `c` ``.
#[must_use]
pub fn quoted_list<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    names
        .into_iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggestions_pick_close_names_only() {
        assert_eq!(
            did_you_mean("albdo", ["color", "albedo", "ior"]),
            Some("albedo")
        );
        assert_eq!(did_you_mean("glas", ["glass", "mirror"]), Some("glass"));
        assert_eq!(did_you_mean("zzz", ["glass", "mirror"]), None);
    }

    #[test]
    fn missing_files_are_matched_against_their_folder() {
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::create_dir(dir.path().join("assets")).expect("folder");
        for name in ["wood.png", "water.png", "boat.obj"] {
            std::fs::write(dir.path().join("assets").join(name), b"").expect("file");
        }
        std::fs::write(dir.path().join("wod.png"), b"").expect("file");
        let near = |f: &str| did_you_mean_file(dir.path(), f);
        assert_eq!(near("assets/wodo.png").as_deref(), Some("assets/wood.png"));
        assert_eq!(near("assets/bot.obj").as_deref(), Some("assets/boat.obj"));
        // Only the folder the path names counts, and a far name gets nothing.
        assert_eq!(near("wood.png").as_deref(), Some("wod.png"));
        assert_eq!(near("assets/zzzzzz.tga"), None);
        assert_eq!(near("nowhere/wood.png"), None);
    }

    #[test]
    fn token_widths() {
        assert_eq!(token_width("-1.33),"), 5);
        assert_eq!(token_width("\"wat\\\"r\", x"), 8);
        assert_eq!(token_width("(1, (2), 3) x"), 11);
        assert_eq!(token_width(""), 1);
    }
}
