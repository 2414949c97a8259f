//! RON errors as located diagnostics: `ron`'s error codes turned into messages that name the
//! field path, what was found and what is valid, and syntax errors placed where the text went
//! wrong.

use super::super::brackets::{
    ron_first_key_in_open_map, ron_matching_open, ron_misnested, ron_unclosed_bracket,
};
use super::super::diagnostic::{Diagnostic, humanize};
use super::super::lexer::{SourceFormat, Tok, lex_code};
use super::super::schema::SceneFile;
use super::super::source::SourceFile;
use super::super::validate::MAX_NESTING;
use super::{
    bare_expectation, is_bare_expectation, line_chars, lower_first, missing_top_level, place,
    skip_space, token_at, unknown_name, user_path,
};

/// RON nesting limit: deep enough for the maximum group nesting, shallow enough for the stack.
const RON_RECURSION_LIMIT: usize = 512;

/// Deserialises RON text.
pub(super) fn parse(src: &SourceFile) -> Result<SceneFile, Box<Diagnostic>> {
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
            let at = (e.span.start.line, e.span.start.col);
            if let Some(d) = left_open(src, at, matches!(code, ron::Error::Eof)) {
                return Err(Box::new(d));
            }
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
        } => {
            // A name read whole before it is checked (the shared settings enums) leaves the
            // parser after it: the caret goes under the name the path points at.
            let d = Diagnostic {
                path: path.to_string(),
                ..unknown_name("variant", found, expected)
            };
            let value = src.index().locate(path).map(|l| (l.line, l.column));
            let at = value
                .filter(|&v| token_at(src, v) == *found)
                .unwrap_or_else(|| skip_space(src, at));
            return place(src, d, Some(at));
        }
        E::MissingStructField { field, .. } if path.is_empty() => {
            let d = missing_top_level(src, field);
            return place(src, d, Some(skip_space(src, at)));
        }
        E::MissingStructField { field, .. } => {
            // Point at the value that lacks the field, not at its closing bracket.
            let d = d(format!("missing required field `{field}`"));
            return place(src, d, None);
        }
        E::InvalidEscape(_) => {
            const VALID: &str =
                "valid escapes are `\\\\`, `\\\"`, `\\n`, `\\t`, `\\r`, `\\0` and `\\u{…}`";
            return match bad_escape(src, at) {
                Some((escape, pos)) => {
                    let d = d(format!("invalid escape `{escape}` in a string; {VALID}"));
                    let mut d = place(src, d, Some(pos));
                    if let Some(p) = &mut d.location {
                        p.width = escape.chars().count();
                    }
                    d
                }
                None => place(
                    src,
                    d(format!("invalid escape in a string; {VALID}")),
                    Some(at),
                ),
            };
        }
        E::ExpectedDifferentLength { .. } => {
            // The parser stops at the closing bracket; the caret goes under the whole value.
            let at = skip_space(src, at);
            let msg = lower_first(&humanize(&code.to_string()));
            return place(src, d(msg), Some(matching_open(src, at).unwrap_or(at)));
        }
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
        E::ExpectedComma => {
            let at = skip_space(src, at);
            let offset = offset_of(src, at);
            let close = ron_unclosed_bracket(&src.text[..offset]).map(|(_, c)| match c {
                '(' => ')',
                '[' => ']',
                _ => '}',
            });
            let token = match token_at(src, at) {
                t if t.is_empty() => "the end of the file".to_string(),
                t => format!("`{t}`"),
            };
            let text = match close {
                Some(c) => format!("expected `,` or `{c}`, found {token}"),
                None => format!("expected `,`, found {token}"),
            };
            return place(src, d(text), Some(at));
        }
        E::Eof => {
            if let Some(d) = unclosed_ron_bracket(src, path) {
                return d;
            }
            d("the file ends in the middle of a value".into())
        }
        E::Message(msg) if is_bare_expectation(msg) => return bare_expectation(src, path, msg),
        E::Message(msg) if msg.ends_with("` is defined twice") => {
            return defined_twice(src, path, msg, skip_space(src, at));
        }
        E::DuplicateStructField { field, .. } => d(format!("field `{field}` is given twice")),
        E::ExceededRecursionLimit => d(format!(
            "values are nested more than {RON_RECURSION_LIMIT} levels deep; groups may nest at most {} levels",
            MAX_NESTING
        )),
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

