//! Tests of the rough dielectric: χ² of `sample` against `pdf` (entering and leaving, normal and
//! grazing, isotropic and anisotropic), energy in importance mode by quadrature and Monte Carlo,
//! the η = 1 pass-through, reciprocity in both transport modes, and the world-space wrappers.

use super::*;
use crate::sampling::Rng;
use crate::sampling::chi2::{SphereBins, chi2_test, integrate, sidak_alpha};
use std::f32::consts::PI;

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn frame_z(entering: bool) -> ShadingFrame {
    ShadingFrame {
        ns: Vec3::Z,
        ng: Vec3::Z,
        entering,
    }
}

fn glass(ax: f32, ay: f32) -> RoughDielectric {
    RoughDielectric {
        distribution: Ggx::new(ax, ay),
        ior: 1.5,
    }
}

const ROUGHNESS: [(f32, f32); 6] = [
    (0.05, 0.05),
    (0.3, 0.3),
    (1.0, 1.0),
    (0.05, 0.2),
    (0.3, 0.1),
    (1.0, 0.4),
];

/// The bin layouts of one χ² case: the whole sphere for wide lobes, otherwise two caps of
/// half-angle 10 α zoomed on the mirror direction and on the macro-surface refraction (if any).
fn layouts(lobe: &RoughDielectric, wo: Vec3, entering: bool) -> Vec<SphereBins> {
    let a = lobe.distribution.alpha_x.max(lobe.distribution.alpha_y);
    let half = 10.0 * a;
    if half >= PI {
        return vec![SphereBins::sphere(Vec3::Z, 16, 32)];
    }
    let cap = f64::from(1.0 - half.cos());
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let mut out = vec![SphereBins::cap(mirror, 16, 32, cap)];
    if let Some(t) = refract(wo, Vec3::Z, 1.0 / lobe.eta(entering)) {
        out.push(SphereBins::cap(t, 16, 32, cap));
    }
    out
}

/// χ² of a rough glass's `sample` against its `pdf` for each `(αx, αy)`, at 0° and 80°,
/// entering and leaving, in every bin layout of [`layouts`] (100 000 samples, streams
/// `seed + k`), all cases at an overall false-rejection rate of 0.01 (Šidák).
fn chi2_cases(roughness: &[(f32, f32)], seed: u64) {
    let mut cases = Vec::new();
    for &(ax, ay) in roughness {
        for theta in [0.0f32, 80.0] {
            for entering in [true, false] {
                let lobe = glass(ax, ay);
                let wo = dir(theta, 30.0);
                for bins in layouts(&lobe, wo, entering) {
                    cases.push((lobe, wo, theta, entering, bins));
                }
            }
        }
    }
    let alpha = sidak_alpha(0.01, cases.len());
    for (k, (lobe, wo, theta, entering, bins)) in cases.iter().enumerate() {
        let fr = frame_z(*entering);
        let r = chi2_test(
            100_000,
            seed + k as u64,
            bins,
            |rng| {
                let u_lobe = rng.next_f32();
                lobe.sample_alone(
                    wo.to_owned(),
                    u_lobe,
                    rng.next_2d(),
                    &fr,
                    TransportMode::Radiance,
                    Vec3::ONE,
                )
                .map(|s| s.wi)
            },
            |wi| lobe.density(*wo, wi, &fr, Vec3::ONE),
        );
        let g = lobe.distribution;
        eprintln!(
            "rough dielectric α ({}, {}) θo {theta}° entering {entering} bins about {:.2}: \
             χ² {:.1} / {} dof, p {:.3}, lost {}",
            g.alpha_x, g.alpha_y, bins.frame.n, r.statistic, r.dof, r.p_value, r.rejected
        );
        assert!(r.impossible == 0 && r.passes(alpha), "case {k}: {r:?}");
    }
}

#[test]
fn chi2_sample_follows_pdf_entering_and_leaving_normal_and_grazing_iso_and_aniso() {
    chi2_cases(&ROUGHNESS, 2_000);
}

