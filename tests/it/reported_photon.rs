//! The kinds of issue 29 (photon mapping, and OBJ line endings) that users of other renderers
//! reported and caustic got wrong, each turned into a test of the right result. Small inputs
//! live in `tests/reported/<case>/`.

use std::path::{Path, PathBuf};

use glam::Vec3;

use caustic::compile::mesh::{ObjMesh, parse_obj};
use caustic::geometry::Ray;
use caustic::integrators::photon::aim::CausticTargets;
use caustic::integrators::photon::emit::LightEmitter;
use caustic::integrators::photon::maps::trace_map;
use caustic::integrators::photon::trace::{MapKind, TraceSettings};
use caustic::integrators::photon::walls::Walls;
use caustic::integrators::photon::{Kernel, PhotonMap};
use caustic::pipeline::SceneOverrides;
use caustic::render::RenderOptions;
use caustic::render_scene::RenderScene;
use caustic::sampling::Sampler;
use caustic::shading::{Bsdf, ShadingFrame};
use caustic::spatial::{KdTree, Photon};

use crate::common::{caustic, render_file, root, scene_from_text};

const PI: f32 = std::f32::consts::PI;

/// A folder of `tests/reported/`.
fn case(name: &str) -> PathBuf {
    root().join("tests/reported").join(name)
}

// ---- OBJ files with CR-only line endings ------------------------------------------------------

/// An OBJ with a comment, a group, a `usemtl`, a quad and a triangle, with LF line endings.
const OBJ_LF: &str = "# two faces\no Part\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n\
vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nusemtl left\nf 1/1/1 2/2/1 3/3/1 4/1/1\ng other\nf 2 5 3\n";

fn mesh_of(text: &str) -> ObjMesh {
    parse_obj(text.as_bytes(), Path::new("m.obj")).unwrap_or_else(|e| panic!("{e}"))
}

fn assert_same_mesh(a: &ObjMesh, b: &ObjMesh, what: &str) {
    assert_eq!(a.positions, b.positions, "{what}: positions");
    assert_eq!(a.normals, b.normals, "{what}: normals");
    assert_eq!(a.uvs, b.uvs, "{what}: uvs");
    assert_eq!(a.triangles, b.triangles, "{what}: triangles");
    assert_eq!(a.names, b.names, "{what}: names");
    assert_eq!(a.triangle_names, b.triangle_names, "{what}: triangle names");
}

