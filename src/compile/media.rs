//! Participating media: the scene's `media` compiled to [`HomogeneousMedium`]s (indexed in the
//! map's name order) and the scene-wide `medium`.

use glam::Vec3;

use crate::render_scene::HomogeneousMedium;
use crate::scene::SceneFile;
use crate::shading::phase::HenyeyGreenstein;

/// The media in name order, and the index of the scene's `medium` (validated names; an
/// unknown one, which validation reports, is none).
pub(super) fn compile_media(scene: &SceneFile) -> (Vec<HomogeneousMedium>, Option<u32>) {
    let media = scene
        .media
        .values()
        .map(|m| {
            let (sigma_a, sigma_s) = m.coefficients();
            HomogeneousMedium {
                sigma_a: Vec3::from(sigma_a).max(Vec3::ZERO),
                sigma_s: Vec3::from(sigma_s).max(Vec3::ZERO),
                phase: HenyeyGreenstein { g: m.g },
            }
        })
        .collect();
    let camera = scene.medium.as_deref().and_then(|n| medium_index(scene, n));
    (media, camera)
}

/// The index of medium `name` among the scene's media.
pub(super) fn medium_index(scene: &SceneFile, name: &str) -> Option<u32> {
    scene.media.keys().position(|k| k == name).map(|i| i as u32)
}
