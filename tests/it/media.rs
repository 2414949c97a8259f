//! Nested dielectrics and participating media against closed forms (docs/media.md): nested
//! interfaces lose no energy in a white furnace, the Fresnel reflectance of a 1.5 | 1.33
//! interface, a scattering-only medium behind an index-matched boundary vanishes in a furnace,
//! an absorbing slab transmits exp(−σ d), single scattering from a point light in an infinite
//! medium matches its 1-D integral, and integrators that do not render media refuse them.

use glam::Vec3;

use caustic::geometry::Ray;
use caustic::render::{RenderOptions, render};
use caustic::render_scene::{Medium, RenderScene};
use caustic::scene::SourceFile;
use caustic::scene::validate::validate;

use crate::common::{estimate_along, scene_from_text};

/// Mean, min and max over the pixels whose centre ray passes within 0.8 of the origin (inside
/// the unit-radius objects the furnaces put there).
fn covered(scene: &RenderScene) -> (f64, f64, f64) {
    let out = render(scene, &RenderOptions::default()).expect("renders");
    let f = &out.film;
    let (mut sum, mut min, mut max, mut n) = (0.0f64, f64::MAX, f64::MIN, 0);
    for y in 0..f.height {
        for x in 0..f.width {
            let r = scene
                .camera
                .ray(x as f32 + 0.5, y as f32 + 0.5, f.width, f.height);
            let d = r.dir.normalize();
            let miss = (r.origin - d * r.origin.dot(d)).length();
            if miss < 0.8 {
                for c in 0..3 {
                    let v = f64::from(f.get(x, y)[c]);
                    sum += v;
                    min = min.min(v);
                    max = max.max(v);
                    n += 1;
                }
            }
        }
    }
    assert!(n > 300, "{n} covered pixel channels");
    assert_eq!(out.stats.nan_samples, 0);
    (sum / f64::from(n), min, max)
}

/// A furnace (background 1, no lights) around `nodes`, rendered by `integrator`.
fn furnace(materials: &str, media: &str, nodes: &str, integrator: &str) -> RenderScene {
    scene_from_text(&format!(
        r#"Scene(
    render: (width: 24, height: 24, samples_per_pixel: 32, max_depth: 256, seed: 5,
             background: (1, 1, 1), integrator: {integrator}),
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 30),
    materials: {{ {materials} }},
    media: {{ {media} }},
    nodes: [ {nodes} ],
)"#
    ))
}

#[test]
fn nested_water_in_glass_loses_no_energy_in_a_white_furnace() {
    // Water (1.33) touching glass (1.5) with no air between, two ways: a water drop inside a
    // glass ball (the water ranks higher, so the ball's glass ends at the drop), and a water
    // ball overlapping a glass ball (the glass ranks higher: the water's surface inside the
    // glass is not there). Every interface is lossless (clear, white), so under a background of
    // 1 every pixel is 1 except paths trapped by total internal reflection past 256 bounces.
    let materials = r#""glass": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5, priority: 1),
        "water": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.33, priority: 2)"#;
    let drop = r#"Sphere(material: "glass", center: (0, 0, 0), radius: 1),
        Sphere(material: "water", center: (0.15, 0.1, 0.2), radius: 0.6)"#;
    let overlap = r#"Sphere(material: "glass", center: (0, 0, 0), radius: 1),
        Sphere(material: "water", center: (0.7, 0.3, 0.3), radius: 0.7)"#;
    let low_water = materials.replace("priority: 2", "priority: 0");
    for (what, m, nodes) in [("drop", materials, drop), ("overlap", &low_water, overlap)] {
        let (mean, min, max) = covered(&furnace(m, "", nodes, "Path"));
        println!("nested furnace ({what}): mean {mean:.5} in [{min:.4}, {max:.4}]");
        assert!(
            (mean - 1.0).abs() < 2e-3 && max < 1.0 + 1e-3 && min > 0.9,
            "{what}: mean {mean}, range [{min}, {max}]"
        );
    }
}

