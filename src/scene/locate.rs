//! Maps dotted field paths in a scene file back to line/column positions.
//!
//! A [`SourceIndex`] is built once per source text. It holds a small tree of
//! every value found in the text (struct fields, map entries, list and tuple
//! elements) with the byte offsets of each value and of its key. Enum variants
//! (`Sphere(radius: 1)` in RON, `{ Sphere = { radius = 1 } }` in TOML) and
//! `Some(..)` are transparent in paths, but may also be named explicitly.
//! Everything is best effort: unparsable input yields an index that finds less.

use toml_edit::{Item, TableLike, Value};

/// Maximum nesting indexed; deeper values are skipped without recursion.
const MAX_DEPTH: usize = 256;

/// Which text format a scene file is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceFormat {
    /// Rusty Object Notation.
    Ron,
    /// TOML.
    Toml,
}

/// A position in a source file: 1-based line and column (column counted in chars), and the byte offset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Location {
    /// 1-based line number.
    pub line: usize,
    /// 1-based column, counted in chars.
    pub column: usize,
    /// Byte offset into the source text.
    pub offset: usize,
}

/// One step of a field path.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// An enum variant (or `Some`) around a value.
#[derive(Debug)]
struct Wrapper {
    variant: String,
    inner: usize,
    /// The payload is a single value, so `[0]` also addresses it.
    newtype: bool,
}

#[derive(Debug, Default)]
struct Node {
    value: usize,
    key: Option<usize>,
    children: Vec<(Seg, usize)>,
    wrapper: Option<Wrapper>,
}

/// Arena of nodes; node 0 (if any) is the root.
#[derive(Default)]
struct Tree {
    nodes: Vec<Node>,
}

impl Tree {
    fn add(&mut self, value: usize, key: Option<usize>) -> usize {
        self.nodes.push(Node {
            value,
            key,
            ..Node::default()
        });
        self.nodes.len() - 1
    }

    fn push_child(&mut self, parent: usize, seg: Seg, child: usize) {
        self.nodes[parent].children.push((seg, child));
    }
}

/// An index from field paths to the positions of their values in one source text.
#[derive(Debug)]
pub struct SourceIndex {
    text: String,
    line_starts: Vec<usize>,
    nodes: Vec<Node>,
}

impl SourceIndex {
    /// Builds the index; never fails (an unparsable text gives an index that finds less).
    pub fn build(text: &str, format: SourceFormat) -> SourceIndex {
        let tree = match format {
            SourceFormat::Ron => ron_tree(text),
            SourceFormat::Toml => toml_tree(text),
        };
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        SourceIndex {
            text: text.to_owned(),
            line_starts,
            nodes: tree.nodes,
        }
    }

    /// Position of the value at `path`, or of the deepest ancestor of `path` that exists.
    /// Returns None only if not even the first segment is found.
    pub fn locate(&self, path: &str) -> Option<Location> {
        let (node, _) = self.resolve(path)?;
        Some(self.location_of_offset(self.nodes[node].value))
    }

    /// Position of the *key* (field name) of `path` if it is a named field, else same as locate.
    pub fn locate_key(&self, path: &str) -> Option<Location> {
        let (node, complete) = self.resolve(path)?;
        let node = &self.nodes[node];
        let offset = match node.key {
            Some(key) if complete => key,
            _ => node.value,
        };
        Some(self.location_of_offset(offset))
    }

    /// True if the whole of `path` names a value written in the text.
    #[must_use]
    pub fn contains(&self, path: &str) -> bool {
        matches!(self.resolve(path), Some((_, true)))
    }

    /// Position of the payload of the enum variant at `path` (`(1, 2)` in `Scale((1, 2))`,
    /// `[1, 2]` in `{ Scale = [1, 2] }`), or of the value itself when it is not a variant.
    #[must_use]
    pub fn locate_payload(&self, path: &str) -> Option<Location> {
        let (node, complete) = self.resolve(path)?;
        let node = match &self.nodes[node].wrapper {
            Some(w) if complete => w.inner,
            _ => node,
        };
        Some(self.location_of_offset(self.nodes[node].value))
    }

