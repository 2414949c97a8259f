//! The rectangle light against Lambert's polygon formula and its own densities (χ²).

use super::*;
use crate::render_scene::light::test_support::{
    cap_around, lambert_polygon_irradiance, local, stratified,
};
use crate::sampling::Rng;
use crate::sampling::chi2::{SphereBins, chi2_test, pearson, sidak_alpha};
use std::f32::consts::PI;

/// A 2 × 1 rectangle in the plane y = 2, facing down, radiance (1, 2, 3).
fn ceiling(two_sided: bool) -> RectLight {
    RectLight::new(
        Vec3::new(-1.0, 2.0, -0.5),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 2.0, 3.0),
        two_sided,
    )
    .expect("a rectangle")
}

fn corners(l: &RectLight) -> [Vec3; 4] {
    [
        l.corner,
        l.corner + l.edge_u,
        l.corner + l.edge_u + l.edge_v,
        l.corner + l.edge_v,
    ]
}

/// E at `p` (normal `n`) estimated with `k²` stratified NEE samples.
fn nee_irradiance(l: &RectLight, p: Vec3, n: Vec3, k: usize, seed: u64) -> f64 {
    let mut rng = Rng::new(seed, 0);
    let sum: f64 = stratified(k, &mut rng)
        .map(|u| {
            l.sample_li(p, u).map_or(0.0, |s| {
                f64::from(s.weight.x) * f64::from(s.wi.dot(n).max(0.0))
            })
        })
        .sum();
    sum / (k * k) as f64
}

#[test]
fn irradiance_matches_lamberts_polygon_formula() {
    let l = ceiling(false);
    assert!((l.normal - Vec3::NEG_Y).length() < 1e-6);
    // (point, receiver normal, which strategy): near points use spherical rectangles, the far
    // one (Ω ≈ 2e-5 sr) area sampling.
    let cases = [
        (Vec3::ZERO, Vec3::Y, true),
        (Vec3::new(0.7, 1.2, 0.3), Vec3::Y, true),
        (
            Vec3::new(-2.0, 0.5, 1.0),
            Vec3::new(0.3, 1.0, -0.2).normalize(),
            true,
        ),
        (Vec3::new(0.2, 1.95, 0.1), Vec3::Y, true),
        (
            Vec3::new(30.0, -300.0, 20.0),
            Vec3::new(-0.1, 1.0, -0.05).normalize(),
            false,
        ),
    ];
    for (i, (p, n, spherical)) in cases.into_iter().enumerate() {
        assert_eq!(l.spherical(p).is_some(), spherical, "case {i}");
        let want = lambert_polygon_irradiance(p, n, &corners(&l), 1.0);
        let got = nee_irradiance(&l, p, n, 1024, i as u64);
        let rel = got / want - 1.0;
        eprintln!(
            "rect E case {i} (spherical {spherical}): NEE {got:.6e} Lambert {want:.6e} rel {rel:.2e}"
        );
        assert!(rel.abs() < 1e-3, "case {i}: {got} vs {want}");
    }
}

#[test]
fn spherical_samples_land_on_the_rectangle_with_the_density_pdf_li_reports() {
    let l = ceiling(true);
    let mut rng = Rng::new(1, 1);
    for p in [
        Vec3::ZERO,
        Vec3::new(0.3, 2.5, 0.2),
        Vec3::new(3.0, 1.99, 0.0),
    ] {
        let s = l.spherical(p).expect("spherical");
        for _ in 0..2000 {
            let smp = l.sample_li(p, rng.next_2d()).expect("lit");
            assert!((smp.point.y - 2.0).abs() < 1e-5, "{smp:?}");
            assert!(smp.point.x >= -1.0 - 1e-5 && smp.point.x <= 1.0 + 1e-5);
            assert!(smp.point.z >= -0.5 - 1e-5 && smp.point.z <= 0.5 + 1e-5);
            assert!((smp.pdf as f64 * s.solid_angle - 1.0).abs() < 1e-5);
            let pdf = l.pdf_li(p, smp.wi);
            assert!((pdf / smp.pdf - 1.0).abs() < 1e-5, "{pdf} vs {smp:?}");
        }
    }
    // The solid angle of a 2b × 2c rectangle seen from height h on its axis (a closed form):
    // Ω = 4 asin(b c / √((b² + h²)(c² + h²))).
    let sq = RectLight::new(
        Vec3::new(-1.0, 1.0, -0.5),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::ONE,
        false,
    )
    .unwrap();
    let (b, c, h) = (1.0f64, 0.5f64, 1.0f64);
    let want = 4.0 * (b * c / ((b * b + h * h) * (c * c + h * h)).sqrt()).asin();
    let got = sq.spherical(Vec3::ZERO).unwrap().solid_angle;
    assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
}

