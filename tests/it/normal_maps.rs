//! Tangent-space normal maps through the whole pipeline (scene text → compile → hit → shading
//! point → image): a flat map changes nothing, bit for bit; a constant tilted map tilts the
//! shading normal by the texel's closed-form angle, towards +u and up the image; and the
//! committed `assets/tiles_normal.png` (made from `assets/tiles_height.png` by
//! `examples/gen_assets`) shades like the bump of that height map.

use crate::common;

use std::path::PathBuf;

use caustic::geometry::Ray;
use caustic::render::{RenderOptions, render};
use caustic::render_scene::RenderScene;
use glam::Vec3;

/// A 4×4 PNG of one RGB value, written once per test process.
fn constant_png(rgb: [u8; 3]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustic-normal-maps-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(format!("n{}_{}_{}.png", rgb[0], rgb[1], rgb[2]));
    if !path.exists() {
        let img = image::RgbImage::from_pixel(4, 4, image::Rgb(rgb));
        let tmp = dir.join(format!("{rgb:?}.{:?}.png", std::thread::current().id()));
        img.save(&tmp).expect("png saved");
        std::fs::rename(&tmp, &path).expect("png renamed");
    }
    path
}

/// A small scene: material "m" (with `material` fields and `textures`) on `nodes`, lit by a
/// point light, seen from +z.
fn scene_text(textures: &str, material: &str, nodes: &str) -> String {
    format!(
        r#"Scene(
            render: (width: 24, height: 24, samples_per_pixel: 2, seed: 3, max_depth: 3),
            camera: Pinhole(eye: (0.3, 0.2, 6), look_at: (0, 0, 0), fov_y: 30),
            textures: {{ {textures} }},
            materials: {{ "m": ({material}) }},
            lights: [Point(position: (2, 3, 6), power: (300, 300, 300))],
            nodes: [{nodes}],
        )"#
    )
}

/// The shading normal where the ray from `from` towards `to` first hits.
fn normal_at(s: &RenderScene, from: Vec3, to: Vec3) -> Vec3 {
    let ray = Ray::new(from, (to - from).normalize());
    let hit = s.geometry.intersect(&ray).expect("the ray hits");
    let sp = s.geometry.surface(&ray, &hit);
    let m = s.objects[sp.object as usize].material.expect("a material");
    s.shading_point(&s.materials[m as usize], &sp, -ray.dir, 0.0)
        .ns
}

const NODES: &str = r#"Quad(material: "m", size: (2, 2), transform: [Translate(0, 0, -0.5)]),
    Sphere(material: "m", center: (0.4, 0.1, 0.3), radius: 0.5)"#;

#[test]
fn a_flat_map_renders_the_same_bytes_as_no_map() {
    let flat = constant_png([128, 128, 255]);
    let textures = format!(
        r#""n": NormalMap(file: "{}", tile: (3, 2))"#,
        flat.display()
    );
    let with = common::scene_from_text(&scene_text(
        &textures,
        r#"color: (0.7, 0.5, 0.3), normal_map: "n""#,
        NODES,
    ));
    let without = common::scene_from_text(&scene_text("", "color: (0.7, 0.5, 0.3)", NODES));
    let opts = RenderOptions {
        threads: Some(2),
        ..RenderOptions::default()
    };
    let a = render(&with, &opts).expect("renders").film;
    let b = render(&without, &opts).expect("renders").film;
    assert_eq!((a.width, a.height), (b.width, b.height));
    let bits = |v: &Vec3| v.to_array().map(f32::to_bits);
    let differ = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| bits(p) != bits(q))
        .count();
    let lit = b.pixels.iter().filter(|q| q.max_element() > 0.0).count();
    assert_eq!(differ, 0, "{differ} pixels differ");
    assert!(lit > 100, "the scene is lit: {lit} pixels");
}

