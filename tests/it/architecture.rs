//! The layering rule, checked on the source: lower layers never import upper ones.

use std::path::Path;

/// (module directory, crate paths it must not use)
const RULES: &[(&str, &[&str])] = &[
    (
        "src/geometry",
        &[
            "crate::accel",
            "crate::render",
            "crate::scene",
            "crate::compile",
            "crate::shading",
            "crate::pipeline",
        ],
    ),
    (
        "src/accel",
        &[
            "crate::render",
            "crate::scene",
            "crate::compile",
            "crate::shading",
            "crate::pipeline",
        ],
    ),
    (
        "src/sampling",
        &[
            "crate::accel",
            "crate::render",
            "crate::scene",
            "crate::compile",
            "crate::pipeline",
        ],
    ),
    (
        "src/shading",
        &[
            "crate::accel",
            "crate::render",
            "crate::scene",
            "crate::compile",
            "crate::pipeline",
        ],
    ),
    (
        "src/render_scene",
        &[
            "crate::render::",
            "crate::scene",
            "crate::compile",
            "crate::pipeline",
        ],
    ),
    (
        "src/render",
        &["crate::scene", "crate::compile", "crate::pipeline"],
    ),
    (
        "src/scene",
        &[
            "crate::render",
            "crate::compile",
            "crate::accel",
            "crate::pipeline",
        ],
    ),
];

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("source dir") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn lower_layers_do_not_import_upper_ones() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut violations = Vec::new();
    for (dir, forbidden) in RULES {
        let mut files = Vec::new();
        rust_files(&root.join(dir), &mut files);
        assert!(!files.is_empty(), "{dir} has no sources");
        for file in files {
            let text = std::fs::read_to_string(&file).expect("read");
            for (n, line) in text.lines().enumerate() {
                for f in *forbidden {
                    if line.contains(f) {
                        violations.push(format!("{}:{}: uses `{f}`", file.display(), n + 1));
                    }
                }
            }
        }
    }
    assert!(violations.is_empty(), "{violations:#?}");
}
