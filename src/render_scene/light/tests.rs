//! Light sampling checked against closed forms (inverse square, the irradiance of a sphere,
//! photon flux = Φ) and against its own densities (χ² goodness of fit, pdfs integrating to 1).

use super::*;
use crate::sampling::Rng;

/// Corners and interior points of the unit square, including the largest `f32` below 1.
const UNIFORMS: [f32; 5] = [0.0, 0.25, 0.5, 0.999, 1.0 - f32::EPSILON / 2.0];

#[test]
fn point_light_follows_inverse_square() {
    let l = Light::point(Vec3::new(0.0, 2.0, 0.0), Vec3::splat(4.0 * PI));
    let s = l.sample_li(Vec3::ZERO, (0.5, 0.5)).unwrap();
    assert!((s.radiance.x - 0.25).abs() < 1e-6);
    assert_eq!(s.weight, s.radiance);
    assert!(s.delta && l.is_delta() && s.pdf == 1.0);
    assert!(s.wi.distance(Vec3::Y) < 1e-6);
    assert!((s.distance - 2.0).abs() < 1e-6);
    assert_eq!(l.pdf_li(Vec3::ZERO, Vec3::Y), 0.0);
    assert!(l.sample_li(Vec3::new(0.0, 2.0, 0.0), (0.5, 0.5)).is_none());
}

#[test]
fn sphere_light_irradiance_matches_a_point_light_far_away() {
    // E at distance D from a sphere of power Φ equals Φ/(4πD²) exactly, for a receiver facing
    // the centre (the sphere's irradiance is π L sin²θmax = π L r²/D², and Φ = 4π² r² L).
    let power = Vec3::splat(100.0);
    let l = Light::sphere(Vec3::new(0.0, 10.0, 0.0), 0.5, power);
    let mut r = Rng::new(0, 0);
    let n = 200_000;
    let mut e = 0.0f64;
    for _ in 0..n {
        let s = l.sample_li(Vec3::ZERO, r.next_2d()).unwrap();
        e += f64::from(s.weight.x * s.wi.y.max(0.0));
    }
    let e = e / f64::from(n);
    let expected = 100.0 / (4.0 * std::f64::consts::PI * 100.0);
    assert!((e / expected - 1.0).abs() < 0.005, "{e} vs {expected}");
    assert!((l.power() - power).abs().max_element() < 1e-3);
}

#[test]
fn sphere_light_irradiance_up_close_is_pi_l_sin2() {
    // Receiver 0.5 above a unit sphere, facing it: E = π L (r/D)² with D = 1.5. The cosine
    // varies over the cap (cos θmax = √5/3), so this checks the cone's distribution, not just
    // its solid angle.
    let l = Light::Sphere {
        center: Vec3::new(0.0, 1.5, 0.0),
        radius: 1.0,
        radiance: Vec3::ONE,
    };
    let mut r = Rng::new(4, 2);
    let n = 200_000;
    let mut e = 0.0f64;
    for _ in 0..n {
        let s = l.sample_li(Vec3::ZERO, r.next_2d()).unwrap();
        e += f64::from(s.weight.x * s.wi.y.max(0.0));
    }
    let e = e / f64::from(n);
    let expected = std::f64::consts::PI / 2.25;
    assert!((e / expected - 1.0).abs() < 0.002, "{e} vs {expected}");
}

/// Sphere lights seen from near, far, grazing-close, tiny and huge: (centre, radius, point).
fn sphere_cases() -> Vec<(Vec3, f32, Vec3)> {
    vec![
        (Vec3::new(0.0, 3.0, 0.0), 1.0, Vec3::ZERO),
        (Vec3::new(1.0, 2.0, -3.0), 0.25, Vec3::new(0.5, -1.0, 2.0)),
        (Vec3::new(0.0, 0.0, 1000.0), 0.5, Vec3::ZERO),
        (Vec3::new(0.0, 1.0 + 1e-4, 0.0), 1.0, Vec3::ZERO),
        (Vec3::new(1e4, 0.0, 0.0), 1e-4, Vec3::ZERO),
        (Vec3::new(0.0, -1e4 - 1.0, 0.0), 1e4, Vec3::ZERO),
        (Vec3::new(3.0, 4.0, 5.0), 1e-3, Vec3::new(3.0, 4.0, 5.002)),
    ]
}