/// Unpolarised Fresnel reflectance from index `n1` into `n2` at incidence cosine `cos_i`
/// (1 past the critical angle): Born & Wolf §1.5.
fn fresnel(n1: f64, n2: f64, cos_i: f64) -> f64 {
    let sin_t = n1 / n2 * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    0.5 * (rs * rs + rp * rp)
}

#[test]
fn fresnel_at_a_glass_water_interface_is_the_closed_form_for_1_5_over_1_33() {
    let scene = furnace(
        r#""glass": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5, priority: 1),
        "water": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.33, priority: 2)"#,
        "",
        r#"Sphere(material: "glass", center: (0, 0, 0), radius: 1),
        Sphere(material: "water", center: (0, 0, 0), radius: 0.5)"#,
        "Path",
    );
    let index = |n: &str| scene.material_names.iter().position(|m| m == n).unwrap() as u32;
    let (glass, water) = (index("glass"), index("water"));
    // In the glass: the water's surface is a true one, refracting 1.33/1.5.
    let in_glass = Medium::outside(&scene).crossed(&scene, glass, true);
    assert!(!in_glass.skips(&scene, water));
    let eta = in_glass
        .interface_ior(&scene, water)
        .expect("a 1.5 | 1.33 interface");
    assert!((eta - 1.33 / 1.5).abs() < 1e-6, "{eta}");
    // In air the glass refracts against air (its own index) and the water is 1.33 against air.
    assert_eq!(Medium::outside(&scene).interface_ior(&scene, glass), None);
    // Delta lobes of the water's BSDF at that ratio, light arriving from the glass side (wo
    // outside the water) and from the water side.
    let bsdf = scene.materials[water as usize].bsdf.with_ior(eta);
    for deg in [0.0f64, 20.0, 45.0, 60.0, 62.0, 63.0, 80.0] {
        let (s, c) = deg.to_radians().sin_cos();
        let wo = Vec3::new(s as f32, 0.0, c as f32);
        // wo on the outside (the glass side): from 1.5 into 1.33, total reflection past 62.46°.
        let lobes = bsdf.delta_lobes(wo, Vec3::Z, Vec3::Z, true);
        let want = fresnel(1.5, 1.33, c);
        let got = f64::from(lobes.reflect_weight.x);
        assert!(
            (got - want).abs() < 1e-5,
            "{deg}° glass→water: {got} vs {want}"
        );
        if let Some((dir, _)) = lobes.refract {
            // Snell: 1.5 sin θi = 1.33 sin θt.
            let sin_t = f64::from(Vec3::new(dir.x, dir.y, 0.0).length());
            assert!(
                (1.5 * s - 1.33 * sin_t).abs() < 1e-5,
                "{deg}°: sin θt {sin_t}"
            );
        } else {
            assert!(
                want == 1.0,
                "{deg}°: no refraction below the critical angle"
            );
        }
        // wo inside the water: from 1.33 into 1.5, never total.
        let lobes = bsdf.delta_lobes(wo, Vec3::Z, Vec3::Z, false);
        let want = fresnel(1.33, 1.5, c);
        let got = f64::from(lobes.reflect_weight.x);
        assert!(
            (got - want).abs() < 1e-5,
            "{deg}° water→glass: {got} vs {want}"
        );
    }
}

