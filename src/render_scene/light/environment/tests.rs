//! The environment light: its map convention, bilinear lookup, densities (χ², normalisation)
//! and irradiance against independent quadrature.

use super::*;
use crate::render_scene::light::test_support::stratified;
use crate::sampling::Rng;
use crate::sampling::chi2::{SphereBins, chi2_test, integrate_sphere, pearson, sidak_alpha};

fn scene() -> SceneSphere {
    SceneSphere::new(Vec3::ZERO, 3.0)
}

/// A 16 × 8 test sky: dim gradient, a black band, and a bright 2 × 1 "sun" texel pair.
fn sky(rotation: f32) -> EnvironmentLight {
    let (w, h) = (16, 8);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if y == 5 {
                Vec3::ZERO
            } else if y == 2 && (x == 3 || x == 4) {
                Vec3::new(40.0, 30.0, 20.0)
            } else {
                Vec3::new(0.2, 0.3, 0.5) * (1.0 + x as f32 / 16.0)
            }
        })
        .collect();
    EnvironmentLight::image(w, h, texels, rotation, scene()).unwrap()
}

#[test]
fn the_map_convention_is_mitsubas() {
    // +y is the zenith (v = 0), −z is u = 0, +x is u = ¼, +z is u = ½.
    let (_, v) = direction_to_uv(Vec3::Y);
    assert!(v < 1e-6);
    let (u, v) = direction_to_uv(Vec3::NEG_Z);
    assert!(u < 1e-6 && (v - 0.5).abs() < 1e-6);
    assert!((direction_to_uv(Vec3::X).0 - 0.25).abs() < 1e-6);
    assert!((direction_to_uv(Vec3::Z).0 - 0.5).abs() < 1e-6);
    let mut rng = Rng::new(1, 0);
    for _ in 0..1000 {
        let (u, v) = rng.next_2d();
        let (d, sin_t) = uv_to_direction(u, v);
        let (u2, v2) = direction_to_uv(d);
        assert!((sin_t - (1.0 - d.y * d.y).max(0.0).sqrt()).abs() < 1e-5);
        if sin_t > 1e-3 {
            let du = (u2 - u).abs().min(1.0 - (u2 - u).abs());
            assert!(du < 1e-4 && (v2 - v).abs() < 1e-4, "{u},{v} → {u2},{v2}");
        }
    }
    // Rotation by 90° about +y takes the map's −z (column 0) to the world's −x.
    let l = sky(std::f32::consts::FRAC_PI_2);
    let unrotated = sky(0.0);
    let (d, _) = uv_to_direction(3.5 / 16.0, 2.5 / 8.0);
    let world = l.to_world(d);
    assert!((l.le(world) - unrotated.le(d)).abs().max_element() < 1e-4);
    assert!((l.to_world(Vec3::NEG_Z) - Vec3::NEG_X).length() < 1e-6);
}

#[test]
fn lookups_hit_texel_centres_exactly_and_interpolate_between() {
    let l = sky(0.0);
    let EnvironmentMap::Image { texels, .. } = &l.map else {
        unreachable!()
    };
    for (x, y) in [(3usize, 2usize), (0, 0), (15, 7), (8, 4)] {
        let (d, _) = uv_to_direction((x as f32 + 0.5) / 16.0, (y as f32 + 0.5) / 8.0);
        let got = l.le(d);
        assert!(
            (got - texels[y * 16 + x]).abs().max_element() < 2e-3 * got.max_element().max(1.0),
            "({x},{y})"
        );
    }
    // Halfway between texels (4, 2) and (5, 2): the mean of the two.
    let (d, _) = uv_to_direction(5.0 / 16.0, 2.5 / 8.0);
    let want = (texels[2 * 16 + 4] + texels[2 * 16 + 5]) * 0.5;
    assert!((l.le(d) - want).abs().max_element() < 1e-2);
    // Wrapping: halfway between the last and the first column.
    let (d, _) = uv_to_direction(0.0, 0.5 / 8.0);
    let want = (texels[0] + texels[15]) * 0.5;
    assert!((l.le(d) - want).abs().max_element() < 1e-4);
}

/// χ² of directions binned on a `(u, v)` grid of the map's frame (each texel split 2 × 2, so
/// bins never straddle a texel edge) against the counts `pdf` predicts: the integral over each
/// bin of `pdf(ω) dω = pdf(ω(u, v)) · 2π² sin θ du dv` by the midpoint rule on 4 × 4 points
/// (exact when `pdf` is the map's piecewise-constant density over `2π² sin θ`, the claim under
/// test; a wrong Jacobian or a misplaced map makes the product vary and the counts disagree).
/// Solid-angle bins would not do here: `pdf_li` is discontinuous along every texel edge and
/// grows as 1/sin θ towards the poles, which defeats the sphere histogram's quadrature.
fn chi2_uv(
    l: &EnvironmentLight,
    seed: u64,
    mut sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
) -> crate::sampling::chi2::Chi2Result {
    let (bu, bv) = (32usize, 16usize);
    let n = 400_000;
    let mut counts = vec![0u64; bu * bv + 1];
    let mut rng = Rng::new(seed, 0);
    for _ in 0..n {
        match sample(&mut rng) {
            Some(w) => {
                let (u, v) = direction_to_uv(l.to_map(w));
                counts[((v * bv as f32) as usize).min(bv - 1) * bu
                    + ((u * bu as f32) as usize).min(bu - 1)] += 1;
            }
            None => counts[bu * bv] += 1,
        }
    }
    let mut expected: Vec<f64> = uv_bin_mass(l, bu, bv, &pdf)
        .iter()
        .map(|p| p * f64::from(n))
        .collect();
    let inside: f64 = expected.iter().sum();
    expected.push((f64::from(n) - inside).max(0.0));
    pearson(&counts, &expected)
}

