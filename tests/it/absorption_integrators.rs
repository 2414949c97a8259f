//! Beer–Lambert absorption in every integrator (issue 26): an absorbing glass slab of thickness
//! d over a lit floor, the floor's radiance against `exp(−σd)` times the Fresnel terms in closed
//! form, for `whitted`, `path`, `photon`, `ppm`, `path-ppm` and the default estimator — along
//! camera rays through the slab, along Whitted's shadow rays through it, and along the photon
//! integrator's final-gather rays through it (against the path tracer).

use glam::{DVec3, Vec3};

use caustic::geometry::Ray;
use caustic::render_scene::RenderScene;
use caustic::settings::IntegratorKind;

use crate::common::{estimate_along, scene_from_text};

const PI: f64 = std::f64::consts::PI;

/// Absorption coefficients of the test glass, per metre, and the slab's thickness and index.
const SIGMA: [f64; 3] = [0.5, 1.0, 2.0];
const D: f64 = 0.4;
const ETA: f64 = 1.5;
/// The floor's albedo and the point light's intensity (W/sr; power 4π·10).
const RHO: f64 = 0.5;
const INTENSITY: f64 = 10.0;

/// Unpolarised Fresnel reflectance of a smooth boundary, cosine `ci` on the side of index 1,
/// index `eta` on the other side.
fn fresnel(ci: f64, eta: f64) -> f64 {
    let st = (1.0 - ci * ci).max(0.0).sqrt() / eta;
    let ct = (1.0 - st * st).sqrt();
    let rs = (ci - eta * ct) / (ci + eta * ct);
    let rp = (ct - eta * ci) / (ct + eta * ci);
    0.5 * (rs * rs + rp * rp)
}

/// Normal-incidence transmittance of the slab, internal reflections included: every pass
/// through it keeps τ = exp(−σd), each crossing 1 − F, each internal reflection F, so
/// T = (1 − F)² τ Σₖ (F τ)²ᵏ = (1 − F)² τ / (1 − F² τ²).
fn slab_transmittance(sigma: f64) -> f64 {
    let f = fresnel(1.0, ETA);
    let tau = (-sigma * D).exp();
    (1.0 - f) * (1.0 - f) * tau / (1.0 - f * f * tau * tau)
}

/// The test scene: a 3 × 3 slab (y ∈ [1.8, 2.2]) of absorbing glass over a grey floor y = 0, a
/// point light at `light`; no photons and no final gather (each integrator then computes direct
/// light at the floor plus the mirror and glass chains of the camera ray, the same quantity),
/// path tracing ends at the first diffuse vertex (`diffuse_depth` 0), and Whitted follows
/// branches down to a weight of 10⁻⁵ (at the default 10⁻³ it drops the second internal
/// reflection, whose weight inside the glass is (1 − F)F²/η² = 7·10⁻⁴: −0.1 %). `integrator`
/// is a RON field or empty (the default estimator).
fn slab_scene(integrator: &str, light: [f64; 3], absorption: bool) -> RenderScene {
    let absorption = if absorption {
        ", absorption: (0.5, 1.0, 2.0)"
    } else {
        ""
    };
    let power = 4.0 * PI * INTENSITY;
    scene_from_text(&format!(
        r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 32, seed: 3, diffuse_depth: 0,
             min_contribution: 0.00001{integrator}),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {{
        "floor": (color: ({RHO}, {RHO}, {RHO})),
        "glass": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: {ETA}{absorption}),
    }},
    photons: (global: 0, caustic: 0, final_gather: 0),
    lights: [ Point(position: ({}, {}, {}), power: ({power}, {power}, {power})) ],
    nodes: [
        Quad(material: "floor", size: (20, 20), transform: [RotateX(-90)]),
        Cube(material: "glass", transform: [Scale((3, {D}, 3)), Translate(0, 2, 0)]),
    ],
)"#,
        light[0], light[1], light[2]
    ))
}

