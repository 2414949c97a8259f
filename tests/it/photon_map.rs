//! Photon mapping against closed forms and independent computations: irradiance under a point
//! light, energy in a closed box, a ball lens's paraxial focus and the power it passes, the η²
//! convention under water, agreement with the path tracer, and determinism.

use glam::Vec3;

use caustic::geometry::Ray;
use caustic::integrators::photon::aim::CausticTargets;
use caustic::integrators::photon::emit::LightEmitter;
use caustic::integrators::photon::maps::trace_map;
use caustic::integrators::photon::trace::{MapKind, TraceCounts, TraceSettings};
use caustic::integrators::photon::walls::Walls;
use caustic::integrators::photon::{Kernel, PhotonMap, build_maps};
use caustic::integrators::{Context, Counters, Integrator, NoTrace};
use caustic::render::{RenderOptions, render};
use caustic::render_scene::RenderScene;
use caustic::sampling::Sampler;
use caustic::shading::{Bsdf, ShadingFrame};
use caustic::spatial::{KdTree, Photon};

use crate::common::scene_from_text;

const PI: f64 = std::f64::consts::PI;

/// A point light of power Φ = 4π W (intensity 1 W/sr) at height 1 over a 100 × 100 plane.
const PLANE: &str = r#"Scene(
    render: (width: 8, height: 8, seed: 5, integrator: Photon),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: { "white": (color: (1, 1, 1)) },
    lights: [ Point(position: (0, 1, 0), power: (12.566371, 12.566371, 12.566371)) ],
    nodes: [ Quad(material: "white", size: (100, 100), transform: [RotateX(-90)]) ],
)"#;

/// Traces `n` photons of the scene's light 0 into one list, storing every diffuse landing
/// (`min_bounces` 0: direct photons included) and nothing after it (`max_bounces` 0), with the
/// tracer the global map uses.
fn direct_photons(scene: &RenderScene, n: u64) -> (Vec<Photon>, TraceCounts) {
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
    let (photons, counts) = trace_map(
        scene,
        &[emitter],
        &CausticTargets::default(),
        settings,
        None,
    );
    (photons, counts[0])
}

fn lambert() -> Bsdf {
    Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [Some(1.0), None, None], 1.0)
}

fn up() -> ShadingFrame {
    ShadingFrame {
        ns: Vec3::Y,
        ng: Vec3::Y,
        entering: true,
    }
}

#[test]
fn point_light_over_a_plane_matches_the_inverse_square_cosine_law() {
    // Hard case 25: I = 1 W/sr at h = 1; E(x) = I h / (h² + x²)^{3/2}; a white Lambert plane
    // reads L = E/π. 10⁶ Fibonacci photons, k = 100.
    let scene = scene_from_text(PLANE);
    let n = 1_000_000;
    let (photons, counts) = direct_photons(&scene, n);
    // Stored fraction of Φ = solid angle of the plane seen from the light / 4π:
    // Ω = 4 asin(a² / (a² + 4h²))... for a square of half-side a at height h,
    // Ω = 4 atan(a² / (h √(2a² + h²))).
    let (a, h) = (50.0f64, 1.0f64);
    let omega = 4.0 * (a * a / (h * (2.0 * a * a + h * h).sqrt())).atan();
    let fraction = counts.stored as f64 / n as f64;
    assert!(
        (fraction - omega / (4.0 * PI)).abs() < 0.002 * omega / (4.0 * PI),
        "stored fraction {fraction} vs {}",
        omega / (4.0 * PI)
    );
    let map = PhotonMap::new(KdTree::build(photons).expect("tree"), 100, 1.0, Kernel::Box);
    for (x, exact_e) in [
        (0.0f32, 1.0f64),
        (0.5, 0.71554),
        (1.0, 0.35355),
        (2.0, 0.08944),
    ] {
        let e = map.estimate(
            Vec3::new(x, 0.0, 0.0),
            Vec3::Y,
            &up(),
            &lambert(),
            Walls::of(&scene, None),
        );
        let irradiance = f64::from(e.radiance.x) * PI;
        assert!(
            (irradiance / exact_e - 1.0).abs() < 0.03,
            "E({x}) = {irradiance} vs {exact_e} (k-NN radius {})",
            e.radius
        );
    }
}

