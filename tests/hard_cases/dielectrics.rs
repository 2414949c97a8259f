//! Dielectrics at the ray level: total internal reflection in an air bubble, grazing incidence,
//! and the index-matched case.

use caustic::geometry::Ray;
use caustic::geometry::offset::offset_ray_origin;
use caustic::shading::Material;
use glam::Vec3;

use super::support::scene;

/// Parallel rays at a sphere of relative index `ior`; returns the fraction of disc hits whose
/// Fresnel reflectance is total (no refracted ray).
fn tir_fraction(ior: f32) -> f64 {
    let s = scene(&format!(
        "Scene(camera: Pinhole(eye: (0, 0, 5), look_at: (0, 0, 0), fov_y: 30),
          materials: {{ \"b\": (transmit: 1, ior: {ior}) }}, lights: [Point(position: (0, 5, 0), power: (1, 1, 1))],
          nodes: [Sphere(material: \"b\")])"
    ));
    let m: &Material = &s.materials[0].bsdf;
    let n = 400;
    let (mut disc, mut tir) = (0u32, 0u32);
    for i in 0..n {
        for j in 0..n {
            let x = -1.0 + 2.0 * (i as f32 + 0.5) / n as f32;
            let y = -1.0 + 2.0 * (j as f32 + 0.5) / n as f32;
            let ray = Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
            let Some(h) = s.geometry.intersect(&ray) else {
                continue;
            };
            disc += 1;
            let sp = s.geometry.surface(&ray, &h);
            let lobes = m.delta_lobes(-ray.dir, sp.ns, sp.ng, true);
            if lobes.refract.is_none() {
                tir += 1;
            }
        }
    }
    f64::from(tir) / f64::from(disc)
}

#[test]
fn air_bubble_in_water_reflects_totally_on_the_analytic_ring() {
    // From water into air (relative index 1/1.33): TIR for impact parameter b > R/1.33.
    let f = tir_fraction(1.0 / 1.33);
    let expected = 1.0 - 1.0 / (1.33f64 * 1.33);
    assert!(
        (f - expected).abs() < 0.01,
        "TIR fraction {f:.4}, expected {expected:.4}"
    );
    let g = tir_fraction(1.0 / 1.5);
    assert!((g - (1.0 - 1.0 / 2.25)).abs() < 0.01, "glass: {g:.4}");
    // No TIR entering a denser medium.
    assert_eq!(tir_fraction(1.5), 0.0);
}

#[test]
fn grazing_and_index_matched_incidence_stay_finite() {
    let glass = Material::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.5);
    let air = Material::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.0);
    let n = Vec3::Y;
    for cos in [0.0f32, 1e-30, 1e-8, 1e-4, 0.5, 1.0] {
        let wo = Vec3::new((1.0 - cos * cos).max(0.0).sqrt(), cos, 0.0).normalize();
        for entering in [true, false] {
            let l = glass.delta_lobes(wo, n, n, entering);
            assert!(
                l.reflect_dir.is_finite() && l.reflect_weight.is_finite(),
                "cos {cos}"
            );
            assert!(l.reflect_weight.x <= 1.0 + 1e-6);
            if let Some((d, w)) = l.refract {
                assert!(d.is_finite() && w.is_finite() && d.dot(n) < 0.0);
                assert!(
                    (l.reflect_weight.x + w.x - 1.0).abs() < 1e-5,
                    "energy split at cos {cos}"
                );
            }
        }
        // Index 1: no reflection, straight through (at cos = 0 exactly, "through" and "reflected"
        // are the same tangent direction, and the energy is counted as reflected).
        let l = air.delta_lobes(wo, n, n, true);
        if cos > 0.0 {
            assert_eq!(l.reflect_weight, Vec3::ZERO, "cos {cos}");
            let (d, w) = l.refract.expect("passes");
            assert!(
                d.distance(-wo) < 1e-5 && w == Vec3::ONE,
                "cos {cos}: {d} {w}"
            );
        }
    }
}

#[test]
fn camera_inside_a_glass_sphere_sees_out() {
    // Rays start inside: they must exit (refract or reflect internally) and never go NaN.
    let s = scene(
        "Scene(render: (width: 24, height: 24, samples_per_pixel: 1, max_depth: 6),
           camera: Pinhole(eye: (0, 0, 0), look_at: (0, 0, -1), fov_y: 90),
           materials: { \"glass\": (transmit: 1, ior: 1.5), \"wall\": (color: (0.8, 0.8, 0.8)) },
           lights: [Point(position: (0, 0, 1.5), power: (100, 100, 100))],
           nodes: [Sphere(material: \"glass\", radius: 1),
                   Quad(material: \"wall\", size: (20, 20), transform: [Translate(0, 0, -5)])])",
    );
    let out = caustic::render::render(&s, &Default::default()).expect("renders");
    assert_eq!(out.stats.nan_samples, 0);
    assert!(
        out.film.mean().max_element() > 0.0,
        "the wall is seen through the glass"
    );
    // The centre pixel's camera ray leaves the sphere from inside along the axis.
    let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
    let h = s.geometry.intersect(&ray).expect("inside hit");
    let sp = s.geometry.surface(&ray, &h);
    assert!(
        (h.t - 1.0).abs() < 1e-5 && sp.ng.dot(ray.dir) > 0.0,
        "hit from inside: {}",
        h.t
    );
    let o = offset_ray_origin(sp.p, sp.p_error, -sp.ng, -Vec3::Z);
    assert!(o.z < -1.0, "exit point pushed outside: {o}");
}
