//! The lights of issue #25 in whole renders: `scenes/lights.ron` and its TOML twin render the
//! same bytes; `caustic check` accepts each light kind and every integrator renders each one
//! finite and lit; the white furnace under a constant environment light (a convex diffuse object
//! of albedo a reads a·L, a mirror and a glass sphere vanish, a closed sphere seen from inside is
//! black) for `path` and `photon`; and the penumbra a sun of angular radius α casts behind a
//! straight edge against its geometric profile. (Each light's own closed forms and χ² tests are
//! unit tests under `src/render_scene/light/`; the thin lens's in `src/render_scene/camera/`.)

use caustic::render::{RenderOptions, render};
use caustic::render_scene::RenderScene;

use crate::common::{self, scene_from_text};

const PI: f64 = std::f64::consts::PI;

#[test]
fn lights_ron_and_toml_are_twins_and_render_identical_bytes() {
    let ron = common::root().join("scenes/lights.ron");
    let toml = common::root().join("scenes/lights.toml");
    let a = caustic::scene::load::load(&ron).expect("ron loads").scene;
    let b = caustic::scene::load::load(&toml).expect("toml loads").scene;
    assert_eq!(a, b, "the twins parse to different scenes");
    let o = common::small(32, 24, 2);
    let (fa, _) = common::render_file(&ron, &o, &RenderOptions::default());
    let (fb, _) = common::render_file(&toml, &o, &RenderOptions::default());
    assert!(
        fa.to_bytes() == fb.to_bytes(),
        "the twins render different pixels"
    );
}

/// One small scene per light kind: a grey floor and a sphere lit by that light only.
fn one_light_scenes() -> Vec<(&'static str, String)> {
    let sky = common::root().join("assets/sky.exr");
    let sky = sky.to_string_lossy();
    let floor = r#"Quad(material: "grey", size: (6, 6), transform: [RotateX(-90)]),
        Sphere(material: "grey", center: (0, 0.5, 0), radius: 0.5),"#;
    let with = |lights: &str, more: &str| {
        format!(
            r#"Scene(
    render: (width: 16, height: 12, samples_per_pixel: 2, max_depth: 4, seed: 1),
    camera: Pinhole(eye: (0, 1.5, 4), look_at: (0, 0.5, 0), fov_y: 40),
    materials: {{ "grey": (color: (0.5, 0.5, 0.5)) }},
    photons: (global: 2000, caustic: 0),
    lights: [{lights}],
    nodes: [
        {floor}
        {more}
    ],
)"#
        )
    };
    vec![
        (
            "quad emission",
            with(
                "",
                "Quad(size: (1, 1), emission: (radiance: (5, 5, 5)), transform: [RotateX(90), Translate(0, 2, 0)]),",
            ),
        ),
        (
            "cube emission",
            with(
                "",
                "Cube(size: 0.3, emission: (radiance: (5, 5, 5)), transform: [Translate(1, 1, 1)]),",
            ),
        ),
        (
            "spot",
            with(
                "Spot(position: (0, 3, 1), direction: (0, -1, -0.3), intensity: (20, 20, 20), inner_angle: 20, outer_angle: 30)",
                "",
            ),
        ),
        (
            "distant",
            with(
                "Distant(direction: (0.3, 1, 0.5), irradiance: (2, 2, 2), angular_radius: 0.2665)",
                "",
            ),
        ),
        (
            "constant environment",
            with("Environment(radiance: (0.5, 0.5, 0.5))", ""),
        ),
        (
            "image environment",
            with(&format!("Environment(file: {sky:?}, rotation: 30)"), ""),
        ),
    ]
}

