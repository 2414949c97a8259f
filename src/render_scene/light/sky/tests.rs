//! The Preetham sky against hand computations of the paper's formulas, its normalisation, the
//! unit rule tying it to the sun, the ground rule, and its sampling densities.

use super::*;
use crate::sampling::Rng;
use crate::sampling::warp::uniform_sphere;

fn scene() -> SceneSphere {
    SceneSphere::new(Vec3::ZERO, 2.0)
}

#[test]
fn zenith_luminance_matches_a_hand_computation() {
    // T = 3, sun 50° above the horizon (θs = 40° = 0.698132 rad):
    // χ = (4/9 − 3/120)(π − 2·0.698132) = 0.419444 · 1.745329 = 0.732069,
    // tan χ = 0.898890, Y_z = (12.1359 − 4.9710)·0.898890 − 0.6465 + 2.4192
    //     = 6.440470 + 1.7727 = 8.21317 kcd/m² (to the digits carried by hand; 8.211436 exactly).
    let yz = zenith_luminance(3.0, 40f64.to_radians());
    assert!((yz - 8.2114).abs() < 2e-3, "{yz}");
    // Sun at the zenith (θs = 0), T = 2: χ = (4/9 − 1/60) π = 1.343904,
    // tan χ = 1/tan(π/2 − χ) = 1/tan(0.226893) = 4.33152,
    // Y_z = (8.0906 − 4.9710)·4.33152 − 0.431 + 2.4192 = 13.51251 + 1.9882 = 15.5007.
    let yz = zenith_luminance(2.0, 0.0);
    assert!((yz - 15.5007).abs() < 1e-3, "{yz}");
    // Zenith chromaticity, T = 3, θs = 40°: x_z = 0.24772, y_z = 0.25348 (the two cubics by hand).
    let (x, y) = zenith_chromaticity(3.0, 40f64.to_radians());
    assert!(
        (x - 0.24772).abs() < 1e-4 && (y - 0.25348).abs() < 1e-4,
        "{x} {y}"
    );
}

#[test]
fn the_distribution_is_normalised_at_the_zenith() {
    let sun = DVec3::new(-0.63, 0.766, 0.12);
    let m = SkyModel::new(sun, 3.0).unwrap();
    // At the zenith θ = 0 and γ = θs: Y = Y_z, x = x_z, y = y_z exactly.
    let (l, x, y) = m.xyy(DVec3::Y);
    let (lz, xz, yz) = m.zenith;
    assert!((l / lz - 1.0).abs() < 1e-12 && (x / xz - 1.0).abs() < 1e-12);
    assert!((y / yz - 1.0).abs() < 1e-12);
    // Elsewhere Y/Y_z = F(θ, γ)/F(0, θs), F written out here from the paper.
    let ts = (0.766 / sun.length()).acos(); // θs of the unit sun
    let c = perez_y(3.0);
    let f = |cos_t: f64, g: f64| {
        (1.0 + c[0] * (c[1] / cos_t).exp())
            * (1.0 + c[2] * (c[3] * g).exp() + c[4] * g.cos().powi(2))
    };
    let w = DVec3::new(0.3, 0.4, -0.5).normalize();
    let gamma = w.dot(sun.normalize()).acos();
    let (lw, _, _) = m.xyy(w);
    assert!((lw / lz - f(w.y, gamma) / f(1.0, ts)).abs() < 1e-12);
    // The sky is brighter towards the sun than away from it, at the same height.
    let towards = DVec3::new(-0.63, 0.3, 0.12).normalize();
    let away = DVec3::new(0.63, 0.3, -0.12).normalize();
    assert!(m.xyy(towards).0 > 2.0 * m.xyy(away).0);
    // A clear sky is blue: more blue than red at the zenith.
    let rgb = m.rgb(DVec3::Y);
    assert!(rgb.z > rgb.x, "{rgb}");
    // Its luminance is the model's Y.
    assert!((0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z - lz).abs() < 1e-3 * lz);
}

