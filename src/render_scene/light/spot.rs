//! Spot light: a point emitter whose intensity falls off from the inner to the outer cone with
//! pbrt-v4's `SpotLight` convention (Pharr, Jakob & Humphreys, PBR 4th ed., §12.1.1):
//! `I(θ) = I · smoothstep(cos θ_outer, cos θ_inner, cos θ)`, with `smoothstep(a, b, x) =
//! t²(3 − 2t)`, `t = clamp((x − a)/(b − a), 0, 1)` — full intensity inside the inner cone, zero
//! outside the outer one, the Hermite step in *cosine* between them (a hard edge when the two
//! angles are equal). Photons leave only inside the outer cone.

use glam::Vec3;
use std::f32::consts::{PI, TAU};

use super::{EmissionSample, LightSample};
use crate::sampling::warp::uniform_cone;

/// A spot light at `position` aimed along `axis`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpotLight {
    /// Position (world units).
    pub position: Vec3,
    /// Unit direction of the cone's axis (where the light shines).
    pub axis: Vec3,
    /// Radiant intensity on the axis, per channel (W/sr).
    pub intensity: Vec3,
    /// `cos θ_inner`: full intensity for `cos θ ≥ cos_inner`.
    pub cos_inner: f32,
    /// `cos θ_outer ≤ cos_inner`: no light for `cos θ < cos_outer`.
    pub cos_outer: f32,
}

impl SpotLight {
    /// The spot at `position` shining along `direction` (any length > 0) with on-axis
    /// intensity `intensity` (W/sr) and cone half-angles `inner ≤ outer` in radians,
    /// `0 < outer ≤ π` (an `inner` above `outer` is lowered to it). `None` when the
    /// direction is zero or the angles are out of range (validation reports those).
    #[must_use]
    pub fn new(
        position: Vec3,
        direction: Vec3,
        intensity: Vec3,
        inner: f32,
        outer: f32,
    ) -> Option<Self> {
        let axis = direction.try_normalize()?;
        if !(outer > 0.0 && outer <= PI && inner >= 0.0 && position.is_finite()) {
            return None;
        }
        let inner = inner.min(outer);
        Some(Self {
            position,
            axis,
            intensity,
            cos_inner: inner.cos(),
            cos_outer: outer.cos(),
        })
    }

    /// The fall-off factor in `[0, 1]` at `cos θ` from the axis.
    #[inline]
    #[must_use]
    pub fn falloff(&self, cos_t: f32) -> f32 {
        if cos_t < self.cos_outer {
            return 0.0;
        }
        if cos_t >= self.cos_inner {
            return 1.0;
        }
        let t = ((cos_t - self.cos_outer) / (self.cos_inner - self.cos_outer)).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    }

    /// Intensity (W/sr) emitted in the unit direction `w`.
    #[inline]
    #[must_use]
    pub fn intensity_towards(&self, w: Vec3) -> Vec3 {
        self.intensity * self.falloff(w.dot(self.axis))
    }

    /// Total flux (W): `I · 2π [(1 − cos θ_i) + (cos θ_i − cos θ_o)/2]` — the smooth step
    /// integrates to half its interval in `cos θ`.
    #[must_use]
    pub fn power(&self) -> Vec3 {
        self.intensity * (TAU * ((1.0 - self.cos_inner) + 0.5 * (self.cos_inner - self.cos_outer)))
    }

    /// The delta sample towards the light from `p` (`u` unused): radiance `I(θ)/d²`, pdf 1,
    /// `delta` true. `None` outside the outer cone, at the light, or for a black light.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, _u: (f32, f32)) -> Option<LightSample> {
        let d = self.position - p;
        let dist2 = d.length_squared();
        if !(dist2 > 0.0 && dist2.is_finite()) {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = d / dist;
        let i = self.intensity_towards(-wi);
        if i == Vec3::ZERO {
            return None;
        }
        let radiance = i / dist2;
        radiance.is_finite().then_some(LightSample {
            wi,
            distance: dist,
            point: self.position,
            radiance,
            pdf: 1.0,
            delta: true,
            weight: radiance,
        })
    }