/// A closed box of diffuse albedo 0.5 around a point light.
const BOX: &str = r#"Scene(
    render: (width: 8, height: 8, seed: 8, integrator: Photon),
    camera: Pinhole(eye: (0, 0, 0.9), look_at: (0, 0, 0), fov_y: 60),
    materials: { "grey": (color: (0.5, 0.5, 0.5)) },
    photons: (global: 200000, caustic: 0, max_bounces: 64),
    lights: [ Point(position: (0.1, 0.2, -0.1), power: (3, 3, 3)) ],
    nodes: [ Cube(material: "grey", size: 2) ],
)"#;

#[test]
fn stored_flux_in_a_closed_box_is_the_emitted_power_times_the_reflected_share() {
    // Every photon lands on the walls; after the first landing it survives each bounce with
    // probability a = 0.5 at equal flux. With `min_bounces` 1 the global map stores landings
    // 2, 3, …: Φ (a + a² + …) = Φ a / (1 − a) = Φ.
    let scene = scene_from_text(BOX);
    let maps = build_maps(&scene);
    assert!(maps.caustic.is_none());
    let t = caustic::integrators::photon::PhotonSummary::total(&maps.summary.global);
    assert_eq!(t.emitted, 200_000);
    let stored = f64::from(t.stored_flux.x);
    assert!(
        (stored / 3.0 - 1.0).abs() < 0.01,
        "stored {stored} W of 3 W"
    );
    assert!(
        f64::from(t.lost_flux.x) < 1e-3 * 3.0,
        "lost {:?}",
        t.lost_flux
    );
}

/// A glass ball (R = 1, η = 1.5) under a point light 50 units up, seen through a square hole of
/// half-side 0.15 in an opaque plate at y = 1.5, over a floor at y = −FLOOR.
pub(crate) fn lens_scene(floor: f64) -> String {
    format!(
        r#"Scene(
    render: (width: 8, height: 8, seed: 4, integrator: Photon),
    camera: Pinhole(eye: (0, 0, 6), look_at: (0, 0, 0), fov_y: 40),
    materials: {{
        "glass": (color: (1, 1, 1), transmit: 1, ior: 1.5),
        "plate": (color: (0.5, 0.5, 0.5)),
        "floor": (color: (0.8, 0.8, 0.8)),
    }},
    photons: (global: 0, caustic: 1000000),
    lights: [ Point(position: (0, 50, 0), power: (100, 100, 100)) ],
    nodes: [
        Sphere(material: "glass", center: (0, 0, 0), radius: 1),
        Quad(material: "plate", size: (6, 2.85), transform: [RotateX(-90), Translate(0, 1.5, 1.575)]),
        Quad(material: "plate", size: (6, 2.85), transform: [RotateX(-90), Translate(0, 1.5, -1.575)]),
        Quad(material: "plate", size: (2.85, 0.3), transform: [RotateX(-90), Translate(1.575, 1.5, 0)]),
        Quad(material: "plate", size: (2.85, 0.3), transform: [RotateX(-90), Translate(-1.575, 1.5, 0)]),
        Quad(material: "floor", size: (20, 20), transform: [RotateX(-90), Translate(0, -{floor}, 0)]),
    ],
)"#
    )
}

/// The power (W) the lens scene's 100 W point light sends through the plate's hole and both
/// refractions of the ball: Φ/(4π) ∫ (1 − F(θ))² dΩ over the hole, θ the incidence on the ball
/// (sin θ = D sin α / R for a ray at angle α from the axis); the exit is at the same angle
/// inside, so the same Fresnel factor applies twice.
pub(crate) fn lens_power() -> f64 {
    let (eta, d, half, plate) = (1.5f64, 50.0f64, 0.15f64, 1.5f64);
    let steps = 400;
    let mut share = 0.0;
    for i in 0..steps {
        for j in 0..steps {
            let x = (i as f64 + 0.5) / steps as f64 * 2.0 * half - half;
            let z = (j as f64 + 0.5) / steps as f64 * 2.0 * half - half;
            let h = d - plate;
            let r2 = x * x + z * z + h * h;
            let cos_a = h / r2.sqrt();
            let d_omega = cos_a / r2 * (2.0 * half / steps as f64).powi(2);
            let sin_a = (1.0 - cos_a * cos_a).sqrt();
            let sin_t = d * sin_a; // R = 1
            let t = 1.0 - fresnel((1.0 - sin_t * sin_t).sqrt(), eta);
            share += t * t * d_omega / (4.0 * PI);
        }
    }
    100.0 * share
}