/// The scene's roughness r is perceptual (α = r²), so the roughness 0.05 and 0.3 are
/// α = 0.0025 and 0.09 (r = 1 is α = 1, tested above): the same χ² there, isotropic and
/// anisotropic ((0.05, 0.2) and (0.3, 0.1) in r), at 0° and 80°, entering and leaving.
#[test]
fn chi2_sample_follows_pdf_at_the_scene_roughnesses_0_05_and_0_3() {
    let scene: [(f32, f32); 4] = [(0.05, 0.05), (0.3, 0.3), (0.05, 0.2), (0.3, 0.1)];
    let alphas: Vec<(f32, f32)> = scene.iter().map(|&(rx, ry)| (rx * rx, ry * ry)).collect();
    chi2_cases(&alphas, 4_000);
}

#[test]
fn chi2_rejects_a_transmission_pdf_without_the_eta_squared_of_its_jacobian() {
    let lobe = glass(0.3, 0.3);
    let fr = frame_z(true);
    let wo = dir(30.0, 0.0);
    let eta = lobe.eta(true);
    let wrong = |wi: Vec3| {
        let p = lobe.density(wo, wi, &fr, Vec3::ONE);
        if wi.z < 0.0 { p / (eta * eta) } else { p }
    };
    let r = chi2_test(
        100_000,
        9,
        &SphereBins::sphere(Vec3::Z, 16, 32),
        |rng| {
            let u_lobe = rng.next_f32();
            lobe.sample_alone(
                wo,
                u_lobe,
                rng.next_2d(),
                &fr,
                TransportMode::Radiance,
                Vec3::ONE,
            )
            .map(|s| s.wi)
        },
        wrong,
    );
    eprintln!(
        "wrong dielectric pdf: χ² {:.0} / {} dof, p {:e}",
        r.statistic, r.dof, r.p_value
    );
    assert!(r.p_value < 1e-6, "{r:?}");
}

/// Reflected and transmitted albedo `∫ f |cos θi| dωi` in importance mode by quadrature.
fn albedo_quadrature(lobe: &RoughDielectric, wo: Vec3, entering: bool) -> (f64, f64) {
    let up = SphereBins::cap(Vec3::Z, 32, 64, 1.0);
    let down = SphereBins::cap(-Vec3::Z, 32, 64, 1.0);
    let f = |wi: Vec3| {
        lobe.f_local(wo, wi, entering, TransportMode::Importance, Vec3::ONE)
            .x
            * wi.z.abs()
    };
    (integrate(&up, f), integrate(&down, f))
}

/// Monte Carlo `E[weight]` in importance mode, split into reflection and transmission, and the
/// standard error of the total.
fn albedo_mc(lobe: &RoughDielectric, wo: Vec3, entering: bool, n: u32) -> (f64, f64, f64) {
    let mut rng = Rng::new(21, 3);
    let fr = frame_z(entering);
    let (mut r, mut t, mut s2) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..n {
        let u_lobe = rng.next_f32();
        if let Some(s) = lobe.sample_alone(
            wo,
            u_lobe,
            rng.next_2d(),
            &fr,
            TransportMode::Importance,
            Vec3::ONE,
        ) {
            let w = f64::from(s.weight.x);
            if s.transmitted {
                t += w
            } else {
                r += w
            }
            s2 += w * w;
        }
    }
    let n = f64::from(n);
    let m = (r + t) / n;
    (r / n, t / n, ((s2 / n - m * m).max(0.0) / n).sqrt())
}

