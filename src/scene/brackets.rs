//! The bracket structure of RON text, from the lexer's tokens: which bracket is still open, which
//! opener a closer matches, and — when the brackets do not balance — where a bracket was most
//! likely left open (the first line that, by its indentation, is no longer inside it).

use super::lexer::{SourceFormat, Tok, Token, lex_code};

/// The closing bracket of an opening one.
#[must_use]
pub(crate) fn closer(open: u8) -> char {
    match open {
        b'(' => ')',
        b'[' => ']',
        _ => '}',
    }
}

/// The innermost `(`, `[` or `{` of RON `text` still open at the end of the text, as its byte
/// offset and the bracket (comments and strings are skipped).
#[must_use]
pub fn ron_unclosed_bracket(text: &str) -> Option<(usize, char)> {
    let mut open = Vec::new();
    for token in lex_code(text, SourceFormat::Ron) {
        match token.tok {
            Tok::Open(c) => open.push((token.start, char::from(c))),
            Tok::Close(_) => {
                open.pop();
            }
            _ => {}
        }
    }
    open.pop()
}

/// The byte offset of the first `"key":` entry directly inside the innermost `{` map still open
/// at the end of RON `text` (comments and strings skipped), so that a key given twice in that
/// map can point back at its first definition. `None` when the innermost open bracket is not a
/// map or the key is not in it.
#[must_use]
pub fn ron_first_key_in_open_map(text: &str, key: &str) -> Option<usize> {
    let tokens = lex_code(text, SourceFormat::Ron);
    let mut open: Vec<(usize, u8)> = Vec::new();
    let mut keys: Vec<(usize, usize)> = Vec::new();
    for (i, t) in tokens.iter().enumerate() {
        match &t.tok {
            Tok::Open(c) => open.push((t.start, *c)),
            Tok::Close(_) => {
                open.pop();
            }
            Tok::Str(s)
                if s.value == key
                    && matches!(tokens.get(i + 1).map(|n| &n.tok), Some(Tok::Colon)) =>
            {
                if let Some(&(map, b'{')) = open.last() {
                    keys.push((map, t.start));
                }
            }
            _ => {}
        }
    }
    let &(map, bracket) = open.last()?;
    if bracket != b'{' {
        return None;
    }
    keys.iter().find(|(m, _)| *m == map).map(|&(_, k)| k)
}

/// The byte offset of the opening bracket matched by the closing bracket that starts at byte
/// `close` of RON `text`; `None` if no closer starts there or it matches nothing.
#[must_use]
pub(crate) fn ron_matching_open(text: &str, close: usize) -> Option<usize> {
    let mut open: Vec<(usize, u8)> = Vec::new();
    for t in lex_code(text, SourceFormat::Ron) {
        match t.tok {
            Tok::Open(c) => open.push((t.start, c)),
            Tok::Close(c) => {
                let (at, o) = open.pop()?;
                if t.start == close {
                    return (closer(o) == char::from(c)).then_some(at);
                }
            }
            _ if t.start > close => return None,
            _ => {}
        }
    }
    None
}

/// A bracket left open where the text moves on (see [`ron_misnested`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Misnested {
    /// Byte offset of the open value: its variant name (`Pinhole` of `Pinhole(`) or its bracket.
    pub opened: usize,
    /// The value as written up to its bracket, with its key: `camera: Pinhole(`.
    pub label: String,
    /// The bracket the value needs (`)`).
    pub expected: char,
    /// Byte range of the token found instead.
    pub found: (usize, usize),
    /// Byte range of the last token before `found` (a trailing `,` skipped), after which the
    /// closer probably belongs.
    pub after: (usize, usize),
}

/// For RON `text` whose brackets do not balance: the first bracket still open where a line, by
/// its indentation (no deeper than the line that opened it) or by a closer of another kind,
/// shows the text has left it. `None` when the brackets balance, when a closer has no opener,
/// or when nothing before the end of the text shows where the bracket should have closed.
#[must_use]
pub(crate) fn ron_misnested(text: &str) -> Option<Misnested> {
    let tokens = lex_code(text, SourceFormat::Ron);
    if balanced(&tokens) {
        return None;
    }
    let line_starts: Vec<usize> = std::iter::once(0)
        .chain(text.match_indices('\n').map(|(i, _)| i + 1))
        .collect();
    let line_of = |offset: usize| line_starts.partition_point(|&s| s <= offset);
    let indent = |line: usize| {
        let start = line_starts[line - 1];
        let rest = &text[start..];
        rest.len() - rest.trim_start_matches([' ', '\t']).len()
    };
    // (token index of the opener, line of the opener)
    let mut open: Vec<(usize, usize)> = Vec::new();
    let mut previous_line = 0;
    for (i, t) in tokens.iter().enumerate() {
        let line = line_of(t.start);
        let first_on_line = line != previous_line;
        previous_line = line;
        if let Some(&(o, open_line)) = open.last() {
            let Tok::Open(bracket) = tokens[o].tok else {
                return None;
            };
            let closes_it = matches!(t.tok, Tok::Close(c) if closer(bracket) == char::from(c));
            let left_by_indent =
                first_on_line && open_line < line && indent(line) <= indent(open_line);
            let other_closer = matches!(t.tok, Tok::Close(_)) && !closes_it;
            if !closes_it && (left_by_indent || other_closer) {
                return misnested(text, &tokens, o, i);
            }
        }
        match t.tok {
            Tok::Open(_) => open.push((i, line)),
            Tok::Close(_) => {
                open.pop()?;
            }
            _ => {}
        }
    }
    None
}