#[test]
fn sphere_samples_land_on_the_near_side_with_consistent_densities() {
    for (center, radius, p) in sphere_cases() {
        let l = Light::sphere(center, radius, Vec3::new(1.0, 2.0, 3.0));
        let Light::Sphere { radiance, .. } = l else {
            unreachable!()
        };
        for &a in &UNIFORMS {
            for &b in &UNIFORMS {
                let s = l.sample_li(p, (a, b)).expect("outside the sphere");
                let ctx = format!("{center} r={radius} p={p} u=({a},{b}): {s:?}");
                assert!((s.wi.length() - 1.0).abs() < 1e-5, "{ctx}");
                assert!(!s.delta && s.pdf.is_finite() && s.pdf > 0.0, "{ctx}");
                assert!(s.weight.is_finite() && s.radiance == radiance, "{ctx}");
                assert!((s.weight * s.pdf / radiance - 1.0).abs().max_element() < 1e-4);
                // The density sample_li used is the one pdf_li reports for that direction.
                let pdf = l.pdf_li(p, s.wi);
                assert!((pdf / s.pdf - 1.0).abs() < 1e-4, "{ctx}: pdf_li {pdf}");
                // The point is on the sphere, on the side facing p, at `distance` along wi.
                let scale = radius + (center - p).length() + center.length();
                let on = (s.point - center).length() - radius;
                assert!(on.abs() < 2e-6 * scale, "{ctx}: off the sphere by {on}");
                let n = (s.point - center) / radius;
                assert!(n.dot(s.wi) < 2e-3, "{ctx}: far side");
                assert!((s.point - p).length() - s.distance < 1e-5 * scale, "{ctx}");
            }
        }
    }
}

#[test]
fn degenerate_spheres_give_none_never_nan() {
    let inside = Light::sphere(Vec3::ZERO, 1.0, Vec3::ONE);
    assert!(
        inside
            .sample_li(Vec3::new(0.0, 0.5, 0.0), (0.3, 0.3))
            .is_none()
    );
    assert!(
        inside
            .sample_li(Vec3::new(0.0, 1.0, 0.0), (0.3, 0.3))
            .is_none()
    );
    assert_eq!(inside.pdf_li(Vec3::new(0.0, 0.5, 0.0), Vec3::Y), 0.0);
    // Cones too small for f32 (the density would overflow) are skipped, not NaN.
    let specks = [
        Light::sphere(Vec3::new(0.0, 1e20, 0.0), 1.0, Vec3::ONE),
        Light::sphere(Vec3::new(0.0, 1.0, 0.0), 1e-30, Vec3::ONE),
        Light::sphere(Vec3::new(0.0, f32::MAX, 0.0), 1.0, Vec3::ONE),
    ];
    for l in specks {
        for &a in &UNIFORMS {
            if let Some(s) = l.sample_li(Vec3::ZERO, (a, a)) {
                assert!(s.weight.is_finite() && s.pdf.is_finite() && s.point.is_finite());
            }
            assert!(l.pdf_li(Vec3::ZERO, Vec3::Y).is_finite());
        }
    }
    let black = Light::sphere(Vec3::new(0.0, 3.0, 0.0), 1.0, Vec3::ZERO);
    assert!(black.sample_li(Vec3::ZERO, (0.5, 0.5)).is_none());
    assert!(black.sample_le((0.5, 0.5), (0.5, 0.5)).is_none());
}

#[test]
fn pdf_li_is_zero_outside_the_cone() {
    let l = Light::sphere(Vec3::new(0.0, 2.0, 0.0), 1.0, Vec3::ONE);
    // sin θmax = 1/2: θmax = 30°.
    let at = |deg: f32| {
        let t = deg.to_radians();
        l.pdf_li(Vec3::ZERO, Vec3::new(t.sin(), t.cos(), 0.0))
    };
    let inside = 1.0 / (TAU * (1.0 - 3f32.sqrt() / 2.0));
    assert!((at(0.0) / inside - 1.0).abs() < 1e-5);
    assert!((at(29.9) / inside - 1.0).abs() < 1e-5);
    assert_eq!(at(30.1), 0.0);
    assert_eq!(at(150.0), 0.0);
    assert_eq!(l.pdf_li(Vec3::ZERO, -Vec3::Y), 0.0);
}

