//! Building small scenes from text and rendering them.

use std::path::Path;

use caustic::compile::compile;
use caustic::render::{Film, RenderOptions, RenderStats, render};
use caustic::render_scene::RenderScene;
use caustic::scene::SourceFile;
use caustic::scene::validate::validate;

/// Parses, validates (no errors allowed) and compiles a RON scene given as text.
pub fn scene(text: &str) -> RenderScene {
    let src = SourceFile::new(Path::new("hard_case.ron"), text.to_string()).expect("ron");
    let file = src.parse().unwrap_or_else(|e| panic!("{e}\n{text}"));
    let diags = validate(&file);
    assert!(!diags.iter().any(|d| d.is_error()), "{diags:?}");
    compile(&file, Path::new(".")).expect("compiles").0
}

/// Renders with default options.
pub fn render_text(text: &str) -> (Film, RenderStats) {
    let s = scene(text);
    let out = render(&s, &RenderOptions::default()).expect("renders");
    (out.film, out.stats)
}

/// Formats a float for embedding in RON.
pub fn f(x: f64) -> String {
    format!("{x:e}")
}
