//! The one scanner of scene-file text: splits RON or TOML into tokens with their byte ranges.
//! Strings (with their escapes), raw strings, char literals and comments (nested block
//! comments in RON) are recognised here and nowhere else; the path index (`locate`), the
//! bracket analysis (`brackets`) and the error messages (`parse`) all read these tokens.
//!
//! Lexing never fails: an unterminated string or comment runs to where it must end (the end of
//! the text, or of the line for TOML's one-line strings) and says so in its token.

/// Which text format a scene file is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceFormat {
    /// Rusty Object Notation.
    Ron,
    /// TOML.
    Toml,
}

/// What a token is.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Tok {
    /// `(`, `[` or `{`.
    Open(u8),
    /// `)`, `]` or `}`.
    Close(u8),
    /// `:` (RON).
    Colon,
    /// `,`.
    Comma,
    /// `=` (TOML).
    Equals,
    /// A RON identifier (a raw `r#name` without its `r#`), or a TOML bare word (keys, numbers,
    /// booleans, dates, dotted keys).
    Ident(String),
    /// A string literal.
    Str(StrLit),
    /// A RON number, char literal or stray character.
    Scalar,
    /// A comment (`//`, `/* */` or `#![…]` in RON; `#` in TOML).
    Comment,
}

/// A string literal's decoded value and what went wrong in it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StrLit {
    /// The value with its escapes decoded (raw strings: as written).
    pub value: String,
    /// False when the text (or, for a TOML one-line string, the line) ends before the closing quote.
    pub terminated: bool,
    /// True for TOML's `"""` and `'''` strings.
    pub multiline: bool,
    /// Byte range of the first escape the format does not know (`\q`), if any.
    pub bad_escape: Option<(usize, usize)>,
}

/// One token: what it is and its byte range in the text.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Token {
    /// What it is.
    pub tok: Tok,
    /// Byte offset of its first character.
    pub start: usize,
    /// Byte offset just past it.
    pub end: usize,
}

/// Splits `text` into tokens (whitespace dropped, comments kept as [`Tok::Comment`]).
pub(crate) fn lex(text: &str, format: SourceFormat) -> Vec<Token> {
    let mut lexer = Lexer {
        text,
        b: text.as_bytes(),
        i: 0,
        format,
        tokens: Vec::new(),
    };
    lexer.run();
    lexer.tokens
}

/// The tokens of `text` without its comments.
pub(crate) fn lex_code(text: &str, format: SourceFormat) -> Vec<Token> {
    let mut tokens = lex(text, format);
    tokens.retain(|t| t.tok != Tok::Comment);
    tokens
}

fn is_ident_char(c: char) -> bool {
    c == '_' || c.is_alphanumeric()
}

/// A TOML bare word's characters: keys, numbers, booleans, dates, and dotted keys.
fn is_toml_word_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | '-' | '+' | '.' | ':')
}

struct Lexer<'a> {
    text: &'a str,
    b: &'a [u8],
    i: usize,
    format: SourceFormat,
    tokens: Vec<Token>,
}

