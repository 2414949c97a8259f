//! The χ² helper itself: its p-values against closed forms and tabulated critical values, its
//! quadrature against known integrals, and the test accepting correct samplers while rejecting
//! subtly wrong ones (the controls that show it can fail).

use super::*;
use crate::sampling::special::ln_gamma;
use crate::sampling::warp::{cosine_hemisphere, uniform_cone, uniform_sphere};
use std::f32::consts::PI;

#[test]
fn p_values_match_closed_forms_for_even_dof() {
    // For dof = 2k: Q(k, x/2) = e^{−x/2} Σ_{i<k} (x/2)^i / i!.
    for k in [1usize, 2, 5, 20, 60] {
        for x in [0.1, 1.0, 3.0, 10.0, 40.0, 150.0] {
            let h: f64 = x / 2.0;
            let (mut term, mut sum) = (1.0, 0.0);
            for i in 0..k {
                if i > 0 {
                    term *= h / i as f64;
                }
                sum += term;
            }
            let want = (-h).exp() * sum;
            let got = chi2_p_value(x, 2 * k);
            assert!(
                (got - want).abs() <= 1e-10 + 1e-9 * want,
                "dof {} x {x}: {got} vs {want}",
                2 * k
            );
        }
    }
}

#[test]
fn p_values_match_tabulated_critical_values() {
    // Upper-tail critical values of the χ² distribution (NIST/SEMATECH e-Handbook, table
    // 1.3.6.7.4, and Abramowitz & Stegun table 26.8).
    let table = [
        (1, 3.841, 0.05),
        (1, 6.635, 0.01),
        (3, 7.815, 0.05),
        (10, 18.307, 0.05),
        (10, 23.209, 0.01),
        (50, 67.505, 0.05),
        (100, 124.342, 0.05),
        (100, 135.807, 0.01),
    ];
    for (dof, x, p) in table {
        let got = chi2_p_value(x, dof);
        assert!(
            (got - p).abs() < 2e-4 * p.max(0.01) / 0.01,
            "dof {dof}: {got} vs {p}"
        );
    }
    assert_eq!(chi2_p_value(0.0, 5), 1.0);
    assert_eq!(chi2_p_value(f64::INFINITY, 5), 0.0);
    // ln Γ at known points: Γ(1/2) = √π, Γ(5) = 24, Γ(30) = 29!.
    assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
    assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-13);
    assert!((ln_gamma(30.0) - 71.257_038_967_168_01).abs() < 1e-11);
}

#[test]
fn sidak_correction() {
    assert!((sidak_alpha(0.01, 1) - 0.01).abs() < 1e-15);
    // 1 − 0.99^(1/10).
    assert!((sidak_alpha(0.01, 10) - 0.001_004_528_708).abs() < 1e-12);
}

#[test]
fn quadrature_integrates_known_densities_to_one() {
    let n = Vec3::new(0.3, -0.5, 0.8).normalize();
    let cosine = |w: Vec3| w.dot(n).max(0.0) / PI;
    assert!((integrate_sphere(n, cosine) - 1.0).abs() < 1e-6);
    // The cosine pdf seen from a frame where its horizon cuts cells diagonally.
    assert!((integrate_sphere(Vec3::X, cosine) - 1.0).abs() < 1e-4);
    let cos_max = 0.95f32;
    let cone = |w: Vec3| {
        if w.dot(n) >= cos_max {
            1.0 / (2.0 * PI * (1.0 - cos_max))
        } else {
            0.0
        }
    };
    assert!((integrate_sphere(n, cone) - 1.0).abs() < 1e-4);
    let cap = SphereBins::cap(n, 10, 20, 0.08);
    assert!((integrate(&cap, cone) - 1.0).abs() < 1e-4);
}

/// Significance for the tests below: Šidák-corrected 1% over this file's accepting tests.
fn alpha() -> f64 {
    sidak_alpha(0.01, 4)
}

