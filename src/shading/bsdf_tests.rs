//! Tests of the BSDF against closed forms and quadrature: normalisation, reciprocity, energy
//! bounds, the η² convention, the adjoint correction and sample/pdf/eval consistency.

use super::*;
use crate::sampling::Rng;
use crate::shading::BsdfAt;
use crate::shading::microfacet::Ggx;

fn diffuse(c: f32) -> Bsdf {
    Bsdf::new(Vec3::splat(c), Vec3::ZERO, 1.0, [None; 3], 1.5)
}

fn frame_z(entering: bool) -> ShadingFrame {
    ShadingFrame {
        ns: Vec3::Z,
        ng: Vec3::Z,
        entering,
    }
}

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// A mixed test material: every lobe present.
fn mixed() -> Bsdf {
    Bsdf::new(
        Vec3::new(0.7, 0.5, 0.3),
        Vec3::splat(0.25),
        20.0,
        [Some(0.5), Some(0.2), Some(0.3)],
        1.5,
    )
}

/// ∫ g(ω) dω over the whole sphere by midpoint quadrature in (cos θ, φ) (exact area weights).
fn integrate_sphere(g: impl Fn(Vec3) -> f64) -> f64 {
    let (nt, np) = (400, 400);
    let mut sum = 0.0;
    for i in 0..nt {
        let z = -1.0 + 2.0 * (i as f64 + 0.5) / nt as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..np {
            let ph = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
            let w = Vec3::new((r * ph.cos()) as f32, (r * ph.sin()) as f32, z as f32);
            sum += g(w);
        }
    }
    sum * 4.0 * std::f64::consts::PI / (nt * np) as f64
}

#[test]
fn weights_are_normalised() {
    let m = Bsdf::new(
        Vec3::ONE,
        Vec3::ZERO,
        1.0,
        [Some(2.0), Some(1.0), Some(1.0)],
        1.5,
    );
    let [d, r, t] = m.weights();
    assert!((d - 0.5).abs() < 1e-6 && (r - 0.25).abs() < 1e-6 && (t - 0.25).abs() < 1e-6);
    let m = Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, Some(3.0), None], 1.5);
    assert_eq!(m.weights(), [0.0, 1.0, 0.0]);
    assert!(m.has_delta() && !m.has_local() && m.flags().contains(LobeFlags::REFLECTION));
    assert!(!m.flags().intersects(LobeFlags::TRANSMISSION) && m.ior().is_none());
    assert_eq!(m.delta_share(), 1.0);
}

/// Hemispherical albedo ∫ f cos dω by quadrature.
fn albedo(m: &Bsdf, wo: Vec3) -> Vec3 {
    let fr = frame_z(true);
    let a = integrate_sphere(|wi| {
        f64::from(m.eval(wo, wi, &fr, TransportMode::Radiance).x * wi.z.max(0.0))
    });
    Vec3::splat(a as f32)
}

#[test]
fn lambert_albedo_equals_color_and_phong_lobe_does_not_create_energy() {
    let a = albedo(&diffuse(1.0), Vec3::new(0.3, 0.0, 0.95).normalize());
    assert!((a.x - 1.0).abs() < 0.01, "{a}");
    let glossy = Bsdf::new(Vec3::ZERO, Vec3::ONE, 40.0, [None; 3], 1.5);
    for z in [1.0f32, 0.7, 0.3] {
        let wo = Vec3::new((1.0 - z * z).sqrt(), 0.0, z);
        let a = albedo(&glossy, wo);
        assert!(a.x <= 1.01, "normalised Phong albedo {a} at cos {z}");
    }
    // At normal incidence the normalised lobe integrates to (m+2)/(m+1)·(m+1)/(m+2) = 1.
    let a = albedo(&glossy, Vec3::Z);
    assert!(a.x > 0.95, "{a}");
}

