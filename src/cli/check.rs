//! `caustic check`: parse, validate and load a scene without rendering.

use caustic::Error;
use caustic::pipeline::prepare;

use super::{SceneArgs, count, print_warnings, quadric_counts};

/// Reports every error of the scene, or a one-line summary of what it holds.
pub fn run(args: &SceneArgs) -> Result<(), Error> {
    let prepared = prepare(&args.scene, &args.overrides())?;
    print_warnings(&prepared.warnings);
    let s = &prepared.stats;
    println!(
        "{}: ok ({}, {}, {}{}, {}, {}; {})",
        args.scene.display(),
        count(s.triangles, "triangle"),
        count(s.spheres, "sphere"),
        count(s.ellipsoids, "ellipsoid"),
        quadric_counts(s),
        count(s.materials, "material"),
        count(s.lights, "light"),
        count(prepared.warnings.len(), "warning"),
    );
    Ok(())
}