/// Unpolarised Fresnel reflectance from air into a medium of index `eta` at incidence cos `ci`.
fn fresnel(ci: f64, eta: f64) -> f64 {
    let st = (1.0 - ci * ci).sqrt() / eta;
    let ct = (1.0 - st * st).sqrt();
    let rs = (ci - eta * ct) / (ci + eta * ct);
    let rp = (ct - eta * ci) / (ct + eta * ci);
    0.5 * (rs * rs + rp * rp)
}

#[test]
fn a_ball_lens_focuses_point_light_photons_at_the_paraxial_focus_with_the_power_it_passes() {
    // A ball lens has its principal planes at its centre and focal length f = ηR / (2(η − 1))
    // = 1.5; a source at s_o = 50 images at s_i = 1/(1/f − 1/s_o) below the centre.
    let (eta, r, so) = (1.5f64, 1.0f64, 50.0f64);
    let f = eta * r / (2.0 * (eta - 1.0));
    let si = 1.0 / (1.0 / f - 1.0 / so);
    let spread = |floor: f64| {
        let maps = build_maps(&scene_from_text(&lens_scene(floor)));
        let map = maps.caustic.expect("a caustic map");
        // The spot: floor photons within 0.2 of the axis (internal reflections inside the
        // ball, T-R-T and beyond, scatter a few per cent of the light widely; the Fresnel
        // reflection off the top lands on the plate's underside).
        let spot: Vec<&Photon> = map
            .photons()
            .iter()
            .filter(|p| {
                let q = p.position();
                q.y < -1.0 && q.x * q.x + q.z * q.z < 0.04
            })
            .collect();
        let n = spot.len() as f64;
        let rms = (spot
            .iter()
            .map(|p| f64::from(p.position().x.powi(2) + p.position().z.powi(2)))
            .sum::<f64>()
            / n)
            .sqrt();
        let flux: f64 = spot.iter().map(|p| f64::from(p.power().x)).sum();
        (rms, flux, maps.summary)
    };
    let (at_focus, flux, summary) = spread(si);
    let (near, _, _) = spread(0.85 * si);
    let (far, _, _) = spread(1.15 * si);
    assert!(
        at_focus < 0.3 * near && at_focus < 0.3 * far,
        "rms spot radius {at_focus} at the paraxial focus, {near} at 0.85×, {far} at 1.15×"
    );
    // Geometric defocus alone gives ≈ 0.15·0.15 ≈ 0.023 at ±15 %; the focus is far tighter.
    assert!(at_focus < 0.01, "rms spot radius at the focus {at_focus}");

    let expected = lens_power();
    assert!(
        (flux / expected - 1.0).abs() < 0.03,
        "caustic flux {flux} W vs {expected} W through the hole and the ball"
    );
    let t = caustic::integrators::photon::PhotonSummary::total(&summary.caustic);
    assert!(t.reached_specular > 0 && t.reached_specular < t.emitted);
}

