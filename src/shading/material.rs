//! The material model (docs/material.md): a weighted mix of a Lambert + normalised-Phong part,
//! a perfect mirror and a smooth Fresnel dielectric. Every integrator evaluates it through here.

use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, PI};

use super::optics::{fresnel_dielectric, reflect, refract};

/// A compiled material; the three weights are normalised to sum to 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Diffuse albedo; also tints the mirror and transmitted light.
    pub color: Vec3,
    /// Reflectance of the normalised Phong lobe.
    pub specular: Vec3,
    /// Phong exponent.
    pub shininess: f32,
    /// Weight of the diffuse + Phong part.
    pub diffuse: f32,
    /// Weight of the perfect mirror.
    pub reflect: f32,
    /// Weight of the smooth dielectric.
    pub transmit: f32,
    /// Index of refraction of the inside relative to the outside.
    pub ior: f32,
}

/// The specular (delta) directions leaving a surface point and their weights, given as radiance
/// multipliers: `L = Σ weight · L(direction)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeltaLobes {
    /// Mirror direction (about the shading normal, kept above the geometric surface).
    pub reflect_dir: Vec3,
    /// Total weight of the mirror direction (mirror part + Fresnel reflection of the dielectric).
    pub reflect_weight: Vec3,
    /// Refracted direction and its weight, when the dielectric part transmits.
    pub refract: Option<(Vec3, Vec3)>,
}

impl Material {
    /// Builds a material, normalising the weights (`None` ones count as 0; all `None` means diffuse).
    #[must_use]
    pub fn new(
        color: Vec3,
        specular: Vec3,
        shininess: f32,
        weights: [Option<f32>; 3],
        ior: f32,
    ) -> Self {
        let w = if weights.iter().all(Option::is_none) {
            [1.0, 0.0, 0.0]
        } else {
            weights.map(|w| w.unwrap_or(0.0))
        };
        let sum = w[0] + w[1] + w[2];
        let w = if sum > 0.0 {
            w.map(|x| x / sum)
        } else {
            [1.0, 0.0, 0.0]
        };
        Self {
            color,
            specular,
            shininess,
            diffuse: w[0],
            reflect: w[1],
            transmit: w[2],
            ior,
        }
    }

    /// True if the material has a non-delta (diffuse or glossy) part that direct lighting sees.
    #[inline]
    #[must_use]
    pub fn has_local(&self) -> bool {
        self.diffuse > 0.0
    }

    /// True if the material has mirror or dielectric parts.
    #[inline]
    #[must_use]
    pub fn has_delta(&self) -> bool {
        self.reflect > 0.0 || self.transmit > 0.0
    }

    /// The non-delta BSDF `f(wo, wi)` (per steradian), with `n` the shading normal on the side of
    /// `wo`: `diffuse · (ρ/π + k_s (m+2)/(2π) max(0, r·wi)^m)`, `r` the mirror of `wo`.
    /// Zero when `wi` is below the surface.
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
        if self.diffuse == 0.0 || n.dot(wi) <= 0.0 {
            return Vec3::ZERO;
        }
        let mut f = self.color * FRAC_1_PI;
        if self.specular != Vec3::ZERO {
            let cos_a = reflect(wo, n).dot(wi).max(0.0);
            f += self.specular * ((self.shininess + 2.0) / (2.0 * PI) * cos_a.powf(self.shininess));
        }
        f * self.diffuse
    }

    /// The fraction of light that crosses the surface in a straight line, for shadow rays of
    /// integrators that do not follow refraction (Whitted): the dielectric part's Fresnel
    /// transmittance, tinted by `color`, at the angle `acos(cos)` to the normal. It is evaluated
    /// as seen from the outside whichever way the ray crosses: light leaving through a surface
    /// left the refracted angle, and by reciprocity its transmittance equals that of entering at
    /// the outside angle, so a slab crossed at θ transmits exactly T(θ)² (and never totally
    /// reflects). Exact for `ior == 1` (the refracted ray is the straight one); for other
    /// indices it ignores the bending, so the light that glass focuses (caustics) needs photon
    /// mapping instead.
    #[inline]
    #[must_use]
    pub fn straight_transmittance(&self, cos: f32) -> Vec3 {
        if self.transmit == 0.0 {
            return Vec3::ZERO;
        }
        self.color * (self.transmit * (1.0 - fresnel_dielectric(cos, 1.0 / self.ior)))
    }

    /// The mirror and dielectric lobes at a point. `n` is the shading normal and `ng` the
    /// geometric normal, both on the side of `wo`; `entering` says whether `wo` is outside the
    /// object (so light refracts from outside to inside).
    #[must_use]
    pub fn delta_lobes(&self, wo: Vec3, n: Vec3, ng: Vec3, entering: bool) -> DeltaLobes {
        let reflect_dir = mirror_above(wo, n, ng);
        let mut reflect_weight = self.color * self.reflect;
        let mut refracted = None;
        if self.transmit > 0.0 {
            let eta = if entering { 1.0 / self.ior } else { self.ior };
            let f = fresnel_dielectric(n.dot(wo), eta);
            reflect_weight += Vec3::splat(self.transmit * f);
            if f < 1.0 {
                if let Some(dir) = refract_below(wo, n, ng, eta) {
                    refracted = Some((dir, self.color * (self.transmit * (1.0 - f))));
                } else {
                    // No valid transmitted direction even about ng: the energy goes to reflection.
                    reflect_weight += Vec3::splat(self.transmit * (1.0 - f));
                }
            }
        }
        DeltaLobes {
            reflect_dir,
            reflect_weight,
            refract: refracted,
        }
    }
}

