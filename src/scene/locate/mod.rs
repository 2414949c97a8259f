//! Maps dotted field paths in a scene file back to line/column positions.
//!
//! A [`SourceIndex`] is built once per source text. It holds a small tree of
//! every value found in the text (struct fields, map entries, list and tuple
//! elements) with the byte offsets of each value and of its key. Enum variants
//! (`Sphere(radius: 1)` in RON, `{ Sphere = { radius = 1 } }` in TOML) and
//! `Some(..)` are transparent in paths, but may also be named explicitly.
//! Everything is best effort: unparsable input yields an index that finds less.

mod ron;
mod toml;

/// Maximum nesting indexed; deeper values are skipped without recursion.
const MAX_DEPTH: usize = 256;

pub use super::lexer::SourceFormat;

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
            SourceFormat::Ron => ron::tree(text),
            SourceFormat::Toml => toml::tree(text),
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

#[cfg(test)]
mod tests;
