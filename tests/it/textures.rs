//! Textures through the whole pipeline (scene text → compile → hit → shading point): texel
//! lookups at known places on every primitive, bump normals against analytic tilts, ripple
//! normals against the height function, and mipmapping against aliasing.

use crate::common;

use std::path::{Path, PathBuf};

use caustic::geometry::Ray;
use caustic::render::{Film, RenderOptions, render};
use caustic::render_scene::RenderScene;
use caustic::texture::Ripples;
use glam::{Vec2, Vec3};

/// A 4×4 linear (non-sRGB) test image with a 2×2-texel block per quadrant: red top-left, green
/// top-right, blue bottom-left, white bottom-right. Written once per test process.
fn quadrant_png() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustic-textures-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("quadrants.png");
    if !path.exists() {
        let mut img = image::RgbImage::new(4, 4);
        for (x, y, p) in img.enumerate_pixels_mut() {
            *p = image::Rgb(match (x < 2, y < 2) {
                (true, true) => [255, 0, 0],
                (false, true) => [0, 255, 0],
                (true, false) => [0, 0, 255],
                (false, false) => [255, 255, 255],
            });
        }
        let tmp = dir.join(format!("quadrants.{:?}.png", std::thread::current().id()));
        img.save(&tmp).expect("png saved");
        std::fs::rename(&tmp, &path).expect("png renamed");
    }
    path
}

const RED: Vec3 = Vec3::new(1.0, 0.0, 0.0);
const GREEN: Vec3 = Vec3::new(0.0, 1.0, 0.0);
const BLUE: Vec3 = Vec3::new(0.0, 0.0, 1.0);
const WHITE: Vec3 = Vec3::ONE;

/// A scene with one node using material "m" (which has the given textures and fields).
fn scene(textures: &str, material: &str, node: &str) -> RenderScene {
    common::scene_from_text(&format!(
        r#"Scene(
            render: (width: 64, height: 64, samples_per_pixel: 1),
            camera: Pinhole(eye: (0, 0, 10), look_at: (0, 0, 0), fov_y: 30),
            textures: {{ {textures} }},
            materials: {{ "m": ({material}) }},
            lights: [Point(position: (0, 0, 10), power: (10, 10, 10))],
            nodes: [{node}],
        )"#
    ))
}

fn quadrant_scene(node: &str) -> RenderScene {
    let png = quadrant_png();
    scene(
        &format!(r#""q": Bitmap(file: "{}", srgb: false)"#, png.display()),
        r#"color: "q""#,
        node,
    )
}

/// The shading point where the ray from `from` towards `to` first hits.
fn shade(s: &RenderScene, from: Vec3, to: Vec3) -> caustic::render_scene::ShadingPoint {
    let ray = Ray::new(from, (to - from).normalize());
    let hit = s.geometry.intersect(&ray).expect("the ray hits");
    let sp = s.geometry.surface(&ray, &hit);
    let m = s.objects[sp.object as usize].material.expect("a material");
    s.shading_point(&s.materials[m as usize], &sp, -ray.dir, 0.0)
}

fn colour_at(s: &RenderScene, from: Vec3, to: Vec3) -> Vec3 {
    shade(s, from, to).bsdf.color()
}

fn assert_colour(got: Vec3, want: Vec3, what: &str) {
    assert!(got.distance(want) < 1e-5, "{what}: got {got}, want {want}");
}

#[test]
fn a_quad_shows_its_image_upright_and_unmirrored() {
    let s = quadrant_scene("Quad(material: \"m\", size: (2, 2))");
    for (x, y, want, what) in [
        (-0.5, 0.5, RED, "top left"),
        (0.5, 0.5, GREEN, "top right"),
        (-0.5, -0.5, BLUE, "bottom left"),
        (0.5, -0.5, WHITE, "bottom right"),
    ] {
        let p = Vec3::new(x, y, 0.0);
        assert_colour(colour_at(&s, p + Vec3::Z * 5.0, p), want, what);
    }
}

/// (outward normal, the viewer's right, the viewer's up) of each cube face seen from outside:
/// side faces upright, the top with the image's top towards −z, the bottom with it towards +z.
const CUBE_FACES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::Z, Vec3::X, Vec3::Y),
    (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    (Vec3::X, Vec3::NEG_Z, Vec3::Y),
    (Vec3::NEG_X, Vec3::Z, Vec3::Y),
    (Vec3::Y, Vec3::X, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::X, Vec3::Z),
];