#[test]
fn dielectric_splits_energy_by_fresnel() {
    let glass = Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.5);
    let l = glass.delta_lobes(Vec3::Z, Vec3::Z, Vec3::Z, true);
    let (dir, w) = l.refract.unwrap();
    assert!((l.reflect_weight.x - 0.04).abs() < 1e-6);
    // Radiance entering glass: (1 − F)·(1/1.5)² = 0.96/2.25.
    assert!((w.x - 0.96 / 2.25).abs() < 1e-6, "{w}");
    assert!(dir.distance(-Vec3::Z) < 1e-6);
    // Leaving glass at normal incidence: (1 − F)·1.5².
    let l = glass.delta_lobes(Vec3::Z, Vec3::Z, Vec3::Z, false);
    assert!((l.refract.unwrap().1.x - 0.96 * 2.25).abs() < 1e-5);
    // From inside beyond the critical angle: everything reflects.
    let wo = Vec3::new(0.8, 0.0, 0.6);
    let l = glass.delta_lobes(wo, Vec3::Z, Vec3::Z, false);
    assert!(l.refract.is_none());
    assert!((l.reflect_weight.x - 1.0).abs() < 1e-6);
}

#[test]
fn tilted_shading_normals_never_send_rays_to_the_wrong_side() {
    let glass = Bsdf::new(
        Vec3::ONE,
        Vec3::ZERO,
        1.0,
        [None, Some(0.5), Some(0.5)],
        1.33,
    );
    let ng = Vec3::Z;
    let mut bad = 0;
    for i in 0..200 {
        for j in 0..50 {
            let tilt = (i as f32 / 200.0) * 1.4; // up to ~80°
            let n = Vec3::new(tilt.sin(), 0.0, tilt.cos());
            let graze = 1e-4 + (j as f32 / 50.0);
            let wo = Vec3::new(-(1.0 - graze * graze).sqrt(), 0.0, graze).normalize();
            for entering in [true, false] {
                let l = glass.delta_lobes(wo, n, ng, entering);
                if l.reflect_dir.dot(ng) <= 0.0 {
                    bad += 1;
                }
                if l.refract.is_some_and(|(t, _)| t.dot(ng) >= 0.0) {
                    bad += 1;
                }
                let fr = ShadingFrame {
                    ns: n,
                    ng,
                    entering,
                };
                for k in 0..8 {
                    let u = (k as f32 + 0.5) / 8.0;
                    if let Some(s) = glass.sample(wo, u, (0.3, 0.6), &fr, TransportMode::Radiance) {
                        let crossed = s.wi.dot(ng) < 0.0;
                        if crossed != s.transmitted {
                            bad += 1;
                        }
                    }
                }
            }
        }
    }
    assert_eq!(bad, 0);
}

#[test]
fn non_delta_part_is_reciprocal() {
    let m = mixed();
    for (a, b) in [((10.0, 0.0), (50.0, 170.0)), ((70.0, 30.0), (20.0, 200.0))] {
        let (wo, wi) = (dir(a.0, a.1), dir(b.0, b.1));
        let fr = frame_z(true);
        let x = m.eval(wo, wi, &fr, TransportMode::Radiance);
        let y = m.eval(wi, wo, &fr, TransportMode::Radiance);
        assert!(x.distance(y) < 1e-6 * x.length().max(1.0), "{x} vs {y}");
        assert!(x.x > 0.0);
    }
}

/// The estimator's expected weight E[weight] over many samples (all lobes), per channel.
fn mean_weight(m: &Bsdf, wo: Vec3, fr: &ShadingFrame, mode: TransportMode, n: u32) -> Vec3 {
    let mut rng = Rng::new(3, 5);
    let mut sum = glam::DVec3::ZERO;
    for _ in 0..n {
        let u_lobe = rng.next_f32();
        if let Some(s) = m.sample(wo, u_lobe, rng.next_2d(), fr, mode) {
            sum += s.weight.as_dvec3();
        }
    }
    (sum / f64::from(n)).as_vec3()
}

