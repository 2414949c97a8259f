//! Deserialising a scene file: RON or TOML text into the schema, every error turned into a
//! located diagnostic that names the field path, what was found and what is valid. The helpers
//! both formats share live here; each format's error wording is in its own file.

mod ron;
mod toml;

use super::diagnostic::{Diagnostic, SourcePoint, did_you_mean, quoted_list};
use super::error::SceneError;
use super::lexer::{Tok, lex};
use super::locate::{Location, SourceFormat};
use super::schema::SceneFile;
use super::source::SourceFile;

impl SourceFile {
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
                SourceFormat::Ron => ron::parse(self),
                SourceFormat::Toml => toml::parse(self),
            }
        };
        result.map_err(|d| SceneError::Invalid(vec![*d]))
    }
}

/// The fields a scene must have at its top level (the rest have defaults).
pub(crate) const REQUIRED_TOP_LEVEL: [&str; 3] = ["camera", "materials", "nodes"];

/// "missing required field(s)" naming every required top-level field the file lacks (serde
/// stops at the first), or `field` alone if the index cannot tell.
fn missing_top_level(src: &SourceFile, field: &str) -> Diagnostic {
    let index = src.index();
    let mut missing: Vec<String> = REQUIRED_TOP_LEVEL
        .into_iter()
        .filter(|f| !index.contains(f))
        .map(|f| format!("`{f}`"))
        .collect();
    if !missing.contains(&format!("`{field}`")) {
        missing = vec![format!("`{field}`")];
    }
    let text = match missing.split_last() {
        Some((last, init)) if !init.is_empty() => {
            format!("missing required fields {} and {last}", init.join(", "))
        }
        _ => format!("missing required field `{field}`"),
    };
    Diagnostic::error("", text)
}

/// True for a message that is only what was expected (a serde `expecting` text such as "a
/// scale factor `s` or …", given when no variant of an untagged enum matched).
fn is_bare_expectation(msg: &str) -> bool {
    msg.starts_with("a ") || msg.starts_with("an ")
}

/// "expected <what>, found `<value>`" with the caret under the value (the enum's payload).
fn bare_expectation(src: &SourceFile, path: &str, what: &str) -> Diagnostic {
    let at = src.index().locate_payload(path).map(|l| (l.line, l.column));
    let found = at.map(|at| token_at(src, at)).unwrap_or_default();
    let text = if found.is_empty() {
        format!("expected {what}")
    } else {
        format!("expected {what}, found `{found}`")
    };
    place(src, Diagnostic::error(path, text), at)
}

/// The unknown field named by an "unknown field" diagnostic.
fn unknown_key(d: &Diagnostic) -> Option<String> {
    let rest = d.message.strip_prefix("unknown field `")?;
    Some(rest.split('`').next()?.to_string())
}

/// Positions a parse diagnostic at the parser's position when it has one, else at its path, and
/// names the named nodes on its path.
fn place(src: &SourceFile, diag: Diagnostic, at: Option<(usize, usize)>) -> Diagnostic {
    let diag = Diagnostic {
        path_label: named_path(src, &diag.path),
        ..diag
    };
    match at {
        Some((line, column)) if line > 0 => {
            let loc = Location {
                line,
                column: column.max(1),
                offset: 0,
            };
            Diagnostic {
                location: Some(SourcePoint::at(&src.path, &src.text, loc)),
                ..diag
            }
        }
        _ => diag.located(&src.path, &src.text, src.index()),
    }
}

/// `path` with the `name` of every node it passes through that has one, as the file spells it
/// (`nodes[2] "ball".radius`); `None` when no node on it is named.
fn named_path(src: &SourceFile, path: &str) -> Option<String> {
    if !path.starts_with("nodes[") {
        return None;
    }
    let (mut prefix, mut label, mut named) = (String::new(), String::new(), false);
    for (i, part) in path.split('.').enumerate() {
        if i > 0 {
            prefix.push('.');
            label.push('.');
        }
        prefix.push_str(part);
        label.push_str(part);
        let is_node = (part.starts_with("nodes[") || part.starts_with("children["))
            && part.ends_with(']')
            && part.matches('[').count() == 1;
        if let Some(name) = is_node
            .then(|| node_name(src, &format!("{prefix}.name")))
            .flatten()
        {
            label.push_str(&format!(" \"{name}\""));
            named = true;
        }
    }
    named.then_some(label)
}