/// The mass `pdf` gives each of `bu × bv` bins of the map's `(u, v)` (see [`chi2_uv`]).
fn uv_bin_mass(l: &EnvironmentLight, bu: usize, bv: usize, pdf: &impl Fn(Vec3) -> f32) -> Vec<f64> {
    let sub = 4;
    let (du, dv) = (1.0 / (bu * sub) as f64, 1.0 / (bv * sub) as f64);
    (0..bu * bv)
        .map(|b| {
            let (bx, by) = (b % bu, b / bu);
            let mut p = 0.0;
            for j in 0..sub {
                for i in 0..sub {
                    let u = ((bx * sub + i) as f64 + 0.5) * du;
                    let v = ((by * sub + j) as f64 + 0.5) * dv;
                    let (d, sin_t) = uv_to_direction(u as f32, v as f32);
                    let jac = 2.0 * std::f64::consts::PI.powi(2) * f64::from(sin_t);
                    p += f64::from(pdf(l.to_world(d))) * jac * du * dv;
                }
            }
            p
        })
        .collect()
}

#[test]
fn sample_li_passes_chi2_against_pdf_li_and_a_wrong_pdf_fails() {
    let alpha = sidak_alpha(0.01, 4);
    // The image map, in the map's (u, v).
    let l = sky(0.7);
    let li = chi2_uv(
        &l,
        1,
        |rng| l.sample_li(Vec3::ZERO, rng.next_2d()).map(|s| s.wi),
        |w| l.pdf_li(Vec3::ZERO, w),
    );
    eprintln!("environment sample_li χ² image: {li:?}");
    assert!(li.passes(alpha) && li.dof > 400, "{li:?}");
    let le = chi2_uv(
        &l,
        2,
        |rng| l.sample_le(rng.next_2d(), rng.next_2d()).map(|s| -s.dir),
        |w| l.pdf_le(-w).1,
    );
    eprintln!("environment sample_le dir χ² image: {le:?}");
    assert!(le.passes(alpha) && le.dof > 400, "{le:?}");
    // Its density has unit mass (exactly, in (u, v); and by the sphere quadrature, which the
    // 1/sin θ poles and texel edges limit to ~1e-4).
    let mass: f64 = uv_bin_mass(&l, 32, 16, &|w| l.pdf_li(Vec3::ZERO, w))
        .iter()
        .sum();
    assert!((mass - 1.0).abs() < 1e-5, "{mass}");
    let sphere = integrate_sphere(Vec3::Y, |w| l.pdf_li(Vec3::ZERO, w));
    assert!((sphere - 1.0).abs() < 1e-3, "{sphere}");
    // Wrong claims are rejected: the uniform density, the unrotated map's density, and the
    // map's density without the sin θ of the Jacobian (renormalised).
    let sample = |rng: &mut Rng| l.sample_li(Vec3::ZERO, rng.next_2d()).map(|s| s.wi);
    let uniform = chi2_uv(&l, 4, sample, |_| 1.0 / (4.0 * PI));
    let unrotated = sky(0.0);
    let turned = chi2_uv(&l, 5, sample, |w| unrotated.pdf_li(Vec3::ZERO, w));
    let no_jacobian = chi2_uv(&l, 6, sample, |w| {
        let d = l.to_map(w);
        l.pdf_li(Vec3::ZERO, w) * (d.x * d.x + d.z * d.z).sqrt() * (PI / 4.0) * PI
    });
    eprintln!(
        "environment χ² wrong pdfs (must fail): uniform {:.0}, unrotated {:.0}, no sin θ {:.0}",
        uniform.statistic, turned.statistic, no_jacobian.statistic
    );
    assert!(uniform.p_value < 1e-6 && turned.p_value < 1e-6 && no_jacobian.p_value < 1e-6);
    // The constant environment, in solid-angle bins.
    let c = EnvironmentLight::constant(Vec3::ONE, scene());
    let bins = SphereBins::sphere(Vec3::Y, 24, 48);
    let r = chi2_test(
        400_000,
        7,
        &bins,
        |rng| c.sample_li(Vec3::ZERO, rng.next_2d()).map(|s| s.wi),
        |w| c.pdf_li(Vec3::ZERO, w),
    );
    eprintln!("environment sample_li χ² constant: {r:?}");
    assert!(r.passes(alpha) && r.rejected == 0 && r.dof > 500, "{r:?}");
    let e = chi2_test(
        400_000,
        8,
        &bins,
        |rng| c.sample_le(rng.next_2d(), rng.next_2d()).map(|s| s.dir),
        |w| c.pdf_le(w).1,
    );
    eprintln!("environment sample_le dir χ² constant: {e:?}");
    assert!(e.passes(alpha) && e.rejected == 0, "{e:?}");
}

