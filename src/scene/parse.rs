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
                Some((escape, col)) => {
                    let d = d(format!("invalid escape `{escape}` in a string; {VALID}"));
                    let mut d = place(src, d, Some((at.0, col)));
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
            let close =
                super::locate::ron_unclosed_bracket(&src.text[..offset]).map(|(_, c)| match c {
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
            super::validate::MAX_NESTING
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
    let first = super::locate::ron_first_key_in_open_map(&src.text[..offset_of(src, at)], key)
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

/// The opening bracket matching the closing bracket at `at`, if there is one there (strings are
/// skipped only roughly: enough for the numbers and names of a scene value).
fn matching_open(src: &SourceFile, at: (usize, usize)) -> Option<(usize, usize)> {
    let close = *line_chars(src, at.0).get(at.1.checked_sub(1)?)?;
    let open = match close {
        ')' => '(',
        ']' => '[',
        '}' => '{',
        _ => return None,
    };
    let mut depth = 0usize;
    for line in (1..=at.0).rev() {
        let chars = line_chars(src, line);
        let end = if line == at.0 { at.1 } else { chars.len() };
        for col in (1..=end).rev() {
            match chars[col - 1] {
                c if c == close => depth += 1,
                c if c == open => {
                    depth -= 1;
                    if depth == 0 {
                        return Some((line, col));
                    }
                }
                _ => {}
            }
        }
    }
    None
}

/// The first invalid escape (`\q`) in the string starting at `at`, with its column.
fn bad_escape(src: &SourceFile, at: (usize, usize)) -> Option<(String, usize)> {
    let chars = line_chars(src, at.0);
    let mut col = at.1;
    // Start inside the string: after its opening quote if the position is on it.
    if chars.get(col - 1) == Some(&'"') {
        col += 1;
    }
    while col <= chars.len() {
        match chars[col - 1] {
            '"' => return None,
            '\\' => {
                let next = *chars.get(col)?;
                if !matches!(
                    next,
                    '\\' | '"' | '\'' | 'n' | 't' | 'r' | '0' | 'u' | 'x' | 'b' | 'f' | '/'
                ) {
                    return Some((format!("\\{next}"), col));
                }
                col += 2;
            }
            _ => col += 1,
        }
    }
    None
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

/// The TOML reader's nesting limit (`toml` 1.x, not configurable): arrays and inline tables may
/// nest at most this deep, and a table header or dotted key may have at most this many parts.
pub(crate) const TOML_NESTING_LIMIT: usize = 80;

/// A TOML file nested past the TOML reader's limit, located at the first value or table header
/// beyond it, with what that limit means for groups.
fn toml_too_deep(src: &SourceFile, at: Option<(usize, usize)>) -> Diagnostic {
    let max = super::validate::MAX_NESTING;
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
        if let Some(col) = unterminated_toml_string(&line_chars(src, line)) {
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
        let rest = &chars[at.1 - 1..toml_comment_start(&chars).max(at.1 - 1)];
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
        let content: String = chars[..toml_comment_start(&chars)].iter().collect();
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

/// The column of the opening quote of a basic (`"`) or literal (`'`) string that is not closed
/// on this line; `None` for lines with multi-line string quotes.
fn unterminated_toml_string(chars: &[char]) -> Option<usize> {
    let line: String = chars.iter().collect();
    if line.contains("\"\"\"") || line.contains("'''") {
        return None;
    }
    let mut open: Option<(char, usize)> = None;
    let mut escaped = false;
    for (i, &c) in chars.iter().enumerate() {
        match open {
            None if c == '#' => return None,
            None if c == '"' || c == '\'' => open = Some((c, i + 1)),
            None => {}
            Some(('"', _)) if escaped => escaped = false,
            Some(('"', _)) if c == '\\' => escaped = true,
            Some((q, _)) if c == q => open = None,
            Some(_) => {}
        }
    }
    open.map(|(_, col)| col)
}

/// Index of the `#` starting a comment on a TOML line (outside strings), or the line's length.
fn toml_comment_start(chars: &[char]) -> usize {
    let mut quote: Option<char> = None;
    let mut escaped = false;
    for (i, &c) in chars.iter().enumerate() {
        match quote {
            None if c == '#' => return i,
            None if c == '"' || c == '\'' => quote = Some(c),
            None => {}
            Some('"') if escaped => escaped = false,
            Some('"') if c == '\\' => escaped = true,
            Some(q) if c == q => quote = None,
            Some(_) => {}
        }
    }
    chars.len()
}

/// A RON file that ends inside brackets: names the innermost unclosed bracket and places the
/// caret just after the last value, where the closing bracket belongs.
fn unclosed_ron_bracket(src: &SourceFile, path: &str) -> Option<Diagnostic> {
    let (offset, open) = super::locate::ron_unclosed_bracket(&src.text)?;
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
        *parse_toml(&src).unwrap_err()
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
                    parse_toml(&src).is_ok()
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
