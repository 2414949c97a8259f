//! Next-event estimation's per-region light choice (`integrators::light_guide`): it learns
//! which light reaches a region, stays unbiased, and removes the noise of choosing by power.

use std::f64::consts::PI;

use caustic::geometry::Ray;
use caustic::integrators::light_guide::{LightGuide, POWER_SHARE};
use glam::Vec3;

use crate::common::{estimate_along, scene_from_text};

/// A grey floor under a sphere light, and a sphere light of 100 times its power under the
/// floor, which hides it from every point the camera sees.
const HIDDEN_LIGHT: &str = r#"Scene(
    render: (width: 16, height: 16, samples_per_pixel: 1, max_depth: 8, integrator: Path, seed: 5),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: { "m": (color: (0.5, 0.5, 0.5)) },
    lights: [
        Sphere(center: (0, 1.5, 0), radius: 0.3, power: (50, 50, 50)),
        Sphere(center: (0, -1, 0), radius: 0.3, power: (5000, 5000, 5000)),
    ],
    nodes: [ Quad(material: "m", size: (40, 40), transform: [RotateX(-90)]) ],
)"#;

#[test]
fn a_light_hidden_below_the_floor_gets_few_samples_and_the_floor_reads_the_analytic_value() {
    let scene = scene_from_text(HIDDEN_LIGHT);
    let guide = LightGuide::learn(&scene);
    assert!(guide.voxels() > 0, "the pilot reached no voxel");
    // At the floor below the visible light (on the plane y = 0, which must not split voxels):
    // by power it would get 1/101 of the samples; learned, only the default share δ·(½·100/101
    // + ½·½) goes to the hidden light.
    let p = Vec3::new(0.0, 0.0, 0.0);
    let (visible, hidden) = (guide.pmf(p, 0), guide.pmf(p, 1));
    let default_hidden = POWER_SHARE * (0.5 * 100.0 / 101.0 + 0.25);
    assert!(
        (visible + hidden - 1.0).abs() < 1e-5 && (hidden - default_hidden).abs() < 0.01,
        "visible {visible}, hidden {hidden} (the default share alone gives {default_hidden})"
    );
    // `choose` picks lights with the probabilities `pmf` states.
    let n = 20_000;
    let mut count = [0u32; 2];
    for k in 0..n {
        let (i, pmf) = guide
            .choose(p, || (k as f32 + 0.5) / n as f32)
            .expect("a light");
        assert_eq!(pmf, guide.pmf(p, i));
        count[i] += 1;
    }
    assert!((f64::from(count[0]) / f64::from(n) - f64::from(visible)).abs() < 1e-3);
    // Unbiased, and the noise of choosing by power is gone: the sphere of radiance L, radius
    // R, height h above the point gives irradiance π L (R/h)², so the floor reads ρ L R²/h².
    let (r, h, phi, rho) = (0.3f64, 1.5f64, 50.0f64, 0.5f64);
    let radiance = phi / (4.0 * PI * PI * r * r);
    let expected = rho * radiance * r * r / (h * h);
    let eye = Vec3::new(0.0, 3.0, 3.0);
    let ray = Ray::new(eye, (Vec3::ZERO - eye).normalize());
    let (l, se) = estimate_along(&scene, ray, 4000);
    let (l, se) = (l.x, se.x);
    assert!(
        (l - expected).abs() < 4.0 * se + 1e-3 * expected,
        "{l} ± {se} vs {expected}"
    );
    // Choosing by power (the visible light 1 time in 101) gives a standard error of about
    // √100/√4000 ≈ 0.16 of the value here; the learned choice well under 0.02.
    assert!(se < 0.02 * expected, "noise {se} of {expected}");
}

#[test]
fn the_guide_is_the_same_for_every_thread_count() {
    let scene = scene_from_text(HIDDEN_LIGHT);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool")
        .install(|| LightGuide::learn(&scene));
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("pool")
        .install(|| LightGuide::learn(&scene));
    assert_eq!(one.voxels(), three.voxels());
    for k in 0..200 {
        let p = Vec3::new(k as f32 * 0.05 - 5.0, 0.0, (k % 17) as f32 * 0.3 - 2.5);
        for i in 0..2 {
            assert_eq!(one.pmf(p, i).to_bits(), three.pmf(p, i).to_bits());
        }
    }
}
