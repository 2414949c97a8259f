//! Light transport against closed forms: the white furnace, a Lambert plane under a point light
//! and under a sphere light, a mirror and a glass pane against a constant background, the η²
//! radiance convention under water, and `path` against `whitted` where both are exact.

use glam::Vec3;

use caustic::geometry::Ray;
use caustic::integrators::Counters;
use caustic::render::{RenderOptions, render};
use caustic::render_scene::RenderScene;

use crate::common::scene_from_text;

const PI: f64 = std::f64::consts::PI;

/// Mean and standard error of `n` estimates of the radiance along `ray` (sample indices
/// 0..n of pixel (0, 0), so the numbers are the renderer's own streams).
fn estimate(scene: &RenderScene, ray: Ray, n: u32) -> (Vec3, Vec3) {
    let (mean, err) = crate::common::estimate_along(scene, ray, n);
    (mean.as_vec3(), err.as_vec3())
}

fn with_integrator(text: &str, integrator: &str) -> RenderScene {
    scene_from_text(&text.replace("INTEGRATOR", integrator))
}

/// The furnace: under a uniform background of radiance 1, a convex object reads its albedo.
fn furnace(material: &str) -> RenderScene {
    scene_from_text(&format!(
        r#"Scene(
    render: (width: 24, height: 24, samples_per_pixel: 16, max_depth: 64, seed: 3,
             background: (1, 1, 1), integrator: Path),
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 30),
    materials: {{ "m": {material} }},
    nodes: [ Sphere(material: "m", center: (0, 0, 0), radius: 1) ],
)"#
    ))
}

/// Mean over the pixels whose centre ray hits the unit sphere (well inside its silhouette).
fn covered_mean(scene: &RenderScene) -> (f64, f64, f64) {
    let out = render(scene, &RenderOptions::default()).expect("renders");
    let f = &out.film;
    let (mut sum, mut min, mut max, mut n) = (0.0f64, f64::MAX, f64::MIN, 0);
    for y in 0..f.height {
        for x in 0..f.width {
            let r = scene
                .camera
                .ray(x as f32 + 0.5, y as f32 + 0.5, f.width, f.height);
            // Distance of the centre ray from the sphere's centre: keep pixels ≥ 1.5 px inside.
            let d = r.dir.normalize();
            let miss = (r.origin - d * r.origin.dot(d)).length();
            if miss < 0.8 {
                let v = f64::from(f.get(x, y).x);
                sum += v;
                min = min.min(v);
                max = max.max(v);
                n += 1;
            }
        }
    }
    assert!(n > 100, "{n} covered pixels");
    assert_eq!(out.stats.nan_samples, 0);
    (sum / f64::from(n), min, max)
}

#[test]
fn white_furnace_diffuse_objects_read_their_albedo_and_lossless_ones_vanish() {
    // A convex Lambertian of albedo a under radiance 1 reflects exactly a (one bounce, then the
    // path escapes), so every sample is a up to rounding: the tolerance is float rounding.
    for a in [0.5f64, 0.9, 1.0] {
        let (mean, min, max) = covered_mean(&furnace(&format!("(color: ({a}, {a}, {a}))")));
        assert!(
            (mean - a).abs() < 1e-4 && (min - a).abs() < 1e-4 && (max - a).abs() < 1e-4,
            "albedo {a}: mean {mean}, range [{min}, {max}]"
        );
    }
    // A mirror of reflectance 1 vanishes exactly.
    let (mean, min, max) = covered_mean(&furnace("(color: (1, 1, 1), reflect: 1)"));
    assert!(
        (mean - 1.0).abs() < 1e-5 && min > 0.9999 && max < 1.0001,
        "{mean} [{min}, {max}]"
    );
    // A clear glass sphere: every path's weight is 1 (η² in and out cancel; Fresnel reflection
    // and refraction are chosen with their own probabilities), except the few trapped by total
    // internal reflection for more than 64 bounces. So the mean is 1 within 0.2%.
    let (mean, min, max) = covered_mean(&furnace("(color: (1, 1, 1), transmit: 1, ior: 1.5)"));
    assert!(
        (mean - 1.0).abs() < 2e-3 && max < 1.0 + 1e-4 && min > 0.9,
        "glass: {mean} [{min}, {max}]"
    );
}

