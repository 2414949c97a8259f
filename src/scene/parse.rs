//! Format-specific deserialisation: RON and TOML errors turned into located diagnostics that
//! name the field path, what was found and what is valid.

use super::diagnostic::{Diagnostic, SourcePoint, did_you_mean, humanize, quoted_list};
use super::load::SourceFile;
use super::locate::Location;
use super::schema::SceneFile;

/// RON nesting limit: deep enough for the maximum group nesting, shallow enough for the stack.
const RON_RECURSION_LIMIT: usize = 512;

/// Deserialises RON text.
pub(super) fn parse_ron(src: &SourceFile) -> Result<SceneFile, Box<Diagnostic>> {
    use ron::extensions::Extensions;
    let options = ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES)
        .with_recursion_limit(RON_RECURSION_LIMIT);
    let mut de = ron::Deserializer::from_str_with_options(&src.text, &options).map_err(|e| {
        Box::new(ron_error(
            src,
            &e.code,
            "",
            (e.span.start.line, e.span.start.col),
        ))
    })?;
    match serde_path_to_error::deserialize::<_, SceneFile>(&mut de) {
        Ok(scene) => match de.end() {
            Ok(()) => Ok(scene),
            Err(code) => {
                let e = de.span_error(code);
                let at = skip_space(src, (e.span.start.line, e.span.start.col));
                let token = token_at(src, at);
                let d = Diagnostic::error(
                    "",
                    format!("unexpected `{token}` after the end of the scene"),
                );
                Err(Box::new(place(src, d, Some(at))))
            }
        },
        Err(err) => {
            let path = user_path(&err.path().to_string());
            let code = err.into_inner();
            let e = de.span_error(code.clone());
            Err(Box::new(ron_error(
                src,
                &code,
                &path,
                (e.span.start.line, e.span.start.col),
            )))
        }
    }
}

fn ron_error(src: &SourceFile, code: &ron::Error, path: &str, at: (usize, usize)) -> Diagnostic {
    use ron::Error as E;
    let d = |msg: String| Diagnostic::error(path, msg);
    let diag = match code {
        E::NoSuchStructField {
            expected, found, ..
        } => unknown_name("field", found, expected),
        E::NoSuchEnumVariant {
            expected, found, ..
        } => unknown_name("variant", found, expected),
        E::MissingStructField { field, .. } => d(format!("missing required field `{field}`")),
        E::DuplicateStructField { field, .. } => d(format!("field `{field}` is given twice")),
        E::ExceededRecursionLimit => d(format!(
            "values are nested more than {RON_RECURSION_LIMIT} levels deep; groups may nest at most {} levels",
            super::validate::MAX_NESTING
        )),
        E::ExpectedComma
            if follows_digit(src, at) && token_at(src, at).starts_with(['.', 'e', 'E']) =>
        {
            let start = number_start(src, at);
            let number = token_at(src, start);
            let path = match key_before(src, start) {
                Some(key) if path.is_empty() => key,
                Some(key) => format!("{path}.{key}"),
                None => path.to_string(),
            };
            let diag =
                Diagnostic::error(path, format!("expected a whole number, found `{number}`"));
            return place(src, diag, Some(start));
        }
        E::ExpectedStringEnd => d("unterminated string".into()),
        other => {
            let msg = humanize(&other.to_string());
            let at = skip_space(src, at);
            let token = token_at(src, at);
            // Serde's own messages ("… but found … instead") already say what was found.
            let text = if (msg.starts_with("expected") || msg.starts_with("Expected"))
                && !msg.contains(" instead")
            {
                let msg = lower_first(&msg);
                if token.is_empty() {
                    format!("{msg}, found the end of the file")
                } else {
                    format!("{msg}, found `{token}`")
                }
            } else if msg.starts_with("Expected") {
                lower_first(&msg)
            } else {
                msg
            };
            return place(src, d(text), Some(at));
        }
    };
    place(
        src,
        Diagnostic {
            path: path.to_string(),
            ..diag
        },
        Some(skip_space(src, at)),
    )
}

/// Deserialises TOML text.
pub(super) fn parse_toml(src: &SourceFile) -> Result<SceneFile, Box<Diagnostic>> {
    let de = toml::Deserializer::parse(&src.text)
        .map_err(|e| Box::new(toml_error(src, &e, String::new())))?;
    serde_path_to_error::deserialize::<_, SceneFile>(de).map_err(|err| {
        let path = user_path(&err.path().to_string());
        Box::new(toml_error(src, err.inner(), path))
    })
}

fn toml_error(src: &SourceFile, e: &toml::de::Error, path: String) -> Diagnostic {
    let msg = humanize(e.message().trim());
    let msg = if msg.contains("recurs") {
        format!(
            "tables are nested more deeply than the TOML reader allows; groups may nest at most {} levels",
            super::validate::MAX_NESTING
        )
    } else {
        msg
    };
    let mut diag = parse_unknown_name(&msg).unwrap_or_else(|| Diagnostic::error("", msg.clone()));
    if let Some(field) = unknown_key(&diag) {
        // serde_path_to_error's path may already end with the unknown key itself.
        diag.path = if path.is_empty() || path == field {
            field
        } else if path.ends_with(&format!(".{field}")) {
            path
        } else {
            format!("{path}.{field}")
        };
        return diag.located(&src.path, &src.text, src.index());
    }
    diag.path = path;
    if diag.path.is_empty() && diag.message.starts_with("missing required field") {
        // A missing top-level field has no place in the file to point at.
        return diag;
    }
    let at = e
        .span()
        .map(|s| src.index().location_of_offset(s.start))
        .map(|l| (l.line, l.column));
    place(src, diag, at)
}

/// The unknown field named by an "unknown field" diagnostic.
fn unknown_key(d: &Diagnostic) -> Option<String> {
    let rest = d.message.strip_prefix("unknown field `")?;
    Some(rest.split('`').next()?.to_string())
}

/// Positions a parse diagnostic at the parser's position when it has one, else at its path.
fn place(src: &SourceFile, diag: Diagnostic, at: Option<(usize, usize)>) -> Diagnostic {
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

fn follows_digit(src: &SourceFile, (line, col): (usize, usize)) -> bool {
    col >= 2
        && line_chars(src, line)
            .get(col - 2)
            .is_some_and(char::is_ascii_digit)
}

fn number_start(src: &SourceFile, (line, col): (usize, usize)) -> (usize, usize) {
    let chars = line_chars(src, line);
    let mut c = col;
    while c >= 2 && (chars[c - 2].is_ascii_digit() || matches!(chars[c - 2], '-' | '+' | '_')) {
        c -= 1;
    }
    (line, c)
}

/// The `name` of a `name: value` pair whose value starts at the given position.
fn key_before(src: &SourceFile, (line, col): (usize, usize)) -> Option<String> {
    let before: String = line_chars(src, line)
        .iter()
        .take(col.saturating_sub(1))
        .collect();
    let before = before.trim_end().strip_suffix(':')?.trim_end();
    let key: String = before
        .chars()
        .rev()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    (!key.is_empty()).then(|| key.chars().rev().collect())
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
}