    /// Converts a byte offset into a Location (line/column), clamped to the text.
    pub fn location_of_offset(&self, offset: usize) -> Location {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self
            .line_starts
            .partition_point(|&start| start <= offset)
            .max(1);
        let start = self.line_starts.get(line - 1).copied().unwrap_or(0);
        let column = self
            .text
            .get(start..offset)
            .map_or(0, |s| s.chars().count())
            + 1;
        Location {
            line,
            column,
            offset,
        }
    }

    /// Finds the node of `path` (or its deepest existing ancestor) and whether the whole path matched.
    fn resolve(&self, path: &str) -> Option<(usize, bool)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut current = 0;
        let segs = parse_path(path);
        if segs.is_empty() {
            return None;
        }
        for (i, seg) in segs.iter().enumerate() {
            match self.step(current, seg) {
                Some(next) => current = next,
                None if i == 0 => return None,
                None => return Some((current, false)),
            }
        }
        Some((current, true))
    }

    /// Follows one path segment from `node`, looking through enum wrappers.
    fn step(&self, mut node: usize, seg: &Seg) -> Option<usize> {
        let mut newtype_fallback = None;
        for _ in 0..=MAX_DEPTH {
            let children = &self.nodes[node].children;
            let direct = match seg {
                Seg::Index(i) => children.get(*i).filter(|(s, _)| s == seg),
                Seg::Key(_) => None,
            };
            if let Some((_, child)) = direct.or_else(|| children.iter().find(|(s, _)| s == seg)) {
                return Some(*child);
            }
            let Some(wrapper) = &self.nodes[node].wrapper else {
                break;
            };
            match seg {
                Seg::Key(name) if *name == wrapper.variant => return Some(wrapper.inner),
                Seg::Index(0) if wrapper.newtype => {
                    newtype_fallback.get_or_insert(wrapper.inner);
                }
                _ => {}
            }
            node = wrapper.inner;
        }
        newtype_fallback
    }
}

/// Splits `a.b[1][2]."c.d"` into segments (a segment may be quoted to contain `.` or `[`).
fn parse_path(path: &str) -> Vec<Seg> {
    fn flush(segs: &mut Vec<Seg>, current: &mut String) {
        if !current.is_empty() {
            segs.push(Seg::Key(std::mem::take(current)));
        }
    }
    let mut segs = Vec::new();
    let mut current = String::new();
    let mut chars = path.chars();
    while let Some(c) = chars.next() {
        match c {
            '.' => flush(&mut segs, &mut current),
            '[' => {
                flush(&mut segs, &mut current);
                let inner: String = chars.by_ref().take_while(|&c| c != ']').collect();
                segs.push(match inner.trim().parse() {
                    Ok(i) => Seg::Index(i),
                    Err(_) => Seg::Key(format!("[{inner}]")),
                });
            }
            '"' if current.is_empty() => current.extend(chars.by_ref().take_while(|&c| c != '"')),
            _ => current.push(c),
        }
    }
    flush(&mut segs, &mut current);
    segs
}

// ---------------------------------------------------------------- TOML

fn toml_tree(text: &str) -> Tree {
    let mut tree = Tree::default();
    if let Ok(doc) = text.parse::<toml_edit::Document<String>>() {
        toml_item(&mut tree, doc.as_item(), 0, None, 0);
    }
    tree
}

fn span_start(span: Option<std::ops::Range<usize>>, fallback: usize) -> usize {
    span.map_or(fallback, |r| r.start)
}

fn toml_item(
    tree: &mut Tree,
    item: &Item,
    fallback: usize,
    key: Option<usize>,
    depth: usize,
) -> usize {
    let node = tree.add(span_start(item.span(), fallback), key);
    if depth >= MAX_DEPTH {
        return node;
    }
    let start = tree.nodes[node].value;
    match item {
        Item::Value(value) => toml_value(tree, node, value, depth),
        Item::Table(table) => toml_table(tree, node, table, depth),
        Item::ArrayOfTables(array) => {
            for (i, table) in array.iter().enumerate() {
                let child = tree.add(span_start(table.span(), start), None);
                toml_table(tree, child, table, depth + 1);
                tree.push_child(node, Seg::Index(i), child);
            }
        }
        Item::None => {}
    }
    node
}

