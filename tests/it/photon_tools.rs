//! The photon-map cache (`--photon-cache`) and the `caustic photons` viewer.

use std::path::{Path, PathBuf};

use glam::Vec3;

use caustic::integrators::photon::cache::{
    MAGIC, build_or_load, cache_file, cache_key, decode, encode,
};
use caustic::integrators::photon::{PhotonMap, build_maps};
use caustic::render::{Film, RenderJob, RenderOptions};
use caustic::render_scene::RenderScene;
use caustic::spatial::{BuildOptions, KdTree};

use crate::common::{caustic, scene_from_text};

/// A glass ball over a floor, between a wall and a ceiling, lit by a point light straight above
/// the ball: the caustic focuses on the floor under the ball (x = z = 0).
fn ball_scene() -> String {
    r#"Scene(
    render: (width: 32, height: 24, samples_per_pixel: 1, max_depth: 6, seed: 5, integrator: Photon),
    camera: Pinhole(eye: (0, 3.5, 5), look_at: (0, 0.3, 0), fov_y: 40),
    materials: {
        "floor": (color: (0.8, 0.8, 0.8)),
        "wall": (color: (0.6, 0.3, 0.2)),
        "glass": (color: (1, 1, 1), transmit: 1.0, ior: 1.5),
    },
    lights: [ Point(position: (0, 5, 0), power: (400, 400, 400)) ],
    photons: (global: 8000, caustic: 20000, final_gather: 0, gather: 30, caustic_gather: 30),
    nodes: [
        Quad(name: "floor", material: "floor", size: (10, 10), transform: [RotateX(-90)]),
        Quad(name: "wall", material: "wall", size: (10, 6), transform: [Translate(0, 3, -3)]),
        Quad(name: "ceiling", material: "floor", size: (10, 10), transform: [RotateX(90), Translate(0, 6, 0)]),
        Sphere(name: "ball", material: "glass", radius: 0.5, center: (0, 1.0, 0)),
    ],
)"#
    .to_string()
}

/// A fresh, empty folder under the target directory's tmp (removed first if left over).
fn temp_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("photon_tools_{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn options(cache: Option<&Path>) -> RenderOptions {
    RenderOptions {
        photon_cache: cache.map(Path::to_path_buf),
        ..RenderOptions::default()
    }
}

/// The film and the summary's cache line of a render with `cache`.
fn render_cached(scene: &RenderScene, cache: Option<&Path>) -> (Film, Option<String>) {
    let job = RenderJob::new(scene, &options(cache)).expect("job");
    let line = job
        .integrator()
        .photon_maps()
        .and_then(|m| m.summary.cache.clone());
    (job.finish().expect("render").film, line)
}

