//! Distant (sun) light: parallel light of irradiance E from one direction, or — with an angular
//! radius α > 0 — uniform radiance over the cone of half-angle α around it (the sun's disc:
//! α = 0.2665°), which gives shadows and caustics their penumbra.
//!
//! Relation used: a disc of uniform radiance L and angular radius α seen face-on gives
//! `E = ∫ L cos θ dω = 2π L ∫₀^α cos θ sin θ dθ = π L sin²α`, so `L = E / (π sin²α)`; the
//! irradiance stays E on a surface facing the light, as for α = 0. Photons leave a disc of the
//! scene's bounding sphere (pbrt-v4's `DistantLight::SampleLe`, extended to the cone).

use glam::Vec3;
use std::f32::consts::{PI, TAU};

use super::infinite::SceneSphere;
use super::{EmissionSample, LightSample};
use crate::sampling::warp::uniform_cone_narrow;

/// A light at infinity towards `to_light`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistantLight {
    /// Unit direction from the scene towards the light (the sun's direction).
    pub to_light: Vec3,
    /// Irradiance (W/m²) per channel on a surface facing the light.
    pub irradiance: Vec3,
    /// `1 − cos α` of the angular radius (0: a delta direction), computed as `2 sin²(α/2)` so
    /// the sun's tiny cone keeps its digits.
    pub one_minus_cos: f32,
    /// Radiance inside the cone, `E / (π sin²α)` (zero for the delta light).
    pub radiance: Vec3,
    /// The scene's bounding sphere (shadow-ray ends, photon disc, power).
    pub scene: SceneSphere,
}

impl DistantLight {
    /// The light towards `to_light` (any length > 0) of irradiance `irradiance` (W/m²) and
    /// angular radius `angular_radius` radians in `[0, π/2)`. `None` for a zero direction, an
    /// angle out of range, or a radiance that overflows `f32` (a cone too narrow to sample:
    /// use 0 for a delta light).
    #[must_use]
    pub fn new(
        to_light: Vec3,
        irradiance: Vec3,
        angular_radius: f32,
        scene: SceneSphere,
    ) -> Option<Self> {
        let to_light = to_light.try_normalize()?;
        if !(0.0..std::f32::consts::FRAC_PI_2).contains(&angular_radius) {
            return None;
        }
        let half = (0.5 * angular_radius).sin();
        let one_minus_cos = 2.0 * half * half;
        let sin2 = angular_radius.sin().powi(2);
        let radiance = if angular_radius > 0.0 {
            irradiance / (PI * sin2)
        } else {
            Vec3::ZERO
        };
        if !radiance.is_finite() || (angular_radius > 0.0 && !(one_minus_cos > 0.0)) {
            return None;
        }
        Some(Self {
            to_light,
            irradiance,
            one_minus_cos,
            radiance,
            scene,
        })
    }

    /// True for the delta-direction light (angular radius 0).
    #[inline]
    #[must_use]
    pub fn is_delta(&self) -> bool {
        self.one_minus_cos == 0.0
    }

    /// Solid angle of the cone, `2π(1 − cos α)` (sr).
    #[inline]
    fn cone_solid_angle(&self) -> f32 {
        TAU * self.one_minus_cos
    }

    /// True when the unit `w` lies in the cone, with a slack of 1e-4 of its `1 − cos α` (the
    /// `f32` rounding of a unit vector moves the sun's rim by ~3e-5 of it), so samples on the
    /// rim count.
    #[inline]
    fn in_cone(&self, w: Vec3) -> bool {
        // 1 − cos θ = |w − axis|² / 2, accurate for tiny angles.
        let omc = 0.5 * (w - self.to_light).length_squared();
        omc <= self.one_minus_cos * (1.0 + 1e-4) + 1e-12
    }

    /// Total flux (W) through the scene's bounding disc: `π R² E` for the delta light,
    /// `π R² · L · 2π(1 − cos α) = π R² E · 2/(1 + cos α)` with a cone.
    #[must_use]
    pub fn power(&self) -> Vec3 {
        if self.is_delta() {
            self.irradiance * self.scene.disc_area()
        } else {
            self.radiance * (self.scene.disc_area() * self.cone_solid_angle())
        }
    }

    /// Radiance arriving along a ray that leaves the scene in the unit direction `w`
    /// (towards the sky): L inside the cone, 0 elsewhere and for the delta light.
    #[inline]
    #[must_use]
    pub fn le(&self, w: Vec3) -> Vec3 {
        if !self.is_delta() && self.in_cone(w) {
            self.radiance
        } else {
            Vec3::ZERO
        }
    }