#[test]
fn caustic_check_accepts_each_light_kind_and_every_integrator_renders_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (kind, text) in one_light_scenes() {
        let path = dir.path().join(format!("{}.ron", kind.replace(' ', "_")));
        std::fs::write(&path, &text).expect("write scene");
        let out = common::caustic(&["check", path.to_str().expect("utf-8 path")]);
        assert!(
            out.status.success(),
            "{kind}: caustic check refused it:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for integrator in ["Whitted", "Path", "Photon", "Ppm", "PathPpm"] {
            let scene = scene_from_text(
                &text.replace("seed: 1)", &format!("seed: 1, integrator: {integrator})")),
            );
            let out = render(&scene, &RenderOptions::default()).expect("renders");
            assert_eq!(
                out.stats.nan_samples, 0,
                "{kind}, {integrator}: NaN samples"
            );
            let px = &out.film.pixels;
            assert!(
                px.iter().all(|p| p.is_finite()),
                "{kind}, {integrator}: non-finite pixel"
            );
            let mean: f64 =
                px.iter().map(|p| f64::from(p.element_sum())).sum::<f64>() / (3 * px.len()) as f64;
            assert!(
                mean > 1e-3,
                "{kind}, {integrator}: the image is black ({mean})"
            );
        }
    }
}

/// A furnace under a constant environment light of radiance 1: a unit sphere of `material`
/// filling the whole frame (its silhouette is 19.5° from the axis, the frame's corners 14°).
fn env_furnace(material: &str, integrator: &str) -> RenderScene {
    scene_from_text(&format!(
        r#"Scene(
    render: (width: 16, height: 16, samples_per_pixel: 64, max_depth: 64, seed: 3,
             integrator: {integrator}),
    camera: Pinhole(eye: (0, 0, 3), look_at: (0, 0, 0), fov_y: 20),
    materials: {{ "m": {material} }},
    photons: (global: 20000, caustic: 20000),
    lights: [ Environment(radiance: (1, 1, 1)) ],
    nodes: [ Sphere(material: "m", center: (0, 0, 0), radius: 1) ],
)"#
    ))
}

/// Mean, smallest and largest pixel (red channel) of a render.
fn stats(scene: &RenderScene) -> (f64, f64, f64) {
    let out = render(scene, &RenderOptions::default()).expect("renders");
    assert_eq!(out.stats.nan_samples, 0);
    let v: Vec<f64> = out.film.pixels.iter().map(|p| f64::from(p.x)).collect();
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let min = v.iter().copied().fold(f64::MAX, f64::min);
    let max = v.iter().copied().fold(f64::MIN, f64::max);
    (mean, min, max)
}

#[test]
fn white_furnace_under_a_constant_environment_light() {
    for integrator in ["Path", "Photon"] {
        // A convex Lambertian of albedo a sees only the environment: L_o = a·L. Light samples
        // and BSDF samples are MIS-weighted, so single samples vary; the mean over 16 384
        // samples is held to 1%, each pixel (64 samples) to 15%.
        for a in [0.5f64, 0.9] {
            let (mean, min, max) = stats(&env_furnace(
                &format!("(color: ({a}, {a}, {a}))"),
                integrator,
            ));
            assert!(
                (mean / a - 1.0).abs() < 0.01 && min > 0.85 * a && max < 1.15 * a,
                "{integrator}, albedo {a}: mean {mean}, range [{min}, {max}]"
            );
        }
        // A perfect mirror and clear glass vanish: every path ends on the environment with
        // weight 1 (glass: but the few kept inside by total internal reflection past 64
        // bounces).
        let (mean, min, max) = stats(&env_furnace("(color: (1, 1, 1), reflect: 1)", integrator));
        assert!(
            (mean - 1.0).abs() < 1e-4 && min > 0.9999 && max < 1.0001,
            "{integrator}, mirror: {mean} [{min}, {max}]"
        );
        let (mean, min, max) = stats(&env_furnace(
            "(color: (1, 1, 1), transmit: 1, ior: 1.5)",
            integrator,
        ));
        // `photon`'s camera paths branch at the first specular vertices and Russian-roulette
        // the deep internal reflections (kept ones weigh 1/q > 1): single pixels reach a few
        // percent above 1 while the mean stays 1; `path`'s weights never exceed 1.
        let max_over = if integrator == "Photon" { 0.05 } else { 1e-3 };
        assert!(
            (mean - 1.0).abs() < 3e-3 && min > 0.9 && max < 1.0 + max_over,
            "{integrator}, glass: {mean} [{min}, {max}]"
        );
        // A closed diffuse sphere seen from inside: no light gets in.
        let inside = scene_from_text(&format!(
            r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 16, max_depth: 16, integrator: {integrator}),
    camera: Pinhole(eye: (0, 0, 0.5), look_at: (0, 0, 0), fov_y: 60),
    materials: {{ "m": (color: (0.9, 0.9, 0.9)) }},
    photons: (global: 20000, caustic: 0),
    lights: [ Environment(radiance: (1, 1, 1)) ],
    nodes: [ Sphere(material: "m", center: (0, 0, 0), radius: 2) ],
)"#
        ));
        let out = render(&inside, &RenderOptions::default()).expect("renders");
        assert!(
            out.film.pixels.iter().all(|p| *p == glam::Vec3::ZERO),
            "{integrator}: light inside a closed sphere"
        );
    }
}

