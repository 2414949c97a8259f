//! The layering rule, checked on the source: lower layers never import upper ones. Each module
//! lists the crate modules it may use (a whitelist, so a new module is forbidden until placed);
//! `crate::a::b`, grouped `crate::{a::b, c}` (across lines) and `caustic::` paths all count;
//! unit tests (after a file's `#[cfg(test)]`) are exempt.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Bottom-layer modules every layer may use; they use no crate module themselves (`settings`:
/// the enums the scene format, the command line and the compiled scene share).
const EVERY_LAYER: &[&str] = &["settings"];

/// (module directory or single-file module without `.rs`, crate modules it may use besides
/// itself and [`EVERY_LAYER`]), lowest layer first.
const RULES: &[(&str, &[&str])] = &[
    ("src/settings", &[]),
    ("src/binfile", &[]),
    ("src/geometry", &[]),
    ("src/sampling", &["geometry"]),
    ("src/texture", &["geometry", "sampling"]),
    ("src/shading", &["geometry", "sampling"]),
    ("src/accel", &["geometry", "sampling"]),
    ("src/spatial", &["geometry", "sampling"]),
    ("src/bench", &["geometry", "sampling", "accel"]),
    (
        "src/render_scene",
        &[
            "binfile", "geometry", "sampling", "texture", "shading", "accel",
        ],
    ),
    (
        "src/integrators",
        &[
            "binfile",
            "geometry",
            "sampling",
            "texture",
            "shading",
            "accel",
            "spatial",
            "render_scene",
        ],
    ),
    (
        "src/render",
        &[
            "binfile",
            "geometry",
            "sampling",
            "texture",
            "shading",
            "accel",
            "spatial",
            "render_scene",
            "integrators",
        ],
    ),
    (
        "src/analysis",
        &[
            "binfile",
            "geometry",
            "sampling",
            "texture",
            "shading",
            "accel",
            "spatial",
            "render_scene",
            "integrators",
            "render",
        ],
    ),
    (
        "src/farm",
        &[
            "binfile",
            "geometry",
            "sampling",
            "texture",
            "shading",
            "accel",
            "spatial",
            "render_scene",
            "integrators",
            "render",
        ],
    ),
    ("src/scene", &[]),
    (
        "src/compile",
        &[
            "binfile",
            "geometry",
            "sampling",
            "texture",
            "shading",
            "accel",
            "spatial",
            "render_scene",
            "scene",
        ],
    ),
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("source dir") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

fn ident(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The top-level crate modules `text` names through `crate::` (or `caustic::`), including every
/// item of grouped imports such as `use crate::{a::x, b::{y, z}};`.
fn used_modules(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for prefix in ["crate::", "caustic::"] {
        let mut rest = text;
        while let Some(i) = rest.find(prefix) {
            rest = &rest[i + prefix.len()..];
            let after = rest.trim_start();
            if let Some(group) = after.strip_prefix('{') {
                // Top-level items of the group, up to its matching brace.
                let (mut depth, mut item_start, mut items) = (0i32, 0usize, Vec::new());
                for (k, c) in group.char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' if depth == 0 => {
                            items.push(&group[item_start..k]);
                            break;
                        }
                        '}' => depth -= 1,
                        ',' if depth == 0 => {
                            items.push(&group[item_start..k]);
                            item_start = k + 1;
                        }
                        _ => {}
                    }
                }
                for item in items {
                    let name = ident(item.trim());
                    if !name.is_empty() {
                        out.insert(name.to_string());
                    }
                }
            } else {
                let name = ident(after);
                if !name.is_empty() {
                    out.insert(name.to_string());
                }
            }
        }
    }
    out
}

#[test]
fn the_import_scanner_sees_grouped_and_multi_line_imports() {
    let text = "use crate::{\n    render::Film,\n    shading::{Bsdf, ShadingFrame},\n};\nfn f() { crate::scene::x(); }";
    let got: Vec<String> = used_modules(text).into_iter().collect();
    assert_eq!(got, ["render", "scene", "shading"]);
}

#[test]
fn lower_layers_do_not_import_upper_ones() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut violations = Vec::new();
    for (dir, allowed) in RULES {
        let me = dir.trim_start_matches("src/");
        let single = root.join(format!("{dir}.rs"));
        let mut files = Vec::new();
        if root.join(dir).is_dir() {
            rust_files(&root.join(dir), &mut files);
        } else if single.is_file() {
            files.push(single);
        } else {
            continue;
        }
        // The bottom layer may not use itself as an excuse to import anything.
        let every_layer: &[&str] = if EVERY_LAYER.contains(&me) {
            &[]
        } else {
            EVERY_LAYER
        };
        assert!(!files.is_empty(), "{dir} has no sources");
        for file in files {
            let text = std::fs::read_to_string(&file).expect("read");
            // Unit tests (by convention the file's last item, after `#[cfg(test)]`) may borrow
            // helpers from any layer: only the code that ships is layered.
            let shipped = text.split("#[cfg(test)]").next().unwrap_or("");
            for m in used_modules(shipped) {
                // `Error` etc. at the crate root are glue, not layers.
                if m == me
                    || allowed.contains(&m.as_str())
                    || every_layer.contains(&m.as_str())
                    || m.chars().next().is_some_and(char::is_uppercase)
                {
                    continue;
                }
                violations.push(format!("{}: uses `crate::{m}`", file.display()));
            }
        }
    }
    assert!(violations.is_empty(), "{violations:#?}");
    // Every module folder has a place in the layering (the binary's `cli` uses them all).
    for entry in std::fs::read_dir(root.join("src")).expect("src") {
        let path = entry.expect("entry").path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if path.is_dir() && name != "cli" {
            assert!(
                RULES
                    .iter()
                    .any(|(d, _)| d.trim_start_matches("src/") == name),
                "src/{name} has no layering rule"
            );
        }
    }
}
