//! `caustic farm cache DIR`: the first job's step. Builds the photon maps of the job's scene
//! once into `DIR/photons`, where every shard reads them (a no-op for integrators without
//! fixed photon maps); refuses a scene whose hash is no longer the planned one.

use std::path::Path;

use caustic::Error;
use caustic::farm::part_meta::settings_hash;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::{RenderJob, RenderOptions};

use super::manifest::{Manifest, PHOTONS, SCENE};

/// Builds the photon cache of job folder `dir` (after checking the scene still has the
/// planned hash), or says there is nothing to build.
pub fn run(dir: &Path, threads: Option<usize>) -> Result<(), Error> {
    let m = Manifest::read(dir)?;
    let prepared = prepare(&dir.join(SCENE), &SceneOverrides::default())?;
    let hash = settings_hash(&prepared.render_scene);
    if hash != m.hash_value()? {
        return Err(Error::Usage(format!(
            "`{}` now has settings hash {hash:016x}, not the planned {}: the scene or its assets changed since `caustic farm plan`; plan the job again",
            dir.join(SCENE).display(),
            m.hash
        )));
    }
    let options = RenderOptions {
        threads,
        photon_cache: Some(dir.join(PHOTONS)),
        ..RenderOptions::default()
    };
    let job = RenderJob::new(&prepared.render_scene, &options)?;
    match job.integrator().photon_maps() {
        Some(maps) => println!("{}", maps.summary),
        None => println!(
            "photon cache: nothing to build (the {} integrator has no fixed photon maps)",
            m.integrator
        ),
    }
    Ok(())
}