#[test]
fn photons_under_water_match_the_analytic_radiance_of_the_floor() {
    // The pool of `light_transport.rs`, rendered by photons: the floor is lit only through the
    // water (shadow rays are blocked), so all its light is the caustic map's. One estimate has
    // a relative noise of about 1/√k, so the test averages 64 estimates at points 0.08 apart
    // (their photon discs, of radius ≈ 0.05, barely overlap) against the average of the exact
    // values there, seen from below the waterline and from above through the surface.
    let pool = r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 16, integrator: Photon, seed: 11),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {
        "floor": (color: (0.8, 0.8, 0.8)),
        "water": (color: (1, 1, 1), transmit: 1, ior: 1.33),
    },
    photons: (global: 0, caustic: 2000000, caustic_gather: 200, final_gather: 0, caustic_filter: Box),
    lights: [ Sphere(center: (0, 1, 0), radius: 0.3, power: (20, 20, 20)) ],
    nodes: [
        Quad(material: "water", size: (60, 60), transform: [RotateX(-90)]),
        Quad(material: "floor", size: (60, 60), transform: [RotateX(-90), Translate(0, -0.3, 0)]),
    ],
)"#;
    let scene = scene_from_text(pool);
    let integrator = Integrator::prepare(&scene);
    let mut sampler = Sampler::new(scene.params.sampler, 1, 1);
    let eta = 1.33f64;
    let radiance = 20.0 / (4.0 * PI * PI * 0.09);
    // The camera ray from above comes in at 50° from the vertical, so that its Fresnel
    // reflection clears the light (the reflected black sky adds nothing).
    let th_w = (50f64.to_radians().sin() / eta).asin();
    let (ca, cw) = (50f64.to_radians().cos(), th_w.cos());
    let rs = (ca - eta * cw) / (ca + eta * cw);
    let rp = (cw - eta * ca) / (cw + eta * ca);
    let t_cam = 1.0 - 0.5 * (rs * rs + rp * rp);
    let down = Vec3::new(
        0.0,
        -(50f32.to_radians().cos()),
        -(50f32.to_radians().sin()),
    );
    let (mut exact, mut below, mut above) = (0.0f64, 0.0f64, 0.0f64);
    let mut i = 0;
    for gx in 0..8 {
        for gz in 0..8 {
            let (x, z) = (0.08 * (gx as f32 - 3.5), 0.08 * (gz as f32 - 3.5));
            let p = Vec3::new(x, -0.3, z);
            let e = crate::light_transport::underwater_irradiance(
                [f64::from(x), -0.3, f64::from(z)],
                [0.0, 1.0, 0.0],
                0.3,
                radiance,
                eta,
            );
            exact += 0.8 / PI * e;
            let from = p + Vec3::new(0.5, 0.2, 0.0);
            sampler.start_pixel_sample(0, 0, i);
            i += 1;
            let l = integrator.li(
                Ray::new(from, (p - from).normalize()),
                &mut Context::new(&mut sampler, &mut Counters::default(), &mut NoTrace),
            );
            below += f64::from(l.x);
            let entry = Vec3::new(x, 0.0, z + (0.3 * th_w.tan()) as f32);
            sampler.start_pixel_sample(0, 0, i);
            i += 1;
            let l = integrator.li(
                Ray::new(entry - down, down),
                &mut Context::new(&mut sampler, &mut Counters::default(), &mut NoTrace),
            );
            above += f64::from(l.x);
        }
    }
    assert!(
        (below / exact - 1.0).abs() < 0.03,
        "below the waterline: photons {below} vs analytic {exact} (sums of 64)"
    );
    let exact_above = exact * t_cam / (eta * eta);
    assert!(
        (above / exact_above - 1.0).abs() < 0.03,
        "from above: photons {above} vs analytic {exact_above} (sums of 64)"
    );
}