#[test]
fn every_cube_face_shows_its_image_upright_from_outside() {
    let s = quadrant_scene("Cube(material: \"m\", size: 2)");
    for (out, right, up) in CUBE_FACES {
        for (a, b, want) in [
            (-0.5, 0.5, RED),
            (0.5, 0.5, GREEN),
            (-0.5, -0.5, BLUE),
            (0.5, -0.5, WHITE),
        ] {
            let p = out + right * a + up * b;
            assert_colour(
                colour_at(&s, p + out * 5.0, p),
                want,
                &format!("face {out}, ({a}, {b})"),
            );
        }
    }
}

#[test]
fn a_sphere_wraps_its_image_upright_and_reading_left_to_right() {
    let s = quadrant_scene("Sphere(material: \"m\", radius: 1)");
    // The seam faces −x, so the front (+z) is u = 0.25 (left half) and +x is u = 0.5.
    let at = |dir: Vec3| {
        let p = dir.normalize();
        colour_at(&s, p * 5.0, p)
    };
    assert_colour(at(Vec3::new(-0.2, 0.5, 1.0)), RED, "front, upper");
    assert_colour(at(Vec3::new(-0.2, -0.5, 1.0)), BLUE, "front, lower");
    // Left to right across the front: u grows, so +x (u just above 0.5) is the right half.
    // (1, ·, −1) is u = 0.625, the centre of texel column 2 (the right half).
    assert_colour(at(Vec3::new(1.0, 0.7, -1.0)), GREEN, "right of +x, upper");
    assert_colour(at(Vec3::new(1.0, -0.7, -1.0)), WHITE, "right of +x, lower");
}

fn write_obj(name: &str, text: &str) -> PathBuf {
    let path = quadrant_png().with_file_name(name);
    std::fs::write(&path, text).expect("obj written");
    path
}

#[test]
fn obj_texture_coordinates_are_flipped_to_v_down_and_meshes_without_them_get_box_uvs() {
    // A 2×2 square facing +z with OBJ's usual bottom-up vt.
    let with_vt = write_obj(
        "square_vt.obj",
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    );
    let s = quadrant_scene(&format!(
        "Mesh(material: \"m\", file: \"{}\")",
        with_vt.display()
    ));
    let p = Vec3::new(-0.5, 0.5, 0.0);
    assert_colour(colour_at(&s, p + Vec3::Z * 5.0, p), RED, "vt: top left");
    let p = Vec3::new(0.5, -0.5, 0.0);
    assert_colour(
        colour_at(&s, p + Vec3::Z * 5.0, p),
        WHITE,
        "vt: bottom right",
    );

    // Without vt: box projection in object units, u = x and v = −y on a +z face, so the
    // image repeats every unit: (0.25, 0.25) is u 0.25, v −0.25 ≡ 0.75 (bottom left, blue).
    let without = write_obj(
        "square_novt.obj",
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n",
    );
    let s = quadrant_scene(&format!(
        "Mesh(material: \"m\", file: \"{}\")",
        without.display()
    ));
    for (x, y, want) in [
        (0.25, 0.25, BLUE),
        (0.25, 0.75, RED),
        (0.75, 0.75, GREEN),
        (-0.25, -0.25, GREEN),
    ] {
        let p = Vec3::new(x, y, 0.0);
        assert_colour(
            colour_at(&s, p + Vec3::Z * 5.0, p),
            want,
            &format!("box uv at ({x}, {y})"),
        );
    }
}

/// A 64×64 16-bit grey ramp, grey = i/63 in column i (16 bits, so the slope is exact to 1e-5;
/// the 8-bit `assets/ramp_height.png` steps by 4 or 5 levels per texel).
/// A mesh cube without `vt` gets box-projected uvs oriented like a `Cube` node's faces: on
/// every face, moving right (as seen from outside) increases u and moving up decreases v.
#[test]
fn box_projected_uvs_are_oriented_like_cube_faces_on_all_six_sides() {
    let obj = write_obj(
        "cube_novt.obj",
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
         f 5 6 7 8\nf 2 1 4 3\nf 6 2 3 7\nf 1 5 8 4\nf 8 7 3 4\nf 1 2 6 5\n",
    );
    let s = quadrant_scene(&format!(
        "Mesh(material: \"m\", file: \"{}\")",
        obj.display()
    ));
    let uv_at = |p: Vec3, out: Vec3| {
        let ray = Ray::new(p + out * 5.0, -out);
        let hit = s.geometry.intersect(&ray).expect("hits");
        s.geometry
            .surface_params(&s.geometry.surface(&ray, &hit))
            .uv
    };
    for (out, right, up) in CUBE_FACES {
        let c = out + right * 0.1 + up * 0.1;
        let (a, r, u) = (
            uv_at(c, out),
            uv_at(c + right * 0.2, out),
            uv_at(c + up * 0.2, out),
        );
        let (dr, du) = (r - a, u - a);
        assert!(
            (dr.x - 0.2).abs() < 1e-5 && dr.y.abs() < 1e-5,
            "face {out}: right moves uv by {dr}"
        );
        assert!(
            du.x.abs() < 1e-5 && (du.y + 0.2).abs() < 1e-5,
            "face {out}: up moves uv by {du}"
        );
    }
}

