//! Inputs that users of other renderers reported as failures (issue 17 §3), each turned into a
//! test of the right result. The small inputs live in `tests/reported/<case>/`.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::root;

/// A folder of `tests/reported/`.
fn case(name: &str) -> PathBuf {
    root().join("tests/reported").join(name)
}

/// Runs `caustic` with `args` in `dir`, killing it (and failing) if it has not ended within
/// `limit`: returns (exit code, stdout, stderr).
fn run_within(dir: &Path, args: &[&str], limit: Duration) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("caustic runs");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > limit {
            child.kill().expect("kill");
            let _ = child.wait();
            panic!("`caustic {}` still running after {limit:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("output");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

// ---- An output path that cannot be written -------------------------------------------------

/// Render flags that would take hours (512×512 at a million samples per pixel): a run that ends
/// in seconds refused the output before rendering.
const FOREVER: [&str; 6] = ["--width", "512", "--height", "512", "--spp", "1000000"];

fn refused_before_rendering(dir: &Path, output: &str, why: &str) {
    let scene = root().join("scenes/cornell.ron");
    let scene = scene.to_str().expect("utf-8 path");
    let mut args = vec!["render", scene, "-o", output];
    args.extend(FOREVER);
    let (code, stdout, stderr) = run_within(dir, &args, Duration::from_secs(60));
    assert_eq!(code, 2, "{stderr}");
    assert!(stdout.is_empty(), "nothing rendered: {stdout}");
    let first = stderr.lines().next().unwrap_or_default();
    assert!(
        first.starts_with(&format!("error: cannot write `{output}`")),
        "{stderr}"
    );
    assert!(first.contains(why), "{stderr}");
    assert!(
        !stderr.contains(".caustic-"),
        "no temporary file named: {stderr}"
    );
    let left: Vec<_> = std::fs::read_dir(dir)
        .expect("ls")
        .map(|e| e.expect("entry").file_name())
        .filter(|n| n.to_string_lossy().starts_with(".caustic-"))
        .collect();
    assert!(left.is_empty(), "probe files left: {left:?}");
}

#[test]
fn unwritable_outputs_are_refused_before_rendering_with_the_users_path() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path();
    std::fs::create_dir(dir.join("adir.png")).expect("mkdir");
    std::fs::write(dir.join("file.txt"), b"x").expect("write");
    refused_before_rendering(dir, "no_such_dir/out.png", "does not exist");
    refused_before_rendering(dir, "adir.png", "it is a folder");
    refused_before_rendering(dir, "file.txt/out.png", "is not a folder");
    // No permission: a folder without write permission refuses the probe, unless we run as a
    // user that permissions do not bind (root), which cannot be tested this way.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let locked = dir.join("locked");
        std::fs::create_dir(&locked).expect("mkdir");
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).expect("chmod");
        let privileged = std::fs::write(locked.join("probe"), b"x").is_ok();
        if !privileged {
            refused_before_rendering(dir, "locked/out.png", "Permission denied");
        }
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    }
    // The checkpoint is checked the same way.
    let scene = root().join("scenes/cornell.ron");
    let mut args = vec![
        "render",
        scene.to_str().expect("utf-8"),
        "-o",
        "out.png",
        "--checkpoint",
        "gone/cp.png",
    ];
    args.extend(FOREVER);
    let (code, _, stderr) = run_within(dir, &args, Duration::from_secs(60));
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.starts_with("error: cannot write `gone/cp.png`: the folder `gone` does not exist"),
        "{stderr}"
    );
    assert!(!dir.join("out.png").exists());
}

// ---- Lights of extreme size or power -------------------------------------------------------

/// Compiles a RON scene given as text, returning the render scene and the compile warnings.
fn compile_text(
    text: &str,
) -> (
    caustic::render_scene::RenderScene,
    Vec<caustic::scene::Diagnostic>,
) {
    let src =
        caustic::scene::SourceFile::new(Path::new("inline.ron"), text.to_string()).expect("ron");
    let file = src.parse().unwrap_or_else(|e| panic!("{e}\n{text}"));
    let diags = caustic::scene::validate::validate(&file);
    assert!(!diags.iter().any(|d| d.is_error()), "{diags:?}");
    let (scene, mut stats) =
        caustic::compile::compile(&file, Path::new(".")).unwrap_or_else(|e| panic!("{e:?}"));
    (scene, std::mem::take(&mut stats.warnings))
}

