//! Disc and cylinder lights against closed forms: a Lambertian disc's irradiance on its axis,
//! E = π L sin²θ (θ its half-angle), the area, the power, and the densities' normalisation.

use super::*;
use crate::sampling::Rng;
use crate::sampling::warp::uniform_sphere;
use glam::DQuat;
use std::f32::consts::PI;

/// A disc of radius `r` at height `h` above the origin, facing down (−y), radiance `l`.
fn ceiling_disc(r: f64, h: f64, l: Vec3, two_sided: bool) -> QuadricLight {
    let m = DAffine3::from_scale_rotation_translation(
        DVec3::splat(r),
        DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2),
        DVec3::new(0.0, h, 0.0),
    );
    QuadricLight::new(QuadricShape::Disc, m, l, two_sided).unwrap()
}

#[test]
fn disc_irradiance_on_its_axis_is_pi_l_sin2() {
    let (r, h) = (0.5, 1.2);
    let l = Vec3::new(3.0, 2.0, 1.0);
    let disc = ceiling_disc(r, h, l, false);
    assert!((disc.area - (std::f64::consts::PI * r * r) as f32).abs() < 1e-6);
    // The normal faces the floor: RotateX(90°) turns +z to −y.
    let (_, n) = disc.sample_position((0.3, 0.6));
    assert!((n - Vec3::NEG_Y).length() < 1e-6, "{n}");
    // E = π L sin²θ, sin²θ = r²/(r² + h²).
    let sin2 = (r * r / (r * r + h * h)) as f32;
    let exact = l * (PI * sin2);
    let k = 512;
    let mut sum = Vec3::ZERO;
    for i in 0..k {
        for j in 0..k {
            let u = ((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
            let s = disc.sample_li(Vec3::ZERO, u).unwrap();
            sum += s.weight * s.wi.y.max(0.0);
            // The density is the one pdf_li gives for the same direction.
            if i % 64 == 0 && j % 64 == 0 {
                let p = disc.pdf_li(Vec3::ZERO, s.wi);
                assert!((p / s.pdf - 1.0).abs() < 1e-3, "{p} vs {}", s.pdf);
            }
        }
    }
    let e = sum / (k * k) as f32;
    assert!(
        ((e - exact) / exact).abs().max_element() < 2e-3,
        "{e} vs {exact}"
    );
    // A one-sided disc sends nothing upwards; a two-sided one does.
    assert!(
        disc.sample_li(Vec3::new(0.0, 2.0, 0.0), (0.5, 0.5))
            .is_none()
    );
    let both = ceiling_disc(r, h, l, true);
    assert!(
        both.sample_li(Vec3::new(0.0, 2.0, 0.0), (0.5, 0.5))
            .is_some()
    );
    assert!((both.power() - disc.power() * 2.0).abs().max_element() < 1e-4);
    assert!((disc.power() - l * (PI * disc.area)).abs().max_element() < 1e-4);
}

#[test]
fn an_elliptic_disc_keeps_a_uniform_density() {
    // Scale (2, 0.5, 1): an ellipse of area π · 2 · 0.5 = π.
    let m = DAffine3::from_scale(DVec3::new(2.0, 0.5, 1.0));
    let e = QuadricLight::new(QuadricShape::Disc, m, Vec3::ONE, true).unwrap();
    assert!((e.area - PI).abs() < 1e-5);
    // Irradiance at a point on the axis by light sampling and by uniform directions agree.
    let p = Vec3::new(0.0, 0.0, 1.0);
    directions_agree(&e, p, 1e-2);
}

/// ∫ L |cos| dω at `p` (cosine about the direction to the light's centre) and the solid angle
/// the surface covers (each wall a line crosses counted once), by the light's own sampling
/// (`E[f/pdf]`) and by uniform directions meeting the surface, within `tol` (a two-sided light:
/// every sample counts). `E[1/pdf]` is bounded, unlike a uniform average of `pdf_li` (whose
/// 1/cos at the silhouette has no variance).
fn directions_agree(light: &QuadricLight, p: Vec3, tol: f64) {
    let n = (light.world_from_object.translation.as_vec3() - p).normalize();
    let mut rng = Rng::new(3, 0);
    let count = 400_000;
    let (mut by_light, mut uniform) = (0.0f64, 0.0f64);
    let (mut omega_light, mut omega_uniform) = (0.0f64, 0.0f64);
    let mut missed = 0u32;
    for _ in 0..count {
        if let Some(s) = light.sample_li(p, rng.next_2d()) {
            by_light += f64::from(s.weight.x * s.wi.dot(n).abs());
            omega_light += 1.0 / f64::from(s.pdf);
            // The density pdf_li gives includes this point's (a line through a rim point or at
            // grazing incidence can round to a miss: counted, and rare).
            let q = light.pdf_li(p, s.wi);
            if q < s.pdf * 0.999 {
                missed += 1;
            }
        }
        let w = uniform_sphere(rng.next_2d());
        // Every wall the line crosses (light sampling ignores the light's own shadow, as
        // `pdf_li` sums them; the shadow ray settles it in rendering), each two-sided: L |cos|.
        let o = light.object_from_world.transform_point3(p.as_dvec3());
        let d = light.object_from_world.transform_vector3(w.as_dvec3());
        let hits = light.shape.hit_ts(o, d).into_iter().flatten().count() as f64;
        uniform += hits * f64::from(light.radiance.x * w.dot(n).abs()) * 4.0 * std::f64::consts::PI;
        omega_uniform += hits * 4.0 * std::f64::consts::PI;
    }
    assert!(
        missed < count / 1000,
        "{missed} sampled directions missed by pdf_li"
    );
    let c = f64::from(count);
    let (by_light, uniform) = (by_light / c, uniform / c);
    let (omega_light, omega_uniform) = (omega_light / c, omega_uniform / c);
    assert!(
        (by_light / uniform - 1.0).abs() < tol,
        "{by_light} vs {uniform}"
    );
    assert!(
        (omega_light / omega_uniform - 1.0).abs() < tol,
        "Ω {omega_light} vs {omega_uniform}"
    );
}

#[test]
fn cylinder_area_sampling_and_density_agree() {
    // Radius 0.3, height 1.5, axis along y, at (0, 1, 0).
    let m = DAffine3::from_translation(DVec3::new(0.0, 1.0, 0.0))
        * DAffine3::from_rotation_x(std::f64::consts::FRAC_PI_2)
        * DAffine3::from_scale(DVec3::new(0.3, 0.3, 1.5));
    let c = QuadricLight::new(QuadricShape::Cylinder, m, Vec3::splat(2.0), true).unwrap();
    assert!((f64::from(c.area) - std::f64::consts::TAU * 0.3 * 1.5).abs() < 1e-5);
    // Sampled points are on the surface, normals outwards and horizontal.
    for u in [(0.1, 0.2), (0.6, 0.9), (0.35, 0.5)] {
        let (p, n) = c.sample_position(u);
        let radial = Vec3::new(p.x, 0.0, p.z);
        assert!((radial.length() - 0.3).abs() < 1e-5 && (p.y - 1.0).abs() <= 0.75 + 1e-5);
        assert!((n - radial.normalize()).length() < 1e-5, "{n}");
    }
    // From outside: light sampling and uniform directions agree (both walls count).
    directions_agree(&c, Vec3::new(1.5, 0.8, 0.4), 1e-2);
    // Not round: refused.
    let oval = m * DAffine3::from_scale(DVec3::new(1.0, 2.0, 1.0));
    assert!(QuadricLight::new(QuadricShape::Cylinder, oval, Vec3::ONE, false).is_none());
}