fn ramp_png() -> String {
    let path = quadrant_png().with_file_name("ramp16.png");
    if !path.exists() {
        let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(64, 64, |x, _| {
            image::Luma([(65535.0 * f64::from(x) / 63.0).round() as u16])
        });
        let tmp = path.with_extension(format!("{:?}.png", std::thread::current().id()));
        img.save(&tmp).expect("ramp saved");
        std::fs::rename(&tmp, &path).expect("ramp renamed");
    }
    path.display().to_string()
}

/// The ramp's height rises by `depth` over 63/64 of the uv square (grey = i/63 at texel
/// centres i = 0..63), so ∂h/∂u = depth · 64/63 inside it.
fn ramp_slope(depth: f32) -> f32 {
    depth * 64.0 / 63.0
}

#[test]
fn a_linear_ramp_height_map_tilts_the_normal_by_the_analytic_angle() {
    let depth = 0.05;
    // A 2 × 2 wall facing +z: u runs along +x over 2 units.
    let s = scene(
        &format!(r#""h": HeightMap(file: "{}", depth: {depth})"#, ramp_png()),
        r#"bump: "h""#,
        "Quad(material: \"m\", size: (2, 2))",
    );
    let dhdx = ramp_slope(depth) / 2.0;
    let want = Vec3::new(-dhdx, 0.0, 1.0).normalize();
    for (x, y) in [(0.1f32, 0.3f32), (-0.4, -0.6), (0.6, 0.1)] {
        let p = Vec3::new(x, y, 0.0);
        let n = shade(&s, p + Vec3::Z * 5.0, p).ns;
        assert!(n.distance(want) < 1e-4, "wall at ({x}, {y}): {n} vs {want}");
    }
    // The same on a floor (normal +y, parallel to the usual "up" of tangent frames), tiled
    // twice along u: twice the slope, along world +x.
    let s = scene(
        &format!(
            r#""h": HeightMap(file: "{}", depth: {depth}, tile: (2, 1))"#,
            ramp_png()
        ),
        r#"bump: "h""#,
        "Quad(material: \"m\", size: (2, 2), transform: [RotateX(-90)])",
    );
    let want = Vec3::new(-2.0 * dhdx, 1.0, 0.0).normalize();
    for (x, z) in [(0.2f32, 0.3f32), (-0.3, -0.2)] {
        let p = Vec3::new(x, 0.0, z);
        let n = shade(&s, p + Vec3::Y * 5.0, p).ns;
        assert!(
            n.distance(want) < 1e-4,
            "floor at ({x}, {z}): {n} vs {want}"
        );
    }
    // Depth 0 leaves the normal exactly geometric.
    let s = scene(
        &format!(r#""h": HeightMap(file: "{}", depth: 0)"#, ramp_png()),
        r#"bump: "h""#,
        "Quad(material: \"m\", size: (2, 2))",
    );
    assert_eq!(
        shade(&s, Vec3::new(0.1, 0.2, 5.0), Vec3::new(0.1, 0.2, 0.0)).ns,
        Vec3::Z
    );
}

#[test]
fn ripple_normals_equal_the_normalised_gradient_of_the_height_function() {
    let (freq, amp, decay) = (60.0, 0.004, 2.0);
    let centers = [Vec2::new(0.3, 0.4), Vec2::new(0.7, 0.2)];
    let s = scene(
        &format!(
            r#""w": Ripple(centers: [(0.3, 0.4), (0.7, 0.2)], frequency: {freq}, amplitude: {amp}, decay: {decay})"#
        ),
        r#"diffuse: 0, transmit: 1, ior: 1.33, bump: "w""#,
        "Quad(material: \"m\", size: (2, 2))",
    );
    let ripples = Ripples::new(centers.to_vec(), freq, amp, decay);
    // World (x, y) on the 2 × 2 quad facing +z ↦ uv (v down).
    let h = |x: f64, y: f64| {
        f64::from(ripples.height(Vec2::new(
            ((x + 1.0) / 2.0) as f32,
            ((1.0 - y) / 2.0) as f32,
        )))
    };
    let mut rng = caustic::sampling::Rng::new(3, 3);
    let mut worst = 0.0f32;
    for _ in 0..500 {
        let (x, y) = (rng.next_f32() * 1.8 - 0.9, rng.next_f32() * 1.8 - 0.9);
        let p = Vec3::new(x, y, 0.0);
        let n = shade(&s, p + Vec3::Z * 5.0, p).ns;
        let e = 1e-3;
        let (x, y) = (f64::from(x), f64::from(y));
        let dx = (h(x + e, y) - h(x - e, y)) / (2.0 * e);
        let dy = (h(x, y + e) - h(x, y - e)) / (2.0 * e);
        let want = Vec3::new(-dx as f32, -dy as f32, 1.0).normalize();
        worst = worst.max(n.distance(want));
    }
    // Central differences of an f32 height with step 1e-3 are good to ~1e-3 of the slope.
    assert!(worst < 2e-3, "worst normal error {worst}");
}

/// A hardwood floor seen at a grazing angle, small, with `filter` and `spp`.
fn grazing_floor(filter: &str, spp: u32, eye_x: f32) -> Film {
    let wood = common::root().join("assets/hardwood.png");
    grazing(
        &format!(r#"Bitmap(file: "{}", tile: (24, 24))"#, wood.display()),
        filter,
        spp,
        eye_x,
    )
}

/// A floor coloured by `texture` seen at a grazing angle, small, with `filter` and `spp`.
fn grazing(texture: &str, filter: &str, spp: u32, eye_x: f32) -> Film {
    let s = common::scene_from_text(&format!(
        r#"Scene(
            render: (width: 96, height: 48, samples_per_pixel: {spp}, seed: 1, texture_filter: {filter}),
            camera: Pinhole(eye: ({eye_x}, 0.35, 4), look_at: ({eye_x}, 0.1, -20), fov_y: 30),
            textures: {{ "wood": {texture} }},
            materials: {{ "floor": (color: "wood") }},
            lights: [Point(position: (0, 30, 0), power: (40000, 40000, 40000))],
            nodes: [Quad(material: "floor", size: (60, 60), transform: [RotateX(-90), Translate(0, 0, -26)])],
        )"#
    ));
    render(
        &s,
        &RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        },
    )
    .expect("renders")
    .film
}

fn rmse(a: &Film, b: &Film) -> f64 {
    caustic::analysis::metrics::compare(a, b)
        .expect("same size")
        .rmse
}

/// The issue's shimmer/moiré test, measured: at 1 spp, the mipmapped floor is closer to the
/// converged image and changes far less when the camera moves by a fraction of a pixel; the
/// anisotropic filter is closer still (sharper) than one trilinear lookup.
#[test]
fn mipmaps_remove_the_aliasing_of_a_grazing_floor() {
    let reference = grazing_floor("Bilinear", 256, 0.0);
    // A quarter-pixel sideways step of the camera (pixel ≈ 2·tan 15°/48 · 4 units wide here).
    let step = 0.25 * 2.0 * (15f32.to_radians().tan()) / 48.0 * 4.0;
    let measure = |filter: &str| {
        let img = grazing_floor(filter, 1, 0.0);
        let error = rmse(&img, &reference);
        let shimmer = rmse(&img, &grazing_floor(filter, 1, step));
        eprintln!(
            "{filter:>11}: error vs 256-spp reference {error:.5}, change after a quarter-pixel step {shimmer:.5}"
        );
        (error, shimmer)
    };
    let (e_bil, s_bil) = measure("Bilinear");
    let (e_tri, s_tri) = measure("Trilinear");
    let (e_ani, s_ani) = measure("Anisotropic");
    // The figures docs/textures.md states: mipmapped filters 2.7-3x closer (at least 2.5x
    // asserted), shimmer 3x (anisotropic, at least 2.5x) and 9x (trilinear, at least 8x) less.
    assert!(e_bil > 2.5 * e_tri, "trilinear error {e_tri} vs {e_bil}");
    assert!(e_bil > 2.5 * e_ani, "anisotropic error {e_ani} vs {e_bil}");
    assert!(
        e_ani < e_tri,
        "anisotropic error {e_ani} vs trilinear {e_tri}"
    );
    assert!(s_bil > 8.0 * s_tri, "trilinear shimmer {s_tri} vs {s_bil}");
    assert!(
        s_bil > 2.5 * s_ani,
        "anisotropic shimmer {s_ani} vs {s_bil}"
    );
}

/// Procedural noise is filtered too: octaves finer than the footprint are left out (fBm) or
/// replaced by their mean (turbulence), so at 1 spp a fine-grained noise floor is closer to the
/// converged image and shimmers less than with every octave evaluated (`Bilinear` turns all
/// footprints off).
#[test]
fn noise_octaves_finer_than_the_footprint_are_filtered_out() {
    // (texture, required error ratio): marble's sine veins themselves are not prefiltered,
    // only its turbulence, so its error improves little (its shimmer does).
    for (texture, error_ratio) in [
        ("Noise(frequency: 6, octaves: 8, seed: 3)", 0.8),
        (
            "Noise(frequency: 6, octaves: 8, turbulence: true, seed: 3)",
            0.8,
        ),
        (
            "Marble(base: (0.9, 0.9, 0.85), vein: (0.2, 0.2, 0.25), frequency: (8, 4, 4), octaves: 8, turbulence: 3)",
            1.0,
        ),
    ] {
        let reference = grazing(texture, "Bilinear", 256, 0.0);
        let step = 0.25 * 2.0 * (15f32.to_radians().tan()) / 48.0 * 4.0;
        let measure = |filter: &str| {
            let img = grazing(texture, filter, 1, 0.0);
            (
                rmse(&img, &reference),
                rmse(&img, &grazing(texture, filter, 1, step)),
            )
        };
        let (e_raw, s_raw) = measure("Bilinear");
        let (e_f, s_f) = measure("Anisotropic");
        eprintln!("{texture}: error {e_raw:.5} -> {e_f:.5}, shimmer {s_raw:.5} -> {s_f:.5}");
        assert!(
            e_f < error_ratio * e_raw,
            "{texture}: error {e_f} vs {e_raw}"
        );
        assert!(s_f < 0.8 * s_raw, "{texture}: shimmer {s_f} vs {s_raw}");
    }
}

#[test]
fn texture_lookups_are_deterministic_across_thread_counts() {
    let path: &Path = &common::root().join("scenes/texture_map.ron");
    let small = common::small(48, 32, 2);
    let one = common::render_file(
        path,
        &small,
        &RenderOptions {
            threads: Some(1),
            ..RenderOptions::default()
        },
    )
    .0;
    let two = common::render_file(
        path,
        &small,
        &RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        },
    )
    .0;
    assert_eq!(one.pixels, two.pixels);
}

