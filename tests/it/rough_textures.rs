//! Roughness from a texture (issue 26): a texture's mean channel is the isotropic roughness r
//! at each hit (GGX α = r²), so a constant texture equals the constant roughness bit for bit,
//! a black one is the smooth material, and a varying one roughens each hit by its own value.

use glam::Vec3;

use caustic::geometry::Ray;
use caustic::render_scene::{Interaction, RenderScene};

use crate::common::scene_from_text;

/// One sphere of material `m` (with textures `textures`) seen by a camera on +z.
fn ball(m: &str, textures: &str) -> RenderScene {
    scene_from_text(&format!(
        r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, integrator: Path),
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 30),
    textures: {{ {textures} }},
    materials: {{ "m": {m} }},
    lights: [ Point(position: (0, 3, 3), power: (10, 10, 10)) ],
    nodes: [ Sphere(material: "m", center: (0, 0, 0), radius: 1) ],
)"#
    ))
}

/// The BSDF at the hit of the ray from (x, y, 4) towards −z.
fn bsdf_at(scene: &RenderScene, x: f32, y: f32) -> caustic::shading::Bsdf {
    let ray = Ray::new(Vec3::new(x, y, 4.0), -Vec3::Z);
    let mut textured = None;
    match scene.interact(&ray, |_| 0.0, &mut textured) {
        Interaction::Surface(v) => *v.bsdf,
        other => panic!("({x}, {y}) missed the ball: {other:?}"),
    }
}

const POINTS: [(f32, f32); 4] = [(0.0, 0.0), (0.3, -0.2), (-0.5, 0.4), (0.6, 0.6)];

#[test]
fn a_constant_roughness_texture_equals_the_constant_roughness_bit_for_bit() {
    let grey =
        r#""grey": Noise(low: (0.3, 0.3, 0.3), high: (0.3, 0.3, 0.3), frequency: 3, seed: 1)"#;
    for (kind, extra) in [
        ("gold", r#"diffuse: 0, reflect: 1, conductor: "gold""#),
        (
            "tinted mirror",
            r#"color: (0.9, 0.7, 0.5), diffuse: 0, reflect: 1"#,
        ),
        (
            "glass",
            r#"color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5"#,
        ),
    ] {
        let constant = ball(&format!("({extra}, roughness: 0.3)"), "");
        let textured = ball(&format!(r#"({extra}, roughness: "grey")"#), grey);
        for (x, y) in POINTS {
            let (a, b) = (bsdf_at(&constant, x, y), bsdf_at(&textured, x, y));
            assert_eq!(a, b, "{kind} at ({x}, {y})");
            let g = b.distribution().expect("rough");
            assert_eq!((g.alpha_x, g.alpha_y), (0.09, 0.09), "{kind}: α = 0.3²");
        }
    }
}

#[test]
fn a_black_roughness_texture_is_the_smooth_material_and_a_varying_one_follows_its_texels() {
    let black = r#""black": Noise(low: (0, 0, 0), high: (0, 0, 0), frequency: 3, seed: 1)"#;
    let extra = r#"color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5"#;
    let smooth = ball(&format!("({extra})"), "");
    let textured = ball(&format!(r#"({extra}, roughness: "black")"#), black);
    for (x, y) in POINTS {
        assert_eq!(
            bsdf_at(&smooth, x, y),
            bsdf_at(&textured, x, y),
            "({x}, {y})"
        );
        assert!(bsdf_at(&textured, x, y).distribution().is_none());
    }
    // Noise between 0.1 and 0.7 (grey): α at each hit is the square of the texture's value
    // there, which the colour of the same texture on a diffuse ball reports.
    let noise = r#""n": Noise(low: (0.1, 0.1, 0.1), high: (0.7, 0.7, 0.7), frequency: 2, octaves: 3, seed: 4)"#;
    let rough = ball(
        r#"(diffuse: 0, reflect: 1, conductor: "chrome", roughness: "n")"#,
        noise,
    );
    let painted = ball(r#"(color: "n")"#, noise);
    let mut alphas = Vec::new();
    for (x, y) in POINTS {
        let r = bsdf_at(&painted, x, y).color().x;
        let g = bsdf_at(&rough, x, y).distribution().expect("rough");
        assert!((0.1..=0.7).contains(&r), "texel {r}");
        assert_eq!((g.alpha_x, g.alpha_y), (r * r, r * r), "({x}, {y})");
        alphas.push(g.alpha_x);
    }
    assert!(
        alphas.iter().any(|&a| (a - alphas[0]).abs() > 1e-3),
        "the noise varies: {alphas:?}"
    );
}