    /// 0: no BSDF-sampled direction can hit a point.
    #[must_use]
    pub fn pdf_li(&self, _p: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    /// Solid-angle density of emitted directions: uniform over the outer cone.
    #[inline]
    fn cone_pdf(&self) -> f32 {
        1.0 / (TAU * (1.0 - self.cos_outer))
    }

    /// A photon direction uniform over the outer cone (`u_pos` unused: a delta in position,
    /// `pdf_pos = 1`), `pdf_dir = 1/(2π(1 − cos θ_o))`, `le` the intensity `I(θ)` along it
    /// (flux `le / pdf_dir`). `None` for a black light or a direction in the fall-off's
    /// zero tail.
    #[must_use]
    pub fn sample_le(&self, _u_pos: (f32, f32), u_dir: (f32, f32)) -> Option<EmissionSample> {
        let dir = uniform_cone(u_dir, self.axis, self.cos_outer).normalize();
        let le = self.intensity_towards(dir);
        (le != Vec3::ZERO).then(|| EmissionSample {
            origin: self.position,
            normal: Vec3::ZERO,
            dir,
            le,
            pdf_pos: 1.0,
            pdf_dir: self.cone_pdf(),
        })
    }

    /// `(pdf_pos, pdf_dir)` of [`SpotLight::sample_le`] for the unit `dir`: `(1, 1/(2π(1 −
    /// cos θ_o)))` inside the outer cone, `(1, 0)` outside.
    #[must_use]
    pub fn pdf_le(&self, dir: Vec3) -> (f32, f32) {
        let inside = dir.dot(self.axis) >= self.cos_outer - 1e-6;
        (1.0, if inside { self.cone_pdf() } else { 0.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::sampling::chi2::{SphereBins, chi2_test};

    /// A spot 3 m above the floor pointing down, inner 20°, outer 40°, I = 5 W/sr.
    fn spot() -> SpotLight {
        SpotLight::new(
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::new(0.0, -2.0, 0.0),
            Vec3::splat(5.0),
            20f32.to_radians(),
            40f32.to_radians(),
        )
        .unwrap()
    }

    /// Floor irradiance at (x, 0, 0) from `sample_li`.
    fn floor_e(l: &SpotLight, x: f32) -> f32 {
        l.sample_li(Vec3::new(x, 0.0, 0.0), (0.5, 0.5))
            .map_or(0.0, |s| s.weight.x * s.wi.y.max(0.0))
    }

    #[test]
    fn floor_irradiance_is_i_cos_over_d2_inside_zero_outside_smoothstep_between() {
        let l = spot();
        let h = 3.0f64;
        // θ from the axis of the floor point at x: tan θ = x/h; E = I cos θ / d² · f(θ).
        let at_angle = |deg: f64| (h * deg.to_radians().tan()) as f32;
        for deg in [0.0, 5.0, 12.0, 19.9] {
            let x = at_angle(deg);
            let d2 = h * h + f64::from(x).powi(2);
            let want = 5.0 * deg.to_radians().cos() / d2;
            let got = f64::from(floor_e(&l, x));
            assert!((got / want - 1.0).abs() < 1e-5, "{deg}°: {got} vs {want}");
        }
        for deg in [40.1, 50.0, 80.0] {
            assert_eq!(floor_e(&l, at_angle(deg)), 0.0, "{deg}°");
        }
        // Between: at cos θ a quarter and a half of the way from cos 40° to cos 20°, the step
        // is 3t² − 2t³ = 0.15625 and 0.5.
        let (co, ci) = (40f64.to_radians().cos(), 20f64.to_radians().cos());
        for (t, step) in [(0.25, 0.15625), (0.5, 0.5)] {
            let cos_t = co + t * (ci - co);
            let theta = cos_t.acos();
            let x = (h * theta.tan()) as f32;
            let d2 = h * h + f64::from(x).powi(2);
            let want = 5.0 * cos_t / d2 * step;
            let got = f64::from(floor_e(&l, x));
            assert!((got / want - 1.0).abs() < 1e-4, "t {t}: {got} vs {want}");
        }
        assert_eq!(l.pdf_li(Vec3::ZERO, Vec3::Y), 0.0);
    }

    #[test]
    fn power_is_the_integral_of_the_intensity() {
        let l = spot();
        // Midpoint rule in cos θ over [cos_outer, 1].
        let n = 200_000;
        let (a, b) = (f64::from(l.cos_outer), 1.0);
        let h = (b - a) / f64::from(n);
        let integral: f64 = (0..n)
            .map(|i| f64::from(l.falloff((a + (f64::from(i) + 0.5) * h) as f32)) * h)
            .sum::<f64>()
            * std::f64::consts::TAU
            * 5.0;
        assert!((integral / f64::from(l.power().x) - 1.0).abs() < 1e-5);
        // Photon flux: the mean of le / pdf_dir is Φ.
        let mut rng = Rng::new(1, 0);
        let n = 200_000;
        let flux: f64 = (0..n)
            .filter_map(|_| l.sample_le(rng.next_2d(), rng.next_2d()))
            .map(|s| f64::from(s.le.x / (s.pdf_pos * s.pdf_dir)))
            .sum::<f64>()
            / f64::from(n);
        assert!((flux / f64::from(l.power().x) - 1.0).abs() < 3e-3, "{flux}");
    }

    #[test]
    fn photons_leave_uniformly_inside_the_outer_cone_only() {
        let l = spot();
        let bins = SphereBins::cap(l.axis, 16, 32, 1.25 * f64::from(1.0 - l.cos_outer));
        let sample = |rng: &mut Rng| l.sample_le(rng.next_2d(), rng.next_2d()).map(|s| s.dir);
        let r = chi2_test(200_000, 2, &bins, sample, |w| l.pdf_le(w).1);
        eprintln!("spot sample_le χ²: {r:?}");
        assert!(r.passes(0.01) && r.rejected == 0, "{r:?}");
        // Claiming a cone of 38° is rejected.
        let narrow =
            SpotLight::new(l.position, l.axis, l.intensity, 0.3, 38f32.to_radians()).unwrap();
        let wrong = chi2_test(200_000, 3, &bins, sample, |w| narrow.pdf_le(w).1);
        eprintln!("spot sample_le χ² against a 38° cone (must fail): {wrong:?}");
        assert!(wrong.p_value < 1e-6, "{wrong:?}");
    }

    #[test]
    fn equal_angles_give_a_hard_edge_and_bad_input_gives_none() {
        let l = SpotLight::new(Vec3::ZERO, Vec3::Z, Vec3::ONE, 0.5, 0.5).unwrap();
        assert_eq!(l.falloff(0.5f32.cos() + 1e-6), 1.0);
        assert_eq!(l.falloff(0.5f32.cos() - 1e-6), 0.0);
        assert!(SpotLight::new(Vec3::ZERO, Vec3::ZERO, Vec3::ONE, 0.1, 0.5).is_none());
        assert!(SpotLight::new(Vec3::ZERO, Vec3::Z, Vec3::ONE, 0.1, 0.0).is_none());
        assert!(SpotLight::new(Vec3::ZERO, Vec3::Z, Vec3::ONE, 0.1, 3.2).is_none());
    }
}
