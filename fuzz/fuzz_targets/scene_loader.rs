//! Arbitrary bytes as a RON or TOML scene: parse, validate, locate diagnostics, compile.
#![no_main]

use std::path::Path;

use caustic::compile::compile;
use caustic::scene::SourceFile;
use caustic::scene::validate::validate;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&selector, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let name = if selector & 1 == 0 {
        "fuzz.ron"
    } else {
        "fuzz.toml"
    };
    let Ok(src) = SourceFile::new(Path::new(name), text.to_string()) else {
        return;
    };
    let scene = match src.parse() {
        Ok(s) => s,
        Err(e) => {
            let _ = e.to_string();
            return;
        }
    };
    let diags = validate(&scene);
    let located = src.locate(diags);
    for d in &located {
        let _ = d.to_string();
    }
    if located.iter().any(|d| d.is_error()) {
        return;
    }
    // Meshes resolve against an empty directory: missing files are reported, not read.
    let _ = compile(&scene, Path::new("/nonexistent-caustic-fuzz"));
});
