//! TOML errors as located diagnostics: `toml`'s messages turned into ones that name the field
//! path, what was found and what is valid, with clearer words for the syntax errors whose parser
//! message misleads.

use super::super::diagnostic::{Diagnostic, humanize};
use super::super::lexer::{SourceFormat, Tok, Token, lex};
use super::super::schema::SceneFile;
use super::super::source::SourceFile;
use super::super::validate::MAX_NESTING;
use super::{
    bare_expectation, is_bare_expectation, line_chars, missing_top_level, parse_unknown_name,
    place, token_at, unknown_key, user_path,
};

/// Deserialises TOML text.
pub(super) fn parse(src: &SourceFile) -> Result<SceneFile, Box<Diagnostic>> {
    let de = toml::Deserializer::parse(&src.text)
        .map_err(|e| Box::new(toml_error(src, &e, String::new())))?;
    serde_path_to_error::deserialize::<_, SceneFile>(de).map_err(|err| {
        let path = user_path(&err.path().to_string());
        Box::new(toml_error(src, err.inner(), path))
    })
}

fn toml_error(src: &SourceFile, e: &toml::de::Error, path: String) -> Diagnostic {
    let raw = e.message().trim();
    let at = e
        .span()
        .map(|s| src.index().location_of_offset(s.start))
        .map(|l| (l.line, l.column));
    if raw.contains("recurs") {
        return toml_too_deep(src, at);
    }
    if path.is_empty()
        && let Some(d) = at.and_then(|at| toml_syntax_error(src, raw, at))
    {
        return d;
    }
    let msg = humanize(raw);
    if is_bare_expectation(&msg) {
        return bare_expectation(src, &path, &msg);
    }
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
        // The caret goes under the unknown key, not its value.
        let key = src
            .index()
            .locate_key(&diag.path)
            .map(|l| (l.line, l.column));
        return place(src, diag, key);
    }
    if path.is_empty()
        && let Some(field) = diag.message.strip_prefix("missing required field `")
    {
        // A missing top-level field has no place in the file to point at.
        return missing_top_level(src, field.trim_end_matches('`'));
    }
    diag.path = path;
    place(src, diag, at)
}

/// The TOML reader's nesting limit (`toml` 1.x, not configurable): arrays and inline tables may
/// nest at most this deep, and a table header or dotted key may have at most this many parts.
pub(crate) const TOML_NESTING_LIMIT: usize = 80;

/// A TOML file nested past the TOML reader's limit, located at the first value or table header
/// beyond it, with what that limit means for groups.
fn toml_too_deep(src: &SourceFile, at: Option<(usize, usize)>) -> Diagnostic {
    let max = MAX_NESTING;
    // A too-long table header has no span: find the first header with too many parts.
    let header = || {
        src.text.lines().enumerate().find_map(|(i, line)| {
            let t = line.trim_start();
            let parts = t.strip_prefix('[')?.split('.').count();
            (parts > TOML_NESTING_LIMIT).then(|| (i + 1, line.len() - t.len() + 1))
        })
    };
    let (what, at) = match at {
        Some(at) => (
            format!(
                "arrays and inline tables are nested more than {TOML_NESTING_LIMIT} deep, the \
                 TOML reader's limit (a group written inline takes 3 levels: about 26 groups)"
            ),
            Some(at),
        ),
        None => (
            format!(
                "a table header has more than {TOML_NESTING_LIMIT} dotted parts, the TOML \
                 reader's limit (a group written as `[[…children]]` headers takes 2: about 39 \
                 groups)"
            ),
            header(),
        ),
    };
    let d = Diagnostic::error("", what).with_help(format!(
        "caustic allows groups {max} levels deep, but a TOML file cannot hold that many; \
         write a deeper scene in RON"
    ));
    place(src, d, at)
}

/// A clearer diagnostic for TOML syntax errors whose parser message misleads: an unterminated
/// string (reported as whatever the parser met next), and an unclosed array or inline table
/// (reported at the start of the next line).
fn toml_syntax_error(src: &SourceFile, raw: &str, at: (usize, usize)) -> Option<Diagnostic> {
    for line in [at.0, at.0.saturating_sub(1)] {
        if let Some(col) = unterminated_toml_string(src, line) {
            let d = Diagnostic::error(
                "",
                "unterminated string: a TOML string must end with its opening quote on the same line",
            );
            return Some(place(src, d, Some((line, col))));
        }
    }
    if raw == "duplicate key" {
        let key = token_at(src, at);
        let d = Diagnostic::error(
            "",
            format!("duplicate key `{key}`: it is already given earlier in this table"),
        );
        return Some(place(src, d, Some(at)));
    }
    if raw.starts_with("string values must be quoted") {
        // `height = 48 px`: a valid value followed by junk reads as an unquoted string.
        let chars = line_chars(src, at.0);
        let rest = &chars[at.1 - 1..toml_comment_start(src, at.0).max(at.1 - 1)];
        let rest: String = rest.iter().collect();
        let mut words = rest.split_whitespace();
        if let (Some(value), Some(junk)) = (words.next(), words.next())
            && toml::from_str::<toml::Table>(&format!("v = {value}")).is_ok()
        {
            let col = at.1 + rest.find(junk).map_or(0, |i| rest[..i].chars().count());
            let d = Diagnostic::error(
                "",
                format!(
                    "unexpected `{junk}` after the value `{value}`: a line holds one `key = value` \
                     (a comment starts with `#`)"
                ),
            );
            return Some(place(src, d, Some((at.0, col))));
        }
    }
    let (what, closer) = if raw.contains("array") {
        ("array", "]")
    } else if raw.contains("inline table") {
        ("inline table", "}")
    } else {
        return None;
    };
    let before: String = line_chars(src, at.0).iter().take(at.1 - 1).collect();
    if !before.trim().is_empty() {
        return None;
    }
    // The parser stopped at the start of a line: the value before it was never closed.
    let (line, content) = (1..at.0).rev().find_map(|l| {
        let chars = line_chars(src, l);
        let content: String = chars[..toml_comment_start(src, l).min(chars.len())]
            .iter()
            .collect();
        let content = content.trim_end().to_string();
        (!content.is_empty()).then_some((l, content))
    })?;
    let last = content.split_whitespace().last().unwrap_or_default();
    let d = Diagnostic::error(
        "",
        format!("unclosed {what}: expected `,` or `{closer}` after `{last}`"),
    );
    Some(place(src, d, Some((line, content.chars().count() + 1))))
}