fn bits(film: &Film) -> Vec<[u32; 3]> {
    film.pixels
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

fn assert_same_maps(a: Option<&PhotonMap>, b: Option<&PhotonMap>) {
    match (a, b) {
        (None, None) => {}
        (Some(a), Some(b)) => {
            assert_eq!(a.photons(), b.photons());
            assert_eq!(a.max_radius().to_bits(), b.max_radius().to_bits());
        }
        _ => panic!("one map is missing"),
    }
}

#[test]
fn a_cache_hit_renders_the_same_bytes_as_a_fresh_build() {
    let dir = temp_dir("hit");
    let scene = scene_from_text(&ball_scene());
    let (fresh, none) = render_cached(&scene, None);
    assert_eq!(none, None);
    let (miss, line) = render_cached(&scene, Some(&dir));
    let file = cache_file(&dir, cache_key(&scene));
    assert_eq!(
        line.as_deref(),
        Some(format!("photon cache: miss: built and saved ({})", file.display()).as_str())
    );
    assert!(file.is_file());
    let (hit, line) = render_cached(&scene, Some(&dir));
    assert_eq!(
        line.as_deref(),
        Some(format!("photon cache: hit ({})", file.display()).as_str())
    );
    assert_eq!(bits(&miss), bits(&fresh));
    assert_eq!(bits(&hit), bits(&fresh));
    // The loaded maps are the built maps: photons in the same slots, the same radii, counts.
    let built = build_maps(&scene);
    let loaded = build_or_load(&scene, Some(&dir), None);
    assert_same_maps(built.caustic.as_ref(), loaded.caustic.as_ref());
    assert_same_maps(built.global.as_ref(), loaded.global.as_ref());
    assert!(built.caustic.as_ref().is_some_and(|m| m.len() > 1000));
    assert!(built.global.as_ref().is_some_and(|m| m.len() > 1000));
    let (b, l) = (&built.summary, &loaded.summary);
    assert_eq!((&b.caustic, &b.global), (&l.caustic, &l.global));
    assert_eq!((b.targets, b.auto_radius), (l.targets, l.auto_radius));
    assert_eq!(
        (b.caustic_radius, b.global_radius),
        (l.caustic_radius, l.global_radius)
    );
}

#[test]
fn the_key_follows_what_photons_depend_on_and_nothing_else() {
    let key = |edit: &dyn Fn(&str) -> String| cache_key(&scene_from_text(&edit(&ball_scene())));
    let same = |s: &str| s.to_string();
    let base = key(&same);
    assert_eq!(base, key(&same), "the key is deterministic");
    // Camera, image size, samples and estimate-only settings: the same maps.
    for (from, to) in [
        ("eye: (0, 3.5, 5)", "eye: (1, 3, 6)"),
        ("width: 32, height: 24", "width: 64, height: 48"),
        ("samples_per_pixel: 1", "samples_per_pixel: 9"),
        (
            "gather: 30, caustic_gather: 30",
            "gather: 50, caustic_gather: 10",
        ),
        ("final_gather: 0", "final_gather: 4"),
        ("integrator: Photon", "integrator: Path"),
    ] {
        assert_eq!(base, key(&|s| s.replace(from, to)), "{from} -> {to}");
    }
    // Geometry, materials, lights, photon counts, seed, sampler: other maps.
    for (from, to) in [
        ("seed: 5", "seed: 6"),
        ("power: (400, 400, 400)", "power: (400, 400, 401)"),
        ("position: (0, 5, 0)", "position: (0, 5, 0.01)"),
        ("ior: 1.5", "ior: 1.52"),
        ("(0.8, 0.8, 0.8)", "(0.8, 0.8, 0.7)"),
        ("radius: 0.5", "radius: 0.51"),
        ("size: (10, 10)", "size: (10, 11)"),
        ("global: 8000", "global: 8001"),
        ("caustic: 20000", "caustic: 20001"),
    ] {
        assert!(ball_scene().contains(from), "{from}");
        assert_ne!(base, key(&|s| s.replace(from, to)), "{from} -> {to}");
    }
    let sampler = |name: &str| {
        key(&|s| {
            s.replace(
                "integrator: Photon",
                &format!("integrator: Photon, sampler: {name}"),
            )
        })
    };
    assert_ne!(sampler("Sobol"), sampler("Independent"));
}

#[test]
fn a_corrupt_or_truncated_file_is_reported_rebuilt_and_never_trusted() {
    let dir = temp_dir("corrupt");
    let scene = scene_from_text(&ball_scene());
    let (fresh, _) = render_cached(&scene, None);
    let file = cache_file(&dir, cache_key(&scene));
    let good = {
        let _ = render_cached(&scene, Some(&dir));
        std::fs::read(&file).expect("saved")
    };
    let mut flipped = good.clone();
    let at = good.len() / 2;
    flipped[at] ^= 0x10;
    let wrong_key = {
        // A valid file of another scene's key, put under this key's name.
        let other = scene_from_text(&ball_scene().replace("seed: 5", "seed: 7"));
        encode(&build_maps(&other), cache_key(&other))
    };
    for (what, bytes) in [
        ("flipped bit", flipped),
        ("truncated", good[..good.len() * 2 / 3].to_vec()),
        ("empty", Vec::new()),
        ("other key", wrong_key),
    ] {
        std::fs::write(&file, &bytes).expect("write");
        let (film, line) = render_cached(&scene, Some(&dir));
        let line = line.expect("cache line");
        assert!(
            line.starts_with("warning: photon cache: corrupt: rebuilt and saved"),
            "{what}: {line}"
        );
        assert!(line.contains(&file.display().to_string()), "{what}: {line}");
        assert_eq!(bits(&film), bits(&fresh), "{what}");
        // The rebuilt file replaced the bad one.
        assert_eq!(std::fs::read(&file).expect("rebuilt"), good, "{what}");
    }
    // The decoder names what is wrong.
    let e = decode(&scene, &good[..40], cache_key(&scene))
        .expect_err("truncated")
        .to_string();
    assert!(e.contains("checksum") || e.contains("truncated"), "{e}");
    let e = decode(&scene, b"not a cache file at all, no", 0)
        .expect_err("magic")
        .to_string();
    assert!(e.contains("signature"), "{e}");
    assert_eq!(&good[..16], MAGIC);
}

#[test]
fn a_hit_with_other_gather_settings_equals_a_fresh_build_with_them() {
    let dir = temp_dir("gather");
    let scene = scene_from_text(&ball_scene());
    let _ = render_cached(&scene, Some(&dir));
    // Other k, a fixed radius, and final gathering (whose precomputed irradiance is rebuilt
    // from the loaded maps).
    let text = ball_scene()
        .replace(
            "gather: 30, caustic_gather: 30",
            "gather: 12, caustic_gather: 45, max_radius: 0.3",
        )
        .replace("final_gather: 0", "final_gather: 3");
    let other = scene_from_text(&text);
    let (fresh, _) = render_cached(&other, None);
    let (hit, line) = render_cached(&other, Some(&dir));
    assert!(line.is_some_and(|l| l.starts_with("photon cache: hit")));
    assert_eq!(bits(&hit), bits(&fresh));
    let loaded = build_or_load(&other, Some(&dir), None);
    assert!(loaded.summary.irradiance_points > 0);
    assert_eq!(
        loaded.summary.irradiance_points,
        build_maps(&other).summary.irradiance_points
    );
}

#[test]
fn renders_racing_on_one_cache_leave_a_whole_file() {
    let dir = temp_dir("race");
    let scene = scene_from_text(&ball_scene());
    let lines: Vec<Option<String>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|_| s.spawn(|| build_or_load(&scene, Some(&dir), None).summary.cache))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("thread"))
            .collect()
    });
    for l in &lines {
        let l = l.as_deref().unwrap_or("");
        assert!(
            l.starts_with("photon cache: miss: built and saved")
                || l.starts_with("photon cache: hit"),
            "{l}"
        );
    }
    // One file, no temporary left behind, and it is a valid cache of this scene.
    let names: Vec<_> = std::fs::read_dir(&dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
    let bytes = std::fs::read(cache_file(&dir, cache_key(&scene))).expect("file");
    assert!(decode(&scene, &bytes, cache_key(&scene)).is_ok());
}