#[test]
fn one_sided_lights_are_dark_behind() {
    let l = ceiling(false);
    let above = Vec3::new(0.0, 3.0, 0.0);
    assert!(l.sample_li(above, (0.5, 0.5)).is_none());
    assert_eq!(l.pdf_li(above, Vec3::NEG_Y), 0.0);
    assert_eq!(l.le(Vec3::Y), Vec3::ZERO);
    assert_eq!(l.le(Vec3::NEG_Y), l.radiance);
    let two = ceiling(true);
    assert!(two.sample_li(above, (0.5, 0.5)).is_some());
    assert!(two.pdf_li(above, Vec3::NEG_Y) > 0.0);
    // In the plane: nothing.
    assert!(
        two.sample_li(Vec3::new(5.0, 2.0, 0.0), (0.5, 0.5))
            .is_none()
    );
    assert!(RectLight::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::ONE, false).is_none());
    assert!((l.power() - l.radiance * (PI * 2.0)).abs().max_element() < 1e-5);
    assert!((two.power() - l.power() * 2.0).abs().max_element() < 1e-5);
}

#[test]
fn sample_li_passes_chi2_against_pdf_li_and_a_wrong_pdf_fails() {
    let rect = ceiling(false);
    let skew = RectLight::new(
        Vec3::new(-1.0, 2.0, -0.5),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.3, 0.0, 1.0),
        Vec3::ONE,
        false,
    )
    .unwrap();
    assert!(!skew.is_rectangle);
    let cases = [
        ("spherical, near", rect, Vec3::new(0.4, 1.3, -0.2)),
        ("spherical, grazing", rect, Vec3::new(2.5, 1.6, 0.0)),
        ("area, far", rect, Vec3::new(5.0, -60.0, 3.0)),
        ("area, parallelogram", skew, Vec3::new(0.1, 0.5, 0.2)),
    ];
    let alpha = sidak_alpha(0.01, cases.len());
    for (i, (label, l, p)) in cases.into_iter().enumerate() {
        let (axis, extent) = cap_around(p, &corners(&l));
        let bins = SphereBins::cap(axis, 16, 32, extent);
        let sample = |rng: &mut Rng| l.sample_li(p, rng.next_2d()).map(|s| s.wi);
        let r = chi2_test(200_000, 10 + i as u64, &bins, sample, |w| l.pdf_li(p, w));
        eprintln!("rect sample_li χ² {label}: {r:?}");
        assert!(
            r.passes(alpha) && r.rejected == 0 && r.dof > 100,
            "{label}: {r:?}"
        );
    }
    // Sampling by solid angle but claiming the area density is detected.
    let p = Vec3::new(0.4, 1.3, -0.2);
    let area_pdf = |w: Vec3| {
        rect.hit(p, w)
            .map_or(0.0, |t| t * t / (rect.area * w.dot(rect.normal).abs()))
    };
    let (axis, extent) = cap_around(p, &corners(&rect));
    let bins = SphereBins::cap(axis, 16, 32, extent);
    let wrong = chi2_test(
        200_000,
        99,
        &bins,
        |rng| rect.sample_li(p, rng.next_2d()).map(|s| s.wi),
        area_pdf,
    );
    eprintln!("rect sample_li χ² against the area density (must fail): {wrong:?}");
    assert!(wrong.p_value < 1e-6, "{wrong:?}");
}

#[test]
fn sample_le_passes_chi2_and_carries_the_power() {
    for two_sided in [false, true] {
        let l = ceiling(two_sided);
        let bins = SphereBins::sphere(l.normal, 20, 40);
        let le = |rng: &mut Rng| {
            let (a, b) = (rng.next_2d(), rng.next_2d());
            l.sample_le(a, b)
        };
        let dirs = chi2_test(
            200_000,
            3,
            &bins,
            |rng| le(rng).map(|s| s.dir),
            |w| l.pdf_le(w).1,
        );
        eprintln!("rect sample_le dir χ² two_sided={two_sided}: {dirs:?}");
        assert!(dirs.passes(0.005) && dirs.rejected == 0, "{dirs:?}");
        // The wrong claim: one-sided cosine for a two-sided light (or uniform for one-sided).
        let wrong = chi2_test(
            200_000,
            4,
            &bins,
            |rng| le(rng).map(|s| s.dir),
            |w| {
                let c = w.dot(l.normal);
                if two_sided {
                    c.max(0.0) / PI
                } else {
                    (c > 0.0) as u8 as f32 / (2.0 * PI)
                }
            },
        );
        assert!(wrong.p_value < 1e-6, "{wrong:?}");
        // Positions: uniform over an 8 × 8 grid of the parallelogram's (s, t); flux = Φ.
        let mut rng = Rng::new(5, 0);
        let mut counts = vec![0u64; 64];
        let n = 64_000;
        let mut flux = 0.0f64;
        for _ in 0..n {
            let s = le(&mut rng).expect("emits");
            let q = s.origin - l.corner;
            let (a, b) = (q.dot(l.edge_u) / 4.0, q.dot(l.edge_v));
            let cell = ((a * 8.0) as usize).min(7) * 8 + ((b * 8.0) as usize).min(7);
            counts[cell] += 1;
            let cos = local(s.normal, s.dir).z;
            flux += f64::from(s.le.x * cos / (s.pdf_pos * s.pdf_dir));
            assert_eq!(l.pdf_le(s.dir), (s.pdf_pos, s.pdf_dir));
        }
        let pos = pearson(&counts, &vec![f64::from(n) / 64.0; 64]);
        assert!(pos.p_value > 0.005, "{pos:?}");
        let flux = flux / f64::from(n);
        assert!((flux / f64::from(l.power().x) - 1.0).abs() < 1e-4, "{flux}");
    }
}
