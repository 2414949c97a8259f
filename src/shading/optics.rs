//! Mirror reflection, Snell refraction and dielectric Fresnel reflectance.

use glam::Vec3;

/// Mirror direction of `wo` (pointing away from the surface) about the unit normal `n`:
/// `R = 2(n·wo)n − wo` (the report's `I − 2(N·I)N` with `I = −wo`).
#[inline]
#[must_use]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * n.dot(wo) * n - wo
}

/// Refracted direction of `wo` (pointing away from the surface, on the side `n` points to) into
/// the other medium, where `eta = η_incident / η_transmitted`. `None` on total internal reflection.
#[inline]
#[must_use]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    if eta == 1.0 {
        // Index-matched: exactly straight through, even at grazing angles.
        return Some(-wo);
    }
    let cos_i = n.dot(wo).clamp(-1.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo * eta + n * (eta * cos_i - cos_t)).normalize())
}

/// Unpolarised Fresnel reflectance of a smooth dielectric boundary for incidence cosine `cos_i`
/// (> 0, measured on the incident side) and `eta = η_incident / η_transmitted`. 1 under total
/// internal reflection; exactly 0 when `eta == 1`.
#[inline]
#[must_use]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    if eta == 1.0 {
        return 0.0;
    }
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    // η_i cos_i vs η_t cos_t with η_i/η_t = eta.
    let r_parl = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (0.5 * (r_parl * r_parl + r_perp * r_perp)).clamp(0.0, 1.0)
}

/// The dielectric's split at one incidence: Fresnel reflectance (1 when nothing refracts),
/// refracted direction (if any) and the relative index `eta = ηₒ/ηᵢ` of the crossing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FresnelSplit {
    /// Fresnel reflectance at `wo`.
    pub fresnel: f32,
    /// The refracted direction, below the geometric surface.
    pub refracted: Option<Vec3>,
    /// `ηₒ/ηᵢ` of the crossing.
    pub eta: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn deg(a: f32) -> f32 {
        a.to_radians().cos()
    }

    #[test]
    fn fresnel_matches_hand_computed_values() {
        let glass = 1.0 / 1.5;
        assert!((fresnel_dielectric(1.0, glass) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.0 / 1.33) - 0.020_059).abs() < 1e-5);
        assert!((fresnel_dielectric(deg(45.0), glass) - 0.050_240).abs() < 1e-5);
        assert!((fresnel_dielectric(deg(80.0), glass) - 0.387_704_35).abs() < 1e-5);
        assert_eq!(
            fresnel_dielectric(deg(45.0), 1.5),
            1.0,
            "45° from inside glass is beyond critical"
        );
        assert!(
            (fresnel_dielectric(0.0, glass) - 1.0).abs() < 1e-6,
            "grazing"
        );
        assert_eq!(fresnel_dielectric(0.3, 1.0), 0.0, "index-matched");
        assert!(
            (fresnel_dielectric(1.000_000_1, glass) - 0.04).abs() < 1e-6,
            "cos slightly above 1"
        );
        // Critical angle of glass 41.810°, water 48.753°.
        assert!(fresnel_dielectric(deg(41.80), 1.5) < 1.0);
        assert_eq!(fresnel_dielectric(deg(41.82), 1.5), 1.0);
        assert!(fresnel_dielectric(deg(48.74), 1.33) < 1.0);
        assert_eq!(fresnel_dielectric(deg(48.77), 1.33), 1.0);
    }

    #[test]
    fn snell_holds_across_incidence_angles() {
        let n = Vec3::Z;
        for i in 0..=90 {
            let th = (i as f32).to_radians();
            let wo = Vec3::new(th.sin(), 0.0, th.cos());
            let eta = 1.0 / 1.5;
            let wt = refract(wo, n, eta).expect("air to glass never reflects totally");
            let sin_t = (wt.x * wt.x + wt.y * wt.y).sqrt();
            assert!((th.sin() - sin_t / eta).abs() < 1e-5, "angle {i}");
            assert!(wt.z < 0.0, "goes through");
            assert!((wt.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn total_internal_reflection_beyond_critical_angle() {
        let n = Vec3::Z;
        let crit = (1.0f32 / 1.5).asin();
        let just_below = crit - 1e-3;
        let just_above = crit + 1e-3;
        let wo = |t: f32| Vec3::new(t.sin(), 0.0, t.cos());
        assert!(refract(wo(just_below), n, 1.5).is_some());
        assert!(refract(wo(just_above), n, 1.5).is_none());
    }

    #[test]
    fn reflection_formula() {
        let n = Vec3::Y;
        let wo = Vec3::new(1.0, 1.0, 0.0).normalize();
        let r = reflect(wo, n);
        assert!(r.distance(Vec3::new(-1.0, 1.0, 0.0).normalize()) < 1e-6);
        assert!((r.length() - 1.0).abs() < 1e-6);
        // The report's form R = I − 2(N·I)N with I = −wo.
        let i = -wo;
        assert!(r.distance(i - 2.0 * n.dot(i) * n) < 1e-6);
    }

    #[test]
    fn index_matched_refraction_is_a_straight_line() {
        let wo = Vec3::new(0.3, 0.4, 0.866).normalize();
        let wt = refract(wo, Vec3::Z, 1.0).unwrap();
        assert!(wt.distance(-wo) < 1e-6);
    }
}
