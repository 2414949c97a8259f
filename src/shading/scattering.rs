//! The vocabulary the BSDF mixture ([`super::Bsdf`]) and its lobes share: the shading frame,
//! the transport mode, a sampled direction, and the lobe flags.
//!
//! Conventions follow pbrt-v4 (Pharr, Jakob, Humphreys, *Physically Based Rendering*, 4th ed.,
//! §9.1–9.5) and Veach's thesis (1997, §5.2–5.3): `wo` is the direction the path arrived from
//! (towards the camera for radiance, towards the light for importance), `wi` the direction it
//! continues in; both unit and pointing away from the surface.

use glam::Vec3;
use std::ops::BitOr;

/// Which quantity a path carries (pbrt-v4's `TransportMode`; Veach 1997, §5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransportMode {
    /// Camera paths carry radiance: crossing from the side of index ηₒ to the side of index ηᵢ
    /// scales it by (ηₒ/ηᵢ)² (radiance is not conserved across a refracting boundary).
    Radiance,
    /// Light and photon paths carry flux (importance): no η² scaling, and the adjoint
    /// shading-normal correction [`shading_normal_correction`] applies.
    Importance,
}

/// The local frame a BSDF is evaluated in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingFrame {
    /// Unit shading normal on the side of `wo`.
    pub ns: Vec3,
    /// Unit geometric normal on the side of `wo`.
    pub ng: Vec3,
    /// Whether `wo` is on the outside of the object (the side its geometric normal points to),
    /// so that a transmitted path goes from index 1 to index `ior`.
    pub entering: bool,
}

/// A direction sampled from the BSDF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// Unit direction the path continues in.
    pub wi: Vec3,
    /// The path throughput multiplier `f · |ns·wi| / pdf` (times the adjoint correction in
    /// importance mode, and the η² factor of a refraction in radiance mode).
    pub weight: Vec3,
    /// Solid-angle density of `wi` (per steradian) for a non-delta sample; for a delta lobe, the
    /// discrete probability of having chosen it.
    pub pdf: f32,
    /// The sample came from a delta lobe (mirror or dielectric: a Dirac delta in direction).
    pub delta: bool,
    /// The path crossed the surface (refraction).
    pub transmitted: bool,
    /// The radiance-mode factor (ηₒ/ηᵢ)² included in `weight` (1 unless refracted in radiance
    /// mode); path tracers divide it out again for Russian roulette.
    pub eta_scale: f32,
}

/// What kind of scattering a lobe (or a whole BSDF, as the union of its lobes') does: a small
/// bit set (pbrt-v4's `BxDFFlags`, our own type). A lobe is exactly one of diffuse, glossy or
/// delta, and reflects, transmits or both.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LobeFlags(u8);

impl LobeFlags {
    /// No scattering at all.
    pub const NONE: Self = Self(0);
    /// Scatters to the side `wo` is on.
    pub const REFLECTION: Self = Self(1);
    /// Scatters through the surface.
    pub const TRANSMISSION: Self = Self(2);
    /// A smooth density over directions, spread over the hemisphere (Lambert).
    pub const DIFFUSE: Self = Self(4);
    /// A smooth density over directions, concentrated around a direction (Phong, GGX).
    pub const GLOSSY: Self = Self(8);
    /// A Dirac delta in direction (perfect mirror, smooth dielectric): has no density, light
    /// sampling never reaches it, and it is followed only by sampling it.
    pub const DELTA: Self = Self(16);
    /// Diffuse or glossy: what next-event estimation and photon density estimates see.
    pub const NON_DELTA: Self = Self(4 | 8);

    /// Both sets' flags.
    #[inline]
    #[must_use]
    pub const fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }

    /// True if every flag of `other` is set.
    #[inline]
    #[must_use]
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// True if any flag of `other` is set.
    #[inline]
    #[must_use]
    pub const fn intersects(self, other: Self) -> bool {
        self.0 & other.0 != 0
    }

    /// True for a delta lobe (or a BSDF with one).
    #[inline]
    #[must_use]
    pub const fn is_delta(self) -> bool {
        self.intersects(Self::DELTA)
    }

    /// True for a diffuse or glossy lobe (or a BSDF with one).
    #[inline]
    #[must_use]
    pub const fn is_non_delta(self) -> bool {
        self.intersects(Self::NON_DELTA)
    }
}

impl BitOr for LobeFlags {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        self.union(rhs)
    }
}

/// Veach's adjoint correction for shading normals (thesis §5.3, eq. 5.19): the factor
/// `|wo·ns| |wi·ng| / (|wo·ng| |wi·ns|)` that makes light paths that scatter at a point with a
/// shading normal carry the flux that the camera-side BSDF (with `|wi·ns|`) implies. 1 when
/// `ns == ng`; 0 when `wo` grazes the geometric surface.
#[inline]
#[must_use]
pub fn shading_normal_correction(wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
    let num = wo.dot(fr.ns).abs() * wi.dot(fr.ng).abs();
    let den = wo.dot(fr.ng).abs() * wi.dot(fr.ns).abs();
    if den > 0.0 { num / den } else { 0.0 }
}

/// The factor a delta sample's weight takes for the transport mode: 1 for radiance, the
/// adjoint correction [`shading_normal_correction`] for importance.
#[inline]
#[must_use]
pub fn mode_correction(mode: TransportMode, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
    match mode {
        TransportMode::Radiance => 1.0,
        TransportMode::Importance => shading_normal_correction(wo, wi, fr),
    }
}

/// Mean of the three channels: how lobes are weighed against each other when sampling.
#[inline]
#[must_use]
pub fn mean(c: Vec3) -> f32 {
    (c.x + c.y + c.z) * (1.0 / 3.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_combine_and_classify() {
        let glass = LobeFlags::DELTA | LobeFlags::REFLECTION | LobeFlags::TRANSMISSION;
        assert!(glass.is_delta() && !glass.is_non_delta());
        assert!(glass.contains(LobeFlags::TRANSMISSION | LobeFlags::REFLECTION));
        assert!(!glass.contains(LobeFlags::DIFFUSE | LobeFlags::REFLECTION));
        let plastic = LobeFlags::DIFFUSE | LobeFlags::GLOSSY | LobeFlags::REFLECTION;
        assert!(plastic.is_non_delta() && !plastic.is_delta());
        assert!(!plastic.intersects(LobeFlags::TRANSMISSION));
        assert_eq!(LobeFlags::NONE | LobeFlags::NONE, LobeFlags::default());
        assert!(!LobeFlags::NONE.is_delta() && !LobeFlags::NONE.is_non_delta());
    }

    #[test]
    fn adjoint_correction_by_hand() {
        let fr = ShadingFrame {
            ns: Vec3::new(0.6, 0.0, 0.8),
            ng: Vec3::Z,
            entering: true,
        };
        let (wo, wi) = (Vec3::Z, Vec3::X);
        // |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|) = 0.8 · 0 / (1 · 0.6) = 0.
        assert_eq!(shading_normal_correction(wo, wi, &fr), 0.0);
        let wi = Vec3::new(0.0, 0.6, 0.8);
        // 0.8 · 0.8 / (1 · 0.64) = 1.
        assert!((shading_normal_correction(wo, wi, &fr) - 1.0).abs() < 1e-6);
        assert_eq!(
            mode_correction(TransportMode::Radiance, wo, Vec3::X, &fr),
            1.0
        );
    }
}
