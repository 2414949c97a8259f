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
    // Plain image arrays in, an image out: the denoiser knows no scene or render, so the
    // render job (and every layer above it) may call it.
    ("src/denoise", &[]),
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
            "denoise",
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
            "denoise",
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
            "denoise",
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

/// The `src/…` paths that `docs/architecture.md` names in backticks, each with whether the page
/// marks it as a file a recipe creates (`` `src/x.rs` (new) ``).
fn architecture_doc_paths(doc: &str) -> Vec<(String, bool)> {
    let mut out = Vec::new();
    for (i, piece) in doc.split('`').enumerate() {
        if i % 2 == 1 && piece.starts_with("src/") {
            let after = doc.split('`').nth(i + 1).unwrap_or("");
            out.push((piece.to_string(), after.starts_with(" (new)")));
        }
    }
    out
}

#[test]
fn every_module_the_architecture_page_names_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).expect("read the page");
    let paths = architecture_doc_paths(&doc);
    assert!(
        paths.len() > 20,
        "the page names only {} paths",
        paths.len()
    );
    for (path, new) in &paths {
        let exists = root.join(path).exists();
        if *new {
            assert!(
                !exists,
                "{path} is marked (new) but exists: name another example"
            );
        } else {
            assert!(
                exists,
                "docs/architecture.md names {path}, which does not exist"
            );
        }
    }
    // Every layered module has its line in the page's table.
    for (dir, _) in RULES {
        assert!(
            doc.contains(&format!("| `{dir}` |")) || doc.contains(&format!("| `{dir}.rs` |")),
            "docs/architecture.md has no table row for {dir}"
        );
    }
}

#[test]
fn each_recipe_of_the_architecture_page_touches_at_most_three_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).expect("read the page");
    let recipes: Vec<&str> = doc.split("\n### ").skip(1).collect();
    assert_eq!(recipes.len(), 3, "an integrator, a light, a lobe");
    for recipe in recipes {
        let title = recipe.lines().next().unwrap_or("");
        let body = recipe.split("\n## ").next().unwrap_or("");
        // A numbered step with its indented continuation lines.
        let mut steps: Vec<String> = Vec::new();
        for line in body.lines() {
            if line.len() > 2 && line.as_bytes()[0].is_ascii_digit() && &line[1..3] == ". " {
                steps.push(line.to_string());
            } else if let (Some(last), true) = (steps.last_mut(), line.starts_with("   ")) {
                last.push(' ');
                last.push_str(line.trim());
            }
        }
        assert!(
            (1..=3).contains(&steps.len()),
            "recipe {title}: {} steps",
            steps.len()
        );
        for step in steps {
            let named = architecture_doc_paths(&step);
            assert_eq!(
                named.len(),
                1,
                "recipe {title}: each step changes one file: {step}"
            );
        }
    }
}