/// The integrators compared: (name, the RON field naming it; empty for the default).
const INTEGRATORS: [(&str, &str); 6] = [
    ("whitted", ", integrator: Whitted"),
    ("path", ", integrator: Path"),
    ("photon", ", integrator: Photon"),
    ("ppm", ", integrator: Ppm"),
    ("path-ppm", ", integrator: PathPpm"),
    ("default", ""),
];

/// Asserts `l` (mean, standard error) is within 1 % of `expected` and within 4 standard errors
/// plus 10⁻³ of it, per channel.
fn assert_close(what: &str, l: DVec3, se: DVec3, expected: [f64; 3]) {
    for c in 0..3 {
        let rel = l[c] / expected[c] - 1.0;
        eprintln!(
            "{what}, σ = {}: L = {:.6} ± {:.6}, closed form {:.6} ({:+.3} %)",
            SIGMA[c],
            l[c],
            se[c],
            expected[c],
            100.0 * rel
        );
        assert!(
            rel.abs() < 0.01 && (l[c] - expected[c]).abs() < 4.0 * se[c] + 1e-3 * expected[c],
            "{what}, channel {c}: {} ± {} vs {} ({rel:+.4})",
            l[c],
            se[c],
            expected[c]
        );
    }
}

#[test]
fn every_integrator_sees_the_floor_through_an_absorbing_slab_dimmed_by_exp_minus_sigma_d() {
    // The camera ray looks straight down through the slab at the floor's origin, lit by a point
    // light at (2.5, 1, 0) below the slab (its segment to the origin passes under the slab's
    // edge): E = I cos θ / r² = I · 1 / 7.25^{3/2}; the floor's radiance ρE/π reaches the
    // camera through the slab at normal incidence, keeping T = (1 − F)² τ / (1 − F² τ²)
    // (radiance's η² factors cancel over the two crossings).
    let light = [2.5, 1.0, 0.0];
    let e = INTENSITY * light[1] / (light[0] * light[0] + light[1] * light[1]).powf(1.5);
    let expected = SIGMA.map(|s| RHO / PI * e * slab_transmittance(s));
    let ray = Ray::new(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y);
    let mut means = Vec::new();
    for (name, field) in INTEGRATORS {
        let scene = slab_scene(field, light, true);
        if field.is_empty() {
            eprintln!("default estimator: {:?}", scene.params.integrator);
            assert_eq!(scene.params.integrator, IntegratorKind::PathPpm);
        }
        let (l, se) = estimate_along(&scene, ray, 20_000);
        assert_close(&format!("through the slab, {name}"), l, se, expected);
        means.push((name, l, se));
    }
    // And with each other: every pair within 1 % (plus their noise).
    for (a, la, sa) in &means {
        for (b, lb, sb) in &means {
            for c in 0..3 {
                let tol = 0.01 * la[c] + 4.0 * (sa[c] * sa[c] + sb[c] * sb[c]).sqrt();
                assert!(
                    (la[c] - lb[c]).abs() < tol,
                    "{a} vs {b}, channel {c}: {} vs {}",
                    la[c],
                    lb[c]
                );
            }
        }
    }
    // The same scene without absorption reads the Fresnel terms alone (τ = 1): what each
    // integrator returned before absorption reached it.
    let clear = SIGMA.map(|_| RHO / PI * e * slab_transmittance(0.0));
    let (l, se) = estimate_along(&slab_scene(", integrator: Whitted", light, false), ray, 16);
    assert_close("clear slab, whitted", l, se, clear);
}