#[test]
fn photon_ppm_and_path_ppm_agree_with_path_tracing_on_a_diffuse_box() {
    // Effort: path 1024 spp; photon 4 spp over 100k global photons with 32 final-gather rays;
    // ppm and path-ppm 64 passes of 20k global photons each. Tolerance: image mean within 3 %,
    // each 8×8 block within 8 % (the photon estimates' blur at the box's corners, and path's
    // noise of about 2 % per block).
    let text = |integrator: &str, spp: u32, global: u32| {
        format!(
            r#"Scene(
    render: (width: 24, height: 24, samples_per_pixel: {spp}, max_depth: 16, seed: 3, integrator: {integrator}),
    camera: Pinhole(eye: (0, 0.6, 3.4), look_at: (0, 0.6, 0), fov_y: 35),
    materials: {{
        "white": (color: (0.7, 0.7, 0.7)),
        "red": (color: (0.7, 0.1, 0.1)),
        "green": (color: (0.1, 0.6, 0.1)),
    }},
    photons: (global: {global}, caustic: 0, gather: 50, final_gather: 32),
    lights: [ Sphere(center: (0, 1.8, 0), radius: 0.1, power: (20, 20, 20)) ],
    nodes: [
        Quad(material: "white", size: (2, 2), transform: [RotateX(-90)]),
        Quad(material: "white", size: (2, 2), transform: [RotateX(90), Translate(0, 2, 0)]),
        Quad(material: "white", size: (2, 2), transform: [Translate(0, 1, -1)]),
        Quad(material: "red", size: (2, 2), transform: [RotateY(90), Translate(-1, 1, 0)]),
        Quad(material: "green", size: (2, 2), transform: [RotateY(-90), Translate(1, 1, 0)]),
        Sphere(material: "white", center: (0.3, 0.35, -0.2), radius: 0.35),
    ],
)"#
        )
    };
    let path = render(
        &scene_from_text(&text("Path", 1024, 0)),
        &RenderOptions::default(),
    )
    .expect("path renders");
    let block = |f: &caustic::render::Film, bx: usize, by: usize| {
        let mut s = 0.0f64;
        for y in by * 8..by * 8 + 8 {
            for x in bx * 8..bx * 8 + 8 {
                let p = f.get(x as u32, y as u32);
                s += f64::from(p.x + p.y + p.z) / 3.0;
            }
        }
        s / 64.0
    };
    let mean = |f: &caustic::render::Film| {
        (0..3)
            .flat_map(|by| (0..3).map(move |bx| (bx, by)))
            .map(|(bx, by)| block(f, bx, by))
            .sum::<f64>()
            / 9.0
    };
    for (integrator, spp, global) in [
        ("Photon", 4, 100_000),
        ("Ppm", 64, 20_000),
        ("PathPpm", 64, 20_000),
    ] {
        let out = render(
            &scene_from_text(&text(integrator, spp, global)),
            &RenderOptions::default(),
        )
        .expect("renders");
        let (mp, mf) = (mean(&path.film), mean(&out.film));
        assert!(
            (mf / mp - 1.0).abs() < 0.03,
            "{integrator}: image means {mf}, path {mp}"
        );
        for by in 0..3 {
            for bx in 0..3 {
                let (a, b) = (block(&out.film, bx, by), block(&path.film, bx, by));
                assert!(
                    (a / b - 1.0).abs() < 0.08,
                    "{integrator}: block ({bx}, {by}): {a}, path {b}"
                );
            }
        }
    }
}

#[test]
fn photon_renders_are_the_same_for_any_thread_count() {
    let scene = scene_from_text(&lens_scene(1.6).replace(
        "render: (width: 8, height: 8,",
        "render: (width: 24, height: 16, samples_per_pixel: 2,",
    ));
    let one = render(
        &scene,
        &RenderOptions {
            threads: Some(1),
            ..RenderOptions::default()
        },
    )
    .expect("renders");
    let two = render(
        &scene,
        &RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        },
    )
    .expect("renders");
    assert_eq!(one.film.to_bytes(), two.film.to_bytes());
    assert!(one.film.mean().max_element() > 0.0);
}

/// A strongly rippled water plane at y = 0 over a floor at y = −1, lit from above.
const RIPPLED_POOL: &str = r#"Scene(
    render: (width: 8, height: 8, seed: 2, integrator: Photon),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    textures: { "waves": Ripple(centers: [(0.5, 0.5), (0.2, 0.7)], frequency: 40, amplitude: 0.02) },
    materials: {
        "floor": (color: (0.8, 0.8, 0.8)),
        "water": (color: (1, 1, 1), diffuse: 0, reflect: 0.05, transmit: 0.95, ior: 1.33, bump: "waves"),
    },
    photons: (global: 50000, caustic: 200000),
    lights: [ Point(position: (0.3, 2, 0.2), power: (50, 50, 50)) ],
    nodes: [
        Quad(material: "water", size: (4, 4), transform: [RotateX(-90)]),
        Quad(material: "floor", size: (4, 4), transform: [RotateX(-90), Translate(0, -1, 0)]),
    ],
)"#;

#[test]
fn photons_refracted_by_ripples_land_only_below_the_water() {
    // Hard case 11: the in/out decision comes from the geometric normal, so no photon that
    // refracted into the water is ever stored above it (the floor is the only diffuse surface).
    let maps = build_maps(&scene_from_text(RIPPLED_POOL));
    let caustic = maps.caustic.expect("a caustic map");
    assert!(caustic.len() > 10_000);
    for p in caustic
        .photons()
        .iter()
        .chain(maps.global.iter().flat_map(|m| m.photons()))
    {
        let q = p.position();
        assert!(q.y < -0.99 && q.y > -1.01, "photon stored at {q}");
        assert!(p.power().is_finite());
        // Arrived from above (the side the floor faces).
        assert!(p.direction().y < 0.0 && p.normal().y > 0.99);
    }
    // Energy: what the floor got through the water is at most the light's power.
    let t = caustic::integrators::photon::PhotonSummary::total(&maps.summary.caustic);
    assert!(t.stored_flux.x <= 50.0 * 1.001, "{:?}", t.stored_flux);
}

