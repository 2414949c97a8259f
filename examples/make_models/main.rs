//! Regenerates the bath scene's models, `assets/duck.obj`, `assets/boat.obj` and
//! `assets/faucet.obj`, from the
//! implicit surfaces in `models.rs` (nothing is downloaded): `scripts/make_models.sh`, or
//! `cargo run --release --example make_models`.
//!
//! Refuses to write a model with a degenerate or inverted triangle, an open or inconsistently
//! wound edge, a non-manifold vertex or inward winding (see `mesher::check`), listing every
//! problem. `tests/it/models.rs` checks the committed files are exactly what this writes.

mod mesher;
mod models;
mod sdf;

use std::path::Path;
use std::process::ExitCode;

/// Writes `text` to `path` through a temporary file beside it, renamed into place.
fn write_atomic(path: &Path, text: &str) -> std::io::Result<()> {
    let tmp = path.with_extension("obj.tmp");
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    let mut failed = false;
    for (file, make) in [
        (
            "duck.obj",
            models::duck_obj as fn() -> Result<String, Vec<String>>,
        ),
        ("boat.obj", models::boat_obj),
        ("faucet.obj", models::faucet_obj),
    ] {
        let t = std::time::Instant::now();
        match make() {
            Ok(text) => {
                let path = root.join(file);
                if let Err(e) = write_atomic(&path, &text) {
                    eprintln!("error: cannot write {}: {e}", path.display());
                    failed = true;
                    continue;
                }
                let count = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
                println!(
                    "assets/{file}: {} vertices, {} triangles, {} bytes, in {:.2?}",
                    count("v "),
                    count("f "),
                    text.len(),
                    t.elapsed()
                );
            }
            Err(problems) => {
                eprintln!(
                    "error: assets/{file} not written: {} problems",
                    problems.len()
                );
                for p in problems.iter().take(20) {
                    eprintln!("  {p}");
                }
                failed = true;
            }
        }
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
