//! Issue 47's transport and film kinds against closed forms: `diffuse_depth: 0` is Whitted's
//! transport behind a clear pane (depth0-behind-glass), a photon path's bounce cap neither
//! biases an integrating sphere by default nor hides what it cuts (photon-bounce-cap), and a
//! radiance far beyond the film's 128-bit fixed-point range keeps its value in the mean and the
//! variance (exr-huge-radiance).

use caustic::integrators::photon::{PhotonSummary, build_maps};
use caustic::render::{RenderOptions, render};

use crate::common::scene_from_text;

/// `../shared/cases/reported/depth0-behind-glass/pane.ron` at 64 samples: a 1 × 1 panel of
/// radiance 1 facing down at y = 1 over a floor of albedo 0.5, a clear pane of `ior` IOR
/// between them (y = 0.49 to 0.51, 60 wide), the camera looking at the floor under the panel.
fn pane(integrator: &str, ior: f32) -> String {
    format!(
        r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 64, max_depth: 16, diffuse_depth: 0, integrator: {integrator}),
    camera: Pinhole(eye: (0, 0.3, 0.36), look_at: (0, 0, 0), fov_y: 1),
    materials: {{
        "grey": (color: (0.5, 0.5, 0.5)),
        "pane": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: {ior}),
    }},
    lights: [],
    nodes: [
        Quad(material: "grey", size: (8, 8), transform: [RotateX(-90)]),
        Cube(name: "pane", material: "pane", transform: [Scale((60, 0.02, 60)), Translate(0, 0.5, 0)]),
        Quad(name: "panel", size: (1, 1), emission: (radiance: (1, 1, 1)), transform: [RotateX(90), Translate(0, 1, 0)]),
    ],
)"#
    )
}

#[test]
fn diffuse_depth_zero_is_whitteds_transport_behind_a_clear_pane() {
    // Floor radiance under the panel's centre without the pane: L = ρ F, with F the form factor
    // from a point 1 below the centre of a 1 × 1 square (four corner rectangles of a = b = ½:
    // F = (2/π) · 2 · a/√(1 + a²) · atan(a/√(1 + a²))) = 0.119728.
    let a: f64 = 0.5;
    let s = (1.0 + a * a).sqrt();
    let form = 2.0 / std::f64::consts::PI * 2.0 * (a / s * (a / s).atan());
    let exact = 0.5 * form;
    assert!((exact - 0.119728).abs() < 1e-5, "{exact}");
    for ior in [1.0, 1.5] {
        let film = |integrator: &str| {
            render(
                &scene_from_text(&pane(integrator, ior)),
                &RenderOptions::default(),
            )
            .expect("renders")
            .film
        };
        let (path, whitted) = (film("Path"), film("Whitted"));
        // Pixel for pixel: the same camera rays and shadow rays; the panel's points are drawn
        // from other sample dimensions (the path tracer reserves one for choosing a light),
        // so the pixels differ by noise (< 10⁻⁴ relative at 64 samples; 10⁻⁵ at 4096).
        for (i, (p, w)) in path.pixels.iter().zip(&whitted.pixels).enumerate() {
            assert!(
                (*p - *w).abs().max_element() <= 1e-3 * w.max_element().max(1e-3),
                "ior {ior}, pixel {i}: path {p} vs whitted {w}"
            );
        }
        let mean = f64::from(path.mean().x);
        eprintln!("ior {ior}: floor {mean:.6} (no pane: {exact:.6})");
        if ior == 1.0 {
            // Index-matched: the pane is invisible, shadow included.
            assert!((mean / exact - 1.0).abs() < 0.002, "{mean} vs {exact}");
        } else {
            // Whitted's straight shadow ray keeps (1 − F)² at each direction's incidence: less
            // than without the pane, more than (1 − F(0))² = 0.9216 of it.
            assert!(mean < exact && mean > 0.9 * exact, "{mean}");
        }
    }
}

/// `../shared/cases/reported/photon-bounce-cap/scene.ron`: a point light of Φ = 4π W at the
/// centre of a closed diffuse sphere of albedo 0.8.
fn integrating_sphere(photons: &str) -> String {
    format!(
        r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 4, seed: 1, integrator: Photon),
    camera: Pinhole(eye: (0, 0, 0), look_at: (0, 0, -1), up: (0, 1, 0), fov_y: 90),
    materials: {{ "wall": (color: (0.8, 0.8, 0.8)) }},
    photons: (global: 200000, caustic: 0{photons}),
    lights: [ Point(position: (0, 0, 0), power: (12.566371, 12.566371, 12.566371)) ],
    nodes: [ Sphere(name: "integrating sphere", material: "wall", center: (0, 0, 0), radius: 1) ],
)"#
    )
}