#[test]
fn no_light_leaks_through_a_bumped_floor_lit_from_below() {
    // Hard case 12: a point light 1 unit under a bumped diffuse plane, the camera above: the
    // top side must be exactly black with direct light, photons and final gathering.
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 16, height: 16, samples_per_pixel: 2, seed: 3, integrator: Photon),
    camera: Pinhole(eye: (0, 2, 0.5), look_at: (0, 0, 0), fov_y: 40),
    textures: { "bumps": Ripple(centers: [(0.5, 0.5)], frequency: 60, amplitude: 0.03) },
    materials: { "floor": (color: (0.8, 0.8, 0.8), bump: "bumps"), "glass": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5) },
    photons: (global: 50000, caustic: 50000, final_gather: 4),
    lights: [ Point(position: (0, -1, 0), power: (100, 100, 100)) ],
    nodes: [
        Quad(material: "floor", size: (6, 6), transform: [RotateX(-90)]),
        Sphere(material: "glass", center: (0, -0.5, 0), radius: 0.2),
    ],
)"#,
    );
    let out = render(&scene, &RenderOptions::default()).expect("renders");
    assert_eq!(
        out.film.mean(),
        Vec3::ZERO,
        "light leaked through the floor"
    );
}

#[test]
fn grazing_photons_on_a_bumped_floor_keep_bounded_flux() {
    // Hard case 14: photons arrive at 89.9°–90° on a bumped floor; the adjoint factor
    // |wo·ns||wi·ng| / (|wo·ng||wi·ns|) blows up as wo·ng → 0. Stored photons (on the ceiling,
    // after one bounce off the floor) must stay ≤ 10× the emitted flux, finite, and carry no
    // more than the light's power.
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, seed: 4, integrator: Photon),
    camera: Pinhole(eye: (0, 2, 3), look_at: (0, 0, 0), fov_y: 40),
    textures: { "bumps": Ripple(centers: [(0.5, 0.5)], frequency: 80, amplitude: 0.02) },
    materials: { "floor": (color: (0.9, 0.9, 0.9), bump: "bumps"), "ceiling": (color: (0.5, 0.5, 0.5)) },
    photons: (global: 100000, caustic: 0, min_bounces: 1),
    lights: [ Point(position: (-20, 0.02, 0), power: (100, 100, 100)) ],
    nodes: [
        Quad(material: "floor", size: (10, 10), transform: [RotateX(-90)]),
        Quad(material: "ceiling", size: (10, 10), transform: [RotateX(90), Translate(0, 1, 0)]),
    ],
)"#,
    );
    let maps = build_maps(&scene);
    let global = maps.global.expect("a global map");
    let per_photon = 100.0 / 100_000.0;
    let max = global
        .photons()
        .iter()
        .map(|p| p.power().max_element())
        .fold(0.0f32, f32::max);
    assert!(
        max.is_finite() && max <= 10.0 * per_photon * 1.01,
        "max photon flux {max}"
    );
    let t = caustic::integrators::photon::PhotonSummary::total(&maps.summary.global);
    assert!(
        t.stored_flux.x <= 100.0 * 1.01,
        "stored {:?}",
        t.stored_flux
    );
}

