//! Building small scenes from text and rendering them.

use caustic::render::{Film, RenderOptions, RenderStats, render};

pub use crate::common::scene_from_text as scene;

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