#[test]
fn accepts_cosine_hemisphere_and_uniform_sphere() {
    let n = Vec3::new(1.0, 2.0, 2.0) / 3.0;
    let bins = SphereBins::sphere(n, 20, 40);
    let r = chi2_test(
        200_000,
        1,
        &bins,
        |rng| Some(cosine_hemisphere(rng.next_2d(), n)),
        |w| w.dot(n).max(0.0) / PI,
    );
    assert!(r.passes(alpha()), "{r:?}");
    assert!(r.dof > 300, "{r:?}");
    let r = chi2_test(
        200_000,
        2,
        &bins,
        |rng| Some(uniform_sphere(rng.next_2d())),
        |_| 1.0 / (4.0 * PI),
    );
    assert!(r.passes(alpha()), "{r:?}");
}

#[test]
fn accepts_uniform_cone_and_samplers_that_sometimes_fail() {
    let n = Vec3::new(0.0, -0.6, 0.8);
    let cos_max = 0.99f32;
    let pdf = |w: Vec3| {
        if w.dot(n) >= cos_max {
            1.0 / (2.0 * PI * (1.0 - cos_max))
        } else {
            0.0
        }
    };
    let cap = SphereBins::cap(n, 16, 32, 0.0125);
    let r = chi2_test(
        200_000,
        3,
        &cap,
        |rng| Some(uniform_cone(rng.next_2d(), n, cos_max)),
        pdf,
    );
    assert!(r.passes(alpha()), "{r:?}");
    // Failing a quarter of the time is consistent with a pdf of three quarters the mass.
    let r = chi2_test(
        200_000,
        4,
        &cap,
        |rng| {
            let w = uniform_cone(rng.next_2d(), n, cos_max);
            (rng.next_f32() < 0.75).then_some(w)
        },
        |w| 0.75 * pdf(w),
    );
    assert!(r.passes(alpha()), "{r:?}");
    assert!(r.rejected > 45_000);
}

#[test]
fn rejects_subtly_wrong_pdfs() {
    let n = Vec3::Z;
    let bins = SphereBins::sphere(n, 20, 40);
    // cos^1.1 lobe sampled, plain cosine claimed: 10% off in exponent.
    let r = chi2_test(
        200_000,
        5,
        &bins,
        |rng| {
            let (u, v) = rng.next_2d();
            let cos_t = u.powf(1.0 / 2.1);
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = 2.0 * PI * v;
            Some(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t))
        },
        |w| w.z.max(0.0) / PI,
    );
    assert!(r.p_value < 1e-6, "{r:?}");
    // A cone sampler whose pdf claims a cone 2% wider in 1 − cos θ.
    let cos_max = 0.9f32;
    let wider = 1.0 - 1.02 * (1.0 - cos_max);
    let r = chi2_test(
        200_000,
        6,
        &SphereBins::cap(n, 16, 32, 0.125),
        |rng| Some(uniform_cone(rng.next_2d(), n, cos_max)),
        |w| {
            if w.z >= wider {
                1.0 / (2.0 * PI * (1.0 - wider))
            } else {
                0.0
            }
        },
    );
    assert!(r.p_value < 1e-6, "{r:?}");
    // A φ distribution 3% lopsided.
    let r = chi2_test(
        200_000,
        7,
        &bins,
        |rng| {
            let (u, v) = rng.next_2d();
            let v = v + 0.03 * (1.0 - v) * v * 4.0;
            Some(cosine_hemisphere((u, v), n))
        },
        |w| w.z.max(0.0) / PI,
    );
    assert!(r.p_value < 1e-4, "{r:?}");
    // Samples where the pdf is zero are impossible, whatever else matches.
    let r = chi2_test(
        10_000,
        8,
        &bins,
        |rng| Some(-cosine_hemisphere(rng.next_2d(), n)),
        |w| w.z.max(0.0) / PI,
    );
    assert!(r.impossible == 10_000 && r.p_value == 0.0, "{r:?}");
}