/// The string written at `path`, if the file gives one there.
fn node_name(src: &SourceFile, path: &str) -> Option<String> {
    if !src.index().contains(path) {
        return None;
    }
    let at = src.index().locate(path)?.offset;
    let token = lex(src.text.get(at..)?, src.format).into_iter().next()?;
    match token.tok {
        Tok::Str(s) if s.terminated => Some(s.value),
        _ => None,
    }
}

fn line_chars(src: &SourceFile, line: usize) -> Vec<char> {
    src.text
        .lines()
        .nth(line.saturating_sub(1))
        .unwrap_or("")
        .chars()
        .collect()
}

/// Moves a position forward over whitespace (onto the next line if needed).
fn skip_space(src: &SourceFile, (mut line, mut col): (usize, usize)) -> (usize, usize) {
    let lines = src.text.lines().count();
    while line <= lines {
        let chars = line_chars(src, line);
        while col <= chars.len() && chars[col - 1].is_whitespace() {
            col += 1;
        }
        if col <= chars.len() {
            return (line, col);
        }
        line += 1;
        col = 1;
    }
    (line.min(lines.max(1)), col)
}

/// The token starting at a position (empty at the end of the file).
fn token_at(src: &SourceFile, (line, col): (usize, usize)) -> String {
    let chars = line_chars(src, line);
    let rest: String = chars.iter().skip(col.saturating_sub(1)).collect();
    let width = super::diagnostic::token_width(&rest);
    let token: String = rest.chars().take(width).collect();
    if token.chars().count() > 40 {
        format!("{}…", token.chars().take(40).collect::<String>())
    } else {
        token
    }
}

fn lower_first(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map_or_else(String::new, |f| f.to_lowercase().chain(c).collect())
}

/// `unknown field `x`, expected one of `a`, `b`` (serde) or `unexpected keys in table: x,
/// available keys: a, b` (toml) as an unknown-name diagnostic.
fn parse_unknown_name(msg: &str) -> Option<Diagnostic> {
    if let Some(rest) = msg.strip_prefix("unexpected keys in table: ") {
        let (found, available) = rest.split_once(", available keys: ")?;
        let found = found.split(',').next()?.trim();
        let expected: Vec<&str> = available
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .collect();
        return Some(unknown_name("field", found, &expected));
    }
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

/// serde's path (`nodes[0].Sphere.radius`) with enum variant names and unknown (`?`) segments
/// removed (`nodes[0].radius`): the form users write and the locator understands.
pub(crate) fn user_path(raw: &str) -> String {
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
    if raw == "." {
        return String::new();
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variant_names_are_dropped_from_paths() {
        assert_eq!(user_path("nodes[0].Sphere.radius"), "nodes[0].radius");
        assert_eq!(user_path("camera.Pinhole.fov_y"), "camera.fov_y");
        assert_eq!(user_path("materials.Sphere.ior"), "materials.Sphere.ior");
        assert_eq!(user_path("render.?"), "render");
        assert_eq!(user_path("."), "");
    }

    #[test]
    fn unknown_name_messages_are_parsed_in_both_wordings() {
        let d =
            parse_unknown_name("unknown field `albdo`, expected one of `color`, `albedo`").unwrap();
        assert!(d.message.contains("`albdo`"));
        assert_eq!(d.help.as_deref(), Some("did you mean `albedo`?"));
        let d =
            parse_unknown_name("unexpected keys in table: raduis, available keys: name, radius")
                .unwrap();
        assert!(
            d.message.starts_with("unknown field `raduis`"),
            "{}",
            d.message
        );
        assert_eq!(d.help.as_deref(), Some("did you mean `radius`?"));
    }

    #[test]
    fn required_top_level_fields_are_the_schemas() {
        let schema: serde_json::Value =
            serde_json::from_str(&super::super::schema::json_schema()).unwrap();
        let mut required: Vec<&str> = schema["required"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        required.sort_unstable();
        assert_eq!(required, REQUIRED_TOP_LEVEL);
    }
}