#[test]
fn no_lobe_returns_more_flux_than_it_receives() {
    // In importance mode (flux), the expected sampled weight is the albedo: ≤ 1 at every
    // incidence, for each lobe alone and mixed, from both sides of a dielectric.
    let white = Vec3::ONE;
    let lobes = [
        diffuse(1.0),
        Bsdf::new(Vec3::ZERO, Vec3::ONE, 40.0, [None; 3], 1.5),
        Bsdf::new(Vec3::splat(0.7), Vec3::splat(0.3), 8.0, [None; 3], 1.5),
        Bsdf::new(white, Vec3::ZERO, 1.0, [None, Some(1.0), None], 1.5),
        Bsdf::new(white, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.5),
        Bsdf::new(white, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.33),
        mixed(),
    ];
    for (k, m) in lobes.iter().enumerate() {
        for theta in [0.0f32, 30.0, 60.0, 85.0, 89.5] {
            for entering in [true, false] {
                let wo = dir(theta, 20.0);
                let fr = frame_z(entering);
                let a = mean_weight(m, wo, &fr, TransportMode::Importance, 40_000);
                assert!(
                    a.max_element() <= 1.0 + 0.02,
                    "lobe set {k} at {theta}° (entering {entering}): albedo {a}"
                );
            }
        }
    }
    // A white mirror and a clear dielectric lose nothing: exactly 1 (every sample weighs 1).
    for m in &lobes[3..6] {
        for theta in [0.0f32, 45.0, 80.0] {
            for entering in [true, false] {
                let a = mean_weight(
                    m,
                    dir(theta, 0.0),
                    &frame_z(entering),
                    TransportMode::Importance,
                    4000,
                );
                assert!((a - Vec3::ONE).abs().max_element() < 1e-4, "{a}");
            }
        }
    }
}

#[test]
fn radiance_across_a_boundary_scales_by_the_squared_index_ratio() {
    let water = Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.33);
    let wo = dir(30.0, 0.0);
    for entering in [true, false] {
        let fr = frame_z(entering);
        // Find a transmitted sample (u_lobe near 1 picks refraction).
        let r = water
            .sample(wo, 0.999, (0.5, 0.5), &fr, TransportMode::Radiance)
            .unwrap();
        let i = water
            .sample(wo, 0.999, (0.5, 0.5), &fr, TransportMode::Importance)
            .unwrap();
        assert!(r.transmitted && i.transmitted && r.wi == i.wi);
        // ηₒ/ηᵢ = 1/1.33 looking into water, 1.33 looking out of it.
        let expected = if entering {
            1.0 / (1.33f32 * 1.33)
        } else {
            1.33 * 1.33
        };
        assert!(
            (r.weight.x / i.weight.x - expected).abs() < 1e-5,
            "{} vs {expected}",
            r.weight.x / i.weight.x
        );
        // Snell: sin θᵢ · ηᵢ = sin θₒ · ηₒ.
        let (eta_o, eta_i) = if entering { (1.0, 1.33) } else { (1.33, 1.0) };
        let sin_t = (1.0 - r.wi.z * r.wi.z).sqrt();
        assert!((sin_t * eta_i - 0.5 * eta_o).abs() < 1e-5);
    }
}

#[test]
fn sampled_weight_is_eval_times_cosine_over_pdf() {
    let m = mixed();
    let mut rng = Rng::new(9, 1);
    let (mut non_delta, mut delta) = (0, 0);
    for _ in 0..5000 {
        let wo = dir(rng.next_f32() * 89.0, rng.next_f32() * 360.0);
        let fr = frame_z(rng.next_f32() < 0.5);
        let Some(s) = m.sample(
            wo,
            rng.next_f32(),
            rng.next_2d(),
            &fr,
            TransportMode::Radiance,
        ) else {
            continue;
        };
        if s.delta {
            delta += 1;
            continue;
        }
        non_delta += 1;
        let f = m.eval(wo, s.wi, &fr, TransportMode::Radiance);
        let pdf = m.pdf(wo, s.wi, &fr);
        assert!((pdf - s.pdf).abs() <= 1e-5 * pdf, "{pdf} vs {}", s.pdf);
        let w = f * s.wi.z / pdf;
        assert!(
            w.distance(s.weight) <= 1e-4 * w.length(),
            "{w} vs {}",
            s.weight
        );
    }
    assert!(non_delta > 1000 && delta > 1000, "{non_delta} {delta}");
}