#[test]
fn only_used_textures_are_loaded_and_each_image_once() {
    let wood = common::root().join("assets/hardwood.png");
    let text = format!(
        r#"Scene(
            camera: Pinhole(eye: (0, 0, 5), look_at: (0, 0, 0), fov_y: 30),
            textures: {{
                "a": Bitmap(file: "{w}", tile: (2, 2)),
                "b": Bitmap(file: "{w}", tile: (8, 8)),
                "c": HeightMap(file: "{w}", depth: 0.01),
                "missing": Bitmap(file: "no/such/file.png"),
                "for_unused_material": Bitmap(file: "no/such/other.png"),
            }},
            materials: {{
                "m1": (color: "a", bump: "c"),
                "m2": (color: "b"),
                "unused": (color: "for_unused_material"),
            }},
            lights: [Point(position: (0, 0, 5), power: (10, 10, 10))],
            nodes: [Quad(material: "m1"), Sphere(material: "m2", center: (2, 0, 0))],
        )"#,
        w = wood.display()
    );
    let src = caustic::scene::SourceFile::new(Path::new("inline.ron"), text).expect("ron");
    let file = src.parse().expect("parses");
    let diags = caustic::scene::validate::validate(&file);
    assert!(!diags.iter().any(|d| d.is_error()), "{diags:?}");
    // The never-referenced texture is reported, the unused material's texture is not loaded.
    assert!(
        diags
            .iter()
            .any(|d| d.to_string().contains("texture `missing` is never used")),
        "{diags:?}"
    );
    let (scene, stats) = caustic::compile::compile(&file, Path::new(".")).expect("compiles");
    assert_eq!(stats.textures, 3, "a, b and c are used");
    // hardwood.png decoded once as colour (shared by a and b) and once as grey (c).
    assert_eq!(stats.images_loaded, 2);
    assert_eq!(scene.textures.len(), 3);
    assert_eq!(scene.materials.len(), 2);
}
