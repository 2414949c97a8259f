//! Beer–Lambert absorption in dielectrics against closed forms (issue 26): the transmittance of
//! an absorbing glass slab for camera paths (`path`) and for photons, and the darkening of a
//! pool's floor with depth.

use glam::{DVec3, Vec3};

use caustic::geometry::Ray;
use caustic::integrators::photon::trace::{MapKind, TraceCounts, TraceSettings, trace_photon};
use caustic::render_scene::RenderScene;
use caustic::sampling::Sampler;

use crate::common::scene_from_text;

const PI: f64 = std::f64::consts::PI;

/// Absorption coefficients of the test glass and water, per metre.
const SIGMA: [f64; 3] = [0.5, 1.0, 2.0];

/// Mean and standard error of `n` radiance estimates along `ray` (the renderer's own streams:
/// sample indices 0..n of pixel (0, 0)).
fn estimate(scene: &RenderScene, ray: Ray, n: u32) -> (DVec3, DVec3) {
    crate::common::estimate_along(scene, ray, n)
}

/// Unpolarised Fresnel reflectance of a smooth boundary, cosine `ci` on the side of index 1,
/// index `eta` on the other side.
fn fresnel(ci: f64, eta: f64) -> f64 {
    let st = (1.0 - ci * ci).max(0.0).sqrt() / eta;
    let ct = (1.0 - st * st).sqrt();
    let rs = (ci - eta * ct) / (ci + eta * ct);
    let rp = (ct - eta * ci) / (ct + eta * ci);
    0.5 * (rs * rs + rp * rp)
}

/// Transmittance of a plane-parallel slab of thickness `d`, index `eta`, absorption `sigma`,
/// for light arriving at `theta` (radians) from the normal: every internal path has length
/// d / cos θₜ, keeping τ = exp(−σ d / cos θₜ), and the incoherent sum over internal
/// reflections (each with the same unpolarised F, as the renderer models it) is
/// (1 − F)² τ Σₖ (F τ)²ᵏ = (1 − F)² τ / (1 − F² τ²).
fn slab_transmittance(theta: f64, d: f64, eta: f64, sigma: f64) -> f64 {
    let ci = theta.cos();
    let f = fresnel(ci, eta);
    let ct = (1.0 - (theta.sin() / eta).powi(2)).sqrt();
    let tau = (-sigma * d / ct).exp();
    (1.0 - f) * (1.0 - f) * tau / (1.0 - f * f * tau * tau)
}

/// A slab of absorbing glass (4 × 4 × `D`, centred at the origin, normal ±z) in front of an
/// emitting wall of radiance 1 at z = −2; the background is black, so a camera ray through the
/// slab reads its transmittance.
const SLAB_D: f64 = 0.4;
const SLAB: &str = r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 64, seed: 7, integrator: Path),
    camera: Pinhole(eye: (0, 0, 5), look_at: (0, 0, 0), fov_y: 30),
    materials: {
        "glass": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5, absorption: (0.5, 1.0, 2.0)),
    },
    nodes: [
        Cube(material: "glass", transform: [Scale((4, 4, 0.4))]),
        Quad(size: (40, 40), emission: (radiance: (1, 1, 1)), transform: [Translate(0, 0, -2)]),
    ],
)"#;

#[test]
fn path_traced_absorbing_slab_transmits_exp_minus_sigma_d_times_the_fresnel_terms() {
    let scene = scene_from_text(SLAB);
    for theta_deg in [0.0f64, 40.0] {
        let th = theta_deg.to_radians();
        let dir = Vec3::new(th.sin() as f32, 0.0, -(th.cos() as f32));
        let ray = Ray::new(Vec3::new(0.0, 0.0, 1.0) - 2.0 * dir, dir);
        let (l, se) = estimate(&scene, ray, 40_000);
        for c in 0..3 {
            let expected = slab_transmittance(th, SLAB_D, 1.5, SIGMA[c]);
            let rel = l[c] / expected - 1.0;
            eprintln!(
                "slab θ = {theta_deg}°, σ = {}: path {:.5} ± {:.5}, closed form {expected:.5}",
                SIGMA[c], l[c], se[c]
            );
            assert!(
                rel.abs() < 0.01 && (l[c] - expected).abs() < 4.0 * se[c] + 1e-4,
                "θ = {theta_deg}°, channel {c}: {} ± {} vs exp(−σd)·Fresnel {expected} ({rel:+.4})",
                l[c],
                se[c]
            );
        }
    }
}