#[test]
fn an_albedo_one_medium_behind_an_index_matched_boundary_vanishes_in_a_furnace() {
    // A sphere of non-absorbing scattering medium (σs = 2, forward-scattering g = 0.5) behind
    // an interface under radiance 1: every path scatters some times and escapes to radiance 1
    // with weight exactly 1 (grey medium), so every pixel is 1. Once with the background as
    // the environment, once with a constant Environment light (next-event estimation through
    // the boundary, MIS with phase sampling), with path, ppm and path-ppm.
    let materials = r#""smoke": (interface: true, medium: "fog")"#;
    let media = r#""fog": (sigma_s: (2, 2, 2), g: 0.5)"#;
    let nodes = r#"Sphere(material: "smoke", center: (0, 0, 0), radius: 1)"#;
    for integrator in ["Path", "PathPpm", "Ppm"] {
        let (mean, min, max) = covered(&furnace(materials, media, nodes, integrator));
        println!("smoke furnace {integrator}: mean {mean:.5} in [{min:.4}, {max:.4}]");
        assert!(
            (mean - 1.0).abs() < 1e-4 && min > 0.999 && max < 1.001,
            "{integrator}: mean {mean}, range [{min}, {max}]"
        );
    }
    let lit = scene_from_text(&format!(
        r#"Scene(
    render: (width: 24, height: 24, samples_per_pixel: 256, max_depth: 256, seed: 5, integrator: Path),
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 30),
    materials: {{ {materials} }},
    media: {{ {media} }},
    lights: [ Environment(radiance: (1, 1, 1)) ],
    nodes: [ {nodes} ],
)"#
    ));
    let (mean, min, max) = covered(&lit);
    println!("smoke furnace, environment light: mean {mean:.5} in [{min:.4}, {max:.4}]");
    // MIS weights make single samples differ from 1; the mean is 1 within noise (a pixel's
    // spread at 32 spp was ±0.1, so the mean of ~400 pixels at 256 spp has σ ≈ 0.002).
    assert!(
        (mean - 1.0).abs() < 0.01,
        "mean {mean}, range [{min}, {max}]"
    );
}

#[test]
fn a_purely_absorbing_slab_transmits_exp_minus_sigma_d_per_channel() {
    // A slab 0.4 thick of σa = (0.5, 2, 5) behind interfaces, seen head-on against a
    // background of 1: exp(−σ·0.4) per channel, exactly (no scattering, nothing sampled).
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 4, max_depth: 16, background: (1, 1, 1), integrator: Path),
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 30),
    materials: { "slab": (interface: true, medium: "ink") },
    media: { "ink": (sigma_a: (0.5, 2, 5)) },
    nodes: [ Cube(material: "slab", transform: [Scale(10, 10, 0.4)]) ],
)"#,
    );
    let ray = Ray::new(Vec3::new(0.0, 0.0, 4.0), Vec3::new(0.0, 0.0, -1.0));
    let (mean, _) = estimate_along(&scene, ray, 16);
    for (c, sigma) in [0.5f64, 2.0, 5.0].into_iter().enumerate() {
        let want = (-sigma * 0.4).exp();
        assert!(
            (mean[c] - want).abs() < 1e-5,
            "channel {c}: {} vs {want}",
            mean[c]
        );
    }
}

/// Mean and standard error per channel of `n` samples of `tracer` along `ray` (as
/// `common::estimate_along`, for a tracer built here), and the sample variance.
fn estimate_with(
    scene: &RenderScene,
    tracer: &caustic::integrators::PathTracer<'_>,
    ray: Ray,
    n: u32,
) -> (glam::DVec3, glam::DVec3, glam::DVec3) {
    crate::common::estimate_by(scene, n, |cx| tracer.li(ray, cx).total().as_dvec3())
}

