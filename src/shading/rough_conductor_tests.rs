//! Tests of the rough conductor: χ² of `sample` against `pdf`, energy (directional albedo with
//! Fresnel 1 by two quadratures and by Monte Carlo), reciprocity, and the world-space wrappers.

use super::*;
use crate::sampling::Rng;
use crate::sampling::chi2::{SphereBins, chi2_test, integrate, sidak_alpha};
use crate::shading::conductor::ConductorPreset;
use std::f32::consts::PI;

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn frame_z() -> ShadingFrame {
    ShadingFrame {
        ns: Vec3::Z,
        ng: Vec3::Z,
        entering: true,
    }
}

fn white(ax: f32, ay: f32) -> RoughConductor {
    RoughConductor {
        distribution: Ggx::new(ax, ay),
        fresnel: ConductorFresnel::schlick(Vec3::ONE),
        tinted: false,
    }
}

/// The roughnesses of the χ² and energy tests: isotropic 0.05, 0.3, 1 and an anisotropic
/// companion of each.
const ROUGHNESS: [(f32, f32); 6] = [
    (0.05, 0.05),
    (0.3, 0.3),
    (1.0, 1.0),
    (0.05, 0.2),
    (0.3, 0.1),
    (1.0, 0.4),
];

/// Bins zoomed on the mirror direction of `wo` for narrow lobes: a cap of half-angle 10 α
/// (the whole sphere from α ≈ 0.31).
fn bins_around(centre: Vec3, alpha: f32) -> SphereBins {
    let half = (10.0 * alpha).min(PI);
    SphereBins::cap(centre, 16, 32, f64::from(1.0 - half.cos()))
}

/// χ² of a gold rough conductor's `sample` against its `pdf` at each `((αx, αy), θo)` case (100 000
/// samples, streams `seed + k`), all cases at an overall false-rejection rate of 0.01 (Šidák).
fn chi2_cases(cases: &[((f32, f32), f32)], seed: u64) {
    let alpha = sidak_alpha(0.01, cases.len());
    let gold = ConductorFresnel::preset(ConductorPreset::Gold);
    for (k, &((ax, ay), theta)) in cases.iter().enumerate() {
        let lobe = RoughConductor {
            distribution: Ggx::new(ax, ay),
            fresnel: gold,
            tinted: false,
        };
        let wo = dir(theta, 30.0);
        let fr = frame_z();
        let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
        let r = chi2_test(
            100_000,
            seed + k as u64,
            &bins_around(mirror, ax.max(ay)),
            |rng| {
                lobe.sample_alone(wo, rng.next_2d(), &fr, TransportMode::Radiance)
                    .map(|s| s.wi)
            },
            |wi| lobe.density(wo, wi, &fr),
        );
        eprintln!(
            "rough conductor α ({ax}, {ay}) θo {theta}°: χ² {:.1} / {} dof, p {:.3}, lost {}",
            r.statistic, r.dof, r.p_value, r.rejected
        );
        assert!(
            r.impossible == 0 && r.passes(alpha),
            "α ({ax}, {ay}) at {theta}°: {r:?}"
        );
    }
}

#[test]
fn chi2_sample_follows_pdf_at_three_roughnesses_normal_and_grazing_iso_and_aniso() {
    let cases: Vec<((f32, f32), f32)> = ROUGHNESS
        .iter()
        .flat_map(|&a| [(a, 0.0), (a, 80.0)])
        .collect();
    chi2_cases(&cases, 1_000);
}

/// The scene's roughness r is perceptual (α = r², docs/material.md), so the roughness
/// 0.05 and 0.3 are α = 0.0025 and 0.09 (r = 1 is α = 1, tested above): the same χ² there,
/// isotropic and anisotropic ((0.05, 0.2) and (0.3, 0.1) in r), at 0° and 80°.
#[test]
fn chi2_sample_follows_pdf_at_the_scene_roughnesses_0_05_and_0_3() {
    let scene: [(f32, f32); 4] = [(0.05, 0.05), (0.3, 0.3), (0.05, 0.2), (0.3, 0.1)];
    let cases: Vec<((f32, f32), f32)> = scene
        .iter()
        .map(|&(rx, ry)| (rx * rx, ry * ry))
        .flat_map(|a| [(a, 0.0), (a, 80.0)])
        .collect();
    chi2_cases(&cases, 3_000);
}