#[test]
fn obj_files_with_cr_only_line_endings_read_as_the_lf_file() {
    let lf = mesh_of(OBJ_LF);
    assert_eq!(lf.triangles.len(), 3, "a quad and a triangle");
    assert_eq!(lf.names, ["Part", "left", "other"]);
    for (name, ending) in [("CRLF", "\r\n"), ("CR", "\r")] {
        let text = OBJ_LF.replace('\n', ending);
        assert_same_mesh(&mesh_of(&text), &lf, name);
    }
    // Errors still name the line an editor shows (line 4 is the bad vertex).
    let bad = "# c\rv 0 0 0\rv 1 0 0\rv 1 x 0\rf 1 2 3\r";
    let e = parse_obj(bad.as_bytes(), Path::new("bad.obj")).expect_err("a bad vertex");
    assert!(e.to_string().contains("line 4: `v 1 x 0`"), "{e}");

    // The reported file, rendered: the same image as its LF twin (it was "contains no faces").
    let dir = case("obj-cr-line-endings");
    let tmp = tempfile::tempdir().expect("tmp");
    let scene = dir.join("scene.ron");
    let render = |obj: &str| {
        let out = tmp.path().join(format!("{obj}.png"));
        let o = caustic(&[
            "render",
            scene.to_str().expect("utf-8"),
            "--set",
            &format!("nodes[0].Mesh.file={obj}"),
            "--quiet",
            "-o",
            out.to_str().expect("utf-8"),
        ]);
        assert!(
            o.status.success(),
            "{obj}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        std::fs::read(out).expect("image")
    };
    assert!(
        !std::fs::read(dir.join("cr.obj"))
            .expect("cr.obj")
            .contains(&b'\n'),
        "the input has CR-only line endings"
    );
    assert_eq!(render("cr.obj"), render("lf.obj"));
}

// ---- The largest search radius only caps searches ----------------------------------------------

/// `path` rendered through the library with `overrides`; the image's mean over channels.
fn mean_of(path: &Path, overrides: &SceneOverrides) -> f64 {
    let (film, _) = render_file(path, overrides, &RenderOptions::default());
    let m = film.mean();
    f64::from(m.x + m.y + m.z) / 3.0
}

#[test]
fn a_generous_largest_radius_does_not_change_the_estimate() {
    // A 1 mm integrating sphere (albedo 0.8, point light at its centre): L = 0.8 · 5 / π =
    // 1.2732 everywhere. Its 50-photon discs are ~2e-5 wide, so no largest radius from 1 cm up
    // cuts a search; the answer must not move with it (it was 0.255 at 1, from a disc raised to
    // 1e-3 of the largest radius).
    let scene = case("estimate-radius-floor").join("small_origin.ron");
    let exact = 0.8 * 5.0 / std::f64::consts::PI;
    for r in [0.01f32, 1.0, 100.0] {
        let overrides = SceneOverrides {
            sets: vec![format!("photons.max_radius={r:?}")],
            ..SceneOverrides::default()
        };
        let m = mean_of(&scene, &overrides);
        assert!(
            (m / exact - 1.0).abs() < 0.03,
            "max radius {r}: mean {m}, exact {exact}"
        );
    }
}

// ---- Photon estimates on smooth-shaded low-poly meshes -----------------------------------------

/// Traces `n` photons of the scene's light 0, storing every direct landing on a diffuse surface
/// and nothing after it, with the tracer the global map uses.
fn direct_photons(scene: &RenderScene, n: u64) -> Vec<Photon> {
    let p = &scene.params;
    let mut sampler = Sampler::new(p.sampler, p.seed, 1);
    let emitter = LightEmitter::new(scene.lights[0].clone(), n, &mut sampler, 99);
    let settings = TraceSettings {
        kind: MapKind::Global,
        min_bounces: 0,
        any_bounce: false,
        max_bounces: 0,
        pass: None,
        near_specular: None,
    };
    trace_map(
        scene,
        &[emitter],
        &CausticTargets::default(),
        settings,
        None,
    )
    .0
}

#[test]
fn photons_on_a_smooth_shaded_low_poly_ball_read_the_shadow_rays_light_per_face() {
    // The reported 12 × 8 UV sphere (radius 0.5, smooth vertex normals) under a point light of
    // I = 10 W/sr, white Lambert: a shadow ray reads L = I (ns·ωl) / (π d²) on every facet that
    // faces the light (the ball is convex: nothing else occludes). Direct photons read through
    // the estimate must give the same per facet: dividing by the query facet's cosine instead
    // of the landing photon's made facets near the terminator up to 4× too bright.
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, seed: 3, integrator: Photon),
    camera: Pinhole(eye: (0, 1.2, 3), look_at: (0, 0.4, 0), fov_y: 30),
    materials: { "ball": (color: (1, 1, 1)) },
    lights: [ Point(position: (1, 2.5, 1), power: (125.66371, 125.66371, 125.66371)) ],
    nodes: [ Mesh(name: "ball", file: "tests/reported/smooth-normal-photons/uvsphere_12x8.obj", material: "ball", smooth: true, transform: [Scale(0.5), Translate(0, 0.5, 0)]) ],
)"#,
    );
    let light = Vec3::new(1.0, 2.5, 1.0);
    let intensity = 10.0f32;
    // 8M photons (84k on the ball) and k = 50 keep the discs small against the facets: a lit
    // facet next to an unlit one still reads a few per cent low along their edge (its disc is
    // half empty there; blur, as the flat-shaded control shows).
    let photons = direct_photons(&scene, 8_000_000);
    let map = PhotonMap::new(KdTree::build(photons).expect("tree"), 50, 1.0, Kernel::Box);
    let white = Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [Some(1.0), None, None], 1.0);
    let g = &scene.geometry;
    let centre = Vec3::new(0.0, 0.5, 0.0);
    // Per lit facet: (mean estimate, mean shadow-ray value) over a grid of points inside it.
    let mut faces = Vec::new();
    for t in &g.triangles {
        let c = (t[0] + t[1] + t[2]) / 3.0;
        if (t[1] - t[0]).cross(t[2] - t[0]).length() < 1e-6 || (light - c).dot(c - centre) <= -0.3 {
            continue; // a pole's degenerate corner, or a facet well on the dark side
        }
        let (mut est, mut exact, mut n) = (0.0f64, 0.0f64, 0);
        for i in 1..8 {
            for j in 1..8 - i {
                let (a, b) = (i as f32 / 8.0, j as f32 / 8.0);
                let p = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
                // The renderer's own frame at p: hit it from outside along the radius.
                let out = (p - centre).normalize();
                let ray = Ray::new(p + out * 0.1, -out);
                let hit = g.intersect(&ray).expect("the ball is hit");
                let sp = g.surface(&ray, &hit);
                let m = scene.objects[sp.object as usize]
                    .material
                    .expect("a material");
                let sh = scene.shading_point(&scene.materials[m as usize], &sp, out, 0.0);
                let fr = ShadingFrame {
                    ns: sh.ns,
                    ng: sh.ng,
                    entering: sh.entering,
                };
                let to_light = light - sp.p;
                let wl = to_light.normalize();
                let shadow_ray = if sh.ng.dot(wl) > 0.0 {
                    intensity * sh.ns.dot(wl).max(0.0) / (PI * to_light.length_squared())
                } else {
                    0.0
                };
                est += f64::from(
                    map.estimate(sp.p, out, &fr, &white, Walls::of(&scene, Some(sp.object)))
                        .radiance
                        .x,
                );
                exact += f64::from(shadow_ray);
                n += 1;
            }
        }
        faces.push((est / f64::from(n), exact / f64::from(n)));
    }
    let brightest = faces.iter().map(|f| f.1).fold(0.0, f64::max);
    let mut off = Vec::new();
    let mut checked = 0;
    for &(est, exact) in &faces {
        // Facets lit at least a tenth as much as the brightest (dimmer ones are a few photons).
        if exact < 0.1 * brightest {
            continue;
        }
        checked += 1;
        if (est / exact - 1.0).abs() > 0.05 {
            off.push(format!("{:.3} (lit {:.2})", est / exact, exact / brightest));
        }
    }
    let (e, x): (f64, f64) = faces.iter().fold((0.0, 0.0), |s, f| (s.0 + f.0, s.1 + f.1));
    eprintln!(
        "{checked} lit facets checked, ball mean ratio {:.4}; off by > 5 %: {off:?}",
        e / x
    );
    assert!(checked >= 20, "{checked} facets checked");
    assert!(off.is_empty(), "facets off by more than 5 %: {off:?}");
    assert!((e / x - 1.0).abs() < 0.02, "ball mean ratio {}", e / x);
}