#[test]
fn reflection_plus_transmission_never_exceeds_one_in_importance_mode() {
    for (ax, ay) in [(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (0.3, 0.1)] {
        let lobe = glass(ax, ay);
        for entering in [true, false] {
            for theta in [0.0f32, 30.0, 60.0, 80.0] {
                let wo = dir(theta, 30.0);
                let (qr, qt) = albedo_quadrature(&lobe, wo, entering);
                let (mr, mt, se) = albedo_mc(&lobe, wo, entering, 100_000);
                eprintln!(
                    "rough glass α ({ax}, {ay}) θo {theta}° entering {entering}: R + T = \
                     {qr:.4} + {qt:.4} = {:.4} (quadrature), {mr:.4} + {mt:.4} = {:.4} ± {se:.4} (MC)",
                    qr + qt,
                    mr + mt
                );
                assert!(qr + qt <= 1.0 + 2e-3, "quadrature {qr} + {qt}");
                assert!(mr + mt <= 1.0 + 4.0 * se, "MC {mr} + {mt}");
                assert!(
                    (qr + qt - mr - mt).abs() < 4.0 * se + 2e-3,
                    "{qr}+{qt} vs {mr}+{mt}"
                );
            }
        }
    }
    // A nearly smooth surface at normal incidence splits as the smooth dielectric: R = 4%.
    let (qr, qt) = albedo_quadrature(&glass(0.05, 0.05), Vec3::Z, true);
    assert!(
        (qr - 0.04).abs() < 2e-3 && (qt - 0.96).abs() < 5e-3,
        "{qr} {qt}"
    );
}

#[test]
fn index_matched_glass_is_a_pass_through_at_any_roughness() {
    // The furnace test: η = 1 glass must vanish, so every sample goes straight on with weight 1
    // (the tint), in both modes and from both sides, and there is no non-delta part.
    for alpha in [0.05, 0.3, 1.0] {
        let lobe = RoughDielectric {
            distribution: Ggx::new(alpha, alpha * 0.5),
            ior: 1.0,
        };
        assert!(lobe.is_pass_through());
        for entering in [true, false] {
            let fr = frame_z(entering);
            for theta in [0.0f32, 45.0, 89.0] {
                let wo = dir(theta, 10.0);
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    for u in [0.0, 0.5, 0.999] {
                        let s = lobe
                            .sample_alone(wo, u, (u, 1.0 - u), &fr, mode, Vec3::ONE)
                            .unwrap();
                        assert_eq!(s.wi, -wo);
                        assert_eq!(s.weight, Vec3::ONE);
                        assert!(s.delta && s.transmitted && s.eta_scale == 1.0 && s.pdf == 1.0);
                    }
                    assert_eq!(lobe.value(wo, -wo, &fr, mode, Vec3::ONE), Vec3::ZERO);
                }
                assert_eq!(lobe.density(wo, -wo, &fr, Vec3::ONE), 0.0);
                assert_eq!(lobe.mean_albedo(wo, &fr, 1.0), 1.0);
            }
        }
    }
}