#[test]
fn photons_under_an_absorbing_slab_carry_exp_minus_sigma_d_times_the_fresnel_terms() {
    // The slab lies horizontally (normal ±y) over a white floor at y = −1. A uniform vertical
    // beam of irradiance E₀ over the 1 m² square above the slab's centre is traced by the photon
    // tracer (importance mode, Russian roulette at each Fresnel choice); the photons stored on
    // the floor (the caustic map's first diffuse landing) give the mean irradiance under the
    // slab, E₀ · T with T the slab's normal-incidence transmittance.
    let scene = scene_from_text(
        r#"Scene(
    render: (width: 8, height: 8, seed: 5, integrator: Photon),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {
        "white": (color: (1, 1, 1)),
        "glass": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5, absorption: (0.5, 1.0, 2.0)),
    },
    lights: [ Point(position: (0, 3, 0), power: (1, 1, 1)) ],
    nodes: [
        Cube(material: "glass", transform: [Scale((4, 0.4, 4))]),
        Quad(material: "white", size: (4, 4), transform: [RotateX(-90), Translate(0, -1, 0)]),
    ],
)"#,
    );
    let n = 200_000u64;
    let e0 = 2.0f32;
    let power = Vec3::splat(e0 / n as f32); // over 1 m²
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
        let origin = Vec3::new(u - 0.5, 2.0, v - 0.5);
        let ray = Ray::new(origin, -Vec3::Y);
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
    let mut e = DVec3::ZERO;
    for ph in &out {
        let p = ph.position();
        assert!((p.y + 1.0).abs() < 1e-4, "landed off the floor at {p}");
        assert!(p.x.abs() <= 0.5 && p.z.abs() <= 0.5, "moved sideways: {p}");
        e += ph.power().as_dvec3();
    }
    // The photon's flux after the slab is E₀/n · τᵏ-weighted by roulette: the stored photons'
    // count is binomial, so the relative noise is about √((1 − T')/(T' n)), T' ≈ 0.92 the
    // Fresnel-only transmittance: ≈ 7·10⁻⁴.
    // `counts.stored_flux` is the flux before the photon's RGBE packing, `e` after it (the
    // packing truncates the mantissa to 8 bits: a few 10⁻³ low on average).
    let exact_flux = counts.stored_flux.as_dvec3();
    for c in 0..3 {
        let expected = f64::from(e0) * slab_transmittance(0.0, SLAB_D, 1.5, SIGMA[c]);
        let rel = exact_flux[c] / expected - 1.0;
        let rel_packed = e[c] / expected - 1.0;
        eprintln!(
            "slab photons, σ = {}: E = {:.5} (packed {:.5}), closed form {expected:.5} ({rel:+.4}, packed {rel_packed:+.4})",
            SIGMA[c], exact_flux[c], e[c]
        );
        assert!(
            rel.abs() < 0.01 && rel_packed.abs() < 0.01,
            "channel {c}: photon irradiance {} vs E₀·exp(−σd)·Fresnel {expected} ({rel:+.4})",
            e[c]
        );
    }
    assert_eq!(counts.lost_at_depth, 0);
}

/// Irradiance at the floor point `x` at depth `h` under a flat water surface y = 0 (index
/// `eta`, absorption `sigma` per metre) from a sphere light (centre `c`, radius `r`, radiance
/// `l`) above it, by quadrature over underwater directions up to the critical angle: each is
/// followed up to the surface (a length h / cos θ in the water, keeping exp(−σ h / cos θ)),
/// refracted into the air (Snell) and kept if it hits the sphere, weighed by L (1 − F) η²
/// cos θ (radiance grows by η² entering the denser medium).
fn absorbed_underwater_irradiance(
    x: [f64; 2],
    h: f64,
    sphere: ([f64; 3], f64, f64),
    eta: f64,
    sigma: f64,
) -> f64 {
    let (c, r, l) = sphere;
    let (nt, np) = (600, 360);
    let crit = (1.0 / eta).asin();
    let dth = crit / f64::from(nt);
    let dph = 2.0 * PI / f64::from(np);
    let mut e = 0.0;
    for i in 0..nt {
        let th = (f64::from(i) + 0.5) * dth;
        let (st, ct) = th.sin_cos();
        let len = h / ct;
        let keep = (-sigma * len).exp();
        let sa = eta * st;
        let ca = (1.0 - sa * sa).sqrt();
        let ci = ca; // the Fresnel of the crossing, from the air side (reciprocal)
        let fr = fresnel(ci, eta);
        for j in 0..np {
            let ph = (f64::from(j) + 0.5) * dph;
            let (sp, cp) = ph.sin_cos();
            let p = [x[0] + len * st * cp, 0.0, x[1] + len * st * sp];
            let a = [sa * cp, ca, sa * sp];
            let oc = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            let b = oc[0] * a[0] + oc[1] * a[1] + oc[2] * a[2];
            let cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
            if b * b - cc < 0.0 || b > 0.0 {
                continue;
            }
            e += l * (1.0 - fr) * eta * eta * keep * ct * st * dth * dph;
        }
    }
    e
}