// ---- Final gathering onto glossy surfaces ------------------------------------------------------

/// `file` of `tests/reported/glossy-final-gather/` rendered at 8 × 8 with `integrator`, `spp`
/// samples and `sets`; the image's mean.
fn isphere_mean(file: &str, integrator: &str, spp: u32, sets: &[String]) -> f64 {
    let mut sets = sets.to_vec();
    sets.push(format!("render.integrator={integrator}"));
    let overrides = SceneOverrides {
        sets,
        ..crate::common::small(8, 8, spp)
    };
    mean_of(&case("glossy-final-gather").join(file), &overrides)
}

#[test]
fn final_gathering_onto_glossy_walls_agrees_with_the_path_tracer() {
    // The reported integrating sphere (R = 1, camera and point light at the centre) with walls
    // of 0.5 diffuse + 0.4 Phong: final gathering (16 rays) against the path tracer for
    // shininess 1, 10 and 50 (it was +8 / +22 / +45 %), and the Lambert control against its
    // closed form a·E/π = 0.8 · 5/π (it was right, and must stay so).
    let photons = |global: u32| {
        vec![
            format!("photons.global={global}"),
            "photons.gather=50".to_string(),
            "photons.final_gather=16".to_string(),
        ]
    };
    let lambert = isphere_mean("isphere.ron", "Photon", 4, &photons(20_000));
    let exact = 0.8 * 5.0 / f64::from(PI);
    assert!(
        (lambert / exact - 1.0).abs() < 0.02,
        "Lambert: {lambert}, exact {exact}"
    );
    for m in [1, 10, 50] {
        let mut sets = photons(20_000);
        sets.push(format!("materials.wall.shininess={m}"));
        let fg = isphere_mean("isphere_glossy.ron", "Photon", 4, &sets);
        let path = isphere_mean("isphere_glossy.ron", "Path", 256, &sets);
        eprintln!("shininess {m}: final gathering {fg:.4}, path {path:.4}");
        assert!(
            (fg / path - 1.0).abs() < 0.03,
            "shininess {m}: final gathering {fg}, path {path}"
        );
    }
}

// ---- Final gathering near concave corners ------------------------------------------------------

/// The mean radiance of the reported white Cornell box's floor at distance `d` from the back
/// wall, seen by a tiny camera looking straight down (8 × 8 pixels over 0.9 mm), rendered by
/// `integrator` at `spp` with the extra settings `sets`.
fn corner_floor_mean(d: f32, integrator: &str, spp: u32, sets: &[&str]) -> f64 {
    let scene = case("corner-final-gather").join("corner_meet.ron");
    let z = -1.0 + d;
    let mut all = vec![
        format!("camera.eye=(0, 0.05, {z:?})"),
        format!("camera.look_at=(0, 0, {z:?})"),
        format!("render.integrator={integrator}"),
    ];
    all.extend(sets.iter().map(|s| (*s).to_string()));
    let overrides = SceneOverrides {
        sets: all,
        ..crate::common::small(8, 8, spp)
    };
    mean_of(&scene, &overrides)
}