/// Mirror image through the surface plane (the local frame of the other side's `wo`).
fn flip(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

#[test]
fn reflection_is_reciprocal_and_transmission_obeys_the_eta_squared_rule() {
    let lobe = glass(0.35, 0.2);
    let mut rng = Rng::new(31, 7);
    let (eta_out, eta_in) = (1.0f32, lobe.ior);
    let mut transmissions = 0;
    let mut worst = 0.0f32;
    for _ in 0..4_000 {
        let wo = crate::sampling::warp::cosine_hemisphere(rng.next_2d(), Vec3::Z);
        let up = crate::sampling::warp::cosine_hemisphere(rng.next_2d(), Vec3::Z);
        for entering in [true, false] {
            // Reflection: symmetric in both modes.
            for mode in [TransportMode::Radiance, TransportMode::Importance] {
                let x = lobe.f_local(wo, up, entering, mode, Vec3::ONE).x;
                let y = lobe.f_local(up, wo, entering, mode, Vec3::ONE).x;
                assert!((x - y).abs() <= 1e-5 * x.max(1.0), "{x} vs {y}");
            }
        }
        // Transmission from outside (wo) to inside (wi = flip(up)); the reverse path starts at
        // flip(up) inside, so in its own frame it is `up` with entering = false.
        let wi = flip(up);
        let rad = lobe
            .f_local(wo, wi, true, TransportMode::Radiance, Vec3::ONE)
            .x;
        let imp = lobe
            .f_local(wo, wi, true, TransportMode::Importance, Vec3::ONE)
            .x;
        let rad_back = lobe
            .f_local(up, flip(wo), false, TransportMode::Radiance, Vec3::ONE)
            .x;
        let imp_back = lobe
            .f_local(up, flip(wo), false, TransportMode::Importance, Vec3::ONE)
            .x;
        // Relative 1e-3 plus 1e-5 absolute (f is O(0.1–10) in the lobe): where a microfacet
        // is seen near grazing from outside, or near the critical angle from inside, F → 1 and
        // f → 0, and the two directions' `1 − F` cancel with different roundings.
        let tol = 1e-3 * rad + 1e-5;
        // The adjoint: f_radiance(wo, wi) = f_importance(wi, wo), and vice versa.
        assert!((rad - imp_back).abs() <= tol, "{rad} vs {imp_back}");
        assert!((imp - rad_back).abs() <= tol * 2.25, "{imp} vs {rad_back}");
        // Veach's rule f(wo, wi)/ηₒ² = f(wi, wo)/ηᵢ² for radiance.
        let lhs = rad / (eta_out * eta_out);
        let rhs = rad_back / (eta_in * eta_in);
        assert!((lhs - rhs).abs() <= tol, "{lhs} vs {rhs}");
        // Importance mode is radiance mode times η² = (ηᵢ/ηₒ)².
        assert!((imp - rad * 2.25).abs() <= 1e-5 * imp + 1e-9);
        transmissions += usize::from(rad > 0.0);
        if rad > 1e-2 {
            worst = worst.max((rad - imp_back).abs() / rad);
        }
    }
    assert!(transmissions > 1_000, "{transmissions}");
    eprintln!("rough glass adjoint reciprocity: worst relative error {worst:e} where f > 0.01");
    assert!(worst < 1e-3, "{worst}");
}

#[test]
fn samples_agree_with_f_and_pdf_and_respect_the_geometric_normal() {
    let lobe = glass(0.25, 0.25);
    let mut rng = Rng::new(41, 1);
    for i in 0..40 {
        let tilt = i as f32 / 40.0 * 1.2;
        for entering in [true, false] {
            let fr = ShadingFrame {
                ns: Vec3::new(tilt.sin(), 0.0, tilt.cos()),
                ng: Vec3::Z,
                entering,
            };
            let wo = dir(60.0, 180.0);
            for mode in [TransportMode::Radiance, TransportMode::Importance] {
                for _ in 0..40 {
                    let u_lobe = rng.next_f32();
                    let Some(s) =
                        lobe.sample_alone(wo, u_lobe, rng.next_2d(), &fr, mode, Vec3::ONE)
                    else {
                        continue;
                    };
                    assert_eq!(s.wi.dot(fr.ng) < 0.0, s.transmitted, "side of ng");
                    assert_eq!(s.wi.dot(fr.ns) < 0.0, s.transmitted, "side of ns");
                    let pdf = lobe.density(wo, s.wi, &fr, Vec3::ONE);
                    assert!((s.pdf - pdf).abs() <= 1e-3 * pdf, "{} vs {pdf}", s.pdf);
                    let mut w =
                        lobe.value(wo, s.wi, &fr, mode, Vec3::ONE) * (s.wi.dot(fr.ns).abs() / pdf);
                    if mode == TransportMode::Importance {
                        w *= shading_normal_correction(wo, s.wi, &fr);
                    }
                    assert!((s.weight - w).abs().max_element() <= 1e-3 * w.max_element().max(1.0));
                    let eta = lobe.eta(entering);
                    let want = if s.transmitted && mode == TransportMode::Radiance {
                        1.0 / (eta * eta)
                    } else {
                        1.0
                    };
                    assert_eq!(s.eta_scale, want);
                }
            }
        }
    }
}