/// Single scattering along `ray` from the origin along +z through an infinite medium of
/// (σa, σs) per channel and Henyey–Greenstein `g`, lit by a point light of power `power` at
/// `light`: L = ∫₀^∞ σs e^{−σt t} p(θ(t)) (Φ/4π) e^{−σt r(t)} / r(t)² dt, r(t) the distance
/// from the point at t to the light, θ the angle between +z and the direction to the light.
/// Composite Simpson on [0, 80] (e^{−σt t} ≤ e^{−12} beyond), 80 000 intervals.
fn single_scattering_integral(
    coefficients: [(f64, f64); 3],
    g: f64,
    light: glam::DVec3,
    power: f64,
) -> [f64; 3] {
    let intensity = power / (4.0 * std::f64::consts::PI);
    let hg = |cos: f64| {
        (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
    };
    coefficients.map(|(sa, ss)| {
        let st = sa + ss;
        let f = |t: f64| {
            let x = glam::DVec3::new(0.0, 0.0, t);
            let to = light - x;
            let r = to.length();
            ss * (-st * t).exp() * hg(to.z / r) * intensity * (-st * r).exp() / (r * r)
        };
        let (a, b, n) = (0.0f64, 80.0f64, 80_000usize);
        let h = (b - a) / n as f64;
        let mut sum = f(a) + f(b);
        for i in 1..n {
            sum += f(a + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * h / 3.0
    })
}

#[test]
fn single_scattering_from_a_point_light_in_fog_matches_its_integral() {
    // A camera ray from the origin along +z through fog filling space (σs = 0.3, σa = 0.1 in
    // red; chromatic in the other channels), a point light of power Φ at (0.5, 0.8, 1.5):
    // max_depth 1 keeps single scattering only (single_scattering_integral).
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 1, integrator: Path),
    camera: Pinhole(eye: (0, 0, -1), look_at: (0, 0, 0), fov_y: 30),
    materials: { "black": (color: (0, 0, 0)) },
    media: { "fog": (sigma_a: (0.1, 0.05, 0.2), sigma_s: (0.3, 0.6, 0.1), g: 0.4) },
    medium: "fog",
    lights: [ Point(position: (0.5, 0.8, 1.5), power: (50, 50, 50)) ],
    nodes: [ Sphere(material: "black", center: (0, -50, 0), radius: 0.1) ],
)"#,
    );
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    let (mean, err) = estimate_along(&scene, ray, 200_000);
    let want = single_scattering_integral(
        [(0.1, 0.3), (0.05, 0.6), (0.2, 0.1)],
        0.4,
        glam::DVec3::new(0.5, 0.8, 1.5),
        50.0,
    );
    for (c, want) in want.into_iter().enumerate() {
        let got = mean[c];
        println!(
            "single scattering channel {c}: {got:.6} ± {:.6} vs {want:.6}",
            err[c]
        );
        assert!(
            (got - want).abs() < 4.0 * err[c] + 1e-3 * want,
            "channel {c}: {got} ± {} vs {want}",
            err[c]
        );
    }
}

#[test]
fn equiangular_sampling_converges_to_single_scattering_with_less_variance() {
    // The closed form above with the light close to the ray (D = 0.1 m from it, 2 m along it),
    // where distance sampling's variance comes from the 1/r² next to the light (Kulla &
    // Fajardo 2012, fig. 3): `path` with equiangular sampling MIS-combined with free-flight
    // sampling (the default) and with free-flight sampling alone both converge to the
    // integral; the variance ratio is measured (printed) and asserted large.
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 1, integrator: Path),
    camera: Pinhole(eye: (0, 0, -1), look_at: (0, 0, 0), fov_y: 30),
    materials: { "black": (color: (0, 0, 0)) },
    media: { "fog": (sigma_a: (0.1, 0.05, 0.2), sigma_s: (0.3, 0.6, 0.1), g: 0.4) },
    medium: "fog",
    lights: [ Point(position: (0.1, 0.0, 2.0), power: (50, 50, 50)) ],
    nodes: [ Sphere(material: "black", center: (0, -50, 0), radius: 0.1) ],
)"#,
    );
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    let want = single_scattering_integral(
        [(0.1, 0.3), (0.05, 0.6), (0.2, 0.1)],
        0.4,
        glam::DVec3::new(0.1, 0.0, 2.0),
        50.0,
    );
    let n = 200_000;
    let equiangular = caustic::integrators::PathTracer::new(&scene);
    let distance = caustic::integrators::PathTracer::new(&scene).with_equiangular(false);
    let (mean_e, err_e, var_e) = estimate_with(&scene, &equiangular, ray, n);
    let (mean_d, err_d, var_d) = estimate_with(&scene, &distance, ray, n);
    for (c, want) in want.into_iter().enumerate() {
        let ratio = var_d[c] / var_e[c];
        println!(
            "channel {c}: equiangular + distance {:.6} ± {:.6}, distance {:.6} ± {:.6}, \
             integral {want:.6}; variance ratio distance / equiangular {ratio:.1}",
            mean_e[c], err_e[c], mean_d[c], err_d[c]
        );
        assert!(
            (mean_e[c] - want).abs() < 4.0 * err_e[c] + 1e-3 * want,
            "equiangular, channel {c}: {} ± {} vs {want}",
            mean_e[c],
            err_e[c]
        );
        assert!(
            (mean_d[c] - want).abs() < 4.0 * err_d[c] + 1e-3 * want,
            "distance, channel {c}: {} ± {} vs {want}",
            mean_d[c],
            err_d[c]
        );
        // Measured 11.1 to 11.6 (200 000 samples each).
        assert!(ratio > 5.0, "channel {c}: variance ratio {ratio}");
    }
}