/// A name given twice in one map (`schema::unique_keys`): named by its full path, placed at the
/// second definition, with the line of the first as help.
fn defined_twice(src: &SourceFile, path: &str, msg: &str, at: (usize, usize)) -> Diagnostic {
    let key = msg.split('`').nth(1).unwrap_or_default();
    let full = if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    };
    let first = ron_first_key_in_open_map(&src.text[..offset_of(src, at)], key)
        .map(|offset| src.text[..offset].matches('\n').count() + 1);
    let text = if path.is_empty() {
        format!("`{key}` is defined twice")
    } else {
        format!("`{key}` is defined twice in `{path}`")
    };
    let mut d = Diagnostic::error(full, text);
    d.help = Some(match first {
        Some(line) => format!(
            "its first definition is on line {line}; each name may be defined once: rename or remove one of them"
        ),
        None => "each name may be defined once: rename or remove one of them".to_string(),
    });
    place(src, d, Some(at))
}

/// The byte offset of a 1-based (line, column in chars) position.
fn offset_of(src: &SourceFile, (line, col): (usize, usize)) -> usize {
    let start: usize = src
        .text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    let rest = src.text.get(start..).unwrap_or_default();
    start
        + rest
            .char_indices()
            .nth(col.saturating_sub(1))
            .map_or(rest.len(), |(i, _)| i)
}

/// A bracket the text left open (`camera: Pinhole(` never closed before `textures:`), when the
/// parser's error at `at` is on the line where the text moved on without it (or at the end of
/// the file): "expected `)` to close … opened at line:column, found …", with where the closer
/// probably belongs. The parser itself would report what follows as out of place (an unknown
/// field of the open value).
fn left_open(src: &SourceFile, at: (usize, usize), at_end: bool) -> Option<Diagnostic> {
    let m = ron_misnested(&src.text)?;
    let index = src.index();
    let found = index.location_of_offset(m.found.0);
    if !at_end && found.line != skip_space(src, at).0 {
        return None;
    }
    let opened = index.location_of_offset(m.opened);
    let token = token_at(src, (found.line, found.column));
    let after = index.location_of_offset(m.after.0);
    let d = Diagnostic::error(
        "",
        format!(
            "expected `{}` to close `{}` opened at {}:{}, found `{token}`",
            m.expected, m.label, opened.line, opened.column
        ),
    )
    .with_help(format!(
        "add `{}` after `{}` on line {}",
        m.expected,
        &src.text[m.after.0..m.after.1],
        after.line
    ));
    Some(place(src, d, Some((found.line, found.column))))
}

/// The first invalid escape (`\q`) of the string at (or just after) `at`, with its position.
fn bad_escape(src: &SourceFile, at: (usize, usize)) -> Option<(String, (usize, usize))> {
    let offset = offset_of(src, at);
    let string = lex_code(&src.text, SourceFormat::Ron)
        .into_iter()
        .find(|t| t.end > offset && matches!(t.tok, Tok::Str(_)))?;
    let Tok::Str(s) = string.tok else {
        return None;
    };
    let (start, end) = s.bad_escape?;
    let l = src.index().location_of_offset(start);
    Some((src.text[start..end].to_string(), (l.line, l.column)))
}

/// The opening bracket matching the closing bracket at `at`, if there is one there.
fn matching_open(src: &SourceFile, at: (usize, usize)) -> Option<(usize, usize)> {
    let open = ron_matching_open(&src.text, offset_of(src, at))?;
    let l = src.index().location_of_offset(open);
    Some((l.line, l.column))
}

/// A RON file that ends inside brackets: names the innermost unclosed bracket and places the
/// caret just after the last value, where the closing bracket belongs.
fn unclosed_ron_bracket(src: &SourceFile, path: &str) -> Option<Diagnostic> {
    let (offset, open) = ron_unclosed_bracket(&src.text)?;
    let close = match open {
        '(' => ')',
        '[' => ']',
        _ => '}',
    };
    let opened = src.index().location_of_offset(offset);
    let end = src.index().location_of_offset(src.text.trim_end().len());
    let d = Diagnostic::error(
        path,
        format!(
            "unclosed `{open}`: the `{open}` at line {}, column {} is never closed; expected `{close}` before the end of the file",
            opened.line, opened.column
        ),
    );
    Some(place(src, d, Some((end.line, end.column))))
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