/// Fraction of a cone of half-angle `alpha` around +y (uniform in solid angle) whose directions
/// pass a straight edge: from a floor point at signed distance `x` from the edge's foot, the
/// ray towards `w` clears a blocker covering `x' < 0` at height `h` iff `x + h·w_x/w_y > 0`.
/// Midpoint quadrature over the cap in (cos θ, φ), where the solid-angle measure is uniform.
fn lit_fraction(x: f64, h: f64, alpha: f64) -> f64 {
    let n = 400;
    let cos_a = alpha.cos();
    let mut lit = 0usize;
    for i in 0..n {
        let c = 1.0 - (1.0 - cos_a) * (i as f64 + 0.5) / n as f64;
        let s = (1.0 - c * c).sqrt();
        for j in 0..n {
            let phi = 2.0 * PI * (j as f64 + 0.5) / n as f64;
            if x + h * s * phi.cos() / c > 0.0 {
                lit += 1;
            }
        }
    }
    lit as f64 / (n * n) as f64
}

#[test]
fn a_suns_penumbra_behind_an_edge_has_the_geometric_width() {
    // The sun straight above with α = 2°; a black blocker at h = 1 over x < 0; a floor of
    // albedo ρ = 0.5 seen straight down from y = 0.5 (under the blocker) over x ∈ [−0.1, 0.1].
    // The penumbra spans |x| < h tan α = 0.0349; floor radiance is ρE/π times the lit fraction.
    let (h, alpha, rho, e) = (1.0f64, 2f64.to_radians(), 0.5f64, 2.0f64);
    let (w, rows, spp) = (64u32, 4u32, 256u32);
    let half_width = 0.1f64;
    let fov_y = 2.0 * (half_width / 0.5 / f64::from(w / rows)).atan().to_degrees();
    let scene = scene_from_text(&format!(
        r#"Scene(
    render: (width: {w}, height: {rows}, samples_per_pixel: {spp}, max_depth: 1, seed: 9,
             integrator: Path),
    camera: Pinhole(eye: (0, 0.5, 0), look_at: (0, 0, 0), up: (0, 0, -1), fov_y: {fov_y}),
    materials: {{ "floor": (color: ({rho}, {rho}, {rho})), "black": (color: (0, 0, 0)) }},
    lights: [ Distant(direction: (0, 1, 0), irradiance: ({e}, {e}, {e}), angular_radius: 2) ],
    nodes: [
        Quad(material: "floor", size: (4, 4), transform: [RotateX(-90)]),
        Quad(material: "black", size: (4, 4), transform: [RotateX(-90), Translate(-2, {h}, 0)]),
    ],
)"#
    ));
    let out = render(&scene, &RenderOptions::default()).expect("renders");
    let full = rho * e / PI;
    let umbra = h * alpha.tan();
    let pixel = 2.0 * half_width / f64::from(w);
    let (mut in_penumbra, mut worst) = (0, 0.0f64);
    for x in 0..w {
        let col: f64 = (0..rows)
            .map(|y| f64::from(out.film.get(x, y).x))
            .sum::<f64>()
            / f64::from(rows);
        // The floor point under the column's centre, and the fraction the column averages
        // (the profile is near-linear across one pixel).
        let fx = -half_width + (f64::from(x) + 0.5) * pixel;
        let expected = lit_fraction(fx, h, alpha);
        let got = col / full;
        if fx.abs() > umbra + pixel {
            // Fully lit or in the umbra: exact up to the cosine's variation inside 2°.
            let want = if fx > 0.0 { 1.0 } else { 0.0 };
            assert!((got - want).abs() < 2e-3, "x = {fx:.4}: {got} vs {want}");
        } else {
            in_penumbra += 1;
            // 1024 Bernoulli samples per column: σ ≤ 0.016; 4σ.
            worst = worst.max((got - expected).abs());
            assert!(
                (got - expected).abs() < 0.065,
                "x = {fx:.4}: lit fraction {got} vs the geometric {expected}"
            );
        }
    }
    // The penumbra is 2h tan α = 0.070 wide: 22 pixels of 0.0031.
    assert!(
        (20..=25).contains(&in_penumbra),
        "{in_penumbra} penumbra columns"
    );
    assert!(worst > 0.0, "no penumbra column compared");
}