fn toml_value(tree: &mut Tree, node: usize, value: &Value, depth: usize) {
    if depth >= MAX_DEPTH {
        return;
    }
    let start = tree.nodes[node].value;
    match value {
        Value::Array(array) => {
            for (i, element) in array.iter().enumerate() {
                let child = tree.add(span_start(element.span(), start), None);
                toml_value(tree, child, element, depth + 1);
                tree.push_child(node, Seg::Index(i), child);
            }
        }
        Value::InlineTable(table) => toml_table(tree, node, table, depth),
        _ => {}
    }
}

/// Indexes a table's entries; a table with one capitalised key becomes an enum wrapper.
fn toml_table(tree: &mut Tree, node: usize, table: &dyn TableLike, depth: usize) {
    let start = tree.nodes[node].value;
    for (name, item) in table.iter() {
        let key = table
            .get_key_value(name)
            .and_then(|(key, _)| key.span())
            .map(|r| r.start);
        let child = toml_item(tree, item, key.unwrap_or(start), key, depth + 1);
        tree.push_child(node, Seg::Key(name.to_owned()), child);
    }
    let entry = &tree.nodes[node].children;
    if let [(Seg::Key(name), child)] = entry.as_slice()
        && name.starts_with(|c: char| c.is_ascii_uppercase())
    {
        let (variant, inner) = (name.clone(), *child);
        let payload = &tree.nodes[inner];
        let newtype = payload.children.is_empty() && payload.wrapper.is_none();
        tree.nodes[node].children.clear();
        tree.nodes[node].wrapper = Some(Wrapper {
            variant,
            inner,
            newtype,
        });
    }
}

// ---------------------------------------------------------------- RON

/// The innermost `(`, `[` or `{` of RON `text` still open at the end of the text, as its byte
/// offset and the bracket (comments and strings are skipped).
#[must_use]
pub fn ron_unclosed_bracket(text: &str) -> Option<(usize, char)> {
    let mut open = Vec::new();
    for token in lex(text) {
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
    let tokens = lex(text);
    let mut open: Vec<(usize, u8)> = Vec::new();
    let mut keys: Vec<(usize, usize)> = Vec::new();
    for (i, t) in tokens.iter().enumerate() {
        match &t.tok {
            Tok::Open(c) => open.push((t.start, *c)),
            Tok::Close(_) => {
                open.pop();
            }
            Tok::Str(s)
                if s == key && matches!(tokens.get(i + 1).map(|n| &n.tok), Some(Tok::Colon)) =>
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

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Open(u8),
    Close(u8),
    Colon,
    Comma,
    Ident(String),
    Str(String),
    Scalar,
}

#[derive(Debug)]
struct Token {
    tok: Tok,
    start: usize,
    end: usize,
}

fn is_ident_char(c: char) -> bool {
    c == '_' || c.is_alphanumeric()
}

/// Splits RON text into tokens, skipping whitespace, comments and `#![..]` attributes.
fn lex(text: &str) -> Vec<Token> {
    let b = text.as_bytes();
    let at = |i: usize| b.get(i).copied().unwrap_or(0);
    let ident_end = |i: usize| {
        text.get(i..).map_or(i, |rest| {
            i + rest.find(|c| !is_ident_char(c)).unwrap_or(rest.len())
        })
    };
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < b.len() {
        // Keep `i` on a char boundary after any byte-wise scan.
        if !text.is_char_boundary(i) {
            i += 1;
            continue;
        }
        let start = i;
        let c = b[i];
        let tok = match c {
            b' ' | b'\t' | b'\n' | b'\r' => {
                i += 1;
                continue;
            }
            b'/' if at(i + 1) == b'/' => {
                i = b[i..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |n| i + n + 1);
                continue;
            }
            b'/' if at(i + 1) == b'*' => {
                let mut depth = 0usize;
                while i < b.len() {
                    match (b[i], at(i + 1)) {
                        (b'/', b'*') => (depth, i) = (depth + 1, i + 2),
                        (b'*', b'/') => (depth, i) = (depth - 1, i + 2),
                        _ => i += 1,
                    }
                    if depth == 0 {
                        break;
                    }
                }
                continue;
            }
            b'#' if at(i + 1) == b'!' && at(i + 2) == b'[' => {
                let mut depth = 0usize;
                i += 2;
                while i < b.len() {
                    match b[i] {
                        b'[' => depth += 1,
                        b']' => depth = depth.saturating_sub(1),
                        _ => {}
                    }
                    i += 1;
                    if depth == 0 {
                        break;
                    }
                }
                continue;
            }
            _ if c == b'"' || (c == b'b' && at(i + 1) == b'"') => {
                let body = i + 1 + usize::from(c == b'b');
                let close = string_end(b, body);
                i = (close + 1).min(b.len());
                Tok::Str(unescape(text.get(body..close).unwrap_or_default()))
            }
            _ if c == b'\'' || (c == b'b' && at(i + 1) == b'\'') => {
                i = char_end(b, i + usize::from(c == b'b'));
                Tok::Scalar
            }
            b'r' | b'b' if raw_string_start(b, i).is_some() => {
                let (hashes, body) = raw_string_start(b, i).unwrap_or((0, i));
                let close = raw_string_end(b, body, hashes);
                i = (close + 1 + hashes).min(b.len());
                Tok::Str(text.get(body..close).unwrap_or_default().to_owned())
            }
            b'r' if at(i + 1) == b'#' && ident_end(i + 2) > i + 2 => {
                i = ident_end(i + 2);
                Tok::Ident(text.get(start + 2..i).unwrap_or_default().to_owned())
            }
            b'(' | b'[' | b'{' | b')' | b']' | b'}' | b':' | b',' => {
                i += 1;
                match c {
                    b':' => Tok::Colon,
                    b',' => Tok::Comma,
                    b'(' | b'[' | b'{' => Tok::Open(c),
                    _ => Tok::Close(c),
                }
            }
            b'0'..=b'9' | b'+' | b'-' | b'.' => {
                i += 1;
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b"_.+-".contains(&b[i])) {
                    i += 1;
                }
                Tok::Scalar
            }
            _ => {
                let ch = text.get(i..).and_then(|s| s.chars().next());
                match ch {
                    Some(ch) if is_ident_char(ch) => {
                        i = ident_end(i);
                        Tok::Ident(text.get(start..i).unwrap_or_default().to_owned())
                    }
                    _ => {
                        i += ch.map_or(1, char::len_utf8);
                        Tok::Scalar
                    }
                }
            }
        };
        let end = i.min(b.len());
        tokens.push(Token { tok, start, end });
    }
    tokens
}

/// Offset of the closing quote (or the end) of a string whose body starts at `i`.
fn string_end(b: &[u8], mut i: usize) -> usize {
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return i,
            _ => i += 1,
        }
    }
    b.len()
}

