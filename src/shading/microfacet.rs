//! The GGX (Trowbridge–Reitz) microfacet distribution, isotropic or anisotropic, with Smith
//! masking-shadowing and sampling of visible normals: the common core of the rough conductor
//! ([`super::rough_conductor`]) and the rough dielectric ([`super::rough_dielectric`]).
//!
//! Everything here works in a local frame whose `z` axis is the shading normal and whose `x`
//! and `y` axes carry the roughnesses `alpha_x` and `alpha_y`.
//!
//! - Distribution (Trowbridge & Reitz 1975; Walter et al. 2007, eq. 33; anisotropic form of
//!   Heitz 2014, eq. 85): `D(h) = 1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)` for `hz > 0`.
//! - Smith's Λ for GGX (Heitz, "Understanding the Masking-Shadowing Function in
//!   Microfacet-Based BRDFs", JCGT 3(2), 2014, eq. 86): `Λ(w) = (√(1 + (αx² wx² + αy² wy²)/wz²)
//!   − 1)/2`, `G1(w) = 1/(1 + Λ(w))`, and the height-correlated masking-shadowing
//!   `G2(wo, wi) = 1/(1 + Λ(wo) + Λ(wi))` (Heitz 2014, eq. 99).
//! - Visible normals (Heitz 2014, eq. 38): `D_wo(h) = G1(wo) max(0, wo·h) D(h) / cos θo`, a
//!   density over microfacet normals that integrates to 1; sampled exactly by Heitz, "Sampling
//!   the GGX Distribution of Visible Normals", JCGT 7(4), 2018 (stretch the view direction to
//!   the unit-roughness configuration, sample the projected hemisphere, unstretch).

use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// Smallest roughness [`Ggx::new`] accepts: below it `D` overflows single precision. Roughness 0
/// is not a GGX lobe at all: it is the perfect mirror or the smooth dielectric.
pub const MIN_ALPHA: f32 = 1e-4;

/// A GGX distribution of microfacet normals with roughness `alpha_x` along the local `x` axis
/// and `alpha_y` along `y` (equal for an isotropic surface). α is the slope-space width; a
/// scene's perceptual roughness is mapped to it by the caller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ggx {
    /// Roughness along the local `x` (first tangent) axis, ≥ [`MIN_ALPHA`].
    pub alpha_x: f32,
    /// Roughness along the local `y` (second tangent) axis, ≥ [`MIN_ALPHA`].
    pub alpha_y: f32,
}

impl Ggx {
    /// An anisotropic distribution; each α is raised to at least [`MIN_ALPHA`] (NaN becomes
    /// [`MIN_ALPHA`] too).
    #[inline]
    #[must_use]
    pub fn new(alpha_x: f32, alpha_y: f32) -> Self {
        Self {
            alpha_x: alpha_x.max(MIN_ALPHA),
            alpha_y: alpha_y.max(MIN_ALPHA),
        }
    }

    /// An isotropic distribution of roughness `alpha`.
    #[inline]
    #[must_use]
    pub fn isotropic(alpha: f32) -> Self {
        Self::new(alpha, alpha)
    }

    /// True when the two roughnesses are equal.
    #[inline]
    #[must_use]
    pub fn is_isotropic(&self) -> bool {
        self.alpha_x == self.alpha_y
    }

    /// The density of microfacet normals `D(h)` per steradian of `h` (unit, local frame),
    /// normalised so that `∫ D(h) cos θh dωh = 1`; 0 for `h` below the surface.
    #[inline]
    #[must_use]
    pub fn d(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let e = (h.x / ax) * (h.x / ax) + (h.y / ay) * (h.y / ay) + h.z * h.z;
        1.0 / (PI * ax * ay * e * e)
    }

