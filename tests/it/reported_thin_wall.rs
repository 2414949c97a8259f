//! Issue 47's thin-wall-photon-leak (`tests/reported/thin-wall-photon-leak/`): a closed box
//! split by a single zero-thickness quad into a lit room and a dark room, seen from the dark
//! room. No light can reach the dark room, so every pixel is exactly 0 (the case's README).
//! On 79282ac the density estimates read the lit floor's photons through the divider (ppm
//! 0.064, path-ppm 0.025, photon 0.108, the default estimator with a lens in the lit room
//! 0.105) and `path` leaked 0.0020 at the divider/floor seam (a shadow ray starting within the
//! f32 triangle test's error bound of the divider).
//!
//! And the other side of the fix: the wall test must not darken an estimate where nothing
//! separates the photons from the query point — under a ball resting on the floor and in a
//! concave corner — where the reverted first attempt (segments lifted by a quarter of their
//! length, any hit rejecting) read far too dark.

use std::f64::consts::PI;

use glam::Vec3;

use caustic::integrators::photon::aim::CausticTargets;
use caustic::integrators::photon::emit::LightEmitter;
use caustic::integrators::photon::maps::trace_map;
use caustic::integrators::photon::trace::{MapKind, TraceSettings};
use caustic::integrators::photon::walls::Walls;
use caustic::integrators::photon::{Kernel, PhotonMap};
use caustic::pipeline::SceneOverrides;
use caustic::render::{Film, RenderOptions};
use caustic::sampling::Sampler;
use caustic::scene::schema::RenderSettings;
use caustic::settings::IntegratorKind;
use caustic::spatial::KdTree;

use crate::common::{render_file, root, scene_from_text};

/// The largest channel of any pixel of `film`.
fn brightest(film: &Film) -> f32 {
    let mut max = 0.0f32;
    for y in 0..film.height {
        for x in 0..film.width {
            max = max.max(film.get(x, y).max_element());
        }
    }
    max
}

