//! `caustic check`: parse, validate and load a scene without rendering.

use caustic::Error;
use caustic::pipeline::prepare;

use super::{SceneArgs, print_warnings};

/// Reports every error of the scene, or a one-line summary of what it holds.
pub fn run(args: &SceneArgs) -> Result<(), Error> {
    let prepared = prepare(&args.scene, &args.overrides())?;
    print_warnings(&prepared.warnings);
    let s = &prepared.stats;
    println!(
        "{}: ok ({} triangles, {} spheres, {} ellipsoids, {} materials, {} lights; {} warning{})",
        args.scene.display(),
        s.triangles,
        s.spheres,
        s.ellipsoids,
        s.materials,
        s.lights,
        prepared.warnings.len(),
        if prepared.warnings.len() == 1 {
            ""
        } else {
            "s"
        }
    );
    Ok(())
}