/// Mirror of `wo` about `n`, replaced by the mirror about `ng` if it would go below the geometric
/// surface (shading normals must not send rays into the surface they leave).
#[inline]
fn mirror_above(wo: Vec3, n: Vec3, ng: Vec3) -> Vec3 {
    let r = reflect(wo, n);
    if r.dot(ng) > 0.0 { r } else { reflect(wo, ng) }
}

/// Refraction of `wo` through `n`, replaced by refraction through `ng` if the result would not
/// cross the geometric surface.
#[inline]
fn refract_below(wo: Vec3, n: Vec3, ng: Vec3, eta: f32) -> Option<Vec3> {
    match refract(wo, n, eta) {
        Some(t) if t.dot(ng) < 0.0 => Some(t),
        _ => refract(wo, ng, eta).filter(|t| t.dot(ng) < 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diffuse(c: f32) -> Material {
        Material::new(Vec3::splat(c), Vec3::ZERO, 1.0, [None; 3], 1.5)
    }

    #[test]
    fn weights_are_normalised() {
        let m = Material::new(
            Vec3::ONE,
            Vec3::ZERO,
            1.0,
            [Some(2.0), Some(1.0), Some(1.0)],
            1.5,
        );
        assert!(
            (m.diffuse - 0.5).abs() < 1e-6
                && (m.reflect - 0.25).abs() < 1e-6
                && (m.transmit - 0.25).abs() < 1e-6
        );
        let m = Material::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, Some(3.0), None], 1.5);
        assert_eq!((m.diffuse, m.reflect, m.transmit), (0.0, 1.0, 0.0));
    }

    /// Hemispherical albedo ∫ f cos dω by midpoint quadrature.
    fn albedo(m: &Material, wo: Vec3) -> Vec3 {
        let n = Vec3::Z;
        let (nt, np) = (256, 512);
        let mut sum = Vec3::ZERO;
        for i in 0..nt {
            let th = (i as f32 + 0.5) / nt as f32 * std::f32::consts::FRAC_PI_2;
            for j in 0..np {
                let ph = (j as f32 + 0.5) / np as f32 * std::f32::consts::TAU;
                let wi = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                let dw = th.sin()
                    * (std::f32::consts::FRAC_PI_2 / nt as f32)
                    * (std::f32::consts::TAU / np as f32);
                sum += m.eval(wo, wi, n) * wi.z * dw;
            }
        }
        sum
    }

    #[test]
    fn lambert_albedo_equals_color_and_phong_lobe_does_not_create_energy() {
        let a = albedo(&diffuse(1.0), Vec3::new(0.3, 0.0, 0.95).normalize());
        assert!((a.x - 1.0).abs() < 0.01, "{a}");
        let glossy = Material::new(Vec3::ZERO, Vec3::ONE, 40.0, [None; 3], 1.5);
        for z in [1.0f32, 0.7, 0.3] {
            let wo = Vec3::new((1.0 - z * z).sqrt(), 0.0, z);
            let a = albedo(&glossy, wo);
            assert!(a.x <= 1.01, "normalised Phong albedo {a} at cos {z}");
        }
        // At normal incidence the normalised lobe integrates to ~1 (it is (m+2)/(m+1)·(m+1)/(m+2)).
        let a = albedo(&glossy, Vec3::Z);
        assert!(a.x > 0.95, "{a}");
    }

    #[test]
    fn dielectric_splits_energy_by_fresnel() {
        let glass = Material::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.5);
        let l = glass.delta_lobes(Vec3::Z, Vec3::Z, Vec3::Z, true);
        let (dir, w) = l.refract.unwrap();
        assert!((l.reflect_weight.x - 0.04).abs() < 1e-6);
        assert!((w.x - 0.96).abs() < 1e-6);
        assert!(dir.distance(-Vec3::Z) < 1e-6);
        // From inside beyond the critical angle: everything reflects.
        let wo = Vec3::new(0.8, 0.0, 0.6);
        let l = glass.delta_lobes(wo, Vec3::Z, Vec3::Z, false);
        assert!(l.refract.is_none());
        assert!((l.reflect_weight.x - 1.0).abs() < 1e-6);
    }

    #[test]
    fn tilted_shading_normals_never_send_rays_to_the_wrong_side() {
        let glass = Material::new(
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
                }
            }
        }
        assert_eq!(bad, 0);
    }
}