    /// Smith's `Λ(w)` for GGX (`w` unit, local frame; either hemisphere): `(√(1 + α(φ)² tan²θ)
    /// − 1)/2`; infinite at grazing `w`.
    #[inline]
    #[must_use]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let z2 = w.z * w.z;
        if z2 == 0.0 {
            return f32::INFINITY;
        }
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / z2;
        ((1.0 + t2).sqrt() - 1.0) * 0.5
    }

    /// Smith's masking function `G1(w) = 1/(1 + Λ(w))`, the fraction of the surface's projected
    /// area seen from `w` that is not hidden by other microfacets.
    #[inline]
    #[must_use]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing `G2(wo, wi) = 1/(1 + Λ(wo) + Λ(wi))` (Heitz 2014,
    /// eq. 99). Used for transmission too (as pbrt-v4 does; the exact height-correlated form
    /// for transmission is a Beta function of the two Λ, Heitz 2014 §6): symmetric in `wo`
    /// and `wi` either way, so reciprocity is unaffected.
    #[inline]
    #[must_use]
    pub fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density of normals visible from `wo` (`wo.z > 0`), per steradian of `h`:
    /// `D_wo(h) = G1(wo) max(0, wo·h) D(h) / cos θo`; it integrates to 1 over `h`.
    #[inline]
    #[must_use]
    pub fn visible_pdf(&self, wo: Vec3, h: Vec3) -> f32 {
        let c = wo.dot(h);
        if wo.z <= 0.0 || c <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * c * self.d(h) / wo.z
    }

    /// A microfacet normal drawn from [`Ggx::visible_pdf`] for `wo` (`wo.z > 0`, unit) from
    /// `u ∈ [0, 1)²` (Heitz 2018): `wo` is stretched to the configuration of roughness 1, where
    /// the visible normals are the projected hemisphere seen from it (a disc, half of it
    /// foreshortened by `(1 + cos θ)/2`), and the sampled normal is unstretched back.
    #[inline]
    #[must_use]
    pub fn sample_visible(&self, wo: Vec3, u: (f32, f32)) -> Vec3 {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let v = Vec3::new(ax * wo.x, ay * wo.y, wo.z).normalize();
        // An orthonormal basis (t1, t2, v) with t1 horizontal.
        let len2 = v.x * v.x + v.y * v.y;
        let t1 = if len2 > 0.0 {
            Vec3::new(-v.y, v.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = v.cross(t1);
        // A point on the unit disc; the half behind the view direction is squeezed by the
        // projected hemisphere's foreshortening.
        let r = u.0.sqrt();
        let phi = TAU * u.1;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + v.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * (r * phi.sin());
        let p3 = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        let nh = t1 * p1 + t2 * p2 + v * p3;
        Vec3::new(ax * nh.x, ay * nh.y, nh.z.max(1e-7)).normalize()
    }
}

crate::key_hash_struct!(Ggx { alpha_x, alpha_y });

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{SphereBins, chi2_test, integrate, sidak_alpha};

    fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
        let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }

    const DISTRIBUTIONS: [(f32, f32); 5] = [
        (0.05, 0.05),
        (0.3, 0.3),
        (1.0, 1.0),
        (0.1, 0.5),
        (0.6, 0.15),
    ];

    #[test]
    fn closed_forms_by_hand() {
        let g = Ggx::isotropic(0.5);
        // D(n) = 1/(π α²).
        assert!((g.d(Vec3::Z) - 1.0 / (PI * 0.25)).abs() < 1e-5);
        // Isotropic D(θ) = α² / (π cos⁴θ (α² + tan²θ)²) at θ = 30°.
        let h = dir(30.0, 70.0);
        let t2 = (30f32.to_radians()).tan().powi(2);
        let c4 = (30f32.to_radians()).cos().powi(4);
        assert!((g.d(h) - 0.25 / (PI * c4 * (0.25 + t2).powi(2))).abs() < 1e-5);
        // Λ(θ) = (√(1 + α² tan²θ) − 1)/2 at 60°: tan² 60° = 3, √(1 + 0.75) = 1.3229.
        let l = g.lambda(dir(60.0, 10.0));
        assert!((l - (1.75f32.sqrt() - 1.0) / 2.0).abs() < 1e-5, "{l}");
        assert_eq!(g.lambda(Vec3::Z), 0.0);
        assert_eq!(g.g1(Vec3::X), 0.0);
        // Anisotropic: along x only αx matters, along y only αy.
        let a = Ggx::new(0.2, 0.8);
        let (wx, wy) = (dir(60.0, 0.0), dir(60.0, 90.0));
        assert!((a.lambda(wx) - Ggx::isotropic(0.2).lambda(wx)).abs() < 1e-6);
        assert!((a.lambda(wy) - Ggx::isotropic(0.8).lambda(wy)).abs() < 1e-6);
        assert_eq!(Ggx::new(0.0, f32::NAN), Ggx::isotropic(MIN_ALPHA));
    }

    #[test]
    fn normal_distribution_and_visible_normals_are_normalised() {
        // ∫ D(h) cos θh dωh = 1 and ∫ D_wo(h) dωh = 1, by adaptive quadrature over the
        // hemisphere (the generic χ² integrator, which knows nothing of GGX).
        let bins = SphereBins::cap(Vec3::Z, 24, 48, 1.0);
        for (ax, ay) in DISTRIBUTIONS {
            let g = Ggx::new(ax, ay);
            let proj = integrate(&bins, |h| g.d(h) * h.z);
            assert!(
                (proj - 1.0).abs() < 2e-3,
                "α ({ax}, {ay}): ∫ D cos = {proj}"
            );
            for (theta, phi) in [(0.0, 0.0), (45.0, 30.0), (80.0, 0.0), (80.0, 120.0)] {
                let wo = dir(theta, phi);
                let vis = integrate(&bins, |h| g.visible_pdf(wo, h));
                assert!(
                    (vis - 1.0).abs() < 2e-3,
                    "α ({ax}, {ay}) at {theta}°, {phi}°: ∫ D_wo = {vis}"
                );
            }
        }
    }

    #[test]
    fn chi2_visible_normal_sampling_follows_its_density() {
        let cases: Vec<((f32, f32), f32)> = DISTRIBUTIONS
            .iter()
            .flat_map(|&a| [(a, 0.0), (a, 80.0)])
            .collect();
        let alpha = sidak_alpha(0.01, cases.len());
        for (k, &((ax, ay), theta)) in cases.iter().enumerate() {
            let g = Ggx::new(ax, ay);
            let wo = dir(theta, 25.0);
            // Zoom on the cap the normals occupy for smooth surfaces.
            let cap = 1.0 - (6.0 * ax.max(ay)).min(PI / 2.0).cos();
            let bins = SphereBins::cap(Vec3::Z, 16, 32, f64::from(cap));
            let r = chi2_test(
                100_000,
                100 + k as u64,
                &bins,
                |rng| Some(g.sample_visible(wo, rng.next_2d())),
                |h| g.visible_pdf(wo, h),
            );
            assert!(
                r.impossible == 0 && r.passes(alpha),
                "α ({ax}, {ay}) at {theta}°: {r:?}"
            );
        }
    }
}