/// True if every bracket closes, in order, with its own kind.
fn balanced(tokens: &[Token]) -> bool {
    let mut open = Vec::new();
    for t in tokens {
        match t.tok {
            Tok::Open(c) => open.push(c),
            Tok::Close(c) => match open.pop() {
                Some(o) if closer(o) == char::from(c) => {}
                _ => return false,
            },
            _ => {}
        }
    }
    open.is_empty()
}

/// The [`Misnested`] for the opener at token `o`, left open at token `found`.
fn misnested(text: &str, tokens: &[Token], o: usize, found: usize) -> Option<Misnested> {
    let Tok::Open(bracket) = tokens[o].tok else {
        return None;
    };
    let src = |t: &Token| &text[t.start..t.end];
    let variant = o
        .checked_sub(1)
        .filter(|&v| matches!(tokens[v].tok, Tok::Ident(_)) && tokens[v].end == tokens[o].start);
    let value = variant.unwrap_or(o);
    let key = value
        .checked_sub(2)
        .filter(|&k| tokens[k + 1].tok == Tok::Colon)
        .filter(|&k| matches!(tokens[k].tok, Tok::Ident(_) | Tok::Str(_)));
    let written = variant.map_or(String::new(), |v| src(&tokens[v]).to_string());
    let open = char::from(bracket);
    let label = match key {
        Some(k) => format!("{}: {written}{open}", src(&tokens[k])),
        None => format!("{written}{open}"),
    };
    Some(Misnested {
        opened: tokens[value].start,
        label,
        expected: closer(bracket),
        found: (tokens[found].start, tokens[found].end),
        after: {
            let mut a = found.saturating_sub(1);
            if tokens[a].tok == Tok::Comma && a > o {
                a -= 1;
            }
            (tokens[a].start, tokens[a].end)
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unclosed_brackets_skip_strings_and_comments() {
        assert_eq!(ron_unclosed_bracket("S(\n a: [1, 2],\n"), Some((1, '(')));
        assert_eq!(ron_unclosed_bracket("S(a: [1, (2)\n"), Some((5, '[')));
        assert_eq!(ron_unclosed_bracket("S(a: \"(\" /* [ */)"), None);
    }

    #[test]
    fn first_key_in_the_open_map_skips_values_comments_and_other_maps() {
        let text = r#"Scene(
    textures: { "white": Checker(a: "white") },
    materials: {
        // "white": a comment, not a key
        "red": (color: (1, 0, 0), note: "white"),
        "white": (color: (1, 1, 1)),
        "blue": (color: (0, 0, 1)),
        "white""#;
        let first = ron_first_key_in_open_map(text, "white").expect("found");
        let line = text[..first].matches('\n').count() + 1;
        assert_eq!(
            line, 6,
            "the key inside `materials`, not the texture or the comment"
        );
        assert_eq!(ron_first_key_in_open_map(text, "green"), None);
        // The innermost open bracket is a tuple, not a map.
        assert_eq!(
            ron_first_key_in_open_map("Scene(materials: { \"a\": (", "a"),
            None
        );
    }

    #[test]
    fn matching_openers_ignore_brackets_in_strings() {
        let text = "(a: [1, \"]\", (2, 3)], b: ')')";
        let close = text.find("],").unwrap();
        assert_eq!(ron_matching_open(text, close), Some(4));
        assert_eq!(ron_matching_open(text, text.len() - 1), Some(0));
        assert_eq!(ron_matching_open(text, 1), None);
    }

    #[test]
    fn a_paren_left_open_is_found_where_the_indentation_leaves_it() {
        let text = "Scene(\n    camera: Pinhole(eye: (0, 1, 4), fov_y: 40,\n    textures: {},\n)\n";
        let m = ron_misnested(text).expect("found");
        assert_eq!(m.label, "camera: Pinhole(");
        assert_eq!(m.expected, ')');
        assert_eq!(&text[m.found.0..m.found.1], "textures");
        assert_eq!(m.opened, text.find("Pinhole").unwrap());
        assert_eq!(&text[m.after.0..m.after.1], "40");
    }

    #[test]
    fn a_closer_of_another_kind_is_found() {
        let text = "(nodes: [Sphere(material: \"w\"], b: 1)";
        let m = ron_misnested(text).expect("found");
        assert_eq!(m.label, "Sphere(");
        assert_eq!(&text[m.found.0..m.found.1], "]");
        let text = "(m: {\n  \"a\": (c: 1,\n  \"b\": (c: 2),\n})";
        let m = ron_misnested(text).expect("found");
        assert_eq!(m.label, "\"a\": (");
        assert_eq!(&text[m.found.0..m.found.1], "\"b\"");
    }

    #[test]
    fn balanced_text_and_a_bracket_open_to_the_end_are_not_misnested() {
        // Odd indentation is no error while the brackets balance.
        assert_eq!(ron_misnested("Scene(\nrender: (\nwidth: 1),\n)"), None);
        // Open to the end with every later line deeper: nothing shows where it should close.
        assert_eq!(ron_misnested("Scene(\n    a: 1,\n    b: (c: 2),\n"), None);
        // A stray closer is not a bracket left open.
        assert_eq!(ron_misnested("(a: 1))"), None);
    }
}
