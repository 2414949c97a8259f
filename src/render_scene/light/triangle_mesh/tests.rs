//! The mesh light against the disc's closed form (through a triangle fan), Lambert's polygon
//! formula, and its own densities (χ²).

use super::*;
use crate::render_scene::light::test_support::{
    cap_around, lambert_polygon_irradiance, local, stratified,
};
use crate::sampling::Rng;
use crate::sampling::chi2::{SphereBins, chi2_test, pearson, sidak_alpha};
use std::f32::consts::PI;

/// A fan of `n` triangles inscribed in the disc of radius `r` centred at (0, h, 0), facing −y.
fn fan(n: usize, r: f32, h: f32) -> MeshLight {
    let mut positions = vec![Vec3::new(0.0, h, 0.0)];
    for k in 0..n {
        let phi = std::f32::consts::TAU * k as f32 / n as f32;
        positions.push(Vec3::new(r * phi.cos(), h, r * phi.sin()));
    }
    let triangles = (0..n as u32)
        .map(|k| [0, 1 + k, 1 + (k + 1) % n as u32])
        .collect();
    MeshLight::new(positions, triangles, Vec3::ONE, false).unwrap()
}

fn nee_irradiance(l: &MeshLight, p: Vec3, n: Vec3, k: usize, seed: u64) -> f64 {
    let mut rng = Rng::new(seed, 0);
    stratified(k, &mut rng)
        .filter_map(|u| l.sample_li(p, u))
        .map(|s| f64::from(s.light.weight.x) * f64::from(s.light.wi.dot(n).max(0.0)))
        .sum::<f64>()
        / (k * k) as f64
}

#[test]
fn a_fan_approximates_the_discs_irradiance_within_the_faceting_error() {
    // Disc of radius 1 at height 1 above the receiver: E = π L sin²α = π/2.
    let (n, r, h) = (64usize, 1.0f32, 1.0f32);
    let l = fan(n, r, h);
    assert!((l.normal(0) - Vec3::NEG_Y).length() < 1e-6);
    let disc = std::f64::consts::PI * f64::from(r * r) / f64::from(r * r + h * h);
    // Faceting error bound: the inscribed 64-gon misses 1 − sin(2π/n)/(2π/n) ≈ 1.6e-3 of the
    // disc's area, at its rim, where a point on the axis receives less per unit area than on
    // average, so the polygon's irradiance deficit is positive and at most that fraction.
    let step = std::f64::consts::TAU / n as f64;
    let facet = 1.0 - step.sin() / step;
    let ring: Vec<Vec3> = l.positions[1..].to_vec();
    let polygon = lambert_polygon_irradiance(Vec3::ZERO, Vec3::Y, &ring, 1.0);
    let deficit = 1.0 - polygon / disc;
    assert!(deficit > 0.0 && deficit < facet, "{deficit} vs {facet}");
    let got = nee_irradiance(&l, Vec3::ZERO, Vec3::Y, 1024, 0);
    eprintln!(
        "mesh fan E: NEE {got:.6} polygon {polygon:.6} disc πL sin²α {disc:.6} (faceting bound {facet:.2e}, polygon deficit {deficit:.2e})"
    );
    assert!((got / polygon - 1.0).abs() < 1e-3, "{got} vs {polygon}");
    assert!((got / disc - 1.0).abs() < facet + 1e-3, "{got} vs {disc}");
    // Off axis and tilted, against the polygon formula.
    let p = Vec3::new(0.8, 0.2, -0.5);
    let nrm = Vec3::new(-0.2, 1.0, 0.1).normalize();
    let want = lambert_polygon_irradiance(p, nrm, &ring, 1.0);
    let got = nee_irradiance(&l, p, nrm, 1024, 1);
    eprintln!("mesh fan E off axis: NEE {got:.6} polygon {want:.6}");
    assert!((got / want - 1.0).abs() < 1e-3, "{got} vs {want}");
    assert!((l.power().x / (PI * l.area) - 1.0).abs() < 1e-6);
    let area = 0.5 * n as f64 * step.sin();
    assert!((f64::from(l.area) / area - 1.0).abs() < 1e-5);
}

/// Two unequal triangles, one behind the other as seen from below, two-sided.
fn layered() -> MeshLight {
    let positions = vec![
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(1.0, 1.0, -1.0),
        Vec3::new(0.0, 1.0, 1.0),
        Vec3::new(-0.5, 2.0, -0.3),
        Vec3::new(0.9, 2.5, -0.5),
        Vec3::new(0.1, 1.8, 0.6),
    ];
    MeshLight::new(positions, vec![[0, 1, 2], [3, 4, 5]], Vec3::ONE, true).unwrap()
}