#[test]
fn white_furnace_a_white_coated_sphere_vanishes_in_the_mean() {
    // A white base under a clear coat reflects F(θ) + (1 − F(θ)) = 1 at every angle
    // (docs/material.md, the coated lobe), and a convex sphere never sees itself, so the mean is
    // 1. The coat's samples weigh exactly 1; the base's weigh (1 − F(θᵢ))/(1 − F_dr,ext), 1 only
    // on average, hence a noise tolerance (≈ 0.3 % standard error over ~4 000 samples).
    for ior in [1.33f64, 1.5, 2.0] {
        let (mean, min, max) =
            covered_mean(&furnace(&format!("(color: (1, 1, 1), coat: (ior: {ior}))")));
        println!("coated furnace η {ior}: mean {mean:.5}, pixels in [{min:.4}, {max:.4}]");
        assert!(
            (mean - 1.0).abs() < 0.005 && min > 0.9 && max < 1.1,
            "coat η {ior}: mean {mean}, range [{min}, {max}]"
        );
    }
}

const PLANE_UNDER_POINT: &str = r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 8, integrator: INTEGRATOR),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: { "m": (color: (0.6, 0.5, 0.4)) },
    lights: [ Point(position: (0.5, 2, -0.3), power: (100, 80, 60)) ],
    nodes: [ Quad(material: "m", size: (20, 20), transform: [RotateX(-90)]) ],
)"#;

#[test]
fn lambert_plane_under_a_point_light_reads_rho_over_pi_times_irradiance() {
    let light = Vec3::new(0.5, 2.0, -0.3);
    let power = Vec3::new(100.0, 80.0, 60.0);
    let rho = Vec3::new(0.6, 0.5, 0.4);
    for integrator in ["Whitted", "Path"] {
        let scene = with_integrator(PLANE_UNDER_POINT, integrator);
        for target in [
            Vec3::ZERO,
            Vec3::new(1.3, 0.0, 0.7),
            Vec3::new(-2.0, 0.0, -1.5),
        ] {
            let eye = Vec3::new(0.0, 3.0, 3.0);
            let ray = Ray::new(eye, (target - eye).normalize());
            let (l, se) = estimate(&scene, ray, 16);
            let d = light - target;
            let cos = d.y / d.length();
            let expected = rho / std::f32::consts::PI * power / (4.0 * std::f32::consts::PI) * cos
                / d.length_squared();
            let rel = ((l - expected) / expected).abs().max_element();
            // Deterministic: one light, a point light, nothing to bounce off (the plane is
            // the whole scene and the background is black).
            assert!(
                rel < 1e-4 && se.max_element() < 1e-6,
                "{integrator} at {target}: {l} vs {expected}"
            );
        }
    }
}

const PLANE_UNDER_SPHERE: &str = r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 8, light_samples: 1,
             integrator: INTEGRATOR, seed: 5),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: { "m": (color: (0.5, 0.5, 0.5)) },
    lights: [ Sphere(center: (0, 1.5, 0), radius: 0.3, power: (50, 50, 50)) ],
    nodes: [ Quad(material: "m", size: (40, 40), transform: [RotateX(-90)]) ],
)"#;

#[test]
fn lambert_plane_under_a_sphere_light_reads_the_analytic_irradiance() {
    // A sphere of radiance L, radius R, centre at height h straight above the point: the
    // irradiance is π L (R/h)² (the sphere is wholly above the horizon), so the plane reads
    // ρ L R²/h², with L = Φ/(4π²R²).
    let (r, h, phi, rho) = (0.3f64, 1.5f64, 50.0f64, 0.5f64);
    let radiance = phi / (4.0 * PI * PI * r * r);
    let expected = rho * radiance * r * r / (h * h);
    for integrator in ["Whitted", "Path"] {
        let scene = with_integrator(PLANE_UNDER_SPHERE, integrator);
        let eye = Vec3::new(0.0, 3.0, 3.0);
        let ray = Ray::new(eye, (Vec3::ZERO - eye).normalize());
        let (l, se) = estimate(&scene, ray, 20_000);
        let (l, se) = (f64::from(l.x), f64::from(se.x));
        // Only direct light reaches the point: the sphere light absorbs what the plane sends up.
        assert!(
            (l - expected).abs() < 4.0 * se + 1e-3 * expected,
            "{integrator}: {l} ± {se} vs {expected}"
        );
        assert!(se < 0.01 * expected, "{integrator}: noise {se}");
    }
}

const MIRROR_AND_PANE: &str = r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 64, integrator: INTEGRATOR,
             background: (0.5, 0.7, 0.9)),
    camera: Pinhole(eye: (0, 0, 5), look_at: (0, 0, 0), fov_y: 20),
    materials: {
        "mirror": (color: (0.8, 0.6, 0.4), reflect: 1),
        "glass": (color: (1, 1, 1), transmit: 1, ior: 1.5),
    },
    nodes: [
        Cube(material: "glass", transform: [Scale((2, 2, 0.1))]),
        Quad(material: "mirror", size: (2, 2), transform: [RotateY(30), Translate(0, 0, -10)]),
    ],
)"#;

