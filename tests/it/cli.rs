//! The command line: schema freshness, checks of every shipped scene, overrides, output safety,
//! debug-pixel, exit codes.

use crate::common;

use common::{caustic, root};

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn committed_schema_is_fresh() {
    let out = caustic(&["schema"]);
    assert!(out.status.success());
    let committed =
        std::fs::read_to_string(root().join("schema/scene.schema.json")).expect("schema file");
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        committed,
        "schema/scene.schema.json is stale: run `caustic schema > schema/scene.schema.json`"
    );
}

#[test]
fn every_scene_checks_and_validates_against_the_json_schema() {
    let schema: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("schema/scene.schema.json")).expect("schema"),
    )
    .expect("schema is JSON");
    for path in common::scene_files() {
        let rel = path
            .strip_prefix(root())
            .expect("under root")
            .to_string_lossy()
            .into_owned();
        let out = caustic(&["check", &rel]);
        assert!(out.status.success(), "{rel}: {}", stderr(&out));
        // The file's own data (TOML as written; RON through its typed parse) must satisfy the schema.
        let value: serde_json::Value = if rel.ends_with(".toml") {
            let t: toml::Value =
                toml::from_str(&std::fs::read_to_string(&path).expect("read")).expect("toml");
            serde_json::to_value(t).expect("json")
        } else {
            serde_json::to_value(caustic::scene::load::load(&path).expect("loads").scene)
                .expect("json")
        };
        let errors = common::json_schema::errors(&schema, &value);
        assert!(errors.is_empty(), "{rel} violates the schema: {errors:#?}");
    }
}

#[test]
fn the_schema_check_rejects_what_the_schema_forbids() {
    // The validator of `common::json_schema` against the committed schema: the Cornell box
    // passes, and each mutation below (a value the serde types refuse too) is caught.
    let schema: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("schema/scene.schema.json")).expect("schema"),
    )
    .expect("schema is JSON");
    let scene = serde_json::to_value(
        caustic::scene::load::load(&root().join("scenes/cornell.ron"))
            .expect("loads")
            .scene,
    )
    .expect("json");
    assert_eq!(
        common::json_schema::errors(&schema, &scene),
        Vec::<String>::new()
    );
    type Mutation = (&'static str, fn(&mut serde_json::Value));
    let mutations: [Mutation; 5] = [
        ("an unknown top-level field", |v| {
            v["lights_extra"] = serde_json::json!(1)
        }),
        ("a negative width", |v| {
            v["render"]["width"] = serde_json::json!(-4)
        }),
        ("a string for the seed", |v| {
            v["render"]["seed"] = serde_json::json!("seven")
        }),
        ("a missing camera", |v| {
            v.as_object_mut().expect("object").remove("camera");
        }),
        ("a two-component colour", |v| {
            let m = v["materials"].as_object_mut().expect("materials");
            let first = m.values_mut().next().expect("a material");
            first["color"] = serde_json::json!([0.5, 0.5]);
        }),
    ];
    for (what, mutate) in mutations {
        let mut v = scene.clone();
        mutate(&mut v);
        assert!(
            !common::json_schema::errors(&schema, &v).is_empty(),
            "the schema check accepts {what}"
        );
    }
}