impl Lexer<'_> {
    fn at(&self, i: usize) -> u8 {
        self.b.get(i).copied().unwrap_or(0)
    }

    fn push(&mut self, tok: Tok, start: usize) {
        let end = self.i.min(self.b.len());
        self.tokens.push(Token { tok, start, end });
    }

    /// Offset just past the run of chars from `i` that satisfy `keep`.
    fn run_end(&self, i: usize, keep: fn(char) -> bool) -> usize {
        self.text
            .get(i..)
            .map_or(i, |rest| i + rest.find(|c| !keep(c)).unwrap_or(rest.len()))
    }

    fn run(&mut self) {
        while self.i < self.b.len() {
            // Keep `i` on a char boundary after any byte-wise scan.
            if !self.text.is_char_boundary(self.i) {
                self.i += 1;
                continue;
            }
            if self.b[self.i].is_ascii_whitespace() {
                self.i += 1;
                continue;
            }
            match self.format {
                SourceFormat::Ron => self.ron_token(),
                SourceFormat::Toml => self.toml_token(),
            }
        }
    }

    /// Brackets, `,` and the format's own punctuation; false if the byte is none of them.
    fn punctuation(&mut self, c: u8) -> bool {
        let tok = match c {
            b'(' | b'[' | b'{' => Tok::Open(c),
            b')' | b']' | b'}' => Tok::Close(c),
            b',' => Tok::Comma,
            b':' if self.format == SourceFormat::Ron => Tok::Colon,
            b'=' if self.format == SourceFormat::Toml => Tok::Equals,
            _ => return false,
        };
        let start = self.i;
        self.i += 1;
        self.push(tok, start);
        true
    }

    fn ron_token(&mut self) {
        let (start, c) = (self.i, self.b[self.i]);
        if self.punctuation(c) {
            return;
        }
        let next = self.at(start + 1);
        let tok = match c {
            b'/' if next == b'/' => {
                self.i = self.line_end(start);
                Tok::Comment
            }
            b'/' if next == b'*' => {
                self.block_comment();
                Tok::Comment
            }
            b'#' if next == b'!' && self.at(start + 2) == b'[' => {
                self.attribute();
                Tok::Comment
            }
            b'"' => Tok::Str(self.quoted(start + 1, b'"', true, false)),
            b'b' if next == b'"' => Tok::Str(self.quoted(start + 2, b'"', true, false)),
            b'\'' => {
                self.char_literal(start);
                Tok::Scalar
            }
            b'b' if next == b'\'' => {
                self.char_literal(start + 1);
                Tok::Scalar
            }
            b'r' | b'b' if self.raw_string_start(start).is_some() => {
                let (hashes, body) = self.raw_string_start(start).unwrap_or((0, start));
                Tok::Str(self.raw_string(body, hashes))
            }
            b'r' if next == b'#' && self.run_end(start + 2, is_ident_char) > start + 2 => {
                self.i = self.run_end(start + 2, is_ident_char);
                Tok::Ident(self.text[start + 2..self.i].to_owned())
            }
            b'0'..=b'9' | b'+' | b'-' | b'.' => {
                self.i += 1;
                while self.i < self.b.len()
                    && (self.b[self.i].is_ascii_alphanumeric() || b"_.+-".contains(&self.b[self.i]))
                {
                    self.i += 1;
                }
                Tok::Scalar
            }
            _ => match self.text[start..].chars().next() {
                Some(ch) if is_ident_char(ch) => {
                    self.i = self.run_end(start, is_ident_char);
                    Tok::Ident(self.text[start..self.i].to_owned())
                }
                ch => {
                    self.i += ch.map_or(1, char::len_utf8);
                    Tok::Scalar
                }
            },
        };
        self.push(tok, start);
    }

    fn toml_token(&mut self) {
        let (start, c) = (self.i, self.b[self.i]);
        if self.punctuation(c) {
            return;
        }
        let tok = match c {
            b'#' => {
                self.i = self.line_end(start);
                Tok::Comment
            }
            b'"' | b'\'' => {
                let triple = self.at(start + 1) == c && self.at(start + 2) == c;
                let body = start + if triple { 3 } else { 1 };
                Tok::Str(self.quoted(body, c, c == b'"', triple))
            }
            _ => match self.text[start..].chars().next() {
                Some(ch) if is_toml_word_char(ch) => {
                    self.i = self.run_end(start, is_toml_word_char);
                    Tok::Ident(self.text[start..self.i].to_owned())
                }
                ch => {
                    self.i += ch.map_or(1, char::len_utf8);
                    Tok::Scalar
                }
            },
        };
        self.push(tok, start);
    }

    /// Offset just past the end of the line containing `i` (past its `\n`).
    fn line_end(&self, i: usize) -> usize {
        self.b[i..]
            .iter()
            .position(|&c| c == b'\n')
            .map_or(self.b.len(), |n| i + n + 1)
    }

    /// A RON `/* … */` comment, nested ones included; an unclosed one runs to the end.
    fn block_comment(&mut self) {
        let mut depth = 0usize;
        while self.i < self.b.len() {
            match (self.b[self.i], self.at(self.i + 1)) {
                (b'/', b'*') => (depth, self.i) = (depth + 1, self.i + 2),
                (b'*', b'/') => (depth, self.i) = (depth - 1, self.i + 2),
                _ => self.i += 1,
            }
            if depth == 0 {
                break;
            }
        }
    }

    /// A RON `#![enable(…)]` attribute (balanced brackets).
    fn attribute(&mut self) {
        let mut depth = 0usize;
        self.i += 2;
        while self.i < self.b.len() {
            match self.b[self.i] {
                b'[' => depth += 1,
                b']' => depth = depth.saturating_sub(1),
                _ => {}
            }
            self.i += 1;
            if depth == 0 {
                break;
            }
        }
    }

    /// A quoted string whose body starts at `body`, closed by `quote` (three of them when
    /// `triple`); `escapes`: backslash escapes are decoded. TOML one-line strings stop at the
    /// end of their line.
    fn quoted(&mut self, body: usize, quote: u8, escapes: bool, triple: bool) -> StrLit {
        let one_line = self.format == SourceFormat::Toml && !triple;
        let closing = if triple { 3 } else { 1 };
        let mut i = body;
        let mut bad_escape = None;
        let mut terminated = false;
        while i < self.b.len() {
            match self.b[i] {
                b'\\' if escapes && !(one_line && self.at(i + 1) == b'\n') => {
                    let next = self.text.get(i + 1..).and_then(|s| s.chars().next());
                    if bad_escape.is_none() && next.is_some_and(|n| !self.known_escape(n)) {
                        bad_escape = Some((i, i + 1 + next.map_or(0, char::len_utf8)));
                    }
                    i += 1 + next.map_or(0, char::len_utf8);
                }
                b'\n' if one_line => break,
                c if c == quote && (0..closing).all(|k| self.at(i + k) == quote) => {
                    terminated = true;
                    break;
                }
                _ => i += 1,
            }
        }
        let close = i.min(self.b.len());
        let raw = self.text.get(body..close).unwrap_or_default();
        self.i = if terminated { close + closing } else { close };
        StrLit {
            value: if escapes {
                unescape(raw)
            } else {
                raw.to_owned()
            },
            terminated,
            multiline: triple,
            bad_escape,
        }
    }

    /// The escapes the format knows after a backslash.
    fn known_escape(&self, c: char) -> bool {
        match self.format {
            SourceFormat::Ron => matches!(
                c,
                '\\' | '"' | '\'' | 'n' | 't' | 'r' | '0' | 'u' | 'x' | 'b' | 'f' | '/'
            ),
            SourceFormat::Toml => matches!(
                c,
                '\\' | '"'
                    | 'b'
                    | 't'
                    | 'n'
                    | 'f'
                    | 'r'
                    | 'e'
                    | 'u'
                    | 'U'
                    | 'x'
                    | '\n'
                    | '\r'
                    | ' '
            ),
        }
    }

    /// A RON char literal whose opening quote is at `i` (stops at a newline).
    fn char_literal(&mut self, i: usize) {
        let mut j = i + if self.at(i + 1) == b'\\' { 3 } else { 2 };
        while j < self.b.len() && self.b[j] != b'\'' && self.b[j] != b'\n' {
            j += 1;
        }
        self.i = (j + 1).min(self.b.len());
    }

    /// For `r#"`, `br"` etc. at `i`: the number of `#` and the offset of the body.
    fn raw_string_start(&self, i: usize) -> Option<(usize, usize)> {
        let mut j = i + usize::from(self.at(i) == b'b');
        if self.at(j) != b'r' {
            return None;
        }
        j += 1;
        let hashes = self.b[j.min(self.b.len())..]
            .iter()
            .take_while(|&&c| c == b'#')
            .count();
        (self.at(j + hashes) == b'"').then_some((hashes, j + hashes + 1))
    }

    /// A raw string body from `body`, closed by `"` and `hashes` `#`s.
    fn raw_string(&mut self, body: usize, hashes: usize) -> StrLit {
        let mut i = body;
        let mut terminated = false;
        while i < self.b.len() {
            let closing = self.b.get(i + 1..i + 1 + hashes);
            if self.b[i] == b'"' && closing.is_some_and(|h| h.iter().all(|&c| c == b'#')) {
                terminated = true;
                break;
            }
            i += 1;
        }
        self.i = if terminated { i + 1 + hashes } else { i };
        StrLit {
            value: self.text.get(body..i).unwrap_or_default().to_owned(),
            terminated,
            multiline: false,
            bad_escape: None,
        }
    }
}