/// The validation messages of a scene given as text.
fn diagnostics(text: &str) -> Vec<String> {
    let src = SourceFile::new(std::path::Path::new("inline.ron"), text.to_string()).expect("ron");
    let file = src.parse().unwrap_or_else(|e| panic!("{e}"));
    validate(&file)
        .iter()
        .filter(|d| d.is_error())
        .map(|d| format!("{}: {}", d.path, d.message))
        .collect()
}

#[test]
fn integrators_without_media_refuse_them_and_bad_media_are_located() {
    let scene = |integrator: &str, extra: &str| {
        format!(
            r#"Scene(
    render: (integrator: {integrator}),
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 30),
    materials: {{ "smoke": (interface: true, medium: "fog"){extra} }},
    media: {{ "fog": (sigma_s: (1, 1, 1)) }},
    lights: [ Point(position: (0, 3, 0), power: (10, 10, 10)) ],
    nodes: [ Sphere(material: "smoke", center: (0, 0, 0), radius: 1) ],
)"#
        )
    };
    for integrator in ["Whitted", "Photon"] {
        let d = diagnostics(&scene(integrator, ""));
        assert!(
            d.iter().any(|m| m.starts_with("render.integrator")
                && m.contains(integrator)
                && m.contains("participating media")),
            "{integrator}: {d:?}"
        );
    }
    for integrator in ["Path", "Ppm", "PathPpm"] {
        assert!(
            diagnostics(&scene(integrator, "")).is_empty(),
            "{integrator}"
        );
    }
    let d = diagnostics(&scene("Path", r#", "x": (medium: "fgo", transmit: 1)"#));
    assert!(
        d.iter()
            .any(|m| m.starts_with("materials.x.medium") && m.contains("unknown medium `fgo`")),
        "{d:?}"
    );
    let d = diagnostics(&scene(
        "Path",
        r#", "y": (interface: true, medium: "fog", diffuse: 1)"#,
    ));
    assert!(
        d.iter().any(|m| m.starts_with("materials.y.diffuse")),
        "{d:?}"
    );
    let d = diagnostics(&scene("Path", r#", "z": (color: (1, 1, 1), priority: 3)"#));
    assert!(
        d.iter().any(|m| m.starts_with("materials.z.priority")),
        "{d:?}"
    );
}

#[test]
fn caustic_photons_under_a_murky_slab_carry_the_unscattered_share() {
    // A horizontal glass slab 0.4 thick filled with a scattering medium over a white floor; a
    // vertical beam of irradiance E₀ over 1 m². Caustic photons are the light that crosses
    // without scattering, so the floor receives E₀ (1 − F)² τ / (1 − F² τ²) per channel with
    // τ = exp(−σt·0.4) (the slab's internal reflections summed), F the normal-incidence
    // Fresnel reflectance ((η − 1)/(η + 1))².
    use caustic::integrators::photon::trace::{MapKind, TraceCounts, TraceSettings, trace_photon};
    use caustic::sampling::Sampler;
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, seed: 5, integrator: Path),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {
        "white": (color: (1, 1, 1)),
        "murky": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5, medium: "silt"),
    },
    media: { "silt": (sigma_a: (0.5, 0.2, 1.0), sigma_s: (0.5, 1.5, 0.3), g: 0.6) },
    lights: [ Point(position: (0, 3, 0), power: (1, 1, 1)) ],
    nodes: [
        Cube(material: "murky", transform: [Scale((4, 0.4, 4))]),
        Quad(material: "white", size: (4, 4), transform: [RotateX(-90), Translate(0, -1, 0)]),
    ],
)"#,
    );
    let n = 200_000u64;
    let e0 = 2.0f32;
    let settings = TraceSettings {
        kind: MapKind::Caustic,
        min_bounces: 0,
        any_bounce: false,
        max_bounces: 64,
        pass: None,
        near_specular: None,
    };
    let mut sampler = Sampler::new(scene.params.sampler, 3, 1);
    let (mut out, mut counts) = (Vec::new(), TraceCounts::default());
    for i in 0..n {
        sampler.start_stream(1, i);
        let (u, v) = sampler.next_2d();
        let ray = Ray::new(Vec3::new(u - 0.5, 2.0, v - 0.5), -Vec3::Y);
        let power = Vec3::splat(e0 / n as f32);
        trace_photon(
            &scene,
            ray,
            power,
            settings,
            &mut sampler,
            &mut out,
            &mut counts,
        );
    }
    for ph in &out {
        let p = ph.position();
        assert!(
            (p.y + 1.0).abs() < 1e-4 && p.x.abs() <= 0.5 && p.z.abs() <= 0.5,
            "{p}"
        );
    }
    let f = (0.5f64 / 2.5).powi(2);
    for (c, st) in [1.0f64, 1.7, 1.3].into_iter().enumerate() {
        let tau = (-st * 0.4).exp();
        let want = f64::from(e0) * (1.0 - f).powi(2) * tau / (1.0 - f * f * tau * tau);
        let got = f64::from(counts.stored_flux[c]);
        println!("murky slab channel {c}: {got:.5} vs {want:.5}");
        assert!(
            (got / want - 1.0).abs() < 0.01,
            "channel {c}: {got} vs {want}"
        );
    }
}

#[test]
fn a_scene_wide_medium_warns_that_lights_at_infinity_reach_nothing() {
    let text = r#"Scene(
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 30),
    materials: { "grey": (color: (0.5, 0.5, 0.5)) },
    media: { "fog": (sigma_s: (0.1, 0.1, 0.1)) },
    medium: "fog",
    lights: [
        Point(position: (0, 3, 0), power: (10, 10, 10)),
        Distant(direction: (0, 1, 0), irradiance: (1, 1, 1)),
    ],
    nodes: [ Sphere(material: "grey", center: (0, 0, 0), radius: 1) ],
)"#;
    let src = SourceFile::new(std::path::Path::new("inline.ron"), text.to_string()).expect("ron");
    let file = src.parse().unwrap_or_else(|e| panic!("{e}"));
    let all = validate(&file);
    assert!(all.iter().all(|d| !d.is_error()), "{all:?}");
    let warnings: Vec<String> = all
        .iter()
        .map(|d| format!("{}: {}", d.path, d.message))
        .filter(|m| m.contains("infinitely far away"))
        .collect();
    // The distant light is named; the point light, inside the fog, is not.
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with("lights[1]: a distant light"),
        "{warnings:?}"
    );
}