#[test]
fn the_unit_rule_keeps_the_sun_to_sky_ratio() {
    let dir = Vec3::new(0.0, 0.5, 0.866_025_4); // 30° above the horizon: θs = 60°, m = 2
    let e = Vec3::new(30.0, 30.0, 30.0);
    let sky = SkyLight::new(
        SkySun::Light {
            direction: dir,
            irradiance: e,
        },
        3.0,
        Vec3::splat(0.2),
        1.0,
        scene(),
    )
    .unwrap();
    // E_dn = 127500 · exp(−0.21 · 2) = 83 777 lux; k = 30 / E_dn.
    let e_dn = 127_500.0 * (-0.42f64).exp();
    // (The f32 direction makes cos θs = 0.5 to a few 1e-8: m = 2 to that precision.)
    assert!(
        (sky.k - 30.0 / e_dn).abs() < 1e-6 * sky.k,
        "{} vs {}",
        sky.k,
        30.0 / e_dn
    );
    // Twice the sun: twice the sky (the ratio is kept).
    let twice = SkyLight::new(
        SkySun::Light {
            direction: dir,
            irradiance: e * 2.0,
        },
        3.0,
        Vec3::splat(0.2),
        1.0,
        scene(),
    )
    .unwrap();
    let w = Vec3::new(0.2, 0.7, 0.1).normalize();
    assert!(
        (twice.map.le(w) / sky.map.le(w) - Vec3::splat(2.0))
            .abs()
            .max_element()
            < 1e-5
    );
    // A sun given only by direction: 1 scene unit per kcd/m² (zenith texel ≈ Y_z / 1000).
    let bare = SkyLight::new(SkySun::Direction(dir), 3.0, Vec3::ZERO, 1.0, scene()).unwrap();
    let y = luminance(bare.map.le(Vec3::Y));
    assert!(
        (y / (bare.model.zenith.0 / 1000.0) - 1.0).abs() < 0.01,
        "{y}"
    );
    // Out of range.
    assert!(matches!(
        SkyLight::new(
            SkySun::Direction(Vec3::new(1.0, -0.1, 0.0)),
            3.0,
            Vec3::ZERO,
            1.0,
            scene()
        ),
        Err(SkyError::SunBelowHorizon(_))
    ));
    assert!(matches!(
        SkyLight::new(SkySun::Direction(dir), 12.0, Vec3::ZERO, 1.0, scene()),
        Err(SkyError::Turbidity(_))
    ));
}

#[test]
fn the_ground_is_lit_by_sky_and_sun() {
    let dir = Vec3::new(-0.63, 0.766, 0.12);
    let e = Vec3::new(30.0, 27.9, 25.2);
    let albedo = Vec3::new(0.3, 0.25, 0.2);
    let sky = SkyLight::new(
        SkySun::Light {
            direction: dir,
            irradiance: e,
        },
        3.0,
        albedo,
        1.0,
        scene(),
    )
    .unwrap();
    // The sky's horizontal irradiance by Monte Carlo over the upper hemisphere of the map's
    // interpolated radiance (independent of the texel sum the ground uses).
    let mut rng = Rng::new(5, 0);
    let n = 400_000;
    let mut e_sky = DVec3::ZERO;
    for _ in 0..n {
        let w = uniform_sphere(rng.next_2d());
        if w.y > 0.0 {
            e_sky += sky.map.le(w).as_dvec3() * f64::from(w.y) * (4.0 * PI);
        }
    }
    e_sky /= f64::from(n);
    let cos_s = f64::from(dir.normalize().y);
    let expect = albedo.as_dvec3() * (e_sky + e.as_dvec3() * cos_s) / PI;
    let ground = sky.map.le(Vec3::new(0.1, -0.5, 0.3).normalize()).as_dvec3();
    let rel = ((ground - expect) / expect).abs().max_element();
    assert!(rel < 0.01, "ground {ground} expected {expect}");
    // Physically the sun outshines the sky on the ground: E_sun cos θs ≫ E_sky (clear sky:
    // diffuse illuminance is 10–25 % of the global one).
    let ratio = luminance(e_sky.as_vec3()) / (luminance(e) * cos_s + luminance(e_sky.as_vec3()));
    assert!((0.05..0.35).contains(&ratio), "diffuse fraction {ratio}");
}

#[test]
fn sampling_density_integrates_to_one_and_follows_the_radiance() {
    let sky = SkyLight::new(
        SkySun::Direction(Vec3::new(0.4, 0.5, -0.3)),
        4.0,
        Vec3::splat(0.3),
        1.0,
        scene(),
    )
    .unwrap();
    let l = &sky.map;
    let mut rng = Rng::new(9, 0);
    let n = 400_000;
    // ∫ pdf dω over the sphere = 1 (uniform directions).
    let mut total = 0.0f64;
    for _ in 0..n {
        let w = uniform_sphere(rng.next_2d());
        total += f64::from(l.pdf_li(Vec3::ZERO, w)) * 4.0 * PI;
    }
    total /= f64::from(n);
    assert!((total - 1.0).abs() < 0.01, "∫ pdf = {total}");
    // The light-sampled estimate of ∫ L dω (luminance) agrees with the uniform one.
    // pdf_li of a sampled direction is the density it was sampled with, except where the
    // direction's (u, v) rounds into the neighbouring cell across a jump of the density (the
    // horizon, where sky meets ground): rare.
    let (mut by_light, mut uniform, mut mismatched) = (0.0f64, 0.0f64, 0u32);
    for _ in 0..n {
        if let Some(s) = l.sample_li(Vec3::ZERO, rng.next_2d()) {
            if (s.pdf / l.pdf_li(Vec3::ZERO, s.wi) - 1.0).abs() > 1e-3 {
                mismatched += 1;
            }
            by_light += luminance(s.weight);
        }
        let w = uniform_sphere(rng.next_2d());
        uniform += luminance(l.le(w)) * 4.0 * PI;
    }
    assert!(
        mismatched < n / 1000,
        "{mismatched} of {n} samples' pdf_li differ"
    );
    let (by_light, uniform) = (by_light / f64::from(n), uniform / f64::from(n));
    assert!(
        (by_light / uniform - 1.0).abs() < 0.01,
        "{by_light} vs {uniform}"
    );
}