/// Decodes the common escapes of a string body (enough for map keys).
fn unescape(body: &str) -> String {
    let mut out = String::with_capacity(body.len());
    let mut chars = body.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('n') => out.push('\n'),
            Some('t') => out.push('\t'),
            Some('r') => out.push('\r'),
            Some('0') => out.push('\0'),
            Some('u') if chars.as_str().starts_with('{') => {
                let hex: String = chars.by_ref().skip(1).take_while(|&c| c != '}').collect();
                let code = u32::from_str_radix(&hex, 16).ok().and_then(char::from_u32);
                out.push(code.unwrap_or(char::REPLACEMENT_CHARACTER));
            }
            Some(other) => out.push(other),
            None => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str, format: SourceFormat) -> Vec<(Tok, &str)> {
        lex(text, format)
            .into_iter()
            .map(|t| {
                let s = &text[t.start..t.end];
                (t.tok, s)
            })
            .collect()
    }

    fn string(value: &str, terminated: bool) -> Tok {
        Tok::Str(StrLit {
            value: value.into(),
            terminated,
            multiline: false,
            bad_escape: None,
        })
    }

    #[test]
    fn ron_strings_raw_strings_chars_and_nested_comments() {
        let text = "a: \"x \\\" (\", /* o /* n ) */ \" */ b: r#\"raw \" ) \"#, c: '\"', d: b'(',\n// ( \"\ne";
        let got = kinds(text, SourceFormat::Ron);
        let want: Vec<(Tok, &str)> = vec![
            (Tok::Ident("a".into()), "a"),
            (Tok::Colon, ":"),
            (string("x \" (", true), "\"x \\\" (\""),
            (Tok::Comma, ","),
            (Tok::Comment, "/* o /* n ) */ \" */"),
            (Tok::Ident("b".into()), "b"),
            (Tok::Colon, ":"),
            (string("raw \" ) ", true), "r#\"raw \" ) \"#"),
            (Tok::Comma, ","),
            (Tok::Ident("c".into()), "c"),
            (Tok::Colon, ":"),
            (Tok::Scalar, "'\"'"),
            (Tok::Comma, ","),
            (Tok::Ident("d".into()), "d"),
            (Tok::Colon, ":"),
            (Tok::Scalar, "b'('"),
            (Tok::Comma, ","),
            (Tok::Comment, "// ( \"\n"),
            (Tok::Ident("e".into()), "e"),
        ];
        assert_eq!(got, want);
    }

    #[test]
    fn ron_escapes_are_decoded_and_bad_ones_found() {
        let text = r#""a\tb\u{e9}" "ok\q" r"\q""#;
        let t = lex(text, SourceFormat::Ron);
        let Tok::Str(first) = &t[0].tok else { panic!() };
        assert_eq!(first.value, "a\tbé");
        assert_eq!(first.bad_escape, None);
        let Tok::Str(second) = &t[1].tok else {
            panic!()
        };
        let (s, e) = second.bad_escape.expect("found");
        assert_eq!(&text[s..e], "\\q");
        let Tok::Str(raw) = &t[2].tok else { panic!() };
        assert_eq!((raw.value.as_str(), raw.bad_escape), ("\\q", None));
    }

    #[test]
    fn unterminated_strings_and_comments_run_to_their_end() {
        let t = lex("(a: \"abc é\n b: 1", SourceFormat::Ron);
        assert_eq!(t.len(), 4);
        assert_eq!(t[3].tok, string("abc é\n b: 1", false));
        let t = lex("(a /* open /* nested */ (", SourceFormat::Ron);
        assert_eq!(t.last().map(|t| &t.tok), Some(&Tok::Comment));
        // A TOML one-line string ends with its line; the next line lexes on its own.
        let t = lex("a = \"open\nb = 1\n", SourceFormat::Toml);
        assert_eq!(t[2].tok, string("open", false));
        assert_eq!(t[3].tok, Tok::Ident("b".into()));
    }

    #[test]
    fn toml_strings_comments_and_words() {
        let text = "k.x = 'li\\t' # c \"\ns = \"\"\"a\n\"b\" \"\"\"\nd = [1979-05-27, -1.5e3]";
        let got: Vec<&str> = kinds(text, SourceFormat::Toml)
            .into_iter()
            .map(|(_, s)| s)
            .collect();
        assert_eq!(
            got,
            [
                "k.x",
                "=",
                "'li\\t'",
                "# c \"\n",
                "s",
                "=",
                "\"\"\"a\n\"b\" \"\"\"",
                "d",
                "=",
                "[",
                "1979-05-27",
                ",",
                "-1.5e3",
                "]"
            ]
        );
        let t = lex("'li\\t'", SourceFormat::Toml);
        assert_eq!(
            t[0].tok,
            string("li\\t", true),
            "literal strings keep backslashes"
        );
    }

    #[test]
    fn garbage_never_panics_and_tokens_tile_the_text_in_order() {
        let pieces = [
            "(", ")", "\"", "'", "r#\"", "/*", "*/", "//", "\n", "a", "é", "日本", "\\", "#![",
            "#", "=", "'''", "\"\"\"", "b'", "r#", "\0", " ",
        ];
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        for round in 0..2000 {
            let mut text = String::new();
            for _ in 0..(round % 40) {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                text.push_str(pieces[(seed % pieces.len() as u64) as usize]);
            }
            for format in [SourceFormat::Ron, SourceFormat::Toml] {
                let mut last = 0;
                for t in lex(&text, format) {
                    assert!(
                        t.start >= last && t.end > t.start && t.end <= text.len(),
                        "{text:?}"
                    );
                    assert!(text.is_char_boundary(t.start) && text.is_char_boundary(t.end));
                    last = t.end;
                }
            }
        }
    }
}