#[test]
fn render_writes_the_image_and_a_summary() {
    let dir = tempfile::tempdir().expect("tmp");
    let out_path = dir.path().join("c.png");
    let out = caustic(&[
        "render",
        "scenes/cornell.ron",
        "-o",
        out_path.to_str().expect("utf8"),
        "--width",
        "24",
        "--height",
        "16",
        "--spp",
        "1",
        "--threads",
        "1",
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(&out_path).expect("a readable PNG");
    assert_eq!((img.width(), img.height()), (24, 16));
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(
        summary.contains("24×16, 1 spp") && summary.contains("Mrays/s"),
        "{summary}"
    );
    // Nothing but the image is left in the directory (no temporary files).
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1);
}

#[test]
fn exr_output_is_linear_float() {
    let dir = tempfile::tempdir().expect("tmp");
    let exr = dir.path().join("c.exr");
    let args = [
        "render",
        "scenes/cornell.ron",
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "1",
        "--quiet",
        "-o",
    ];
    let out = caustic(&[&args[..], &[exr.to_str().expect("utf8")]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(&exr).expect("EXR readable").into_rgb32f();
    // Exactly the film the library renders (f32 stored as f32), not merely "something positive".
    let (film, _) = common::render_file(
        &root().join("scenes/cornell.ron"),
        &common::small(8, 8, 1),
        &caustic::render::RenderOptions::default(),
    );
    let stored: Vec<[f32; 3]> = img.pixels().map(|p| p.0).collect();
    let rendered: Vec<[f32; 3]> = film.pixels.iter().map(|p| p.to_array()).collect();
    assert_eq!(stored, rendered);
    assert!(
        rendered.iter().flatten().filter(|c| **c > 0.0).count() > 8 * 8 * 3 / 2,
        "the film itself must not be mostly black"
    );
}

/// Renders the Cornell box small to `name` in `dir` with `seed`, returning the path as text.
fn small_render(dir: &std::path::Path, name: &str, seed: &str) -> String {
    let path = dir.join(name).to_str().expect("utf8").to_string();
    let out = caustic(&[
        "render",
        "scenes/cornell.ron",
        "--width",
        "24",
        "--height",
        "24",
        "--spp",
        "2",
        "--seed",
        seed,
        // Exposure 1 with the linear clip: a PNG is then its EXR clamped to [0, 1] (an
        // automatic exposure would scale it), the raw estimate (not denoised) as the EXR holds.
        "--exposure",
        "1",
        "--no-denoise",
        "--quiet",
        "-o",
        &path,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    path
}

/// The RMSE printed by `caustic compare`.
fn compare_rmse(a: &str, b: &str) -> (f64, String) {
    let out = caustic(&["compare", a, b]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let rmse = text
        .split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no rmse in {text}"));
    (rmse, stderr(&out))
}

#[test]
fn compare_of_a_png_with_an_exr_compares_like_with_like() {
    let dir = tempfile::tempdir().expect("tmp");
    let (png1, exr1) = (
        small_render(dir.path(), "a.png", "1"),
        small_render(dir.path(), "a.exr", "1"),
    );
    let (png2, exr2) = (
        small_render(dir.path(), "b.png", "2"),
        small_render(dir.path(), "b.exr", "2"),
    );
    // The same render as PNG and EXR: the EXR brought to 8-bit range is exactly the PNG.
    let (same, note) = compare_rmse(&png1, &exr1);
    assert_eq!(same, 0.0, "{note}");
    assert!(note.contains("clamped to [0, 1]"), "{note}");
    // Two seeds: PNG against EXR gives the PNG-against-PNG figure, in either order (the
    // light seen directly is ~80 in the EXR and would otherwise dominate).
    let (png_png, _) = compare_rmse(&png1, &png2);
    let (png_exr, _) = compare_rmse(&png1, &exr2);
    let (exr_png, _) = compare_rmse(&exr1, &png2);
    assert!(png_png > 0.0);
    assert_eq!((png_exr, exr_png), (png_png, png_png));
    // Two EXRs keep their unclamped figures, larger here because of the light.
    let (exr_exr, note) = compare_rmse(&exr1, &exr2);
    assert!(
        note.is_empty() && exr_exr > png_png,
        "{exr_exr} {png_png} {note}"
    );
}

#[test]
fn every_error_line_starts_with_error() {
    let dir = tempfile::tempdir().expect("tmp");
    let p = dir.path().join("x.png");
    let p = p.to_str().expect("utf8");
    for args in [
        vec!["check", "scenes/no_such_scene.ron"],
        vec!["render", "scenes/no_such_scene.ron", "-o", p],
        vec!["render", "scenes/cornell.ron", "-o", p, "--region", "1,2"],
        vec![
            "render",
            "scenes/cornell.ron",
            "-o",
            p,
            "--region",
            "60,60,10,10",
            "--width",
            "64",
        ],
        vec!["render", "scenes/cornell.ron", "-o", "x.jpg"],
        vec!["render", "README.md", "-o", p],
        vec!["compare", "no_such.png", "no_such.exr"],
        vec!["check", "tests/bad_scenes/zero_ior.toml"],
        vec!["render", "scenes/cornell.ron", "-o", p, "--threads", "0"],
    ] {
        let out = caustic(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        let first = err.lines().next().unwrap_or_default();
        assert!(first.starts_with("error: "), "{args:?}: {err}");
        assert!(!first.starts_with("error: error:"), "{args:?}: {err}");
    }
}

#[test]
fn counts_read_as_english() {
    let dir = tempfile::tempdir().expect("tmp");
    let scene = dir.path().join("one.ron");
    std::fs::write(
        &scene,
        "Scene(camera: Pinhole(eye: (0, 0, 5), look_at: (0, 0, 0), fov_y: 40), \
         materials: { \"m\": () }, lights: [Point(position: (0, 5, 5), power: (9, 9, 9))], \
         nodes: [Sphere(material: \"m\"), Quad(material: \"m\", transform: [Translate(0, -1, 0)])])",
    )
    .expect("write");
    let s = scene.to_str().expect("utf8");
    let out = caustic(&["check", s]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.ends_with(
            "ok (2 triangles, 1 sphere, 0 ellipsoids, 1 material, 1 light; 0 warnings)\n"
        ),
        "{text}"
    );
    let png = dir.path().join("one.png");
    let out = caustic(&[
        "render",
        s,
        "--stats",
        "--width",
        "4",
        "--height",
        "4",
        "--spp",
        "1",
        "--quiet",
        "-o",
        png.to_str().expect("utf8"),
    ]);
    let err = stderr(&out);
    assert!(
        err.contains(
            "scene: 2 triangles (0 degenerate triangles dropped), 1 sphere, 0 ellipsoids, \
             1 material, 1 light, 0 OBJ files"
        ),
        "{err}"
    );
}

#[test]
fn set_override_equals_editing_the_file() {
    let dir = tempfile::tempdir().expect("tmp");
    let text = std::fs::read_to_string(root().join("scenes/cornell.ron")).expect("read");
    assert!(text.contains("fov_y: 39"));
    let edited = dir.path().join("edited.ron");
    std::fs::write(
        &edited,
        text.replace("fov_y: 39", "fov_y: 60")
            .replace("ior: 1.5", "ior: 1.7"),
    )
    .expect("write");
    let small = ["--width", "20", "--height", "20", "--spp", "1", "--quiet"];
    let a = dir.path().join("a.png");
    let b = dir.path().join("b.png");
    let c = dir.path().join("c.png");
    let run = |args: Vec<&str>| {
        let o = caustic(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    let (a_s, b_s, c_s) = (
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        c.to_str().unwrap(),
    );
    run([
        &[
            "render",
            "scenes/cornell.ron",
            "-o",
            a_s,
            "--set",
            "camera.fov_y=60",
            "--set",
            "materials.glass.ior=1.7",
        ],
        &small[..],
    ]
    .concat());
    run([&["render", edited.to_str().unwrap(), "-o", b_s], &small[..]].concat());
    run([&["render", "scenes/cornell.ron", "-o", c_s], &small[..]].concat());
    let bytes = |p: &std::path::Path| std::fs::read(p).expect("image");
    assert_eq!(
        bytes(&a),
        bytes(&b),
        "--set renders exactly like the edited file"
    );
    assert_ne!(bytes(&a), bytes(&c), "and differently from the original");
}

#[test]
fn bad_overrides_are_clear_errors() {
    let cases = [
        ("camera.fov=35", "has no field `fov`"),
        ("camera.fov_y=wide", "camera.fov_y"),
        ("materials.glas.ior=1.7", "did you mean `glass`?"),
        ("lights[5].radius=1", "out of range"),
        ("materials.glass.ior=-1", "greater than 0"),
        ("render.width", "expected `path=value`"),
    ];
    for (set, expect) in cases {
        let out = caustic(&["check", "scenes/cornell.ron", "--set", set]);
        assert_eq!(out.status.code(), Some(2), "{set}");
        let err = stderr(&out);
        assert!(
            err.contains(expect),
            "--set {set}: expected `{expect}` in:\n{err}"
        );
        assert!(!err.contains("panicked"));
    }
}

#[test]
fn bad_flags_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().expect("tmp");
    let png = dir.path().join("x.png");
    let p = png.to_str().expect("utf8");
    for args in [
        vec!["render", "scenes/cornell.ron", "-o", p, "--region", "1,2,3"],
        vec![
            "render",
            "scenes/cornell.ron",
            "-o",
            p,
            "--region",
            "60,60,10,10",
            "--width",
            "64",
            "--height",
            "64",
        ],
        vec!["render", "scenes/cornell.ron", "-o", p, "--threads", "0"],
        vec!["render", "scenes/cornell.ron", "-o", p, "--width", "0"],
        vec![
            "render",
            "scenes/cornell.ron",
            "-o",
            dir.path().join("x.jpg").to_str().unwrap(),
        ],
        vec!["render", "scenes/missing.ron", "-o", p],
        vec!["render", "README.md", "-o", p],
    ] {
        let out = caustic(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).contains("panicked"));
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).expect("dir").count(),
        0,
        "no file written"
    );
}

#[test]
fn debug_pixel_prints_the_ray_tree() {
    // The centre of the glass ball: camera ray, refraction into and out of the ball, the wall behind.
    let args = [
        "debug-pixel",
        "scenes/cornell.ron",
        "--width",
        "64",
        "--height",
        "64",
    ];
    let out = caustic(&[&args[..], &["40", "50"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Camera ray depth 0"), "{text}");
    assert!(text.contains("hit `glass ball`"), "{text}");
    assert!(text.contains("Refract ray depth 1"), "{text}");
    assert!(text.contains("from inside"), "{text}");
    let out = caustic(&[&args[..], &["40", "50", "--json"]].concat());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert!(v["nodes"].as_array().is_some_and(|n| n.len() >= 3));
    assert_eq!(v["pixel"], serde_json::json!([40, 50]));
    let out = caustic(&[&args[..], &["64", "0"]].concat());
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("outside"));
}

#[test]
fn a_closed_output_pipe_ends_the_program_quietly() {
    // `caustic schema | head -0`: the reader is gone before the program writes; it must stop
    // without a panic message (it used to panic in `println!` on the broken pipe).
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_caustic"))
        .arg("schema")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("caustic starts");
    drop(child.stdout.take()); // Close the pipe's only reader.
    let out = child.wait_with_output().expect("caustic ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_ne!(out.status.code(), Some(101), "a panic's exit code");
}

/// One spelling per integrator is not enough (#28): `PathPpm` and `path-ppm` are both accepted
/// by `--integrator`, `--set` and scene files (RON and TOML), and mean the same integrator.
#[test]
fn integrator_names_are_accepted_in_both_spellings_everywhere() {
    use caustic::pipeline::{SceneOverrides, prepare};
    use caustic::settings::IntegratorKind;
    let cornell = root().join("scenes/cornell.ron");
    for kind in IntegratorKind::ALL {
        for name in [kind.name(), kind.cli_name()] {
            let set = SceneOverrides {
                sets: vec![format!("render.integrator={name}")],
                ..SceneOverrides::default()
            };
            let got = prepare(&cornell, &set).expect("--set takes either spelling");
            assert_eq!(got.render_scene.params.integrator, *kind, "--set {name}");
            let cornell = cornell.to_str().expect("utf-8 path");
            for args in [
                vec!["check", cornell, "--integrator", name],
                vec![
                    "check",
                    cornell,
                    "--set",
                    &format!("render.integrator={name}"),
                ],
            ] {
                let out = caustic(&args);
                assert!(out.status.success(), "{args:?}: {}", stderr(&out));
            }
        }
    }
    let dir = tempfile::tempdir().expect("tmp");
    let ron = std::fs::read_to_string(&cornell).expect("cornell");
    let toml = std::fs::read_to_string(root().join("scenes/cornell.toml")).expect("cornell.toml");
    assert!(toml.contains("[render]") && ron.contains("render: ("));
    for (file, text) in [
        (
            "a.ron",
            ron.replacen("render: (", "render: (integrator: \"path-ppm\", ", 1),
        ),
        (
            "b.ron",
            ron.replacen("render: (", "render: (integrator: PathPpm, ", 1),
        ),
        (
            "c.toml",
            toml.replacen("[render]", "[render]\nintegrator = \"path-ppm\"", 1),
        ),
        (
            "d.toml",
            toml.replacen("[render]", "[render]\nintegrator = \"PathPpm\"", 1),
        ),
    ] {
        let path = dir.path().join(file);
        std::fs::write(&path, text).expect("write");
        // Relative asset paths: cornell uses none.
        let got = prepare(&path, &SceneOverrides::default()).expect(file);
        assert_eq!(
            got.render_scene.params.integrator,
            IntegratorKind::PathPpm,
            "{file}"
        );
    }
}

#[test]
fn plot_draws_curves_from_csv_files_with_their_slopes() {
    // Two curves of known power laws: RMSE = 0.1·t^−½ and 0.2·t^−¼ (by hand: slopes −0.5 and
    // −0.25); with the reference's noise σ = 0.01 taken out of the first, √(RMSE² − σ²) is
    // steeper than −0.5. A CSV without a `seconds` column is refused with its file and line.
    let dir = tempfile::tempdir().expect("temp dir");
    let write = |name: &str, f: &dyn Fn(f64) -> f64| {
        let mut text = String::from("seconds,rmse,spp\n");
        for t in [1.0f64, 4.0, 16.0, 64.0] {
            text.push_str(&format!("{t},{},8\n", f(t)));
        }
        let p = dir.path().join(name);
        std::fs::write(&p, text).expect("csv");
        p.to_string_lossy().into_owned()
    };
    let a = write("a.csv", &|t| 0.1 / t.sqrt());
    let b = write("b.csv", &|t| 0.2 / t.powf(0.25));
    let out = dir.path().join("plot");
    let o = out.to_str().expect("utf-8");
    let run = common::caustic(&[
        "plot",
        &format!("ours={a}"),
        &format!("theirs={b}"),
        "-o",
        o,
        "--ref-noise",
        "0.01",
    ]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains("ours: 4 points") && stdout.contains("slope -0.500"),
        "{stdout}"
    );
    assert!(
        stdout.contains("theirs: 4 points") && stdout.contains("slope -0.250"),
        "{stdout}"
    );
    for ext in ["svg", "png", "json"] {
        assert!(out.with_extension(ext).is_file(), "{ext}");
    }
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "time,rmse\n1,0.1\n").expect("csv");
    let run = common::caustic(&["plot", &format!("x={}", bad.display()), "-o", o]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("bad.csv:1") && stderr.contains("seconds"),
        "{stderr}"
    );
}

#[test]
fn check_counts_discs_and_cylinders() {
    // One disc lamp, one closed cylinder (a wall and two cap discs) and one open tube: 3 discs
    // and 2 cylinder walls; scenes without them keep their summary as before.
    let dir = tempfile::tempdir().expect("tmp");
    let scene = dir.path().join("q.ron");
    std::fs::write(
        &scene,
        r#"Scene(
    camera: Pinhole(eye: (0, 1, 4), look_at: (0, 0.5, 0), fov_y: 40),
    materials: { "grey": (color: (0.5, 0.5, 0.5)) },
    nodes: [
        Disc(radius: 0.2, emission: (radiance: (5, 5, 4)), transform: [RotateX(90), Translate(0, 2, 0)]),
        Cylinder(radius: 0.1, height: 0.5, caps: true, material: "grey"),
        Cylinder(radius: 0.1, height: 0.5, caps: false, material: "grey", transform: [Translate(1, 0, 0)]),
    ],
)"#,
    )
    .expect("write");
    let out = caustic(&["check", scene.to_str().expect("utf8")]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("0 ellipsoids, 3 discs, 2 cylinders, "),
        "{text}"
    );
    let plain = caustic(&["check", "scenes/cornell.ron"]);
    let plain = String::from_utf8_lossy(&plain.stdout);
    assert!(
        !plain.contains("disc") && !plain.contains("cylinder"),
        "{plain}"
    );
}