#[test]
fn no_light_reaches_the_dark_room_through_a_single_quad_wall() {
    // The case at its own settings (16 × 16, 100 spp; 100 passes of 20 000 global photons for
    // the progressive integrators, radius cap 5 cm). The right result is exactly 0: no path
    // carries light into the dark room, so no noise bound is needed. For `path` the bound is
    // exact too: a shadow ray from a dark-floor point now sees the divider however close the
    // point (decided in f64 within the f32 bound, geometry::triangle); what remains is a floor
    // point computed on the lit side of the divider by its own rounding (|x| < ~1e-6 m: one
    // camera sample in ~10⁵ of the seam pixel's), expected 0.01 times in these 25 600 samples.
    let case = root().join("tests/reported/thin-wall-photon-leak/two_rooms.ron");
    for integrator in [
        IntegratorKind::Ppm,
        IntegratorKind::PathPpm,
        IntegratorKind::Photon,
        IntegratorKind::Path,
    ] {
        let overrides = SceneOverrides {
            render: RenderSettings {
                integrator: Some(integrator),
                ..RenderSettings::default()
            },
            ..SceneOverrides::default()
        };
        let (film, _) = render_file(&case, &overrides, &RenderOptions::default());
        let max = brightest(&film);
        assert!(
            max == 0.0,
            "{integrator:?}: the dark room reads up to {max}"
        );
    }
    // The default estimator (path tracing with a progressive caustic map), with a glass ball in
    // the lit room focusing the light onto the floor beside the divider (0.105 on 79282ac).
    let text = std::fs::read_to_string(&case).expect("the case");
    let lens = text
        .replace(", integrator: Ppm", "")
        .replace(
            r#""white": (color: (0.8, 0.8, 0.8)) }"#,
            r#""white": (color: (0.8, 0.8, 0.8)), "glass": (color: (1, 1, 1), transmit: 1.0, ior: 1.5) }"#,
        )
        .replace(
            "    nodes: [\n",
            "    nodes: [\n        Sphere(material: \"glass\", center: (0.35, 0.35, 0), radius: 0.25),\n",
        );
    assert_ne!(lens, text);
    let dir = std::env::temp_dir().join(format!("caustic-thin-wall-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(dir.join("lens.ron"), lens).expect("write");
    std::fs::copy(
        root().join("tests/reported/thin-wall-photon-leak/rooms.obj"),
        dir.join("rooms.obj"),
    )
    .expect("copy");
    let (film, stats) = render_file(
        &dir.join("lens.ron"),
        &SceneOverrides::default(),
        &RenderOptions::default(),
    );
    std::fs::remove_dir_all(&dir).ok();
    assert!(stats.photon_estimates > 0, "the caustic map was read");
    let max = brightest(&film);
    assert!(
        max == 0.0,
        "default estimator: the dark room reads up to {max}"
    );
}

/// A ball of radius 0.3 resting on a floor at the origin, a wall standing on the floor at
/// z = −0.35 (a concave corner), and a point light of intensity 1 W/sr low beside the ball, at
/// (1.2, 0.15, 0), so that it shines under the ball's overhang nearly to the contact.
const BALL_ON_FLOOR: &str = r#"Scene(
    render: (width: 8, height: 8, seed: 3, integrator: Photon),
    camera: Pinhole(eye: (0, 2, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: { "white": (color: (1, 1, 1)) },
    lights: [ Point(position: (1.2, 0.15, 0), power: (12.566371, 12.566371, 12.566371)) ],
    nodes: [
        Quad(material: "white", size: (20, 20), transform: [RotateX(-90)]),
        Sphere(material: "white", center: (0, 0.3, 0), radius: 0.3),
        Quad(material: "white", size: (4, 2), transform: [Translate(0, 1, -0.35)]),
    ],
)"#;

/// Irradiance (W/m²) at floor point `x` (y = 0) of [`BALL_ON_FLOOR`]: `I cos θ / d²` when the
/// segment to the light misses the ball and the point is in front of the wall, else 0.
fn floor_irradiance(x: [f64; 2]) -> f64 {
    let light = [1.2, 0.15, 0.0];
    if x[1] < -0.35 {
        return 0.0;
    }
    let p = [x[0], 0.0, x[1]];
    let d = [light[0] - p[0], light[1] - p[1], light[2] - p[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    // Segment p + t d, t ∈ (0, 1), against the ball |y − c| = R.
    let (c, r) = ([0.0, 0.3, 0.0], 0.3);
    let oc = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    let b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    let cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
    let disc = b * b - dd * cc;
    if disc > 0.0 {
        let (t0, t1) = ((-b - disc.sqrt()) / dd, (-b + disc.sqrt()) / dd);
        if (t0 > 0.0 && t0 < 1.0) || (t1 > 0.0 && t1 < 1.0) {
            return 0.0;
        }
    }
    d[1] / (dd * dd.sqrt())
}

#[test]
fn the_wall_test_does_not_darken_contact_regions_or_concave_corners() {
    // Direct photons of the point light (8 M emitted), estimates of irradiance on the floor
    // under the ball's overhang on the light's side (5 to 25 cm from the contact: the ball
    // touches the floor inside every one of these discs and rises above it, so each photon is
    // tested by a ray) and at the foot of the wall (2 cm from it). Reference: the closed form
    // with the ball's exact shadow, averaged over the estimate's own disc (polar midpoint
    // quadrature: what the estimate converges to at this radius). Noise: k = 400 photons from
    // the point light's Fibonacci lattice, well under Poisson's 1/√k = 5 % (measured: every
    // ratio within 1.5 %); bounds 8 % per point, 3 % on the mean of the 9. The reverted first
    // attempt (segments lifted by d/4, any hit rejecting; the same photons, brute-force k
    // nearest, run once) read 0.609, 0.917 and 0.952 at the first three points (5 and 8 cm from
    // the contact: its lifted ends start inside the overhang) and a mean of 0.939: it fails
    // both bounds.
    let scene = scene_from_text(BALL_ON_FLOOR);
    let n = 8_000_000u64;
    let p = &scene.params;
    let mut sampler = Sampler::new(p.sampler, p.seed, 1);
    let emitter = LightEmitter::new(scene.lights[0].clone(), n, &mut sampler, 41);
    let settings = TraceSettings {
        kind: MapKind::Global,
        min_bounces: 0,
        any_bounce: false,
        max_bounces: 0,
        pass: None,
        near_specular: None,
    };
    let (photons, _) = trace_map(
        &scene,
        &[emitter],
        &CausticTargets::default(),
        settings,
        None,
    );
    let k = 400;
    let mut map = PhotonMap::new(KdTree::build(photons).expect("tree"), k, 0.2, Kernel::Box);
    map.mark_walls(Walls::of(&scene, None));
    let points = [
        [0.05f64, 0.0],
        [0.08, 0.03],
        [0.08, -0.04],
        [0.12, 0.0],
        [0.18, 0.06],
        [0.25, -0.05],
        [0.6, -0.33],
        [0.9, -0.33],
        [0.4, -0.33],
    ];
    let (mut sum, mut rays) = (0.0, 0);
    for x in points {
        let e = map.irradiance(
            Vec3::new(x[0] as f32, 0.0, x[1] as f32),
            Vec3::Y,
            Walls::of(&scene, None),
        );
        assert!(!e.cut, "{x:?}: the estimate reached the largest radius");
        let r = f64::from(e.radius);
        let (rings, spokes) = (40, 80);
        let mut disc = 0.0;
        for i in 0..rings {
            let rho = r * ((f64::from(i) + 0.5) / f64::from(rings)).sqrt();
            for j in 0..spokes {
                let phi = 2.0 * PI * (f64::from(j) + 0.5) / f64::from(spokes);
                disc += floor_irradiance([x[0] + rho * phi.cos(), x[1] + rho * phi.sin()]);
            }
        }
        disc /= f64::from(rings * spokes);
        let ratio = f64::from(e.radiance.x) / disc;
        eprintln!(
            "floor {x:?}: photon E {:.5}, disc average {disc:.5} (ratio {ratio:.4}), radius {r:.4}, {} rays, {} hidden",
            e.radiance.x, e.rays, e.hidden
        );
        assert!(
            (ratio - 1.0).abs() < 0.08,
            "{x:?}: photon irradiance {} vs {disc} ({ratio:.3})",
            e.radiance.x
        );
        sum += ratio;
        rays += e.rays;
    }
    let mean = sum / points.len() as f64;
    assert!((mean - 1.0).abs() < 0.03, "mean ratio {mean:.4}");
    assert!(
        rays > 0,
        "the ball and the wall made the estimates test photons"
    );
}

/// A floor with a fin standing across it, as one OBJ of two groups, or as a floor mesh and a
/// separate fin node: the lifted segment from a floor point to a floor photon beyond the fin
/// crosses the fin either way.
fn floor_and_fin(fin_in_mesh: bool) -> caustic::render_scene::RenderScene {
    let dir =
        std::env::temp_dir().join(format!("caustic-body-{}-{fin_in_mesh}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let floor = "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n";
    let fin = "v 0 0 -1\nv 0 1 -1\nv 0 1 1\nv 0 0 1\n";
    let (mesh, nodes) = if fin_in_mesh {
        (
            format!("{floor}{fin}g floor\nf 1 4 3 2\ng fin\nf 5 6 7 8\n"),
            r#"Mesh(name: "m", file: "MESH", materials: {"floor": "white", "fin": "grey"})"#
                .to_string(),
        )
    } else {
        (
            format!("{floor}g floor\nf 1 4 3 2\n"),
            r#"Mesh(name: "m", file: "MESH", material: "white"),
        Quad(name: "fin", material: "grey", size: (2, 1), transform: [RotateY(90), Translate(0, 0.5, 0)])"#
                .to_string(),
        )
    };
    let path = dir.join("m.obj");
    std::fs::write(&path, mesh).expect("obj written");
    let text = format!(
        r#"Scene(
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {{ "white": (color: (0.8, 0.8, 0.8)), "grey": (color: (0.5, 0.5, 0.5)) }},
    lights: [ Point(position: (0.5, 2, 0), power: (10, 10, 10)) ],
    nodes: [ {} ],
)"#,
        nodes.replace("MESH", &path.display().to_string())
    );
    scene_from_text(&text)
}

#[test]
fn a_meshs_material_groups_are_one_body_for_the_wall_test() {
    // The toy boat of scenes/bath.ron is one OBJ whose hull, deck and cabin are material
    // groups (one object each). Its hull was taken for a wall between a cabin point and its
    // own photons: ppm read 0.92 where `path` reads 1.98 and the estimate without the wall
    // test 1.44 (200 × 150, pixel (89, 93)). A mesh's groups are one body: none of them is a
    // wall to a point of another — the documented price (module docs of `walls`): a fin in
    // the same mesh as the floor does not separate the floor either, while the same fin as a
    // node of its own does.
    use caustic::integrators::photon::walls::separated;
    let (q, p, n) = (Vec3::new(-0.3, 0.0, 0.0), Vec3::new(0.3, 0.0, 0.0), Vec3::Y);
    for fin_in_mesh in [true, false] {
        let scene = floor_and_fin(fin_in_mesh);
        let down = caustic::geometry::Ray {
            origin: Vec3::new(-0.3, 1.0, 0.2),
            dir: Vec3::NEG_Y,
            t_max: f32::INFINITY,
        };
        let hit = scene.geometry.intersect(&down).expect("the floor is below");
        let floor = scene.geometry.surface(&down, &hit);
        assert!(floor.ng.y.abs() > 0.99, "hit the floor: {:?}", floor.ng);
        let hidden = separated(&Walls::of(&scene, Some(floor.object)), q, n, p, n);
        assert_eq!(
            hidden, !fin_in_mesh,
            "fin in the floor's mesh: {fin_in_mesh}; separated: {hidden}"
        );
    }
}
