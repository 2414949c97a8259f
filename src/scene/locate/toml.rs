//! The TOML side of the path index: a walk over `toml_edit`'s document.

use toml_edit::{Item, TableLike, Value};

use super::{MAX_DEPTH, Seg, Tree, Wrapper};

pub(super) fn tree(text: &str) -> Tree {
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