#[test]
fn sample_li_passes_chi2_against_pdf_li_and_a_wrong_pdf_fails() {
    let cases = [
        ("fan", fan(12, 1.0, 1.0), Vec3::new(0.3, 0.0, 0.2)),
        ("layered, two-sided", layered(), Vec3::new(0.1, 0.0, -0.1)),
    ];
    let alpha = sidak_alpha(0.01, cases.len());
    for (i, (label, l, p)) in cases.iter().enumerate() {
        let (axis, extent) = cap_around(*p, &l.positions);
        let bins = SphereBins::cap(axis, 16, 32, extent);
        let r = chi2_test(
            200_000,
            i as u64,
            &bins,
            |rng| l.sample_li(*p, rng.next_2d()).map(|s| s.light.wi),
            |w| l.pdf_li(*p, w),
        );
        eprintln!("mesh sample_li χ² {label}: {r:?}");
        assert!(
            r.passes(alpha) && r.rejected == 0 && r.dof > 100,
            "{label}: {r:?}"
        );
    }
    // Claiming each triangle is picked with probability ½ (not by area) is detected.
    let l = layered();
    let p = Vec3::new(0.1, 0.0, -0.1);
    let wrong_pdf = |w: Vec3| {
        let ray = Ray::new(p, w);
        let tr = TriRay::new(&ray);
        (0..2)
            .filter_map(|i| {
                let [a, b, c] = l.vertices(i);
                let hit = intersect_triangle(&tr, a, b, c, f32::INFINITY)?;
                let tri_area = 0.5 * (b - a).cross(c - a).length();
                let cos = w.dot(l.normal(i)).abs();
                Some(0.5 / tri_area * hit.t * hit.t / cos)
            })
            .sum()
    };
    let (axis, extent) = cap_around(p, &l.positions);
    let bins = SphereBins::cap(axis, 16, 32, extent);
    let wrong = chi2_test(
        200_000,
        7,
        &bins,
        |rng| l.sample_li(p, rng.next_2d()).map(|s| s.light.wi),
        wrong_pdf,
    );
    eprintln!("mesh sample_li χ² against an equal-pick pdf (must fail): {wrong:?}");
    assert!(wrong.p_value < 1e-6, "{wrong:?}");
}

#[test]
fn sample_le_is_uniform_by_area_cosine_in_direction_and_carries_the_power() {
    for l in [fan(12, 1.0, 1.0), layered()] {
        let mut rng = Rng::new(2, 0);
        let n = 100_000;
        let mut picks = vec![0u64; l.triangles.len()];
        let mut flux = 0.0f64;
        for _ in 0..n {
            let s = l.sample_le(rng.next_2d(), rng.next_2d()).expect("emits");
            let tri = (0..l.triangles.len())
                .find(|&i| {
                    let [a, b, c] = l.vertices(i);
                    let nn = (b - a).cross(c - a);
                    (s.origin - a).dot(nn).abs() < 1e-4 * nn.length()
                        && [(a, b), (b, c), (c, a)]
                            .iter()
                            .all(|&(x, y)| (y - x).cross(s.origin - x).dot(nn) >= -1e-5)
                })
                .expect("on a triangle");
            picks[tri] += 1;
            let cos = local(s.normal, s.dir).z;
            flux += f64::from(s.le.x * cos / (s.pdf_pos * s.pdf_dir));
            let (pp, pd) = l.pdf_le(l.normal(tri), s.dir);
            assert!((pp - s.pdf_pos).abs() < 1e-6 && (pd / s.pdf_dir - 1.0).abs() < 1e-4);
        }
        let expected: Vec<f64> = (0..l.triangles.len())
            .map(|i| {
                let [a, b, c] = l.vertices(i);
                f64::from(0.5 * (b - a).cross(c - a).length() / l.area) * f64::from(n)
            })
            .collect();
        let r = pearson(&picks, &expected);
        assert!(r.p_value > 0.005, "{r:?}");
        assert!((flux / f64::from(n) / f64::from(l.power().x) - 1.0).abs() < 1e-4);
        // Directions about the emitting side's normal are cosine-distributed.
        let bins = SphereBins::sphere(Vec3::Z, 16, 32);
        let d = chi2_test(
            100_000,
            3,
            &bins,
            |rng| {
                l.sample_le(rng.next_2d(), rng.next_2d())
                    .map(|s| local(s.normal, s.dir))
            },
            |w| w.z.max(0.0) / PI,
        );
        assert!(d.passes(0.005), "{d:?}");
    }
}

#[test]
fn one_sided_meshes_are_dark_behind_and_degenerate_meshes_are_refused() {
    let l = fan(8, 1.0, 1.0);
    assert!(l.sample_li(Vec3::new(0.0, 2.0, 0.0), (0.4, 0.4)).is_none());
    assert_eq!(l.pdf_li(Vec3::new(0.0, 2.0, 0.0), Vec3::NEG_Y), 0.0);
    assert!(l.pdf_li(Vec3::ZERO, Vec3::Y) > 0.0);
    assert_eq!(l.le(Vec3::NEG_Y, Vec3::Y), Vec3::ZERO);
    assert!(MeshLight::new(vec![Vec3::ZERO; 3], vec![[0, 1, 2]], Vec3::ONE, false).is_none());
    assert!(MeshLight::new(vec![Vec3::ZERO; 3], vec![[0, 1, 5]], Vec3::ONE, false).is_none());
}