fn pool(h: f64, absorption: &str) -> RenderScene {
    scene_from_text(&format!(
        r#"Scene(
    render: (width: 8, height: 8, samples_per_pixel: 1, max_depth: 16, integrator: Path,
             seed: 11, diffuse_depth: 1),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {{
        "floor": (color: (0.8, 0.8, 0.8)),
        "water": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.33{absorption}),
    }},
    lights: [ Sphere(center: (0, 1, 0), radius: 0.3, power: (20, 20, 20)) ],
    nodes: [
        Quad(material: "water", size: (60, 60), transform: [RotateX(-90)]),
        Quad(material: "floor", size: (60, 60), transform: [RotateX(-90), Translate(0, -{h}, 0)]),
    ],
)"#
    ))
}

#[test]
fn a_deep_pools_floor_darkens_as_exp_minus_two_sigma_h_seen_from_above() {
    // A vertical view of the floor at (0.5, −h, 0) through the water surface: the light reaches
    // the floor through h / cos θ of water and the view ray climbs h back, so the floor's
    // radiance is ρ/π · E_σ(h) · exp(−σh) · (1 − F(0))/η² (the camera ray entering the water;
    // its Fresnel reflection goes straight up, clear of the light). E_σ(h) is the quadrature
    // above; E_σ(h)/E_0(h) is exp(−σh) up to the obliquity of the light's cone under water
    // (θ ≤ 13°), so the floor darkens as exp(−2σh) to within the ratios printed.
    let (eta, rho) = (1.33f64, 0.8f64);
    let radiance = 20.0 / (4.0 * PI * PI * 0.09);
    let f0 = fresnel(1.0, eta);
    for h in [0.25f64, 0.5, 1.0] {
        let scene = pool(h, ", absorption: (0.5, 1.0, 2.0)");
        let ray = Ray::new(Vec3::new(0.5, 1.0, 0.0), -Vec3::Y);
        let (l, se) = estimate(&scene, ray, 1_000_000);
        for c in 0..3 {
            let e = absorbed_underwater_irradiance(
                [0.5, 0.0],
                h,
                ([0.0, 1.0, 0.0], 0.3, radiance),
                eta,
                SIGMA[c],
            );
            let e_clear = absorbed_underwater_irradiance(
                [0.5, 0.0],
                h,
                ([0.0, 1.0, 0.0], 0.3, radiance),
                eta,
                0.0,
            );
            let view = (-SIGMA[c] * h).exp();
            let expected = rho / PI * e * view * (1.0 - f0) / (eta * eta);
            let darkening = e / e_clear * view;
            eprintln!(
                "h = {h}, σ = {}: L = {:.5} ± {:.5}, closed form {expected:.5}; L/L_clear = {darkening:.4}, exp(−2σh) = {:.4}",
                SIGMA[c],
                l[c],
                se[c],
                (-2.0 * SIGMA[c] * h).exp()
            );
            assert!(
                (l[c] - expected).abs() < 4.0 * se[c] + 2e-3 * expected,
                "h = {h}, channel {c}: {} ± {} vs {expected}",
                l[c],
                se[c]
            );
            // The obliquity correction is small: within 4 % of exp(−2σh) in the exponent.
            let ratio = darkening.ln() / (-2.0 * SIGMA[c] * h);
            assert!((ratio - 1.0).abs() < 0.04, "h = {h}, channel {c}: {ratio}");
        }
    }
}