#[test]
fn mirror_and_glass_pane_against_a_constant_background() {
    let bg = Vec3::new(0.5, 0.7, 0.9);
    // A pane at normal incidence: the incoherent sum over internal reflections transmits
    // (1 − F)² Σ F²ᵏ = (1 − F)/(1 + F) and reflects 2F/(1 + F), F = 0.04. The reflected part
    // goes back to the background; the transmitted part meets the tilted mirror behind, which
    // sends ρ of it off to the background, clear of the pane.
    let f = 0.04f32;
    let pane = (1.0 - f) / (1.0 + f);
    let reflected = 2.0 * f / (1.0 + f);
    for integrator in ["Whitted", "Path"] {
        let scene = with_integrator(MIRROR_AND_PANE, integrator);
        // Through the pane's centre to the mirror, reflected off to the background.
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        let (l, se) = estimate(&scene, ray, 4000);
        let expected = (pane * Vec3::new(0.8, 0.6, 0.4) + Vec3::splat(reflected)) * bg;
        assert!(
            ((l - expected).abs() - 4.0 * se).max_element() < 2e-3 * expected.max_element(),
            "{integrator}: {l} ± {se} vs {expected}"
        );
    }
}

/// Exact irradiance at floor point `x` (depth `d` under a flat water surface y = 0 of index
/// `eta`) from a sphere light (centre `c`, radius `r`, radiance `l`) above the surface, by
/// quadrature over underwater directions: each is refracted into the air (Snell), kept if it
/// then hits the sphere, and weighed by radiance L·(1 − F)·η² (radiance grows by η² entering
/// the denser medium) times cos θ. The compression of the light's solid angle by refraction is
/// in which directions hit.
pub(crate) fn underwater_irradiance(x: [f64; 3], c: [f64; 3], r: f64, l: f64, eta: f64) -> f64 {
    let (nt, np) = (600, 360);
    // Only directions inside the cone towards the sphere's refracted image matter; integrate
    // the hemisphere up to the critical angle (beyond it nothing leaves the water).
    let crit = (1.0 / eta).asin();
    let mut e = 0.0;
    for i in 0..nt {
        let th = (i as f64 + 0.5) / nt as f64 * crit;
        let (st, ct) = th.sin_cos();
        let dth = crit / nt as f64;
        for j in 0..np {
            let ph = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
            let dw = st * dth * (2.0 * PI / np as f64);
            let dir = [st * ph.cos(), ct, st * ph.sin()];
            // Up to the surface.
            let t = -x[1] / dir[1];
            let p = [x[0] + t * dir[0], 0.0, x[2] + t * dir[2]];
            // Snell into air: sin θa = η sin θw.
            let sa = eta * st;
            let ca = (1.0 - sa * sa).sqrt();
            let a = [
                dir[0] / st.max(1e-300) * sa,
                ca,
                dir[2] / st.max(1e-300) * sa,
            ];
            // Hit the sphere?
            let oc = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            let b = oc[0] * a[0] + oc[1] * a[1] + oc[2] * a[2];
            let cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
            if b * b - cc < 0.0 || b > 0.0 {
                continue;
            }
            // Fresnel for the crossing (unpolarised), from the water side.
            let rs = (eta * ct - ca) / (eta * ct + ca);
            let rp = (ct - eta * ca) / (ct + eta * ca);
            let fresnel = 0.5 * (rs * rs + rp * rp);
            e += l * (1.0 - fresnel) * eta * eta * ct * dw;
        }
    }
    e
}

const POOL: &str = r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 16, integrator: INTEGRATOR,
             seed: 11, diffuse_depth: 1),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {
        "floor": (color: (0.8, 0.8, 0.8)),
        "water": (color: (1, 1, 1), transmit: 1, ior: 1.33),
    },
    lights: [ Sphere(center: (0, 1, 0), radius: 0.3, power: (20, 20, 20)) ],
    nodes: [
        Quad(material: "water", size: (60, 60), transform: [RotateX(-90)]),
        Quad(material: "floor", size: (60, 60), transform: [RotateX(-90), Translate(0, -0.3, 0)]),
    ],
)"#;