#[test]
fn the_default_photon_bounce_cap_does_not_darken_an_integrating_sphere() {
    // Photons survive each bounce with probability ρ = 0.8 at equal flux (Russian roulette);
    // with `min_bounces` 1 the global map stores landings 2, 3, …: Φ (ρ + ρ² + …) = 4 Φ. The old
    // default cap of 16 bounces kept Φ Σ₁¹⁶ ρᵏ = 4 Φ (1 − ρ¹⁶): −2.8 % of the stored flux, which
    // read the sphere's wall 1.7 % dark.
    let phi = 4.0 * std::f64::consts::PI;
    let maps = build_maps(&scene_from_text(&integrating_sphere("")));
    let t = PhotonSummary::total(&maps.summary.global);
    let stored = f64::from(t.stored_flux.x);
    eprintln!(
        "default cap: stored {stored:.4} W of 4 Φ = {:.4} W",
        4.0 * phi
    );
    // σ of the stored flux with 2·10⁵ photons ≈ 0.25 %.
    assert!((stored / (4.0 * phi) - 1.0).abs() < 0.0075, "{stored}");
    assert_eq!(t.lost_at_depth, 0, "no path reaches the default cap");
}

#[test]
fn a_photon_bounce_cap_reports_the_flux_it_takes_from_the_map() {
    // With the cap at 16 the map misses 4 Φ ρ¹⁶ (the landings after the 17th). The summary
    // reports what the cut paths would have stored (traced on without storing for another 16
    // bounces: 4 Φ (ρ¹⁶ − ρ³²)), not the flux they carried when cut (Φ ρ¹⁶, four times less).
    let phi = 4.0 * std::f64::consts::PI;
    let rho: f64 = 0.8;
    let maps = build_maps(&scene_from_text(&integrating_sphere(", max_bounces: 16")));
    let t = PhotonSummary::total(&maps.summary.global);
    let (stored, lost) = (f64::from(t.stored_flux.x), f64::from(t.lost_flux.x));
    let kept = 4.0 * phi * (1.0 - rho.powi(16));
    let cut = 4.0 * phi * (rho.powi(16) - rho.powi(32));
    eprintln!(
        "cap 16: stored {stored:.4} W (exact {kept:.4}), reported cut {lost:.4} W (exact {cut:.4})"
    );
    assert!((stored / kept - 1.0).abs() < 0.0075, "{stored} vs {kept}");
    assert!((lost / cut - 1.0).abs() < 0.05, "{lost} vs {cut}");
    // The photons still alive after the cap's 16 bounces from their first landing: 2·10⁵ ρ¹⁷
    // ≈ 4504 (binomial, σ ≈ 67).
    let alive = 200_000.0 * rho.powi(17);
    assert!(
        (t.lost_at_depth as f64 - alive).abs() < 4.0 * alive.sqrt(),
        "{} cut",
        t.lost_at_depth
    );
    let text = maps.summary.to_string();
    assert!(text.contains("would have stored"), "{text}");
}

/// `../shared/cases/reported/exr-huge-radiance/huge.ron`: a panel of radiance 1e30 beside one
/// of 0.5, seen directly.
const HUGE: &str = r#"Scene(
    render: (width: 32, height: 16, samples_per_pixel: 256, max_depth: 4, integrator: Path),
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 14.25),
    materials: { "grey": (color: (0.5, 0.5, 0.5)) },
    lights: [],
    nodes: [
        Quad(name: "huge", size: (2, 1), emission: (radiance: (1e30, 1e30, 1e30)), transform: [Translate(-1, 0, 0)]),
        Quad(name: "dim", size: (2, 1), emission: (radiance: (0.5, 0.5, 0.5)), transform: [Translate(1, 0, 0)]),
        Quad(name: "floor", material: "grey", size: (8, 8), transform: [RotateX(-90), Translate(0, -0.5, 0)]),
    ],
)"#;

#[test]
fn a_radiance_beyond_the_fixed_point_range_keeps_its_value_and_variance() {
    let scene = scene_from_text(HUGE);
    let one = RenderOptions {
        threads: Some(1),
        ..RenderOptions::default()
    };
    let result = render(&scene, &one).expect("renders");
    let sums = &result.sums;
    let (w, i) = (result.film.width as usize, |x: usize, y: usize| y * 32 + x);
    assert_eq!(w, 32);
    // Pixel (8, 8) sees the huge panel wholly: every sample is 1e30 (as f32), so the mean is
    // that value and the sample variance 0 (before: 9.2e18 × 2⁶⁴ / 256 = 3.6e16).
    let huge = f64::from(1e30f32);
    let m = sums.mean(i(8, 8));
    assert!(
        (f64::from(m.x) / huge - 1.0).abs() < 1e-6,
        "mean {m} (expected {huge:e})"
    );
    assert_eq!(sums.variance(i(8, 8)).x, 0.0);
    // The dim panel's pixel is untouched: 0.5 exactly.
    assert_eq!(sums.mean(i(24, 8)).x, 0.5);
    // The same bytes for any thread count (the wide sums are exact integers too).
    let four = RenderOptions {
        threads: Some(4),
        ..RenderOptions::default()
    };
    let other = render(&scene, &four).expect("renders");
    assert_eq!(other.film.to_bytes(), result.film.to_bytes());
    assert_eq!(&other.sums, sums);
}