#[test]
fn the_cli_reports_miss_then_hit_and_writes_identical_images() {
    let dir = temp_dir("cli");
    let scene = dir.join("ball.ron");
    std::fs::write(&scene, ball_scene()).expect("scene");
    let cache = dir.join("cache");
    let run = |out: &str| {
        let o = caustic(&[
            "render",
            scene.to_str().expect("utf-8"),
            "-o",
            dir.join(out).to_str().expect("utf-8"),
            "--photon-cache",
            cache.to_str().expect("utf-8"),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let first = run("a.png");
    assert!(
        first.contains("photon cache: miss: built and saved"),
        "{first}"
    );
    let second = run("b.png");
    assert!(second.contains("photon cache: hit"), "{second}");
    let a = std::fs::read(dir.join("a.png")).expect("a");
    assert_eq!(a, std::fs::read(dir.join("b.png")).expect("b"));
    // debug-pixel reads the same maps.
    let dp = |extra: &[&str]| {
        let mut args = vec!["debug-pixel", scene.to_str().expect("utf-8"), "16", "14"];
        args.extend_from_slice(extra);
        let o = caustic(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        o.stdout
    };
    assert_eq!(
        dp(&[]),
        dp(&["--photon-cache", cache.to_str().expect("utf-8")])
    );
}

/// Pixels of an 8-bit RGB image that are clearly caustic-coloured (orange: red well above
/// blue, as the viewer's caustic colour and no grey or blue pixel is), as `(x, y)`.
fn orange_pixels(png: &Path, margin: u8) -> Vec<(u32, u32)> {
    let img = image::open(png).expect("png").to_rgb8();
    img.enumerate_pixels()
        .filter(|(_, _, p)| p[0] > p[2].saturating_add(margin) && p[0] > p[1])
        .map(|(x, y, _)| (x, y))
        .collect()
}

/// Where the camera of [`ball_scene`] sees `p`, for a `w × h` image, by hand: the pinhole
/// projection onto the image plane at distance 1 (tan 20° is half the height).
fn project(p: Vec3, w: f32, h: f32) -> (f32, f32) {
    let eye = Vec3::new(0.0, 3.5, 5.0);
    let f = (Vec3::new(0.0, 0.3, 0.0) - eye).normalize();
    let r = f.cross(Vec3::Y).normalize();
    let u = r.cross(f);
    let d = p - eye;
    let t = 20f32.to_radians().tan();
    let (x, y) = (d.dot(r) / d.dot(f), d.dot(u) / d.dot(f));
    ((x / (t * w / h) + 1.0) * 0.5 * w, (1.0 - y / t) * 0.5 * h)
}

#[test]
fn the_viewer_shows_the_caustic_under_the_ball_and_nowhere_else() {
    let dir = temp_dir("viewer");
    let scene = dir.join("ball.ron");
    std::fs::write(&scene, ball_scene()).expect("scene");
    let (w, h) = (96u32, 72u32);
    let view = |out: &str, extra: &[&str]| {
        let png = dir.join(out);
        let (ws, hs) = (w.to_string(), h.to_string());
        let mut args = vec![
            "photons",
            scene.to_str().expect("utf-8"),
            "-o",
            png.to_str().expect("utf-8"),
            "--width",
            &ws,
            "--height",
            &hs,
            "--quiet",
        ];
        args.extend_from_slice(extra);
        let o = caustic(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (png, String::from_utf8_lossy(&o.stdout).into_owned())
    };
    let (png, out) = view("view.png", &[]);
    assert!(out.contains("caustic"), "{out}");
    let (cx, cy) = project(Vec3::ZERO, w as f32, h as f32);
    let (ex, _) = project(Vec3::new(0.5, 0.0, 0.0), w as f32, h as f32);
    let ball_radius_px = ex - cx;
    let strong = orange_pixels(&png, 80);
    let near = |&(x, y): &(u32, u32)| {
        (x as f32 + 0.5 - cx).hypot(y as f32 + 0.5 - cy) <= 2.5 * ball_radius_px
    };
    // The focus and the halo that rings the ball's shadow (light refracted near its rim): the
    // shadow's radius on the floor is 5 tan(asin(0.5 / 4)) = 0.63, 1.26 ball radii; the disc
    // checked is 2.5 ball radii. Outside it lie only the sparse photons the ball reflects.
    let under = strong.iter().filter(|p| near(p)).count();
    assert!(under >= 10, "{under} strong caustic pixels under the ball");
    let elsewhere: Vec<_> = strong.iter().filter(|p| !near(p)).collect();
    assert!(
        elsewhere.is_empty(),
        "caustic pixels away from the focus: {elsewhere:?}"
    );
    // Blue (global) photons are drawn on the floor and wall, not orange.
    let img = image::open(&png).expect("png").to_rgb8();
    assert!(img.pixels().any(|p| p[2] > p[0].saturating_add(40)));

    let (none, _) = view("none.png", &["--caustic-photons", "0"]);
    let faint = orange_pixels(&none, 10);
    assert!(
        faint.is_empty(),
        "{} orange pixels without caustic photons",
        faint.len()
    );
}

/// Restoring a tree from its tree order against rebuilding it, for 1M photons, and the time
/// the cache key of each demo scene takes (run with `--ignored --nocapture` to see the timings;
/// the figures are in docs/photon_map.md).
#[test]
#[ignore = "timing (1M photons)"]
fn restoring_a_million_photons_is_faster_than_building() {
    use caustic::spatial::Photon;
    use std::time::Instant;
    let mut s = 12345u64;
    let mut next = || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let photons: Vec<Photon> = (0..1_000_000)
        .map(|_| {
            Photon::new(
                Vec3::new(next() * 4.0, 0.0, next() * 4.0),
                -Vec3::Y,
                Vec3::Y,
                Vec3::splat(1e-6),
            )
        })
        .collect();
    let t = Instant::now();
    let built = KdTree::build(photons.clone()).expect("tree");
    let build = t.elapsed();
    let ordered = built.items().to_vec();
    let t = Instant::now();
    let restored = KdTree::from_tree_order(ordered.clone(), BuildOptions::default()).expect("r");
    let restore = t.elapsed();
    let t = Instant::now();
    let rebuilt = KdTree::build(ordered).expect("tree");
    let rebuild = t.elapsed();
    assert_eq!(restored.items(), built.items());
    for path in crate::common::scene_files() {
        let prepared = caustic::pipeline::prepare(&path, &Default::default()).expect("scene");
        let t = Instant::now();
        let key = cache_key(&prepared.render_scene);
        println!(
            "{}: key {key:016x} in {:.4} s ({} triangles, {} textures)",
            path.display(),
            t.elapsed().as_secs_f64(),
            prepared.render_scene.geometry.triangles.len(),
            prepared.render_scene.textures.len()
        );
    }
    println!(
        "1M photons: build {:.3} s, from_tree_order {:.3} s, build from tree order {:.3} s (same order: {})",
        build.as_secs_f64(),
        restore.as_secs_f64(),
        rebuild.as_secs_f64(),
        rebuilt.items() == built.items()
    );
}