#[test]
fn floor_under_water_matches_the_analytic_radiance_from_above_and_from_below_the_waterline() {
    let (r, phi, rho, eta) = (0.3f64, 20.0f64, 0.8f64, 1.33f64);
    let radiance = phi / (4.0 * PI * PI * r * r);
    let e = underwater_irradiance([0.0, -0.3, 0.0], [0.0, 1.0, 0.0], r, radiance, eta);
    // Radiance of the floor, in the water, from direct light only: `diffuse_depth: 1` keeps
    // the light the surface reflects back down (total internal reflection) out of both sides.
    let floor = rho / PI * e;
    let scene = with_integrator(POOL, "Path");
    // From below the waterline (a camera in the water): the floor's radiance itself.
    let below = Ray::new(
        Vec3::new(0.5, -0.1, 0.0),
        (Vec3::new(0.0, -0.3, 0.0) - Vec3::new(0.5, -0.1, 0.0)).normalize(),
    );
    let (l, se) = estimate(&scene, below, 500_000);
    let (l, se) = (f64::from(l.x), f64::from(se.x));
    assert!(
        (l - floor).abs() < 4.0 * se + 2e-3 * floor,
        "below the waterline: {l} ± {se} vs {floor}"
    );
    // From above, through the surface: times (1 − F)/η² for the camera ray entering the water,
    // plus the Fresnel reflection of the black sky (0; the reflected ray clears the light).
    // The camera ray comes in at 25° from the vertical and is aimed to refract onto the point.
    let th_w = (25f64.to_radians().sin() / eta).asin();
    let entry = Vec3::new(0.0, 0.0, (0.3 * th_w.tan()) as f32);
    let dir = Vec3::new(
        0.0,
        -(25f32.to_radians().cos()),
        -(25f32.to_radians().sin()),
    );
    let eye = entry - dir;
    let ca = 25f64.to_radians().cos();
    let cw = th_w.cos();
    let rs = (ca - eta * cw) / (ca + eta * cw);
    let rp = (cw - eta * ca) / (cw + eta * ca);
    let t_cam = 1.0 - 0.5 * (rs * rs + rp * rp);
    let above = floor * t_cam / (eta * eta);
    let (l, se) = estimate(&scene, Ray::new(eye, dir), 500_000);
    let (l, se) = (f64::from(l.x), f64::from(se.x));
    assert!(
        (l - above).abs() < 4.0 * se + 2e-3 * above,
        "from above: {l} ± {se} vs {above} (floor {floor})"
    );
}

#[test]
fn a_sphere_light_shadows_another_light_but_never_itself() {
    // Seen from the origin, the near light (radius 0.5 at height 2: a 14.5° half-angle) covers
    // the far one (radius 0.3 at height 5: 3.4°) entirely. Shadow rays skip the surface of the
    // light they aim at, never the others: every sample of the far light is blocked, none of
    // the near light's.
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 4, height: 4),
    camera: Pinhole(eye: (0, 1, 5), look_at: (0, 0, 0), fov_y: 30),
    materials: { "m": (color: (0.5, 0.5, 0.5), diffuse: 1) },
    lights: [
        Sphere(center: (0, 2, 0), radius: 0.5, power: (10, 10, 10)),
        Sphere(center: (0, 5, 0), radius: 0.3, power: (10, 10, 10)),
    ],
    nodes: [ Quad(material: "m", size: (10, 10), transform: [RotateX(-90)]) ],
)"#,
    );
    let ray = Ray::new(
        Vec3::new(0.0, 1.0, 5.0),
        Vec3::new(0.0, -1.0, -5.0).normalize(),
    );
    let hit = scene.geometry.intersect(&ray).expect("the floor");
    let sp = scene.geometry.surface(&ray, &hit);
    let m = scene.objects[sp.object as usize]
        .material
        .expect("material");
    let wo = -ray.dir;
    let sh = scene.shading_point(&scene.materials[m as usize], &sp, wo, 0.0);
    let fr = caustic::shading::ShadingFrame {
        ns: sh.ns,
        ng: sh.ng,
        entering: sh.entering,
    };
    let at = sh.bsdf.at(wo, &fr);
    let mut rng = caustic::sampling::Rng::new(3, 0);
    let mut counters = Counters::default();
    let mut blocked = [0u32; 2];
    let n = 2000;
    for _ in 0..n {
        let u = rng.next_2d();
        for (light, b) in blocked.iter_mut().enumerate() {
            let c = caustic::integrators::shadow::connect_light(
                &scene,
                light,
                &sp,
                &at,
                u,
                &mut counters,
            )
            .expect("both lights are above the floor");
            *b += u32::from(c.occluded);
        }
    }
    assert_eq!(blocked, [0, n]);
}