#[test]
fn chi2_rejects_the_full_distribution_pdf_and_a_wrong_roughness() {
    // A classic bug: sampling visible normals but reporting the density of sampling D(h) cos θh.
    let lobe = white(0.3, 0.3);
    let fr = frame_z();
    let wo = dir(80.0, 0.0);
    let wrong = |wi: Vec3| {
        let h = (wo + wi).normalize();
        if wi.z <= 0.0 || wo.dot(h) <= 0.0 {
            return 0.0;
        }
        lobe.distribution.d(h) * h.z / (4.0 * wo.dot(h))
    };
    let sample = |rng: &mut Rng| {
        lobe.sample_alone(wo, rng.next_2d(), &fr, TransportMode::Radiance)
            .map(|s| s.wi)
    };
    let bins = SphereBins::sphere(Vec3::Z, 16, 32);
    let r = chi2_test(100_000, 7, &bins, sample, wrong);
    eprintln!(
        "wrong pdf (D cos θh) at 80°: χ² {:.0} / {} dof, p {:e}",
        r.statistic, r.dof, r.p_value
    );
    assert!(r.p_value < 1e-6, "{r:?}");
    // The density of α = 0.33 for samples of α = 0.3, at normal incidence.
    let other = white(0.33, 0.33);
    let wo = Vec3::Z;
    let r = chi2_test(
        100_000,
        8,
        &bins,
        |rng| {
            lobe.sample_alone(wo, rng.next_2d(), &fr, TransportMode::Radiance)
                .map(|s| s.wi)
        },
        |wi| other.density(wo, wi, &fr),
    );
    eprintln!(
        "wrong pdf (α 0.33 for 0.3): χ² {:.0} / {} dof, p {:e}",
        r.statistic, r.dof, r.p_value
    );
    assert!(r.p_value < 1e-6, "{r:?}");
}

/// Directional albedo `∫ f cos θi dωi` of `lobe` at `wo` by adaptive quadrature over `wi`.
fn albedo_over_wi(lobe: &RoughConductor, wo: Vec3) -> f64 {
    let bins = SphereBins::cap(Vec3::Z, 32, 64, 1.0);
    integrate(&bins, |wi| lobe.f_local(wo, wi).x * wi.z)
}

/// The same albedo as an integral over microfacet normals, `∫ D_wo(h) G2(wo, wi)/G1(wo) dωh`
/// with `wi` the reflection of `wo` about `h` (no Jacobian of `wi` involved).
fn albedo_over_h(lobe: &RoughConductor, wo: Vec3) -> f64 {
    let g = lobe.distribution;
    let bins = SphereBins::cap(Vec3::Z, 32, 64, 1.0);
    integrate(&bins, |h| {
        let wi = reflect(wo, h);
        if wi.z <= 0.0 {
            return 0.0;
        }
        g.visible_pdf(wo, h) * g.g2(wo, wi) / g.g1(wo)
    })
}

/// Monte Carlo albedo `E[weight]` and its standard error.
fn albedo_mc(lobe: &RoughConductor, wo: Vec3, n: u32, seed: u64) -> (f64, f64) {
    let mut rng = Rng::new(seed, 1);
    let fr = frame_z();
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        if let Some(x) = lobe.sample_alone(wo, rng.next_2d(), &fr, TransportMode::Importance) {
            let w = f64::from(x.weight.x);
            s += w;
            s2 += w * w;
        }
    }
    let m = s / f64::from(n);
    (
        m,
        ((s2 / f64::from(n) - m * m).max(0.0) / f64::from(n)).sqrt(),
    )
}