#[test]
fn pdf_integrates_to_the_probability_of_a_non_delta_sample() {
    // ∫ pdf dω over the sphere equals the fraction of samples that are non-delta and valid
    // (Phong mass below the horizon is lost, not renormalised). Lambert alone: exactly 1.
    let cases = [
        (diffuse(0.8), dir(0.0, 0.0)),
        (diffuse(0.8), dir(80.0, 0.0)),
        (
            Bsdf::new(Vec3::splat(0.3), Vec3::splat(0.5), 30.0, [None; 3], 1.5),
            dir(60.0, 10.0),
        ),
        (mixed(), dir(45.0, 0.0)),
        (mixed(), dir(85.0, 0.0)),
    ];
    for (k, (m, wo)) in cases.iter().enumerate() {
        let fr = frame_z(true);
        let integral = integrate_sphere(|wi| f64::from(m.pdf(*wo, wi, &fr)));
        let n = 200_000;
        let mut rng = Rng::new(4, k as u64);
        let hits = (0..n)
            .filter(|_| {
                let u = rng.next_f32();
                m.sample(*wo, u, rng.next_2d(), &fr, TransportMode::Radiance)
                    .is_some_and(|s| !s.delta)
            })
            .count();
        let frac = hits as f64 / f64::from(n);
        // Binomial σ ≤ 0.0012 at n = 200k; quadrature error ~1e-3 near Phong peaks.
        assert!(
            (integral - frac).abs() < 0.006,
            "case {k}: ∫pdf = {integral}, sampled fraction {frac}"
        );
        if k < 2 {
            assert!((integral - 1.0).abs() < 2e-3, "Lambert: {integral}");
        }
    }
}

#[test]
fn adjoint_correction_is_one_without_shading_normals_and_matches_veach() {
    let m = diffuse(0.5);
    let wo = dir(40.0, 0.0);
    let flat = frame_z(true);
    let s = m
        .sample(wo, 0.1, (0.3, 0.7), &flat, TransportMode::Importance)
        .unwrap();
    let r = m
        .sample(wo, 0.1, (0.3, 0.7), &flat, TransportMode::Radiance)
        .unwrap();
    assert!(s.weight.distance(r.weight) < 1e-6);
    // Tilted shading normal: importance weight = radiance weight · |wo·ns||wi·ng|/(|wo·ng||wi·ns|).
    let ns = Vec3::new(0.2, 0.0, 1.0).normalize();
    let fr = ShadingFrame {
        ns,
        ng: Vec3::Z,
        entering: true,
    };
    let s = m
        .sample(wo, 0.1, (0.3, 0.7), &fr, TransportMode::Importance)
        .unwrap();
    let r = m
        .sample(wo, 0.1, (0.3, 0.7), &fr, TransportMode::Radiance)
        .unwrap();
    let c = wo.dot(ns).abs() * s.wi.z.abs() / (wo.z.abs() * s.wi.dot(ns).abs());
    assert!((s.weight.x / r.weight.x - c).abs() < 1e-5);
    // Lambert sampled about ns weighs ρ in radiance mode, so by hand the importance weight is
    // ρ·|wo·ns||wi·ng|/(|wo·ng||wi·ns|).
    let hand = 0.5 * wo.dot(ns) * s.wi.z / (wo.z * s.wi.dot(ns));
    assert!((s.weight.x - hand).abs() < 1e-5, "{} vs {hand}", s.weight.x);
}