#[test]
fn whitteds_shadow_rays_through_an_absorbing_slab_keep_exp_minus_sigma_d() {
    // The point light straight above the floor's origin at (0, 4, 0), over the slab; the camera
    // ray reaches the origin from the side, under the slab. Whitted's shadow ray crosses the
    // slab in a straight line at normal incidence: (1 − F)/η² entering, (1 − F)·η² leaving,
    // exp(−σd) inside: L = ρ/π · I/16 · (1 − F)² exp(−σd) (no internal reflections: shadow
    // rays do not branch).
    let f = fresnel(1.0, ETA);
    let expected =
        SIGMA.map(|s| RHO / PI * INTENSITY / 16.0 * (1.0 - f) * (1.0 - f) * (-s * D).exp());
    let origin = Vec3::new(0.0, 0.5, 4.0);
    let ray = Ray::new(origin, -origin.normalize());
    let scene = slab_scene(", integrator: Whitted", [0.0, 4.0, 0.0], true);
    let (l, se) = estimate_along(&scene, ray, 16);
    assert_close("whitted shadow ray through the slab", l, se, expected);
}

#[test]
fn final_gather_rays_through_an_absorbing_slab_agree_with_the_path_tracer() {
    // A wide absorbing slab (y ∈ [1, 1.4]) separates a grey floor (y = 0) from a white
    // ceiling (y = 3) lit by a 1 × 1 panel at y = 2 that emits upwards only: the floor sees the
    // light only as the ceiling's diffuse radiance through the slab. One diffuse bounce is
    // compared: the path tracer with `diffuse_depth` 1 (the ceiling's light by next-event
    // estimation) and the photon integrator with no photons and 64 final-gather rays (each
    // followed through the slab's glass to the ceiling, whose direct light it reads). The
    // camera ray meets the floor under the slab, so only the gather rays cross it.
    let scene = |integrator: &str, absorption: bool| {
        let absorption = if absorption {
            ", absorption: (0.5, 1.0, 2.0)"
        } else {
            ""
        };
        scene_from_text(&format!(
            r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 32, seed: 5, diffuse_depth: 1{integrator}),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {{
        "floor": (color: ({RHO}, {RHO}, {RHO})),
        "ceiling": (color: (1, 1, 1)),
        "glass": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: {ETA}{absorption}),
    }},
    photons: (global: 0, caustic: 0, final_gather: 64),
    nodes: [
        Quad(material: "floor", size: (40, 40), transform: [RotateX(-90)]),
        Quad(material: "ceiling", size: (40, 40), transform: [RotateX(90), Translate(0, 3, 0)]),
        Cube(material: "glass", transform: [Scale((40, {D}, 40)), Translate(0, 1.2, 0)]),
        Quad(size: (1, 1), emission: (radiance: (20, 20, 20)), transform: [RotateX(-90), Translate(0, 2, 0)]),
    ],
)"#
        ))
    };
    let ray = Ray::new(Vec3::new(0.3, 0.5, 0.2), -Vec3::Y);
    let (path, path_se) = estimate_along(&scene(", integrator: Path", true), ray, 200_000);
    let (gather, gather_se) = estimate_along(&scene(", integrator: Photon", true), ray, 4_000);
    let (clear, clear_se) = estimate_along(&scene(", integrator: Photon", false), ray, 4_000);
    for c in 0..3 {
        let rel = gather[c] / path[c] - 1.0;
        let se = (path_se[c] * path_se[c] + gather_se[c] * gather_se[c]).sqrt();
        eprintln!(
            "final gather through the slab, σ = {}: photon {:.6} ± {:.6}, path {:.6} ± {:.6} \
             ({:+.2} %); clear slab {:.6} ± {:.6} (absorbed/clear {:.4})",
            SIGMA[c],
            gather[c],
            gather_se[c],
            path[c],
            path_se[c],
            100.0 * rel,
            clear[c],
            clear_se[c],
            gather[c] / clear[c]
        );
        assert!(
            (gather[c] - path[c]).abs() < 4.0 * se + 0.01 * path[c],
            "channel {c}: final gather {} ± {} vs path {} ± {} ({rel:+.4})",
            gather[c],
            gather_se[c],
            path[c],
            path_se[c]
        );
        // Absorption is visible: the clear slab's value is far outside the noise.
        assert!(
            clear[c] - gather[c] > 10.0 * se,
            "channel {c}: absorbing {} vs clear {}",
            gather[c],
            clear[c]
        );
    }
}