/// Offset just past a char literal whose opening quote is at `i` (stops at a newline).
fn char_end(b: &[u8], i: usize) -> usize {
    let mut j = i + if b.get(i + 1) == Some(&b'\\') { 3 } else { 2 };
    while j < b.len() && b[j] != b'\'' && b[j] != b'\n' {
        j += 1;
    }
    (j + 1).min(b.len())
}

/// For `r#"`, `br"` etc. at `i`: the number of `#` and the offset of the body.
fn raw_string_start(b: &[u8], i: usize) -> Option<(usize, usize)> {
    let mut j = i + usize::from(b.get(i) == Some(&b'b'));
    if b.get(j) != Some(&b'r') {
        return None;
    }
    j += 1;
    let hashes = b[j.min(b.len())..]
        .iter()
        .take_while(|&&c| c == b'#')
        .count();
    (b.get(j + hashes) == Some(&b'"')).then_some((hashes, j + hashes + 1))
}

/// Offset of the `"##..` closing a raw string (or the end).
fn raw_string_end(b: &[u8], mut i: usize, hashes: usize) -> usize {
    while i < b.len() {
        let closing = b.get(i + 1..i + 1 + hashes);
        if b[i] == b'"' && closing.is_some_and(|h| h.iter().all(|&c| c == b'#')) {
            return i;
        }
        i += 1;
    }
    b.len()
}

/// Decodes the common escapes of a RON string body (enough for map keys).
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

fn ron_tree(text: &str) -> Tree {
    let mut parser = RonParser {
        text,
        tokens: lex(text),
        pos: 0,
        tree: Tree::default(),
    };
    if let Some(first) = parser.tokens.first() {
        let root = parser.tree.add(first.start, None);
        // A syntax error just stops indexing; everything linked so far stays.
        let _ = parser.value(root, 0);
    }
    parser.tree
}