/// χ² goodness of fit of `sample` against `pdf` (pbrt-v4's and Mitsuba 3's BSDF test, our own
/// code in `sampling::chi2`): non-delta samples histogrammed over the sphere; delta samples and
/// lost ones go to the "outside" cell, whose expected share is 1 − ∫pdf.
fn chi2_of(m: &Bsdf, wo: Vec3, fr: &ShadingFrame, seed: u64) -> crate::sampling::chi2::Chi2Result {
    use crate::sampling::chi2::{SphereBins, chi2_test};
    let bins = SphereBins::sphere(Vec3::Z, 16, 32);
    chi2_test(
        100_000,
        seed,
        &bins,
        |rng| {
            let u = rng.next_f32();
            m.sample(wo, u, rng.next_2d(), fr, TransportMode::Radiance)
                .filter(|s| !s.delta)
                .map(|s| s.wi)
        },
        |wi| m.pdf(wo, wi, fr),
    )
}

#[test]
fn chi2_sample_follows_pdf_for_every_lobe_and_mixture_at_normal_and_grazing_incidence() {
    use crate::sampling::chi2::sidak_alpha;
    let lobes = [
        ("lambert", diffuse(0.8)),
        (
            "phong m=5",
            Bsdf::new(Vec3::ZERO, Vec3::ONE, 5.0, [None; 3], 1.5),
        ),
        (
            "phong m=40",
            Bsdf::new(Vec3::ZERO, Vec3::ONE, 40.0, [None; 3], 1.5),
        ),
        (
            "lambert+phong",
            Bsdf::new(Vec3::splat(0.5), Vec3::splat(0.4), 15.0, [None; 3], 1.5),
        ),
        ("mixed", mixed()),
        (
            "diffuse+glass",
            Bsdf::new(
                Vec3::splat(0.6),
                Vec3::ZERO,
                1.0,
                [Some(0.5), None, Some(0.5)],
                1.33,
            ),
        ),
    ];
    let angles = [0.0f32, 80.0];
    let tests = lobes.len() * angles.len() * 2;
    let alpha = sidak_alpha(0.01, tests);
    let mut report = Vec::new();
    for (k, (name, m)) in lobes.iter().enumerate() {
        for (j, theta) in angles.iter().enumerate() {
            for entering in [true, false] {
                let wo = dir(*theta, 30.0);
                let r = chi2_of(m, wo, &frame_z(entering), (k * 10 + j) as u64);
                report.push(format!(
                    "{name} at {theta}° (entering {entering}): χ² {:.1}, dof {}, p {:.3}",
                    r.statistic, r.dof, r.p_value
                ));
                assert!(r.dof >= 10, "{}", report.last().unwrap_or(&String::new()));
                assert!(
                    r.impossible == 0 && r.passes(alpha),
                    "{}\n(α = {alpha:.2e} after Šidák over {tests} tests)",
                    report.last().unwrap_or(&String::new())
                );
            }
        }
    }
    println!("{}", report.join("\n"));
}

#[test]
fn chi2_rejects_a_pdf_that_does_not_match_the_sampler() {
    // Control: the Phong sampler tested against the density of a different exponent.
    let m = Bsdf::new(Vec3::ZERO, Vec3::ONE, 20.0, [None; 3], 1.5);
    let wrong = Bsdf::new(Vec3::ZERO, Vec3::ONE, 24.0, [None; 3], 1.5);
    let wo = dir(30.0, 0.0);
    let fr = frame_z(true);
    let r = crate::sampling::chi2::chi2_test(
        100_000,
        1,
        &crate::sampling::chi2::SphereBins::sphere(Vec3::Z, 16, 32),
        |rng| {
            let u = rng.next_f32();
            m.sample(wo, u, rng.next_2d(), &fr, TransportMode::Radiance)
                .map(|s| s.wi)
        },
        |wi| wrong.pdf(wo, wi, &fr),
    );
    assert!(r.p_value < 1e-6, "{r:?}");
}