#[test]
fn final_gathering_near_a_concave_corner_agrees_with_the_path_tracer() {
    // Final gathering (16 rays) against the path tracer at D = 1 cm and 3 cm from the wall (it
    // was −5.2 % at 1 cm with the reported 1M photons; here 200k photons and k = 50 make the
    // discs wider, which made it worse).
    let maps = [
        "photons.global=200000",
        "photons.gather=50",
        "photons.final_gather=16",
    ];
    for d in [0.01f32, 0.03] {
        let fg = corner_floor_mean(d, "Photon", 16, &maps);
        let path = corner_floor_mean(d, "Path", 2048, &maps);
        eprintln!("D = {d}: final gathering {fg:.4}, path {path:.4}");
        // The issue asks for 3 % at every D ≥ 1 cm; 1.5 % holds here (−0.4 % and −0.8 %), and
        // keeps the short-ray rule needed: without it this box reads −2.6 % at 1 cm.
        assert!(
            (fg / path - 1.0).abs() < 0.015,
            "D = {d}: final gathering {fg}, path {path}"
        );
    }
}

#[test]
fn path_ppm_final_gathering_near_a_concave_corner_agrees_with_the_path_tracer() {
    // The same box and camera for `path-ppm` with a global map (read after one diffuse bounce,
    // fresh maps every pass): its gather rays from the floor 1 cm from the back wall that land
    // on the wall near the corner are short, and the wall's estimate there reads a half-empty
    // disc. The short-gather rule sends them one bounce further, as final gathering does
    // (without it: −6.1 % at 1 cm; with it +0.2 % and +0.4 %).
    let maps = ["photons.global=20000", "photons.gather=20"];
    for d in [0.01f32, 0.03] {
        let ppm = corner_floor_mean(d, "PathPpm", 64, &maps);
        let path = corner_floor_mean(d, "Path", 2048, &maps);
        eprintln!("D = {d}: path-ppm with a global map {ppm:.4}, path {path:.4}");
        assert!(
            (ppm / path - 1.0).abs() < 0.015,
            "D = {d}: path-ppm {ppm}, path {path}"
        );
    }
}

// ---- Photon budgets per map, and Ctrl-C during photon passes -----------------------------------

/// Errors of `text` (a RON scene) found by validation, as `path: message` lines.
fn validation_errors(text: &str) -> Vec<String> {
    let src =
        caustic::scene::SourceFile::new(Path::new("inline.ron"), text.to_string()).expect("source");
    let file = src.parse().unwrap_or_else(|e| panic!("{e}"));
    caustic::scene::validate::validate(&file)
        .iter()
        .filter(|d| d.is_error())
        .map(|d| format!("{}: {}", d.path, d.message))
        .collect()
}

/// A floor and a mirror ball under lights with the given fields, `photons.caustic` = `shared`.
fn budget_scene(lights: &[&str], shared: u32) -> String {
    let lights: Vec<String> = lights
        .iter()
        .enumerate()
        .map(|(i, extra)| format!("Point(position: ({i}, 2, 0), power: (10, 10, 10){extra})"))
        .collect();
    format!(
        r#"Scene(
    render: (width: 8, height: 8),
    camera: Pinhole(eye: (0, 1, 4), look_at: (0, 0, 0), fov_y: 40),
    photons: (caustic: {shared}),
    materials: {{ "white": (color: (0.5, 0.5, 0.5)), "mirror": (color: (1, 1, 1), diffuse: 0, reflect: 1) }},
    lights: [ {} ],
    nodes: [ Quad(material: "white", size: (4, 4), transform: [RotateX(-90)]), Sphere(material: "mirror", center: (0, 0.5, 0), radius: 0.5) ],
)"#,
        lights.join(", ")
    )
}