#[test]
fn white_rough_metal_loses_only_what_single_scattering_loses() {
    // Fresnel 1: the albedo is 1 minus the energy single scattering drops (multiple bounces
    // between microfacets). Two quadratures (over wi, and over h) and Monte Carlo must agree,
    // and no albedo exceeds 1.
    for (ax, ay) in ROUGHNESS {
        let lobe = white(ax, ay);
        for theta in [0.0f32, 30.0, 60.0, 80.0, 89.0] {
            let wo = dir(theta, 30.0);
            let a_wi = albedo_over_wi(&lobe, wo);
            let a_h = albedo_over_h(&lobe, wo);
            let (a_mc, se) = albedo_mc(&lobe, wo, 100_000, 3);
            eprintln!(
                "white rough conductor α ({ax}, {ay}) θo {theta}°: E = {a_h:.4} (over h), \
                 {a_wi:.4} (over wi), {a_mc:.4} ± {se:.4} (MC)"
            );
            assert!(a_h <= 1.0 + 1e-3 && a_wi <= 1.0 + 1e-3, "albedo above 1");
            assert!(
                (a_wi - a_h).abs() < 3e-3,
                "quadratures disagree: {a_wi} vs {a_h}"
            );
            assert!(
                (a_mc - a_h).abs() < 4.0 * se + 1e-4,
                "MC {a_mc} ± {se} vs {a_h}"
            );
            if theta < 1.0 && ax <= 0.05 && ay <= 0.05 {
                assert!(a_h > 0.995, "a smooth metal loses nearly nothing: {a_h}");
            }
        }
    }
    // A closed form: for α = 1, D = 1/π, so at normal incidence the visible normals are
    // cosine-distributed, wi = reflect(z, h) stays above the surface for θh < 45° and
    // G2/G1 = 2 cos θi / (1 + cos θi): E = ∫₀¹ x/(1 + x) dx = 1 − ln 2 = 0.306 853.
    let rough = white(1.0, 1.0);
    let e = albedo_over_h(&rough, Vec3::Z);
    assert!((e - (1.0 - std::f64::consts::LN_2)).abs() < 1e-4, "{e}");
    assert!((albedo_over_wi(&rough, Vec3::Z) - (1.0 - std::f64::consts::LN_2)).abs() < 1e-4);
    // Single scattering loses more the rougher the surface.
    let at_normal = |a: f32| albedo_over_h(&white(a, a), Vec3::Z);
    assert!(at_normal(0.05) > at_normal(0.3) && at_normal(0.3) > at_normal(1.0));
}

#[test]
fn f_is_reciprocal_and_sample_weights_are_consistent() {
    let lobe = RoughConductor {
        distribution: Ggx::new(0.4, 0.15),
        fresnel: ConductorFresnel::preset(ConductorPreset::Copper),
        tinted: false,
    };
    let fr = frame_z();
    let mut rng = Rng::new(11, 2);
    for _ in 0..2_000 {
        let (a, b) = (rng.next_2d(), rng.next_2d());
        let wo = crate::sampling::warp::cosine_hemisphere(a, Vec3::Z);
        let wi = crate::sampling::warp::cosine_hemisphere(b, Vec3::Z);
        let (x, y) = (lobe.value(wo, wi, &fr), lobe.value(wi, wo, &fr));
        assert!(
            (x - y).abs().max_element() <= 1e-5 * x.max_element().max(1.0),
            "{wo} {wi}: {x} vs {y}"
        );
        if let Some(s) = lobe.sample_alone(wo, rng.next_2d(), &fr, TransportMode::Radiance) {
            let pdf = lobe.density(wo, s.wi, &fr);
            assert!((s.pdf - pdf).abs() <= 1e-4 * pdf, "{} vs {pdf}", s.pdf);
            let w = lobe.value(wo, s.wi, &fr) * (s.wi.z / pdf);
            assert!((s.weight - w).abs().max_element() <= 1e-4 * w.max_element().max(1.0));
            assert!(!s.delta && !s.transmitted && s.eta_scale == 1.0);
        }
    }
    // Below the surface nothing.
    assert_eq!(lobe.value(Vec3::Z, -Vec3::Z, &fr), Vec3::ZERO);
    assert_eq!(lobe.density(Vec3::Z, dir(100.0, 0.0), &fr), 0.0);
}

#[test]
fn tilted_shading_normals_never_reflect_below_the_geometric_surface() {
    let lobe = white(0.5, 0.5);
    let mut rng = Rng::new(4, 4);
    for i in 0..60 {
        let tilt = i as f32 / 60.0 * 1.3;
        let fr = ShadingFrame {
            ns: Vec3::new(tilt.sin(), 0.0, tilt.cos()),
            ng: Vec3::Z,
            entering: true,
        };
        let wo = dir(70.0, 180.0);
        for mode in [TransportMode::Radiance, TransportMode::Importance] {
            for _ in 0..50 {
                if let Some(s) = lobe.sample_alone(wo, rng.next_2d(), &fr, mode) {
                    assert!(s.wi.dot(fr.ng) > 0.0 && s.weight.is_finite());
                }
            }
        }
        let below = Vec3::new(0.9, 0.0, -0.1).normalize();
        assert_eq!(lobe.value(wo, below, &fr), Vec3::ZERO);
        assert_eq!(lobe.density(wo, below, &fr), 0.0);
    }
    // Mean reflectance at normal incidence of white Schlick: 1.
    assert_eq!(lobe.mean_reflectance(Vec3::Z, &frame_z()), 1.0);
}