#[test]
fn lobe_number_matters_exactly_where_lobe_choice_matters_says() {
    let c = Vec3::new(0.7, 0.5, 0.3);
    let materials = [
        ("lambert", diffuse(0.8)),
        ("black", diffuse(0.0)),
        (
            "phong only",
            Bsdf::new(
                Vec3::ZERO,
                Vec3::splat(0.4),
                30.0,
                [Some(1.0), None, None],
                1.5,
            ),
        ),
        (
            "mirror",
            Bsdf::new(c, Vec3::ZERO, 1.0, [None, Some(1.0), None], 1.5),
        ),
        (
            "glass",
            Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.5),
        ),
        (
            "lambert + phong",
            Bsdf::new(c, Vec3::splat(0.25), 20.0, [Some(1.0), None, None], 1.5),
        ),
        (
            "lambert + mirror",
            Bsdf::new(c, Vec3::ZERO, 1.0, [Some(0.5), Some(0.5), None], 1.5),
        ),
        ("mixed", mixed()),
    ];
    let mut rng = Rng::new(41, 2);
    for (name, m) in materials {
        let mut differs = false;
        for entering in [true, false] {
            let fr = frame_z(entering);
            for wo in [dir(10.0, 30.0), dir(80.0, 200.0)] {
                let wo = if entering { wo } else { -wo };
                for _ in 0..200 {
                    let u = rng.next_2d();
                    let first = m.sample(wo, 0.0, u, &fr, TransportMode::Radiance);
                    for k in 1..16 {
                        let other = m.sample(wo, k as f32 / 16.0, u, &fr, TransportMode::Radiance);
                        differs |= other != first;
                    }
                }
            }
        }
        assert_eq!(differs, m.lobe_choice_matters(), "{name}");
    }
}

#[test]
fn roughness_zero_without_a_conductor_is_the_smooth_bsdf_bit_for_bit() {
    let b = mixed();
    assert_eq!(b.with_microfacets(None, None), b);
    assert_eq!(
        format!("{:?}", b.with_microfacets(None, None)),
        format!("{b:?}")
    );
}

#[test]
fn rough_parts_are_glossy_and_index_matched_rough_glass_stays_a_pass_through() {
    let g = Ggx::isotropic(0.09);
    let glass = Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.5)
        .with_microfacets(Some(g), None);
    assert!(
        glass
            .flags()
            .contains(LobeFlags::GLOSSY | LobeFlags::TRANSMISSION)
    );
    assert!(!glass.has_delta() && glass.has_local() && !glass.is_diffuse_only());
    // η = 1: the smooth dielectric's exact pass-through at any roughness (the furnace with
    // index-matched glass vanishes): every sample continues straight with weight 1.
    let matched = Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.0);
    assert_eq!(matched.with_microfacets(Some(g), None), matched);
    let wo = dir(40.0, 10.0);
    let s = matched
        .with_microfacets(Some(Ggx::isotropic(1.0)), None)
        .sample(
            wo,
            0.7,
            (0.3, 0.6),
            &frame_z(true),
            TransportMode::Importance,
        )
        .expect("a sample");
    assert!(s.wi.distance(-wo) < 1e-6 && s.weight.distance(Vec3::ONE) < 1e-6);
}