#[test]
fn emission_samples_carry_exactly_the_light_power() {
    let power = Vec3::new(10.0, 20.0, 30.0);
    let lights = [
        Light::sphere(Vec3::new(1.0, 2.0, 3.0), 0.5, power),
        Light::point(Vec3::new(-1.0, 0.0, 2.0), power),
    ];
    let mut r = Rng::new(8, 1);
    for l in &lights {
        let mut dir_sum = Vec3::ZERO;
        for _ in 0..10_000 {
            let s = l.sample_le(r.next_2d(), r.next_2d()).unwrap();
            assert!((s.dir.length() - 1.0).abs() < 1e-5);
            let (pdf_pos, pdf_dir) = l.pdf_le(s.normal, s.dir);
            assert!((pdf_pos / s.pdf_pos - 1.0).abs() < 1e-6);
            assert!((pdf_dir / s.pdf_dir - 1.0).abs() < 1e-4);
            let flux = match l {
                Light::Point { position, .. } => {
                    let position = *position;
                    assert_eq!(s.origin, position);
                    assert_eq!(s.normal, Vec3::ZERO);
                    s.le / (s.pdf_pos * s.pdf_dir)
                }
                Light::Sphere { center, radius, .. } => {
                    let (center, radius) = (*center, *radius);
                    assert!(((s.origin - center).length() - radius).abs() < 1e-5);
                    assert!(s.normal.distance((s.origin - center) / radius) < 1e-5);
                    let cos = s.dir.dot(s.normal);
                    assert!(cos > 0.0);
                    assert_eq!(l.le(s.normal, s.dir), s.le);
                    assert_eq!(l.le(s.normal, -s.dir), Vec3::ZERO);
                    s.le * cos / (s.pdf_pos * s.pdf_dir)
                }
                other => panic!("not a case of this test: {other:?}"),
            };
            assert!((flux / power - 1.0).abs().max_element() < 1e-4, "{flux}");
            dir_sum += s.dir;
        }
        // Both emit isotropically overall: the mean direction is near zero (σ ≈ 0.006).
        assert!(dir_sum.length() / 10_000.0 < 0.03, "{dir_sum}");
    }
}