/// The column of the opening quote of a basic (`"`) or literal (`'`) string on `line` that is
/// not closed on that line (multi-line strings are not considered).
fn unterminated_toml_string(src: &SourceFile, line: usize) -> Option<usize> {
    tokens_on_line(src, line).find_map(|t| match t.tok {
        Tok::Str(s) if !s.terminated && !s.multiline => {
            Some(src.index().location_of_offset(t.start).column)
        }
        _ => None,
    })
}

/// Index (in chars) of the `#` starting a comment on TOML `line`, or the line's length.
fn toml_comment_start(src: &SourceFile, line: usize) -> usize {
    tokens_on_line(src, line)
        .find(|t| t.tok == Tok::Comment)
        .map_or_else(
            || line_chars(src, line).len(),
            |t| src.index().location_of_offset(t.start).column - 1,
        )
}

/// The tokens of the file that start on `line`.
fn tokens_on_line(src: &SourceFile, line: usize) -> impl Iterator<Item = Token> + '_ {
    lex(&src.text, SourceFormat::Toml)
        .into_iter()
        .filter(move |t| src.index().location_of_offset(t.start).line == line)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_toml_nesting_limit_is_the_readers() {
        let parse = |text: String| toml::from_str::<toml::Table>(&text);
        let arrays = |n: usize| format!("a = {}1{}", "[".repeat(n), "]".repeat(n));
        assert!(parse(arrays(TOML_NESTING_LIMIT)).is_ok());
        let e = parse(arrays(TOML_NESTING_LIMIT + 1)).unwrap_err();
        assert!(e.message().contains("recurs"), "{}", e.message());
        let header = |n: usize| format!("[{}]\nx = 1\n", vec!["k"; n].join("."));
        assert!(parse(header(TOML_NESTING_LIMIT)).is_ok());
        let e = parse(header(TOML_NESTING_LIMIT + 1)).unwrap_err();
        assert!(e.message().contains("recurs"), "{}", e.message());
    }

    fn toml_message(text: &str) -> Diagnostic {
        let src = SourceFile::new(std::path::Path::new("t.toml"), text.to_string()).unwrap();
        *parse(&src).unwrap_err()
    }

    /// A TOML scene of `n` groups nested inline (`inline`) or as table headers, around a sphere.
    fn nested_toml(n: usize, inline: bool) -> String {
        let mut s = String::from(
            "[camera.Pinhole]\neye = [0, 1, 4]\nlook_at = [0, 1, 0]\nfov_y = 40\n\
             [materials]\nw = {}\n[[nodes]]\n",
        );
        if inline {
            let open = "{ Group = { children = [".repeat(n - 1);
            let close = "] } }".repeat(n - 1);
            s += &format!(
                "Group = {{ children = [{open}{{ Sphere = {{ material = \"w\" }} }}{close}] }}\n"
            );
        } else {
            let mut key = String::from("nodes");
            for _ in 0..n {
                key += ".Group";
                s += &format!("[{key}]\nname = \"g\"\n");
                key += ".children";
                s += &format!("[[{key}]]\n");
            }
            s += &format!("[{key}.Sphere]\nmaterial = \"w\"\n");
        }
        s
    }

    #[test]
    fn the_stated_group_counts_match_where_toml_fails() {
        // "about 26 groups" inline and "about 39" as headers: the last depth that parses.
        let last_ok = |inline: bool| {
            (1..100)
                .take_while(|&n| {
                    let src =
                        SourceFile::new(std::path::Path::new("t.toml"), nested_toml(n, inline))
                            .unwrap();
                    parse(&src).is_ok()
                })
                .last()
        };
        assert_eq!(last_ok(true), Some(26));
        assert_eq!(last_ok(false), Some(39));
        let d = toml_message(&nested_toml(27, true));
        assert!(d.message.contains("about 26 groups"), "{}", d.message);
        assert!(d.location.is_some());
        let d = toml_message(&nested_toml(40, false));
        assert!(d.message.contains("about 39 groups"), "{}", d.message);
        assert!(d.location.is_some());
    }
}