#[test]
fn rough_glass_samples_transmit_with_weight_f_cos_over_pdf_and_the_eta_scale() {
    let g = Ggx::isotropic(0.25);
    let glass = Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.5)
        .with_microfacets(Some(g), None);
    let fr = frame_z(true);
    let wo = dir(30.0, 0.0);
    let mut rng = Rng::new(3, 1);
    let (mut transmitted, mut sum) = (0, 0.0f64);
    let n = 20_000;
    for _ in 0..n {
        let Some(s) = glass.sample(
            wo,
            rng.next_f32(),
            rng.next_2d(),
            &fr,
            TransportMode::Importance,
        ) else {
            continue;
        };
        // The sample agrees with eval and pdf.
        let f = glass.eval(wo, s.wi, &fr, TransportMode::Importance);
        let pdf = glass.pdf(wo, s.wi, &fr);
        assert!(
            (s.pdf - pdf).abs() <= 1e-4 * pdf.max(1.0),
            "{} vs {pdf}",
            s.pdf
        );
        let w = f * (s.wi.z.abs() / pdf);
        assert!(w.distance(s.weight) <= 1e-3 * w.length().max(1.0));
        if s.transmitted {
            transmitted += 1;
            assert!(s.wi.z < 0.0 && s.eta_scale == 1.0);
        }
        sum += f64::from(s.weight.x);
    }
    // Most light enters glass at 30°; flux is conserved up to single-scattering loss (≤ 1).
    assert!(transmitted > n * 8 / 10, "{transmitted}");
    let albedo = sum / f64::from(n);
    assert!(albedo <= 1.0 + 5e-3 && albedo > 0.95, "{albedo}");
    // Radiance mode: a refraction reports (ηₒ/ηᵢ)² = 1/1.5².
    let s = (0..64)
        .filter_map(|i| {
            glass.sample(
                wo,
                0.99,
                ((i as f32 + 0.5) / 64.0, 0.3),
                &fr,
                TransportMode::Radiance,
            )
        })
        .find(|s| s.transmitted)
        .expect("a refraction");
    assert!((s.eta_scale - 1.0 / 2.25).abs() < 1e-6);
}

#[test]
fn the_lambert_fast_path_gives_the_general_mixtures_numbers_bit_for_bit() {
    // The same matte BSDFs with the fast path switched off: every query must return the same
    // bits, in both modes, for directions on both sides and tilted shading normals, black and
    // coloured tints (a black Phong lobe, no Phong lobe, and a weight below 1 are all matte).
    let no_phong = {
        let d = diffuse(0.6);
        let mut parts = d.parts;
        parts[0].lobes[1] = None;
        Bsdf::with_parts(d.tint, parts)
    };
    let matte = [
        diffuse(0.6),
        diffuse(0.0),
        no_phong,
        Bsdf::new(
            Vec3::new(0.9, 0.2, 0.0),
            Vec3::ZERO,
            50.0,
            [Some(0.5), None, None],
            1.5,
        ),
    ];
    let frames = [
        frame_z(true),
        ShadingFrame {
            ns: Vec3::new(0.3, 0.0, 1.0).normalize(),
            ng: Vec3::Z,
            entering: false,
        },
    ];
    let mut rng = Rng::new(17, 0);
    for m in matte {
        assert!(m.is_lambert());
        for fr in &frames {
            for _ in 0..200 {
                let wo = crate::sampling::warp::uniform_sphere(rng.next_2d());
                let wi = crate::sampling::warp::uniform_sphere(rng.next_2d());
                let (fast, slow) = (m.at(wo, fr), BsdfAt::general(&m, wo, fr));
                assert!(fast.is_lambert() && !slow.is_lambert());
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    assert_eq!(
                        fast.eval(wi, mode).to_array().map(f32::to_bits),
                        slow.eval(wi, mode).to_array().map(f32::to_bits)
                    );
                    assert_eq!(
                        m.eval(wo, wi, fr, mode).to_array().map(f32::to_bits),
                        slow.eval(wi, mode).to_array().map(f32::to_bits)
                    );
                    let (u_lobe, u) = (rng.next_f32(), rng.next_2d());
                    assert_eq!(
                        format!("{:?}", fast.sample(u_lobe, u, mode)),
                        format!("{:?}", slow.sample(u_lobe, u, mode))
                    );
                }
                assert_eq!(fast.pdf(wi).to_bits(), slow.pdf(wi).to_bits());
            }
        }
    }
    // Anything with a lit Phong lobe, a mirror or glass is not matte.
    assert!(!mixed().is_lambert());
    assert!(!Bsdf::new(Vec3::ONE, Vec3::splat(0.1), 10.0, [None; 3], 1.5).is_lambert());
    assert!(
        !Bsdf::new(
            Vec3::ONE,
            Vec3::ZERO,
            1.0,
            [Some(0.5), Some(0.5), None],
            1.5
        )
        .is_lambert()
    );
}