    /// A direction towards the light from `p`: the one direction (radiance E, pdf 1, `delta`)
    /// or uniform over the cone (`pdf = 1/(2π(1 − cos α))`). The shadow ray ends beyond the
    /// scene's bounding sphere. `None` for a black light.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, u: (f32, f32)) -> Option<LightSample> {
        if self.irradiance == Vec3::ZERO {
            return None;
        }
        let distance = self.scene.far_distance(p);
        let (wi, radiance, pdf, delta) = if self.is_delta() {
            (self.to_light, self.irradiance, 1.0, true)
        } else {
            let wi = uniform_cone_narrow(u, self.to_light, self.one_minus_cos).normalize();
            (wi, self.radiance, 1.0 / self.cone_solid_angle(), false)
        };
        let weight = radiance / pdf;
        weight.is_finite().then(|| LightSample {
            wi,
            distance,
            point: p + wi * distance,
            radiance,
            pdf,
            delta,
            weight,
        })
    }

    /// Solid-angle density of [`DistantLight::sample_li`] for the unit `wi`: `1/(2π(1 −
    /// cos α))` inside the cone, 0 outside and for the delta light.
    #[must_use]
    pub fn pdf_li(&self, _p: Vec3, wi: Vec3) -> f32 {
        if !self.is_delta() && self.in_cone(wi) {
            1.0 / self.cone_solid_angle()
        } else {
            0.0
        }
    }

    /// A photon: the direction it travels (`−to_light`, or `−wi` for `wi` uniform in the cone
    /// from `u_dir`), starting uniformly on the disc of the bounding sphere perpendicular to it
    /// (`pdf_pos = 1/(π R²)`, `normal = dir`, so its flux is `le / (pdf_pos · pdf_dir)`).
    /// Delta light: `le = E`, `pdf_dir = 1`, flux `π R² E`; cone: `le = L`, `pdf_dir = 1/(2π(1
    /// − cos α))`. `None` for a black light.
    #[must_use]
    pub fn sample_le(&self, u_pos: (f32, f32), u_dir: (f32, f32)) -> Option<EmissionSample> {
        if self.irradiance == Vec3::ZERO {
            return None;
        }
        let (wi, le, pdf_dir) = if self.is_delta() {
            (self.to_light, self.irradiance, 1.0)
        } else {
            let wi = uniform_cone_narrow(u_dir, self.to_light, self.one_minus_cos).normalize();
            (wi, self.radiance, 1.0 / self.cone_solid_angle())
        };
        let dir = -wi;
        Some(EmissionSample {
            origin: self.scene.disc_origin(dir, u_pos),
            normal: dir,
            dir,
            le,
            pdf_pos: 1.0 / self.scene.disc_area(),
            pdf_dir,
        })
    }

    /// `(pdf_pos, pdf_dir)` of [`DistantLight::sample_le`] for a photon travelling along the
    /// unit `dir`: `(1/(π R²), pdf_li(−dir))`, and `pdf_dir = 1` for the delta light.
    #[must_use]
    pub fn pdf_le(&self, dir: Vec3) -> (f32, f32) {
        let pdf_dir = if self.is_delta() {
            1.0
        } else {
            self.pdf_li(Vec3::ZERO, -dir)
        };
        (1.0 / self.scene.disc_area(), pdf_dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render_scene::light::test_support::stratified;
    use crate::sampling::Rng;
    use crate::sampling::chi2::{SphereBins, chi2_test, pearson};

    const SUN: f32 = 0.2665 * PI / 180.0;

    fn scene() -> SceneSphere {
        SceneSphere::new(Vec3::new(0.0, 1.0, 0.0), 5.0)
    }

    /// Outgoing radiance of a Lambert plane (albedo ρ, normal +y) lit by `l`, by NEE with
    /// `k²` stratified samples: ρ/π · E_est.
    fn lambert_radiance(l: &DistantLight, rho: f64, k: usize) -> f64 {
        let mut rng = Rng::new(0, 0);
        let e: f64 = stratified(k, &mut rng)
            .filter_map(|u| l.sample_li(Vec3::ZERO, u))
            .map(|s| f64::from(s.weight.x) * f64::from(s.wi.y.max(0.0)))
            .sum::<f64>()
            / (k * k) as f64;
        rho / std::f64::consts::PI * e
    }

    #[test]
    fn a_lambert_plane_reads_rho_e_cos_over_pi() {
        let theta = 35f32.to_radians();
        let dir = Vec3::new(theta.sin(), theta.cos(), 0.0);
        let rho = 0.6;
        for (alpha, tol) in [(0.0, 1e-6), (SUN, 1e-5), (3f32.to_radians(), 1e-5)] {
            let l = DistantLight::new(dir, Vec3::splat(2.0), alpha, scene()).unwrap();
            let want = rho * 2.0 * f64::from(theta.cos()) / std::f64::consts::PI;
            // With a cone the exact value is ρ/π · L ∫cone cos θ_n dω; for a cone wholly above
            // the horizon that is ρ/π · π L sin²α · cos θ = ρ E cos θ / π (the cone's mean
            // cosine about any tilted normal is cos θ · (1 + cos α)/2, times its solid angle).
            let got = lambert_radiance(&l, rho, 256);
            eprintln!("distant α={alpha:.5}: Lo {got:.7} vs ρE cosθ/π {want:.7}");
            assert!((got / want - 1.0).abs() < tol, "α={alpha}: {got} vs {want}");
        }
    }

    #[test]
    fn cone_sampling_passes_chi2_and_a_wrong_pdf_fails() {
        let dir = Vec3::new(0.2, 1.0, -0.4).normalize();
        for alpha in [SUN, 5f32.to_radians()] {
            let l = DistantLight::new(dir, Vec3::ONE, alpha, scene()).unwrap();
            let bins = SphereBins::cap(dir, 16, 32, 1.25 * f64::from(l.one_minus_cos));
            let r = chi2_test(
                200_000,
                1,
                &bins,
                |rng| l.sample_li(Vec3::ZERO, rng.next_2d()).map(|s| s.wi),
                |w| l.pdf_li(Vec3::ZERO, w),
            );
            eprintln!("distant sample_li χ² α={alpha}: {r:?}");
            assert!(r.passes(0.005) && r.rejected == 0 && r.dof > 300, "{r:?}");
            let le = chi2_test(
                200_000,
                2,
                &bins,
                |rng| l.sample_le(rng.next_2d(), rng.next_2d()).map(|s| -s.dir),
                |w| l.pdf_le(-w).1,
            );
            eprintln!("distant sample_le dir χ² α={alpha}: {le:?}");
            assert!(le.passes(0.005) && le.rejected == 0, "{le:?}");
            // A cone 3 % wider claimed: rejected.
            let wide = DistantLight::new(dir, Vec3::ONE, alpha * 1.03, scene()).unwrap();
            let wrong = chi2_test(
                200_000,
                3,
                &bins,
                |rng| l.sample_li(Vec3::ZERO, rng.next_2d()).map(|s| s.wi),
                |w| wide.pdf_li(Vec3::ZERO, w),
            );
            assert!(wrong.p_value < 1e-6, "{wrong:?}");
        }
    }

    #[test]
    fn photons_cover_the_scene_disc_uniformly_with_the_stated_power() {
        for alpha in [0.0, 2f32.to_radians()] {
            let l = DistantLight::new(Vec3::new(1.0, 2.0, 0.5), Vec3::splat(3.0), alpha, scene())
                .unwrap();
            let mut rng = Rng::new(9, 0);
            let n = 64_000;
            let mut counts = vec![0u64; 32];
            let mut flux = 0.0f64;
            for _ in 0..n {
                let s = l.sample_le(rng.next_2d(), rng.next_2d()).unwrap();
                assert_eq!(s.normal, s.dir);
                // The ray passes the centre's plane within R of it: the offset from the axis.
                let c = l.scene.center - s.origin;
                let along = c.dot(s.dir);
                assert!((along - l.scene.radius).abs() < 1e-3);
                let off = c - s.dir * along;
                let r2 = off.length_squared() / (l.scene.radius * l.scene.radius);
                assert!(r2 <= 1.0 + 1e-4);
                let f = crate::geometry::Frame::from_normal(s.dir);
                let phi = off.dot(f.t).atan2(off.dot(f.s)).rem_euclid(TAU);
                counts[((r2 * 4.0) as usize).min(3) * 8 + ((phi / TAU * 8.0) as usize).min(7)] += 1;
                flux += f64::from(s.le.x / (s.pdf_pos * s.pdf_dir));
                let (pp, pd) = l.pdf_le(s.dir);
                assert!((pp / s.pdf_pos - 1.0).abs() < 1e-6 && (pd / s.pdf_dir - 1.0).abs() < 1e-6);
            }
            let r = pearson(&counts, &vec![f64::from(n) / 32.0; 32]);
            assert!(r.p_value > 0.005, "{r:?}");
            let flux = flux / f64::from(n);
            assert!((flux / f64::from(l.power().x) - 1.0).abs() < 1e-5, "{flux}");
            let disc = f64::from(3.0 * PI * 25.0);
            let cone = if alpha > 0.0 {
                2.0 / (1.0 + f64::from(alpha.cos()))
            } else {
                1.0
            };
            assert!((flux / (disc * cone) - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn the_sun_is_seen_only_inside_its_disc_and_bad_input_gives_none() {
        let l = DistantLight::new(Vec3::Y, Vec3::splat(1000.0), SUN, scene()).unwrap();
        let want = 1000.0 / (PI * SUN.sin().powi(2));
        assert!((l.radiance.x / want - 1.0).abs() < 1e-5);
        let tilt = |a: f32| Vec3::new(a.sin(), a.cos(), 0.0);
        assert_eq!(l.le(tilt(0.99 * SUN)), l.radiance);
        assert_eq!(l.le(tilt(1.02 * SUN)), Vec3::ZERO);
        let delta = DistantLight::new(Vec3::Y, Vec3::ONE, 0.0, scene()).unwrap();
        assert!(delta.is_delta() && delta.le(Vec3::Y) == Vec3::ZERO);
        let s = delta.sample_li(Vec3::ZERO, (0.3, 0.3)).unwrap();
        assert!(s.delta && s.wi == Vec3::Y && s.distance >= 12.0);
        assert!(DistantLight::new(Vec3::ZERO, Vec3::ONE, 0.0, scene()).is_none());
        assert!(DistantLight::new(Vec3::Y, Vec3::ONE, -0.1, scene()).is_none());
        assert!(DistantLight::new(Vec3::Y, Vec3::ONE, 1.6, scene()).is_none());
    }
}
