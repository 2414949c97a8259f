//! Robustness of the front end: randomly mutated versions of every shipped scene go through
//! parse → validate → compile without a panic (they may, of course, be rejected).

use crate::common;

use std::path::Path;

use caustic::compile::compile;
use caustic::scene::SourceFile;
use caustic::scene::validate::validate;
use proptest::prelude::*;

/// Fragments that tend to reach interesting code: odd numbers, brackets, names, keywords.
const FRAGMENTS: &[&str] = &[
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "-1",
    "0",
    "1e-45",
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ":",
    "=",
    "\"",
    "\"x\"",
    "Sphere(",
    "Group(children: [",
    "Scale(0)",
    "Scale((0, 1, 1))",
    "Mesh(file: \"nope.obj\", material: \"x\")",
    "Some(",
    "r#\"",
    "/*",
    "//",
    "\n",
    "[[nodes]]",
    "material",
    "radius: -3",
    "width: 0",
    "4294967296",
    "é",
];

#[derive(Debug, Clone)]
enum Mutation {
    Delete { at: usize, len: usize },
    Insert { at: usize, fragment: usize },
    Duplicate { at: usize, len: usize },
    Truncate { at: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1usize..20).prop_map(|(at, len)| Mutation::Delete { at, len }),
        (any::<usize>(), 0..FRAGMENTS.len())
            .prop_map(|(at, fragment)| Mutation::Insert { at, fragment }),
        (any::<usize>(), 1usize..80).prop_map(|(at, len)| Mutation::Duplicate { at, len }),
        any::<usize>().prop_map(|at| Mutation::Truncate { at }),
    ]
}

fn apply(text: &str, muts: &[Mutation]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for m in muts {
        let n = chars.len().max(1);
        match *m {
            Mutation::Delete { at, len } => {
                let at = at % n;
                let end = (at + len).min(chars.len());
                chars.drain(at.min(end)..end);
            }
            Mutation::Insert { at, fragment } => {
                let at = (at % n).min(chars.len());
                chars.splice(at..at, FRAGMENTS[fragment].chars());
            }
            Mutation::Duplicate { at, len } => {
                let at = at % n;
                let end = (at + len).min(chars.len());
                let piece: Vec<char> = chars[at.min(end)..end].to_vec();
                chars.splice(end..end, piece);
            }
            Mutation::Truncate { at } => chars.truncate(at % n),
        }
    }
    chars.into_iter().collect()
}

/// The front half of `caustic render`, on text instead of a file.
fn front_end(path: &Path, text: String) {
    let Ok(src) = SourceFile::new(path, text) else {
        return;
    };
    let Ok(scene) = src.parse() else { return };
    let diags = validate(&scene);
    let _ = src.locate(diags.clone());
    if diags.iter().any(|d| d.is_error()) {
        return;
    }
    let base = path.parent().unwrap_or(Path::new("."));
    let _ = compile(&scene, base);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_scenes_never_panic(scene in 0usize..16, muts in proptest::collection::vec(mutation(), 1..6)) {
        let files = common::scene_files();
        let path = &files[scene % files.len()];
        let text = std::fs::read_to_string(path).expect("scene");
        front_end(path, apply(&text, &muts));
    }
}