/// A white floor (albedo 0.5) at y = 0 seen from straight above through a 0.5° lens, so every
/// pixel sees the floor within 0.03 of the point below `light`.
fn floor_under(light: &str) -> String {
    format!(
        "Scene(render: (width: 9, height: 9, samples_per_pixel: 2),
          camera: Pinhole(eye: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, -1), fov_y: 0.5),
          materials: {{ \"white\": (color: (0.5, 0.5, 0.5)) }},
          lights: [{light}],
          nodes: [Quad(material: \"white\", size: (4, 4), transform: [RotateX(-90)])])"
    )
}

#[test]
fn a_sphere_light_too_small_to_sample_is_its_point_light() {
    use caustic::render::{RenderOptions, render};
    // Φ = 400 W at height h = 2 over a Lambertian floor of albedo ρ = 0.5:
    // L = ρ/π · Φ/(4πh²) (cos θ = 1 straight below).
    let expected = 0.5 / std::f64::consts::PI * 400.0 / (4.0 * std::f64::consts::PI * 4.0);
    for (radius, point) in [
        ("1e-19", true), // r² leaves f32's normal range: NaN samples before the fallback
        ("1e-30", true), // r² is 0 in f32
        ("1e-16", true), // radiance 1e33 W/(m²·sr), above the radiance limit
        ("1e-3", false), // an ordinary small sphere, sampled as a sphere (the control)
    ] {
        let light = format!("Sphere(center: (0, 2, 0), radius: {radius}, power: (400, 400, 400))");
        let (scene, warnings) = compile_text(&floor_under(&light));
        let is_point = scene.lights[0].is_delta();
        assert_eq!(is_point, point, "radius {radius}");
        assert_eq!(
            warnings
                .iter()
                .any(|w| w.path == "lights[0].radius"
                    && w.message.contains("rendered as a point light")),
            point,
            "radius {radius}: {warnings:?}"
        );
        let out = render(&scene, &RenderOptions::default()).expect("renders");
        assert_eq!(out.stats.nan_samples, 0, "radius {radius}");
        for p in &out.film.pixels {
            let got = f64::from(p.x);
            assert!(
                (got / expected - 1.0).abs() < 0.01,
                "radius {radius}: floor {got} vs closed form {expected}"
            );
        }
    }
    // The same point light written as one.
    let (scene, warnings) = compile_text(&floor_under(
        "Point(position: (0, 2, 0), power: (400, 400, 400))",
    ));
    assert!(warnings.is_empty());
    let out = render(&scene, &RenderOptions::default()).expect("renders");
    assert!((f64::from(out.film.pixels[40].x) / expected - 1.0).abs() < 0.01);
}

// ---- OBJ polygons with more than three corners ---------------------------------------------

#[test]
fn a_concave_obj_polygon_is_triangulated_by_its_shape() {
    let dir = case("obj-ngon");
    let bytes = std::fs::read(dir.join("c_shape.obj")).expect("c_shape.obj");
    let mesh = caustic::compile::mesh::parse_obj(&bytes, Path::new("c_shape.obj")).expect("parses");
    assert!(mesh.warnings.is_empty(), "{:?}", mesh.warnings);
    // The C is the 3×3 square less the notch x ∈ [1, 3], y ∈ [1, 2]: area 9 − 2 = 7.
    assert_eq!(mesh.triangles.len(), 6);
    let mut total = 0.0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|k| mesh.positions[k.p as usize].as_dvec3());
        total += 0.5 * (b - a).cross(c - a).length();
        // Inside the C means outside the notch: test points near each corner, pulled in.
        let g = (a + b + c) / 3.0;
        for p in [a, b, c].map(|v| v + (g - v) * 0.01) {
            let in_notch = p.x > 1.0 && p.y > 1.0 && p.y < 2.0;
            let in_square = (0.0..=3.0).contains(&p.x) && (0.0..=3.0).contains(&p.y);
            assert!(in_square && !in_notch, "triangle {t:?} reaches {p}");
        }
    }
    assert!((total - 7.0).abs() < 1e-9, "area {total}");

    // Rendered: the notch shows the background, the C's bar beside it is lit. By hand, the C
    // is placed by Scale(0.6), Translate(0.4, −0.9, 0): the notch centre (2, 1.5) lands at
    // (1.6, 0, 0), the bar point (0.5, 1.5) at (0.7, 0, 0). The camera at z = 6 with fov_y 40
    // sees ±6·tan 20° = ±2.184 vertically over 48 rows and ±2.912 across 64 columns, so x = 1.6
    // is column 32 + 1.6/2.912·32 = 49.6 and x = 0.7 column 39.7, both on row 24.
    let (film, _) = crate::common::render_file(
        &dir.join("scene.ron"),
        &crate::common::small(64, 48, 1),
        &caustic::render::RenderOptions::default(),
    );
    let px = |x: u32, y: u32| film.pixels[(y * 64 + x) as usize];
    let background = glam::Vec3::new(0.1, 0.1, 0.3);
    for x in 47..=52 {
        assert_eq!(px(x, 24), background, "notch pixel ({x}, 24) is not empty");
    }
    assert!(px(39, 24).x > 0.2, "the C's bar is lit: {}", px(39, 24));
    // The convex hexagon on the left is whole: its centre (−1.6, 0) is column 14.4.
    assert!(px(14, 24).x > 0.2, "{}", px(14, 24));
}

#[test]
fn warped_and_self_intersecting_obj_faces_warn_with_their_line() {
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0.3\nv 0 1 0\n# a warped quad\nf 1 2 3 4\n\
               v 0 0 1\nv 1 1 1\nv 1 0 1\nv 0 1 1\nf 5 6 7 8\nf 1 2 4\n";
    let mesh =
        caustic::compile::mesh::parse_obj(obj.as_bytes(), Path::new("w.obj")).expect("parses");
    assert_eq!(mesh.warnings.len(), 2, "{:?}", mesh.warnings);
    assert!(mesh.warnings[0].starts_with("line 6:") && mesh.warnings[0].contains("not planar"));
    assert!(
        mesh.warnings[1].starts_with("line 11:") && mesh.warnings[1].contains("crosses itself")
    );
    assert_eq!(mesh.triangles.len(), 5);
    // Through the scene: warnings reach `check`, attributed to the node's file field.
    let tmp = tempfile::tempdir().expect("tmp");
    std::fs::write(tmp.path().join("w.obj"), obj).expect("write");
    let scene = tmp.path().join("s.ron");
    std::fs::write(
        &scene,
        "Scene(camera: Pinhole(eye: (0, 0, 5), look_at: (0, 0, 0), fov_y: 40), materials: { \"m\": (color: (0.5, 0.5, 0.5)) },
           lights: [Point(position: (0, 0, 5), power: (10, 10, 10))],
           nodes: [Mesh(file: \"w.obj\", material: \"m\"), Mesh(file: \"w.obj\", material: \"m\")])",
    )
    .expect("write");
    let (code, stdout, stderr) =
        run_within(tmp.path(), &["check", "s.ron"], Duration::from_secs(60));
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("2 warnings"),
        "each file's warnings once: {stdout}"
    );
    assert!(
        stderr.contains("warning: nodes[0].file: `w.obj` line 6: the 4-corner face is not planar"),
        "{stderr}"
    );
}

// ---- Nearly singular transforms ------------------------------------------------------------

/// The reported pancake (a unit sphere squashed along y, seen from 4.5 units) with `factor`.
fn pancake(factor: &str) -> String {
    let text = std::fs::read_to_string(case("near-singular-scale").join("pancake.ron"))
        .expect("pancake.ron");
    assert!(text.contains("1e-8"));
    text.replace("1e-8", factor)
}

#[test]
fn a_squashed_sphere_shades_right_down_to_the_limit_and_is_refused_below_it() {
    use caustic::render::{RenderOptions, render};
    let film = |text: &str| {
        let (scene, _) = compile_text(text);
        let out = render(&scene, &RenderOptions::default()).expect("renders");
        assert_eq!(out.stats.nan_samples, 0);
        out.film
    };
    // 1e-5 is far from any precision limit: the reference. Before the fix 1e-8 rendered about
    // half the disc black (the f32 hit distance put the hit on the far side).
    let reference = film(&pancake("1e-5"));
    let lit = reference.pixels.iter().filter(|p| p.x > 0.2).count();
    assert!(lit > 500, "the disc covers many pixels: {lit}");
    for factor in ["1e-6", "1e-8", "1e-10"] {
        let f = film(&pancake(factor));
        let worst = f
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(a, b)| (*a - *b).abs().max_element())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "factor {factor}: max difference {worst}");
    }
    // Below the limit (2^-36 ≈ 1.46e-11), a clear error naming the node.
    for factor in ["1.4e-11", "1e-20"] {
        let text = pancake(factor).replace("Sphere(material", "Sphere(name: \"pancake\", material");
        let src = caustic::scene::SourceFile::new(Path::new("p.ron"), text).expect("ron");
        let file = src.parse().expect("parses");
        let errors = caustic::compile::compile(&file, Path::new(".")).expect_err("refused");
        assert_eq!(errors.len(), 1, "{errors:?}");
        assert_eq!(errors[0].path, "nodes[0].transform");
        assert!(
            errors[0].message.contains("squash it to")
                && errors[0].message.contains("double precision"),
            "{}",
            errors[0].message
        );
    }
}