/// E at the origin on a plane of normal `n`, by quadrature of `le` (θ, φ midpoint rule).
fn quadrature_irradiance(l: &EnvironmentLight, n: Vec3) -> f64 {
    let (nt, np) = (800, 1600);
    let mut e = 0.0;
    for i in 0..nt {
        let theta = std::f64::consts::PI * (i as f64 + 0.5) / nt as f64;
        for j in 0..np {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5) / np as f64;
            let w = Vec3::new(
                (theta.sin() * phi.cos()) as f32,
                theta.cos() as f32,
                (theta.sin() * phi.sin()) as f32,
            );
            let cos = f64::from(w.dot(n).max(0.0));
            e += f64::from(l.le(w).y) * cos * theta.sin();
        }
    }
    e * (std::f64::consts::PI / nt as f64) * (std::f64::consts::TAU / np as f64)
}

#[test]
fn irradiance_matches_quadrature_and_a_constant_sky_gives_pi_l() {
    let l = sky(0.3);
    for n in [Vec3::Y, Vec3::new(0.6, 0.2, -0.77).normalize()] {
        let want = quadrature_irradiance(&l, n);
        let mut rng = Rng::new(3, 0);
        let k = 512;
        let got: f64 = stratified(k, &mut rng)
            .filter_map(|u| l.sample_li(Vec3::ZERO, u))
            .map(|s| f64::from(s.weight.y) * f64::from(s.wi.dot(n).max(0.0)))
            .sum::<f64>()
            / (k * k) as f64;
        eprintln!("environment E n={n}: NEE {got:.6} quadrature {want:.6}");
        assert!((got / want - 1.0).abs() < 3e-3, "{got} vs {want}");
    }
    // A constant sky, and a constant image, give E = π L on any plane.
    let flat = EnvironmentLight::image(8, 4, vec![Vec3::splat(0.5); 32], 1.0, scene()).unwrap();
    for l in [EnvironmentLight::constant(Vec3::splat(0.5), scene()), flat] {
        let mut rng = Rng::new(4, 0);
        let k = 512;
        let e: f64 = stratified(k, &mut rng)
            .filter_map(|u| l.sample_li(Vec3::ZERO, u))
            .map(|s| f64::from(s.weight.x) * f64::from(s.wi.y.max(0.0)))
            .sum::<f64>()
            / (k * k) as f64;
        assert!((e / (0.5 * std::f64::consts::PI) - 1.0).abs() < 2e-3, "{e}");
        assert!((l.power().x / (0.5 * 4.0 * PI * l.scene.disc_area()) - 1.0).abs() < 1e-4);
    }
}

#[test]
fn photon_flux_matches_the_power_estimate() {
    let l = sky(0.0);
    let mut rng = Rng::new(6, 0);
    let n = 400_000;
    let flux: f64 = (0..n)
        .filter_map(|_| l.sample_le(rng.next_2d(), rng.next_2d()))
        .map(|s| f64::from(s.le.y / (s.pdf_pos * s.pdf_dir)))
        .sum::<f64>()
        / f64::from(n);
    // The photons carry π R² ∫ (bilinear L) dω; power() sums texels × solid angles: the two
    // differ by the interpolation's smoothing of the 2-texel sun (a few %), plus noise.
    let p = f64::from(l.power().y);
    eprintln!("environment photon flux {flux:.4} vs power estimate {p:.4}");
    assert!((flux / p - 1.0).abs() < 0.05, "{flux} vs {p}");
}

#[test]
fn bad_maps_are_errors_and_black_maps_emit_nothing() {
    let e = EnvironmentLight::image(4, 2, vec![Vec3::ONE; 7], 0.0, scene()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "environment map: 4×2 needs 8 texels, found 7"
    );
    let mut t = vec![Vec3::ONE; 8];
    t[5] = Vec3::new(1.0, f32::NAN, 0.0);
    let e = EnvironmentLight::image(4, 2, t, 0.0, scene()).unwrap_err();
    assert!(
        matches!(e, EnvironmentError::Texel { x: 1, y: 1, .. }),
        "{e}"
    );
    let black = EnvironmentLight::image(4, 2, vec![Vec3::ZERO; 8], 0.0, scene()).unwrap();
    assert!(black.sample_li(Vec3::ZERO, (0.5, 0.5)).is_none());
    assert_eq!(black.pdf_li(Vec3::ZERO, Vec3::Y), 0.0);
    assert!(black.sample_le((0.5, 0.5), (0.5, 0.5)).is_none());
}