#[test]
fn a_constant_tilted_map_tilts_the_normal_by_the_closed_form_angle() {
    // Red 200: x = (200 − 128)/127; blue 230: z = (230 − 128)/127; the normal tilts towards +u
    // (world +x on a quad facing +z) by atan(x/z) = 35.22°.
    let (x, z) = (72.0f32 / 127.0, 102.0f32 / 127.0);
    let angle = x.atan2(z);
    let cases = [
        ([200u8, 128, 230], false, Vec3::new(x, 0.0, z)),
        // Green 200 points up the image, which is world +y on an upright quad...
        ([128, 200, 230], false, Vec3::new(0.0, x, z)),
        // ... and down with flip_y.
        ([128, 200, 230], true, Vec3::new(0.0, -x, z)),
    ];
    for (rgb, flip, want) in cases {
        let png = constant_png(rgb);
        let s = common::scene_from_text(&scene_text(
            &format!(
                r#""n": NormalMap(file: "{}", flip_y: {flip})"#,
                png.display()
            ),
            r#"normal_map: "n""#,
            r#"Quad(material: "m", size: (2, 2))"#,
        ));
        let want = want.normalize();
        for (px, py) in [(0.1f32, 0.3f32), (-0.6, -0.2), (0.7, 0.8)] {
            let p = Vec3::new(px, py, 0.0);
            let n = normal_at(&s, p + Vec3::new(0.0, 0.0, 5.0), p);
            assert!(
                n.distance(want) < 1e-5,
                "{rgb:?} flip {flip}: {n} vs {want}"
            );
            let tilt = n.dot(Vec3::Z).clamp(-1.0, 1.0).acos();
            assert!((tilt - angle).abs() < 1e-4, "tilt {tilt} vs {angle}");
        }
    }
    // Strength 0.5 halves the tangent of the tilt.
    let png = constant_png([200, 128, 230]);
    let s = common::scene_from_text(&scene_text(
        &format!(
            r#""n": NormalMap(file: "{}", strength: 0.5)"#,
            png.display()
        ),
        r#"normal_map: "n""#,
        r#"Quad(material: "m", size: (2, 2))"#,
    ));
    let n = normal_at(&s, Vec3::new(0.2, 0.1, 5.0), Vec3::new(0.2, 0.1, 0.0));
    assert!((n.x / n.z - 0.5 * x / z).abs() < 1e-5, "{n}");
}

/// The normal map generated from the tile height map shades like the bump of that height map:
/// a 2 × 2 wall, one repeat of the 128² images, the height map at depth 0.01 (the relief the
/// generator encodes: `TILES_NORMAL_RELIEF` = 0.005 per image width). Compared at every texel
/// centre (where both use the same central difference; the normal map's is quantised to 8 bits)
/// and between them (where the height map interpolates heights and the normal map normals).
#[test]
fn the_generated_normal_map_agrees_with_the_bump_of_its_height_map() {
    let root = common::root();
    let wall = r#"Quad(material: "m", size: (2, 2))"#;
    let bump = common::scene_from_text(&scene_text(
        &format!(
            r#""h": HeightMap(file: "{}", depth: 0.01)"#,
            root.join("assets/tiles_height.png").display()
        ),
        r#"bump: "h""#,
        wall,
    ));
    let normal = common::scene_from_text(&scene_text(
        &format!(
            r#""n": NormalMap(file: "{}")"#,
            root.join("assets/tiles_normal.png").display()
        ),
        r#"normal_map: "n""#,
        wall,
    ));
    let measure = |offset: f32| {
        let (mut worst, mut sum, mut count, mut tilted) = (0.0f32, 0.0f64, 0, 0);
        for j in 0..128 {
            for i in 0..128 {
                // u along +x, v down along −y.
                let u = (i as f32 + offset) / 128.0;
                let v = (j as f32 + offset) / 128.0;
                let p = Vec3::new(-1.0 + 2.0 * u, 1.0 - 2.0 * v, 0.0);
                let from = p + Vec3::Z * 5.0;
                let (a, b) = (normal_at(&bump, from, p), normal_at(&normal, from, p));
                let angle = a.dot(b).clamp(-1.0, 1.0).acos().to_degrees();
                worst = worst.max(angle);
                sum += f64::from(angle);
                count += 1;
                tilted += usize::from(a.z < 0.99);
            }
        }
        (worst, sum / f64::from(count), tilted)
    };
    let (worst, mean, tilted) = measure(0.5);
    println!("texel centres: largest angle {worst:.3}°, mean {mean:.4}° ({tilted} tilted by > 8°)");
    assert!(tilted > 2_000, "the bevels are sampled: {tilted}");
    assert!(worst < 0.5 && mean < 0.1, "{worst}° / {mean}°");
    let (worst, mean, _) = measure(0.25);
    println!("between texels: largest angle {worst:.3}°, mean {mean:.4}°");
    assert!(worst < 0.5 && mean < 0.1, "{worst}° / {mean}°");
}
