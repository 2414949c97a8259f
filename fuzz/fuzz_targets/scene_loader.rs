//! Arbitrary bytes as a RON or TOML scene: parse, validate, locate diagnostics, compile, and
//! shade a few primary-ray hits (textures, bump mapping, footprints).
//!
//! Scenes compile against the repository's `scenes/` directory, so the demo scenes' textures and
//! meshes (`../assets/…`) load; file references that would leave the repository's `assets/`,
//! `scenes/` and `tests/` directories (absolute paths, `/dev/zero`, …) are not followed.
#![no_main]

use std::path::{Component, Path};

use caustic::compile::compile;
use caustic::scene::SourceFile;
use caustic::scene::schema::{NodeSpec, SceneFile, TextureSpec};
use caustic::scene::validate::validate;
use libfuzzer_sys::fuzz_target;

/// The directory scene files are compiled from: `<repo>/scenes`.
const SCENES_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes");

/// Whether `file`, relative to `scenes/`, stays inside the repository's `assets/`, `scenes/` or
/// `tests/`.
fn confined(file: &str) -> bool {
    // Lexically resolved from the repository root, starting in `scenes/`.
    let mut parts = vec!["scenes".to_string()];
    for c in Path::new(file).components() {
        match c {
            Component::Normal(s) => parts.push(s.to_string_lossy().into_owned()),
            Component::CurDir => {}
            Component::ParentDir => {
                if parts.pop().is_none() {
                    return false;
                }
            }
            Component::RootDir | Component::Prefix(_) => return false,
        }
    }
    parts.len() >= 2 && matches!(parts[0].as_str(), "assets" | "scenes" | "tests")
}

fn files_confined(scene: &SceneFile) -> bool {
    fn nodes_ok(nodes: &[NodeSpec]) -> bool {
        nodes.iter().all(|n| match n {
            NodeSpec::Mesh { file, .. } => confined(file),
            NodeSpec::Group { children, .. } => nodes_ok(children),
            _ => true,
        })
    }
    scene.textures.values().all(|t| match t {
        TextureSpec::Bitmap { file, .. } | TextureSpec::HeightMap { file, .. } => confined(file),
        _ => true,
    }) && nodes_ok(&scene.nodes)
}

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
    if located.iter().any(|d| d.is_error()) || !files_confined(&scene) {
        return;
    }
    let Ok((rs, _)) = compile(&scene, Path::new(SCENES_DIR)) else {
        return;
    };
    // A 4×4 grid of primary rays: whatever they hit is shaded as the integrators do, with the
    // ray cone's width at the hit and with width 0.
    let spread = rs.pixel_spread();
    for j in 0..4 {
        for i in 0..4 {
            let ray = rs.camera.ray(i as f32 + 0.5, j as f32 + 0.5, 4, 4);
            let Some(hit) = rs.geometry.intersect(&ray) else {
                continue;
            };
            let sp = rs.geometry.surface(&ray, &hit);
            let Some(m) = rs.objects[sp.object as usize].material else {
                continue;
            };
            let wo = -ray.dir.normalize();
            for width in [spread * hit.t, 0.0] {
                let s = rs.shading_point(&rs.materials[m as usize], &sp, wo, width);
                if sp.p.is_finite() && sp.uv.is_finite() {
                    assert!(
                        s.bsdf.color().is_finite(),
                        "colour {} at {sp:?}",
                        s.bsdf.color()
                    );
                    assert!(
                        s.ns.is_finite() && (s.ns.length() - 1.0).abs() < 1e-3,
                        "shading normal {} at {sp:?}",
                        s.ns
                    );
                }
            }
        }
    }
});