#[test]
fn a_squashed_cube_is_refused_below_what_f32_resolves() {
    let cube = |factor: &str| {
        format!(
            "Scene(render: (width: 48, height: 32),
              camera: Pinhole(eye: (0, 2, 4), look_at: (0, 0, 0), fov_y: 40),
              materials: {{ \"red\": (color: (0.8, 0.1, 0.1)) }},
              lights: [ Point(position: (0, 4, 4), power: (900, 900, 900)) ],
              nodes: [ Group(name: \"g\", transform: [Scale((1, {factor}, 1))],
                             children: [Cube(name: \"slab\", material: \"red\", size: 1.5)]) ])"
        )
    };
    let compiled = |factor: &str| {
        let src = caustic::scene::SourceFile::new(Path::new("c.ron"), cube(factor)).expect("ron");
        caustic::compile::compile(&src.parse().expect("parses"), Path::new("."))
    };
    // Limit: 2^-20 ≈ 9.54e-7 of the side.
    assert!(compiled("9.6e-7").is_ok());
    let errors = compiled("9.5e-7").expect_err("refused");
    assert_eq!(errors[0].path, "nodes[0].children[0].transform");
    assert!(
        errors[0].message.contains("single precision"),
        "{}",
        errors[0].message
    );
}

// ---- Float textures (EXR) ------------------------------------------------------------------

/// Writes a float RGB EXR of `width × height` texels.
fn write_exr(path: &Path, width: u32, height: u32, texels: Vec<f32>) {
    image::DynamicImage::ImageRgb32F(
        image::Rgb32FImage::from_raw(width, height, texels).expect("size"),
    )
    .save(path)
    .expect("exr written");
}

/// A scene showing texture file `file` on a quad filling the frame, lit from the camera.
fn textured(file: &str, srgb: &str) -> String {
    format!(
        "Scene(render: (width: 32, height: 32, samples_per_pixel: 1),
          camera: Pinhole(eye: (0, 0, 3), look_at: (0, 0, 0), fov_y: 30),
          textures: {{ \"tex\": Bitmap(file: \"{file}\"{srgb}) }},
          materials: {{ \"m\": (color: \"tex\") }},
          lights: [ Point(position: (0, 0, 3), power: (500, 500, 500)) ],
          nodes: [ Quad(material: \"m\", size: (2, 2)) ])"
    )
}

#[test]
fn float_textures_are_linear_unless_the_scene_says_otherwise() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path();
    // A 2×2 PNG of sRGB bytes, and an EXR of the same colours decoded to linear by the sRGB
    // formula (IEC 61966-2-1), computed here independently of the renderer.
    let bytes: [[u8; 3]; 4] = [[200, 30, 90], [10, 250, 128], [128, 128, 128], [64, 0, 180]];
    let decode = |b: u8| {
        let v = f64::from(b) / 255.0;
        (if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }) as f32
    };
    image::RgbImage::from_fn(2, 2, |x, y| image::Rgb(bytes[(y * 2 + x) as usize]))
        .save(dir.join("t.png"))
        .expect("png");
    write_exr(
        &dir.join("t.exr"),
        2,
        2,
        bytes.iter().flatten().map(|b| decode(*b)).collect(),
    );
    let render = |name: &str, text: String| {
        let scene = dir.join(name);
        std::fs::write(&scene, text).expect("scene");
        crate::common::render_file(
            &scene,
            &caustic::pipeline::SceneOverrides::default(),
            &caustic::render::RenderOptions::default(),
        )
        .0
    };
    let png = render("png.ron", textured("t.png", ""));
    let exr = render("exr.ron", textured("t.exr", ""));
    let worst = png
        .pixels
        .iter()
        .zip(&exr.pixels)
        .map(|(a, b)| (*a - *b).abs().max_element())
        .fold(0.0f32, f32::max);
    assert!(
        worst < 1e-5,
        "EXR read as linear renders like the sRGB PNG: {worst}"
    );
    assert!(png.pixels.iter().any(|p| p.x > 0.3), "the quad is lit");
    // Saying `srgb: true` decodes the EXR's values again: darker.
    let twice = render("twice.ron", textured("t.exr", ", srgb: true"));
    let (a, b): (f32, f32) = (
        exr.pixels.iter().map(|p| p.element_sum()).sum(),
        twice.pixels.iter().map(|p| p.element_sum()).sum(),
    );
    assert!(b < 0.75 * a, "{b} vs {a}");
    // And `srgb: false` on the PNG reads its bytes as linear: brighter.
    let raw = render("raw.ron", textured("t.png", ", srgb: false"));
    let c: f32 = raw.pixels.iter().map(|p| p.element_sum()).sum();
    assert!(c > 1.3 * a, "{c} vs {a}");
}

#[test]
fn non_finite_texels_are_an_error_and_negative_ones_a_warning_in_check() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path();
    // Texel (1, 0) is NaN in red, (0, 1) +inf in blue.
    write_exr(
        &dir.join("bad.exr"),
        2,
        2,
        vec![
            0.5,
            0.5,
            0.5,
            f32::NAN,
            0.1,
            0.1,
            0.2,
            0.2,
            f32::INFINITY,
            1.0,
            1.0,
            1.0,
        ],
    );
    std::fs::write(dir.join("bad.ron"), textured("bad.exr", "")).expect("scene");
    let (code, _, stderr) = run_within(dir, &["check", "bad.ron"], Duration::from_secs(60));
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.starts_with("error: textures.tex.file: cannot load image `bad.exr`: the image has 2 texels with NaN or infinite values, the first at x = 1, y = 0"),
        "{stderr}"
    );
    // Negative values: clamped to 0 with a warning naming the first texel; the render shows 0.
    // Every texel's green is negative, one texel's blue too.
    write_exr(
        &dir.join("neg.exr"),
        2,
        2,
        vec![
            0.5, -0.25, 0.5, 0.5, -1.0, -0.5, 0.5, -1e-3, 0.5, 0.5, -0.1, 0.5,
        ],
    );
    std::fs::write(dir.join("neg.ron"), textured("neg.exr", "")).expect("scene");
    let (code, stdout, stderr) = run_within(dir, &["check", "neg.ron"], Duration::from_secs(60));
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("1 warning"), "{stdout}");
    assert!(
        stderr.contains("warning: textures.tex.file: `")
            && stderr.contains(
                "has 4 texels with negative values (the first at x = 0, y = 0), clamped to 0"
            ),
        "{stderr}"
    );
    let (film, _) = crate::common::render_file(
        &dir.join("neg.ron"),
        &caustic::pipeline::SceneOverrides::default(),
        &caustic::render::RenderOptions::default(),
    );
    assert!(
        film.pixels
            .iter()
            .all(|p| p.min_element() >= 0.0 && p.is_finite())
    );
    // Green is 0 everywhere, red is lit everywhere.
    assert!(film.pixels.iter().all(|p| p.y == 0.0 && p.x > 0.1));
}

#[test]
fn light_power_beyond_single_precision_is_refused() {
    let text = |p: &str| floor_under(&format!("Point(position: (0, 2, 0), power: (1, {p}, 1))"));
    let diags = |p: &str| {
        let src = caustic::scene::SourceFile::new(Path::new("l.ron"), text(p)).expect("ron");
        caustic::scene::validate::validate(&src.parse().expect("parses"))
    };
    assert!(!diags("1e30").iter().any(|d| d.is_error()));
    let d = diags("2e30");
    assert!(
        d.iter().any(|d| d.is_error()
            && d.path == "lights[0].power"
            && d.message.contains("at most 1e30")),
        "{d:?}"
    );
}