#[test]
fn a_caustic_map_over_the_photon_limit_is_refused_with_its_memory() {
    let own = |n: u32| format!(", caustic_photons: {n}");
    let (a, b) = (own(30_000_000), own(25_000_000));
    // Two lights' own budgets, each under the limit, add up to one map over it.
    let e = validation_errors(&budget_scene(&[&a, &b], 1000));
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].starts_with("lights[1].caustic_photons: the caustic map would hold 55000000 photons")
            && e[0].contains("could need 5.3 GB"),
        "{e:?}"
    );
    // A light without its own budget shares `photons.caustic`, which then counts too.
    let e = validation_errors(&budget_scene(&[&a, ""], 30_000_000));
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(e[0].contains("+ photons.caustic 30000000"), "{e:?}");
    // When every light has its own budget the shared one is unused, and sums under the limit
    // are fine.
    assert!(validation_errors(&budget_scene(&[&a, &own(20_000_000)], 40_000_000)).is_empty());
    assert!(validation_errors(&budget_scene(&[&a, ""], 20_000_000)).is_empty());
    // One field over the limit is reported once, by its own check.
    let e = validation_errors(&budget_scene(&[&own(60_000_000), &b], 0));
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].starts_with("lights[0].caustic_photons: must be at most"),
        "{e:?}"
    );

    // The reported scene (three lights at 4e7) is refused by `check`, before any work.
    let scene = case("photon-budget-and-cancel").join("km_plane_three_budgets.ron");
    let o = caustic(&["check", scene.to_str().expect("utf-8")]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("the caustic map would hold 120000000 photons")
            && stderr.contains("11.5 GB"),
        "{stderr}"
    );
}

#[test]
fn a_raised_cancel_flag_stops_photon_tracing_promptly() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::{Duration, Instant};

    use caustic::render::{RenderError, render};

    // 5e7 global photons over a 1 km plane: a minute of tracing on two cores, for the photon
    // integrator's maps and for a progressive pass alike.
    for integrator in ["Photon", "Ppm"] {
        let overrides = SceneOverrides {
            sets: vec![
                "photons.global=50000000".into(),
                format!("render.integrator={integrator}"),
            ],
            ..crate::common::small(8, 8, 1)
        };
        let scene = caustic::pipeline::prepare(
            &case("photon-budget-and-cancel").join("km_plane.ron"),
            &overrides,
        )
        .expect("prepares")
        .render_scene;
        let flag = Arc::new(AtomicBool::new(false));
        let raiser = {
            let flag = Arc::clone(&flag);
            std::thread::spawn(move || {
                std::thread::sleep(Duration::from_millis(300));
                flag.store(true, Ordering::SeqCst);
                Instant::now()
            })
        };
        let options = RenderOptions {
            threads: Some(2),
            cancel: Some(flag),
            ..RenderOptions::default()
        };
        let result = render(&scene, &options);
        let stopped = Instant::now();
        let raised = raiser.join().expect("raiser");
        assert!(
            matches!(result, Err(RenderError::Cancelled)),
            "{integrator}: {:?}",
            result.map(|o| o.stats)
        );
        let lag = stopped.saturating_duration_since(raised);
        assert!(
            lag < Duration::from_secs(1),
            "{integrator}: stopped {lag:?} after the flag"
        );
    }
}

#[cfg(unix)]
#[test]
fn ctrl_c_and_sigterm_stop_a_photon_pass_within_moments() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};

    let dir = case("photon-budget-and-cancel");
    let tmp = tempfile::tempdir().expect("tmp");
    // The reported commands: 5e7 photons per pass (64 s on one thread) for `ppm`, and the
    // photon integrator's one build; the signal comes while photons are traced.
    for (integrator, signal) in [("ppm", "-INT"), ("photon", "-TERM")] {
        let out = tmp.path().join(format!("{integrator}.exr"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_caustic"))
            .args([
                "render",
                "km_plane.ron",
                "--integrator",
                integrator,
                "--photons",
                "50000000",
                "--spp",
                "1",
                "--width",
                "8",
                "--height",
                "8",
                "--threads",
                "2",
                "-o",
                out.to_str().expect("utf-8"),
            ])
            .current_dir(&dir)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("caustic starts");
        std::thread::sleep(Duration::from_millis(1500));
        assert!(
            child.try_wait().expect("wait").is_none(),
            "{integrator}: still tracing photons after 1.5 s"
        );
        let status = Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .expect("kill runs");
        assert!(status.success());
        let sent = Instant::now();
        while child.try_wait().expect("wait").is_none() && sent.elapsed() < Duration::from_secs(20)
        {
            std::thread::sleep(Duration::from_millis(10));
        }
        let lag = sent.elapsed();
        let _ = child.kill();
        let o = child.wait_with_output().expect("output");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(
            o.status.code(),
            Some(130),
            "{integrator} {signal}: {stderr}"
        );
        assert!(
            lag < Duration::from_secs(2),
            "{integrator}: exited {lag:?} after {signal}"
        );
        assert_eq!(stderr.trim(), "interrupted: no image written");
        assert!(!out.exists(), "no image written");
    }
}