/// Irradiance at `p` (unit normal `n`) from a planar polygon of uniform radiance `l` wholly
/// above `p`'s horizon, by Lambert's formula E = (L/2) |Σᵢ θᵢ cos γᵢ| (θᵢ the angle edge
/// (vᵢ, vᵢ₊₁) subtends at `p`, γᵢ the angle between `n` and the normal of the plane through `p`
/// and the edge). Exact, in f64; written independently of the renderer's own test helper (it is
/// crate-private).
fn lambert_polygon(p: [f64; 3], n: [f64; 3], vertices: &[[f64; 3]], l: f64) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let unit = |a: [f64; 3]| {
        let len = dot(a, a).sqrt();
        [a[0] / len, a[1] / len, a[2] / len]
    };
    let mut sum = 0.0;
    for i in 0..vertices.len() {
        let a = unit(sub(vertices[i], p));
        let b = unit(sub(vertices[(i + 1) % vertices.len()], p));
        let theta = dot(a, b).clamp(-1.0, 1.0).acos();
        sum += theta * dot(unit(cross(a, b)), n);
    }
    0.5 * l * sum.abs()
}

#[test]
fn a_quad_lights_irradiance_through_the_global_photon_map_matches_lamberts_polygon_formula() {
    // A one-sided 2 × 1 panel of radiance L = 3 at y = 2 facing down, over a white Lambert
    // floor (ρ = 1). Photons leave the panel as the global map's photons do (cosine-distributed
    // from uniform points, equal flux) and the floor stores each first landing (`min_bounces`
    // 0: direct photons; `max_bounces` 0: none after), with no specular object: the map is
    // caustic-free. Its density estimate at a floor point is the radiance of the white
    // receiver, E·ρ/π, so π times it is E.
    //
    // Noise and bias: 4·10⁶ photons (Φ = πLA = 18.85 W); k = 10⁴ nearest photons in a box
    // kernel: the count in the disc is Poisson-like, relative noise ≈ 1/√k = 1 %. The disc
    // (radius ≈ 0.1–0.2) averages E over its area: that bias is computed below from the
    // closed form averaged over the disc, and is below 0.3 % at every point.
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, seed: 4, integrator: Photon),
    camera: Pinhole(eye: (0, 3, 4), look_at: (0, 0, 0), fov_y: 40),
    materials: { "white": (color: (1, 1, 1)) },
    nodes: [
        Quad(material: "white", size: (40, 40), transform: [RotateX(-90)]),
        Quad(size: (2, 1), emission: (radiance: (3, 3, 3)), transform: [RotateX(90), Translate(0, 2, 0)]),
    ],
)"#,
    );
    assert_eq!(scene.lights.len(), 1, "the panel is the one light");
    use caustic::integrators::photon::aim::CausticTargets;
    use caustic::integrators::photon::emit::LightEmitter;
    use caustic::integrators::photon::maps::trace_map;
    use caustic::integrators::photon::trace::{MapKind, TraceSettings};
    use caustic::integrators::photon::walls::Walls;
    use caustic::integrators::photon::{Kernel, PhotonMap};
    use caustic::shading::{Bsdf, ShadingFrame};
    use caustic::spatial::KdTree;
    use glam::Vec3;

    let n = 4_000_000u64;
    let p = &scene.params;
    let mut sampler = caustic::sampling::Sampler::new(p.sampler, p.seed, 1);
    let emitter = LightEmitter::new(scene.lights[0].clone(), n, &mut sampler, 17);
    let settings = TraceSettings {
        kind: MapKind::Global,
        min_bounces: 0,
        any_bounce: false,
        max_bounces: 0,
        pass: None,
        near_specular: None,
    };
    let (photons, counts) = trace_map(
        &scene,
        &[emitter],
        &CausticTargets::default(),
        settings,
        None,
    );
    // Every photon leaves downwards and lands on the 40 × 40 floor but for the few that
    // leave nearly parallel to it.
    let stored = counts[0].stored as f64 / n as f64;
    assert!(stored > 0.97, "stored fraction {stored}");
    let k = 10_000usize;
    let map = PhotonMap::new(KdTree::build(photons).expect("tree"), k, 1.0, Kernel::Box);
    let white = Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [Some(1.0), None, None], 1.0);
    let up = ShadingFrame {
        ns: Vec3::Y,
        ng: Vec3::Y,
        entering: true,
    };
    let panel = [
        [-1.0, 2.0, -0.5],
        [1.0, 2.0, -0.5],
        [1.0, 2.0, 0.5],
        [-1.0, 2.0, 0.5],
    ];
    let l = 3.0;
    for x in [[0.0f64, 0.0], [0.8, 0.3], [-1.6, -0.9]] {
        let point = [x[0], 0.0, x[1]];
        let exact = lambert_polygon(point, [0.0, 1.0, 0.0], &panel, l);
        let e = map.estimate(
            Vec3::new(x[0] as f32, 0.0, x[1] as f32),
            Vec3::Y,
            &up,
            &white,
            Walls::of(&scene, None),
        );
        assert!(!e.cut, "the estimate at {x:?} reached the largest radius");
        let got = f64::from(e.radiance.x) * PI;
        // The estimate's expectation: E averaged over its disc (polar midpoint quadrature).
        let r = f64::from(e.radius);
        let (rings, spokes) = (24, 48);
        let mut disc = 0.0;
        for i in 0..rings {
            let rho = r * ((f64::from(i) + 0.5) / f64::from(rings)).sqrt();
            for j in 0..spokes {
                let phi = 2.0 * PI * (f64::from(j) + 0.5) / f64::from(spokes);
                let q = [x[0] + rho * phi.cos(), 0.0, x[1] + rho * phi.sin()];
                disc += lambert_polygon(q, [0.0, 1.0, 0.0], &panel, l);
            }
        }
        disc /= f64::from(rings * spokes);
        let rel = got / exact - 1.0;
        let bias = disc / exact - 1.0;
        eprintln!(
            "quad light, floor point {x:?}: photon E = {got:.5}, Lambert {exact:.5} ({:+.2} %); \
             radius {r:.4}, disc-average bias {:+.3} %, noise 1/√k = {:.2} %",
            100.0 * rel,
            100.0 * bias,
            100.0 / (k as f64).sqrt()
        );
        assert!(
            bias.abs() < 0.005,
            "at {x:?} the radius {r} is too large: disc bias {bias:+.4}"
        );
        assert!(
            rel.abs() < 0.03,
            "at {x:?}: photon irradiance {got} vs Lambert's {exact} ({rel:+.4})"
        );
    }
}