struct RonParser<'a> {
    text: &'a str,
    tokens: Vec<Token>,
    pos: usize,
    tree: Tree,
}

impl RonParser<'_> {
    fn peek(&self, ahead: usize) -> Option<&Tok> {
        self.tokens.get(self.pos + ahead).map(|t| &t.tok)
    }

    /// Creates a child node at the current token and links it to `parent`.
    fn child(&mut self, parent: usize, seg: Option<Seg>, key: Option<usize>) -> Option<usize> {
        let start = self.tokens.get(self.pos)?.start;
        let node = self.tree.add(start, key);
        if let Some(seg) = seg {
            self.tree.push_child(parent, seg, node);
        }
        Some(node)
    }

    /// Parses the value at the current token into the already created `node`.
    fn value(&mut self, node: usize, depth: usize) -> Option<()> {
        if depth >= MAX_DEPTH {
            return self.skip_value();
        }
        match self.peek(0)?.clone() {
            Tok::Ident(variant) => {
                self.pos += 1;
                if self.peek(0) == Some(&Tok::Open(b'(')) {
                    let group = self.child(node, None, None)?;
                    self.tree.nodes[node].wrapper = Some(Wrapper {
                        variant,
                        inner: group,
                        newtype: false,
                    });
                    let single = self.container(group, b')', depth + 1)?;
                    if let (Some(payload), Some(wrapper)) =
                        (single, &mut self.tree.nodes[node].wrapper)
                    {
                        (wrapper.inner, wrapper.newtype) = (payload, true);
                    }
                }
                Some(())
            }
            Tok::Open(b'(') => self.container(node, b')', depth + 1).map(drop),
            Tok::Open(b'[') => self.container(node, b']', depth + 1).map(drop),
            Tok::Open(b'{') => self.container(node, b'}', depth + 1).map(drop),
            Tok::Str(_) | Tok::Scalar => {
                self.pos += 1;
                Some(())
            }
            _ => None,
        }
    }

    /// Parses a `( )`, `[ ]` or `{ }` group; returns its only element if it is a 1-tuple.
    fn container(&mut self, node: usize, close: u8, depth: usize) -> Option<Option<usize>> {
        self.pos += 1;
        let is_struct = close == b')'
            && matches!(self.peek(0), Some(Tok::Ident(_)))
            && self.peek(1) == Some(&Tok::Colon);
        let mut count = 0;
        loop {
            match self.peek(0)? {
                Tok::Close(c) if *c == close => {
                    self.pos += 1;
                    break;
                }
                Tok::Close(_) => return None,
                _ => {}
            }
            let token = self.tokens.get(self.pos)?;
            let key_start = token.start;
            if is_struct || close == b'}' {
                let seg = match &token.tok {
                    Tok::Str(s) | Tok::Ident(s) => Some(Seg::Key(s.clone())),
                    Tok::Scalar => self
                        .text
                        .get(token.start..token.end)
                        .map(|s| Seg::Key(s.into())),
                    _ => None,
                };
                if seg.is_some() && self.peek(1) == Some(&Tok::Colon) {
                    self.pos += 2;
                    let child = self.child(node, seg, Some(key_start))?;
                    self.value(child, depth)?;
                } else if is_struct {
                    return None;
                } else {
                    // A compound map key: skip it and its value.
                    self.skip_value()?;
                    (self.peek(0) == Some(&Tok::Colon)).then_some(())?;
                    self.pos += 1;
                    self.skip_value()?;
                }
            } else {
                let child = self.child(node, Some(Seg::Index(count)), None)?;
                self.value(child, depth)?;
            }
            count += 1;
            match self.peek(0)? {
                Tok::Comma => self.pos += 1,
                Tok::Close(_) => {}
                _ => return None,
            }
        }
        let only = &self.tree.nodes[node].children;
        Some(match only.as_slice() {
            [(Seg::Index(0), child)] if close == b')' && !is_struct => Some(*child),
            _ => None,
        })
    }

    /// Skips one value (balanced brackets) without indexing or recursion.
    fn skip_value(&mut self) -> Option<()> {
        if matches!(self.peek(0)?, Tok::Ident(_)) && matches!(self.peek(1), Some(Tok::Open(_))) {
            self.pos += 1;
        }
        let mut depth = 0usize;
        loop {
            match self.peek(0)? {
                Tok::Open(_) => depth += 1,
                Tok::Close(_) if depth == 0 => return None,
                Tok::Close(_) => depth -= 1,
                Tok::Colon | Tok::Comma if depth == 0 => return None,
                _ => {}
            }
            self.pos += 1;
            if depth == 0 {
                return Some(());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    const RON: &str = r#"// demo
Scene(
    render: (width: 64, height: 48, samples_per_pixel: 4),
    camera: Pinhole(eye: (0, 1, 4), look_at: (0, 1, 0), up: (0, 1, 0), fov_y: 40),
    materials: {
        "glass": (color: (1, 1, 1), transmit: 1.0, ior: 1.5),
        "water": (color: (0.9, 0.95, 1.0), transmit: 0.9, reflect: 0.1, ior: -1.33),
    },
    lights: [
        Point(position: (0, 3, 0), power: (50, 50, 50)),
        Sphere(center: (1, 3, 0), radius: -0.1, power: (10, 10, 10)),
    ],
    nodes: [
        Group(transform: [Translate(0, 1, 0), Scale(0.5)], children: [
            Sphere(radius: 1.0, material: "glass"),
            Cube(material: "watr"),
        ]),
    ],
)
"#;

    const TOML: &str = r#"# demo
[render]
width = 64
height = 48
samples_per_pixel = 4

[camera.Pinhole]
eye = [0, 1, 4]
look_at = [0, 1, 0]
up = [0, 1, 0]
fov_y = 40

[materials.glass]
color = [1, 1, 1]
transmit = 1.0
ior = 1.5

[materials.water]
color = [0.9, 0.95, 1.0]
transmit = 0.9
reflect = 0.1
ior = -1.33

[[lights]]
Point = { position = [0, 3, 0], power = [50, 50, 50] }

[[lights]]
[lights.Sphere]
center = [1, 3, 0]
radius = -0.1
power = [10, 10, 10]

[[nodes]]
[nodes.Group]
transform = [{ Translate = [0, 1, 0] }, { Scale = 0.5 }]
children = [
    { Sphere = { radius = 1.0, material = "glass" } },
    { Cube = { material = "watr" } },
]
"#;

    /// Checks whitespace-separated `path@line:col` cases with `locate` (or `locate_key`).
    fn check(index: &SourceIndex, key: bool, cases: &str) {
        let mut bad = Vec::new();
        for case in cases.split_whitespace() {
            let (path, want) = case.rsplit_once('@').expect("case is path@line:col");
            let got = if key {
                index.locate_key(path)
            } else {
                index.locate(path)
            };
            let got = got.map(|l| format!("{}:{}", l.line, l.column));
            if got.as_deref() != Some(want) {
                bad.push(format!("{path}: got {got:?}, want {want}"));
            }
        }
        assert!(bad.is_empty(), "{bad:#?}");
    }

    fn ron(text: &str) -> SourceIndex {
        SourceIndex::build(text, SourceFormat::Ron)
    }

    fn toml(text: &str) -> SourceIndex {
        SourceIndex::build(text, SourceFormat::Toml)
    }

    #[test]
    fn ron_fields_map_keys_and_enum_variants() {
        let index = ron(RON);
        check(
            &index,
            false,
            "render@3:13 render.width@3:21 render.height@3:33 \
            camera@4:13 camera.fov_y@4:79 camera.Pinhole.fov_y@4:79 Scene.render.width@3:21 \
            materials.water.ior@7:78 materials.glass.color@6:26 lights[1]@11:9 \
            lights[1].radius@11:43 lights[1].center@11:24 lights[1].power[2]@11:65 \
            nodes[0].children[0]@15:13 nodes[0].children[0].radius@15:28 \
            nodes[0].children[1].material@16:28",
        );
        check(
            &index,
            true,
            "render.width@3:14 camera@4:5 camera.fov_y@4:72 \
            materials.water@7:9 materials.water.ior@7:73 lights[1].radius@11:35 \
            lights[1]@11:9 nodes[0].children@14:60",
        );
    }

    #[test]
    fn ron_tuple_variant_elements() {
        check(
            &ron(RON),
            false,
            "nodes[0].transform@14:26 nodes[0].transform[0]@14:27 \
            nodes[0].transform[1]@14:47 nodes[0].transform[0][0]@14:37 \
            nodes[0].transform[0][2]@14:43 nodes[0].transform[0].Translate[1]@14:40 \
            nodes[0].transform[1][0]@14:53",
        );
    }

    #[test]
    fn missing_paths_fall_back_or_give_none() {
        let index = ron(RON);
        check(
            &index,
            false,
            "materials.water.foo@7:18 materials.watr.ior@5:16 \
            lights[7].radius@9:13 nodes[0].children[1].material.deeper[3]@16:28 \
            render.width[0]@3:21",
        );
        // A missing field has no key, so locate_key falls back like locate.
        check(&index, true, "materials.water.foo@7:18");
        for path in ["foo", "foo.bar", "", "[0]", ".", "render2.width"] {
            assert_eq!(index.locate(path), None, "{path}");
            assert_eq!(index.locate_key(path), None, "{path}");
        }
    }

    #[test]
    fn toml_tables_arrays_of_tables_and_inline_tables() {
        let index = toml(TOML);
        check(
            &index,
            false,
            "render@2:1 render.width@3:9 camera@7:2 camera.fov_y@11:9 \
            camera.Pinhole.fov_y@11:9 materials.water@18:1 materials.water.ior@22:7 \
            lights[0]@24:1 lights[0].position@25:22 lights[0].Point.power[1]@25:46 \
            lights[1]@27:1 lights[1].radius@30:10 lights[1].Sphere.radius@30:10 \
            nodes[0].transform[0]@35:14 nodes[0].transform[0][1]@35:32 \
            nodes[0].transform[1][0]@35:51 nodes[0].children[0].radius@37:27 \
            nodes[0].children[1].material@38:27 nodes[0].children[1].oops@38:5 \
            materials.water.foo@18:1",
        );
        check(
            &index,
            true,
            "render.width@3:1 materials.water@18:12 lights[1].radius@30:1 \
            nodes[0].children[1].material@38:16 nodes[0].transform[0]@35:14",
        );
        assert_eq!(index.locate("scene.render"), None);
    }

    #[test]
    fn toml_dotted_keys() {
        let index = toml(
            "render.width = 64\ncamera.Pinhole.fov_y = 40\n\
            camera.Pinhole.eye = [0, 1, 4]\n\
            lights = [{ Sphere = { radius = -0.1 } }, { Point.power = 3 }]\n",
        );
        check(
            &index,
            false,
            "render.width@1:16 camera.fov_y@2:24 camera.eye[2]@3:29 \
            lights[0].radius@4:33 lights[1].power@4:59",
        );
        check(&index, true, "render.width@1:8 camera.fov_y@2:16");
    }

    #[test]
    fn toml_unparsable_finds_nothing() {
        let index = toml("a = [1, 2\nb = 3\n");
        assert_eq!(index.locate("b"), None);
        assert_eq!(
            index.location_of_offset(12),
            Location {
                line: 2,
                column: 3,
                offset: 12
            }
        );
    }

    #[test]
    fn ron_comments_strings_and_literals() {
        let index = ron("#![enable(implicit_some)]\n\
            ( // a comment with ( and \" and :\n\
            \x20 /* block ( \" : /* nested ) */ still \" */\n\
            \x20 a: \"x: ( \\\" y\", // (\n\
            \x20 b: r#\"raw \" ) \"#, c: '\"', e: '(',\n\
            \x20 d: [1e-3, -inf, NaN, 0x1F, +2, b\"x)\", b'(', r\"q\"],\n\
            \x20 m: {\"a.b\": 1, \"quo\\\"te\": 2, 7: 3, (1, 2): 4, \"k\": Some((z: 5))},\n\
            \x20 f: (),\n\
            )");
        check(
            &index,
            false,
            "a@4:6 b@5:6 c@5:24 e@5:32 d[1]@6:13 d[4]@6:30 d[7]@6:47 \
            m.\"a.b\"@7:14 m.quo\"te@7:28 m.7@7:34 m.k.z@7:62 m.k.Some.z@7:62 m.k[0].z@7:62 f@8:6",
        );
    }

    #[test]
    fn unclosed_brackets_and_payloads() {
        assert_eq!(ron_unclosed_bracket("S(\n a: [1, 2],\n"), Some((1, '(')));
        assert_eq!(ron_unclosed_bracket("S(a: [1, (2)\n"), Some((5, '[')));
        assert_eq!(ron_unclosed_bracket("S(a: \"(\" /* [ */)"), None);
        let index = ron("(t: [Scale((1, 2)), Translate(0, 1, 0)], s: 3)");
        check(&index, false, "t[0]@1:6 t[1]@1:21");
        let at = |p: &str| index.locate_payload(p).map(|l| l.column);
        assert_eq!(
            (at("t[0]"), at("t[1]"), at("s")),
            (Some(12), Some(30), Some(45))
        );
        let index = toml("t = [{ Scale = [1, 2] }]\n");
        assert_eq!(index.locate_payload("t[0]").map(|l| l.column), Some(16));
        assert!(index.contains("t[0]") && !index.contains("t[1]") && !index.contains("u"));
    }

    #[test]
    fn garbage_never_panics() {
        let pieces = [
            "(", ")", "[", "]", "{", "}", ":", ",", "\"", "'", "r#\"", "/*", "*/", "//", "\n",
            "\r\n", "a", "Foo", "é", "日本", "\\", "#![", "=", "[[x]]", "x.y", " ", "1.5", "-",
            "b'", "r#", "\0",
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
            for index in [ron(&text), toml(&text)] {
                for path in [
                    "a",
                    "a.b",
                    "x[0].y",
                    "Foo[1][2]",
                    "[",
                    "a..b[",
                    "a[99999999999999999999]",
                ] {
                    let _ = (index.locate(path), index.locate_key(path));
                }
                for offset in [0, 1, 2, 3, text.len(), text.len() + 10, usize::MAX] {
                    let loc = index.location_of_offset(offset);
                    assert!(loc.offset <= text.len() && loc.line >= 1 && loc.column >= 1);
                }
            }
        }
    }

    #[test]
    fn unterminated_string_and_comment() {
        check(&ron("(a: 1, b: \"abc é"), false, "a@1:5 b@1:11 b.c@1:11");
        check(&ron("(a: 1, /* open /* nested */ ("), false, "a@1:5");
        check(&ron("(a: 1, b: r##\"never é"), false, "b@1:11");
        check(&ron("(a: 'é"), false, "a@1:5");
        check(&ron("(a: [1, 2], b: (c: ]"), false, "a[1]@1:9 b.c@1:20");
    }

    #[test]
    fn deep_nesting_does_not_overflow() {
        let depth = 10_000;
        let index = ron(&format!("{}1{}", "[".repeat(depth), "]".repeat(depth)));
        check(&index, false, "[0][0]@1:3");
        let deep = index.locate(&"[0]".repeat(depth)).map(|l| l.column);
        assert_eq!(deep, Some(MAX_DEPTH + 1));
        let somes = "Some(".repeat(depth) + "1" + &")".repeat(depth);
        check(
            &ron(&format!("(a: {somes}, b: 2)")),
            false,
            "b@1:60011 a.x@1:5",
        );
        let arrays = format!("a = {}1{}", "[".repeat(depth), "]".repeat(depth));
        assert_eq!(toml(&arrays).locate("a"), None);
        let tables = format!("a = {}1{}", "{ A = ".repeat(depth), " }".repeat(depth));
        assert_eq!(toml(&tables).locate("a"), None);
    }

    #[test]
    fn crlf_line_endings() {
        let paths = "camera.fov_y@4:79 nodes[0].children[1].material@16:28";
        check(&ron(&RON.replace('\n', "\r\n")), false, paths);
        let paths = "camera.fov_y@11:9 lights[1].radius@30:10";
        check(&toml(&TOML.replace('\n', "\r\n")), false, paths);
    }

    #[test]
    fn columns_count_chars() {
        let index = ron("(name: \"héllo wörld 日本\", ñ: 1, x: 2)");
        check(&index, false, "x@1:35 ñ@1:29");
        assert_eq!(index.locate("x").map(|l| l.offset), Some(41));
        let index = toml("a = { s = \"日本語\", x = 5 }\n");
        check(&index, false, "a.x@1:22");
        // An offset inside a multi-byte char moves back to its start; past the end clamps.
        assert_eq!(
            index.location_of_offset(12),
            Location {
                line: 1,
                column: 12,
                offset: 11
            }
        );
        assert_eq!(index.location_of_offset(usize::MAX).line, 2);
    }
}
