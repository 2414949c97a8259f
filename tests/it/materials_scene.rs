//! Issue 26's materials at the scene level: `scenes/materials.ron` and its TOML twin are the same
//! scene and render the same bytes, and a material of roughness 0 (written `0` or `(0, 0)`) is
//! the smooth material bit for bit — the same BSDF at every hit and the same image under every
//! integrator — for a tinted mirror, glass, absorbing water, a mixture of all three and a
//! polished conductor. (The lobes' own χ², energy and reciprocity tests are unit tests under
//! `src/shading/`.)

use glam::Vec3;

use caustic::geometry::Ray;
use caustic::render::{RenderOptions, render};
use caustic::render_scene::{Interaction, RenderScene};

use crate::common::{self, scene_from_text};

#[test]
fn materials_ron_and_toml_are_twins_and_render_identical_bytes() {
    let ron = common::root().join("scenes/materials.ron");
    let toml = common::root().join("scenes/materials.toml");
    let a = caustic::scene::load::load(&ron).expect("ron loads").scene;
    let b = caustic::scene::load::load(&toml).expect("toml loads").scene;
    assert_eq!(a, b, "the twins parse to different scenes");
    let o = common::small(48, 18, 2);
    let (fa, _) = common::render_file(&ron, &o, &RenderOptions::default());
    let (fb, _) = common::render_file(&toml, &o, &RenderOptions::default());
    assert!(
        fa.to_bytes() == fb.to_bytes(),
        "the twins render different pixels"
    );
}

/// A ball of material `m` on a grey floor, under a point light, rendered by `integrator`.
fn ball(m: &str, integrator: &str) -> RenderScene {
    scene_from_text(&format!(
        r#"Scene(
    render: (width: 12, height: 10, samples_per_pixel: 2, max_depth: 6, seed: 3, integrator: {integrator}),
    photons: (global: 2000, caustic: 2000),
    camera: Pinhole(eye: (0, 1, 4), look_at: (0, 0.5, 0), fov_y: 35),
    materials: {{ "grey": (color: (0.5, 0.5, 0.5)), "m": {m} }},
    lights: [ Point(position: (1, 3, 2), power: (60, 60, 60)) ],
    nodes: [
        Quad(material: "grey", size: (6, 6), transform: [RotateX(-90)]),
        Sphere(material: "m", center: (0, 0.5, 0), radius: 0.5),
    ],
)"#
    ))
}

/// The BSDF at the ball's hit of the ray from (x, y, 4) towards the ball's centre.
fn bsdf_at(scene: &RenderScene, x: f32, y: f32) -> caustic::shading::Bsdf {
    let o = Vec3::new(x, y, 4.0);
    let ray = Ray::new(o, (Vec3::new(0.0, 0.5, 0.0) - o).normalize());
    let mut textured = None;
    match scene.interact(&ray, |_| 0.0, &mut textured) {
        Interaction::Surface(v) => *v.bsdf,
        other => panic!("({x}, {y}) missed the ball: {other:?}"),
    }
}

#[test]
fn roughness_zero_is_the_smooth_material_bit_for_bit_in_every_integrator() {
    let materials = [
        (
            "tinted mirror",
            "color: (0.9, 0.7, 0.5), diffuse: 0, reflect: 1",
        ),
        (
            "glass",
            "color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5",
        ),
        (
            "water",
            "color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.33, absorption: (2, 0.4, 0.2)",
        ),
        (
            "mixture",
            "color: (0.8, 0.6, 0.4), diffuse: 0.3, reflect: 0.3, transmit: 0.4, ior: 1.4",
        ),
        (
            "polished gold",
            r#"diffuse: 0, reflect: 1, conductor: "gold""#,
        ),
    ];
    let integrators = ["Whitted", "Path", "Photon", "Ppm", "PathPpm"];
    for (kind, fields) in materials {
        for zero in ["0", "(0, 0)"] {
            let smooth = ball(&format!("({fields})"), "Path");
            let zeroed = ball(&format!("({fields}, roughness: {zero})"), "Path");
            for (x, y) in [(0.0, 0.5), (0.2, 0.7), (-0.3, 0.3), (0.4, 0.9)] {
                let b = bsdf_at(&zeroed, x, y);
                assert_eq!(bsdf_at(&smooth, x, y), b, "{kind}, roughness {zero}");
                assert!(b.distribution().is_none(), "{kind}: no microfacets");
            }
            for integrator in integrators {
                let image = |m: &str| {
                    let scene = ball(m, integrator);
                    render(&scene, &RenderOptions::default())
                        .expect("renders")
                        .film
                        .to_bytes()
                };
                assert!(
                    image(&format!("({fields})"))
                        == image(&format!("({fields}, roughness: {zero})")),
                    "{kind}, roughness {zero}, {integrator}: different bytes"
                );
            }
        }
    }
}