/// Sphere lights for the χ² tests: (label, centre, radius, shading point).
fn chi2_cases() -> [(&'static str, Vec3, f32, Vec3); 4] {
    [
        ("near", Vec3::new(0.2, 1.5, -0.3), 1.0, Vec3::ZERO),
        // Seen from 0.1% of its radius above the surface: a cone of half-angle 87.4°, whose
        // rim directions graze the sphere.
        ("grazing", Vec3::new(0.0, 0.0, 2.002), 2.0, Vec3::ZERO),
        ("far", Vec3::new(600.0, -800.0, 0.0), 1.0, Vec3::ZERO),
        // 1 − cos θmax = 5e-9: rounds to 0 in f32 as cos θmax.
        (
            "tiny",
            Vec3::new(1.0, 2.0, 10.0),
            1e-3,
            Vec3::new(1.0, 2.0, 0.0),
        ),
    ]
}

/// `1 − cos θmax` of the cone in f64, for sizing the histogram's cap.
fn cone_extent(center: Vec3, radius: f32, p: Vec3) -> f64 {
    let sin2 = f64::from(radius).powi(2) / (center - p).as_dvec3().length_squared();
    sin2 / (1.0 + (1.0 - sin2).sqrt())
}

#[test]
fn sphere_cone_sampling_passes_chi2_against_pdf_li() {
    use crate::sampling::chi2::{SphereBins, chi2_test, sidak_alpha};
    let alpha = sidak_alpha(0.01, chi2_cases().len());
    for (i, (label, center, radius, p)) in chi2_cases().into_iter().enumerate() {
        let l = Light::sphere(center, radius, Vec3::ONE);
        let axis = (center - p).normalize();
        // The cap spans 1.25× the cone, so the rim and the empty band past it are binned too.
        let bins = SphereBins::cap(axis, 16, 32, 1.25 * cone_extent(center, radius, p));
        let r = chi2_test(
            200_000,
            i as u64,
            &bins,
            |rng| l.sample_li(p, rng.next_2d()).map(|s| s.wi),
            |w| l.pdf_li(p, w),
        );
        eprintln!("sample_li χ² {label}: {r:?}");
        assert!(r.passes(alpha) && r.rejected == 0, "{label}: {r:?}");
        assert!(r.dof > 300, "{label}: {r:?}");
    }
}

#[test]
fn pdf_li_integrates_to_one() {
    use crate::sampling::chi2::{SphereBins, integrate, integrate_sphere};
    for (label, center, radius, p) in chi2_cases() {
        let l = Light::sphere(center, radius, Vec3::ONE);
        let axis = (center - p).normalize();
        let extent = cone_extent(center, radius, p);
        let cap = integrate(&SphereBins::cap(axis, 16, 32, 1.25 * extent), |w| {
            l.pdf_li(p, w)
        });
        // The rim test's slack adds a band of relative mass ~2 · RIM_SLACK · D/r.
        let slack = 2.2 * f64::from(RIM_SLACK * (center - p).length() / radius) + 2e-5;
        eprintln!("∫ pdf_li over the cap, {label}: {cap} (slack {slack:.1e})");
        assert!((cap - 1.0).abs() < 1e-4 + slack, "{label}: {cap}");
        if extent > 1e-3 {
            // Wide cones: the whole sphere too (narrow ones fit inside one cell of it).
            let all = integrate_sphere(axis, |w| l.pdf_li(p, w));
            assert!((all - 1.0).abs() < 1e-4 + slack, "{label}: {all}");
        }
    }
}

#[test]
fn emission_directions_and_positions_pass_chi2() {
    use crate::sampling::chi2::{SphereBins, chi2_test, sidak_alpha};
    let alpha = sidak_alpha(0.01, 3);
    let sphere = Light::sphere(Vec3::new(1.0, -2.0, 0.5), 0.7, Vec3::ONE);
    let point = Light::point(Vec3::new(1.0, -2.0, 0.5), Vec3::ONE);
    let bins = SphereBins::sphere(Vec3::Z, 20, 40);
    let sample = |l: Light| {
        move |rng: &mut Rng| {
            let (a, b) = (rng.next_2d(), rng.next_2d());
            l.sample_le(a, b)
        }
    };
    // Sphere: directions about their own normal are cosine-distributed...
    let le = sample(sphere.clone());
    let local = chi2_test(
        200_000,
        1,
        &bins,
        |rng| le(rng).map(|s| Frame::from_normal(s.normal).to_local(s.dir)),
        |w| w.z.max(0.0) / PI,
    );
    // ...and the points (normals) are uniform over the sphere.
    let le = sample(sphere.clone());
    let normals = chi2_test(
        200_000,
        2,
        &bins,
        |rng| le(rng).map(|s| s.normal),
        |_| 1.0 / (4.0 * PI),
    );
    // Point: uniform directions.
    let le = sample(point.clone());
    let points = chi2_test(
        200_000,
        3,
        &bins,
        |rng| le(rng).map(|s| s.dir),
        |w| point.pdf_le(Vec3::ZERO, w).1,
    );
    for (label, r) in [
        ("sphere dir", local),
        ("sphere pos", normals),
        ("point dir", points),
    ] {
        eprintln!("sample_le χ² {label}: {r:?}");
        assert!(r.passes(alpha) && r.rejected == 0, "{label}: {r:?}");
    }
}

#[test]
fn a_point_light_on_the_surface_gives_no_light_rather_than_infinity() {
    // Power at the validation limit (1e30 W), the point 1e-20 away: intensity/d² overflows f32.
    let l = Light::point(Vec3::new(0.0, 1e-20, 0.0), Vec3::splat(1e30));
    assert!(l.sample_li(Vec3::ZERO, (0.5, 0.5)).is_none());
    // A little further it is finite and exact.
    let s = l.sample_li(Vec3::new(0.0, -1.0, 0.0), (0.5, 0.5)).unwrap();
    assert!(s.radiance.is_finite());
    assert!((s.radiance.x / (1e30 / (4.0 * std::f32::consts::PI)) - 1.0).abs() < 1e-5);
}