#[test]
fn empty_maps_and_tiny_settings_render_direct_light_only() {
    // Hard case 30: zero photons (no maps), k = 1, a 1×1 image: no NaN, and with no maps the
    // photon integrator's image is direct light plus mirror/glass chains, which is what the
    // path tracer computes with `diffuse_depth: 0` (same scene, in expectation).
    let text = |integrator: &str, spp: u32, photons: &str| {
        format!(
            r#"Scene(
    render: (width: 12, height: 12, samples_per_pixel: {spp}, seed: 9, integrator: {integrator}, diffuse_depth: 0),
    camera: Pinhole(eye: (0, 1, 3), look_at: (0, 0.5, 0), fov_y: 45),
    materials: {{ "white": (color: (0.8, 0.8, 0.8)), "mirror": (color: (0.9, 0.9, 0.9), diffuse: 0, reflect: 1) }},
    photons: ({photons}),
    lights: [ Point(position: (0, 2, 1), power: (40, 40, 40)) ],
    nodes: [
        Quad(material: "white", size: (4, 4), transform: [RotateX(-90)]),
        Sphere(material: "mirror", center: (0.3, 0.4, 0), radius: 0.4),
    ],
)"#
        )
    };
    let none = "global: 0, caustic: 0, gather: 1, caustic_gather: 1, final_gather: 0";
    let photon = render(
        &scene_from_text(&text("Photon", 1, none)),
        &RenderOptions::default(),
    )
    .expect("renders");
    let path = render(
        &scene_from_text(&text("Path", 1, none)),
        &RenderOptions::default(),
    )
    .expect("renders");
    assert_eq!(photon.stats.nan_samples, 0);
    // Point light, Lambert and a perfect mirror: both integrators are exact here and trace the
    // same camera rays, so they agree pixel by pixel to rounding.
    for y in 0..12 {
        for x in 0..12 {
            let (a, b) = (photon.film.get(x, y), path.film.get(x, y));
            assert!(
                (a - b).abs().max_element() <= 1e-4 * (1.0 + b.max_element()),
                "({x}, {y}): {a} vs {b}"
            );
        }
    }
    let one = scene_from_text(
        &text(
            "Photon",
            1,
            "global: 1000, caustic: 1000, gather: 1, caustic_gather: 1",
        )
        .replace("width: 12, height: 12", "width: 1, height: 1"),
    );
    let out = render(&one, &RenderOptions::default()).expect("renders");
    assert!(out.film.get(0, 0).is_finite());
}

#[test]
fn estimates_at_a_planes_edge_and_corner_read_the_boundary_bias() {
    // Hard case 24 (and the bias issue 13 asks to state): a 2 × 2 plane under a point light
    // 2 units above its centre. Inside, the estimate matches E(x); at an edge midpoint only
    // half of the disc has photons, so the uncorrected estimate reads ≈ 0.5 E, and ≈ 0.25 E at
    // a corner (no boundary correction is made).
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, seed: 6, integrator: Photon),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: { "white": (color: (1, 1, 1)) },
    lights: [ Point(position: (0, 2, 0), power: (12.566371, 12.566371, 12.566371)) ],
    nodes: [ Quad(material: "white", size: (2, 2), transform: [RotateX(-90)]) ],
)"#,
    );
    let (photons, _) = direct_photons(&scene, 4_000_000);
    let map = PhotonMap::new(KdTree::build(photons).expect("tree"), 100, 1.0, Kernel::Box);
    let ratio = |x: f32, z: f32| {
        let e = map.estimate(
            Vec3::new(x, 0.0, z),
            Vec3::Y,
            &up(),
            &lambert(),
            Walls::of(&scene, None),
        );
        let r2 = f64::from(x * x + z * z);
        let exact = 2.0 / (4.0 + r2).powf(1.5);
        f64::from(e.radiance.x) * PI / exact
    };
    let (centre, edge, corner) = (ratio(0.0, 0.0), ratio(1.0, 0.0), ratio(1.0, 1.0));
    eprintln!("estimate / exact: centre {centre:.3}, edge midpoint {edge:.3}, corner {corner:.3}");
    assert!((centre - 1.0).abs() < 0.03, "centre {centre}");
    assert!((0.45..0.55).contains(&edge), "edge {edge}");
    assert!((0.22..0.28).contains(&corner), "corner {corner}");
}

#[test]
fn photon_flags_and_unset_optional_fields_can_be_overridden() {
    // `--max-radius` and `--set` on fields a scene leaves unset (they are optional in the
    // schema) must work; a typo must still be refused with a suggestion.
    for args in [
        vec!["check", "scenes/water.ron", "--max-radius", "0.05"],
        vec![
            "check",
            "scenes/water.ron",
            "--set",
            "lights[0].caustic_photons=1000",
        ],
        vec![
            "check",
            "scenes/cornell.ron",
            "--set",
            "render.diffuse_depth=2",
        ],
        vec![
            "check",
            "scenes/water.ron",
            "--photons",
            "0",
            "--caustic-photons",
            "0",
            "--gather",
            "7",
            "--final-gather",
            "0",
        ],
    ] {
        let out = crate::common::caustic(&args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let out = crate::common::caustic(&["check", "scenes/water.ron", "--set", "photons.gathr=7"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("did you mean `gather`?"), "{err}");
}
