//! The RON side of the path index: a small recursive parser over the lexer's tokens.

use super::super::lexer::{SourceFormat, Tok, Token, lex_code};
use super::{MAX_DEPTH, Seg, Tree, Wrapper};

pub(super) fn tree(text: &str) -> Tree {
    let mut parser = RonParser {
        text,
        tokens: lex_code(text, SourceFormat::Ron),
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
                    Tok::Str(s) => Some(Seg::Key(s.value.clone())),
                    Tok::Ident(s) => Some(Seg::Key(s.clone())),
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
