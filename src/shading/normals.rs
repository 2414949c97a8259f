//! Keeping shading normals usable: a bumped, rippled or interpolated normal can face away from
//! the viewer or mirror rays into the surface; this bends it just enough that it cannot.

use glam::Vec3;

use super::optics::reflect;

/// The shading normal every integrator shades with, given the raw shading normal `ns` and the
/// geometric normal `ng` (both unit, on the side of the unit outgoing direction `wo`).
///
/// Rule (the one Cycles uses in `ensure_valid_specular_reflection`): the mirror direction of
/// `wo` about the returned normal must leave the geometric surface by at least
/// `q = min(0.9 · (wo·ng), 0.01)`. When the mirror `r` of `wo` about `ns` satisfies
/// `r·ng ≥ q`, `ns` is returned unchanged (bit-identical). Otherwise `r` is lowered onto the
/// cone `r'·ng = min(0.95 · (wo·ng), 0.0105)` (a margin above `q` for rounding) keeping its tangential direction, and the result is the half vector
/// `normalize(wo + r')`, whose mirror of `wo` is exactly `r'`. Consequences:
/// - `wo · n > 0`: the BSDF is never evaluated "from behind" (no black speckles);
/// - the mirrored ray leaves above the geometric surface (no self-hits, no light leaks);
/// - the change is the smallest rotation towards `wo` that achieves both, so it is continuous
///   (except that a normal facing away from `wo` altogether is replaced by `ng`).
///
/// Non-finite input gives back `ng`.
#[must_use]
pub fn usable_shading_normal(ns: Vec3, ng: Vec3, wo: Vec3) -> Vec3 {
    let cos_o = wo.dot(ng);
    let q = (0.9 * cos_o).min(0.01);
    if !(ns.dot(wo) > 0.0) {
        // Facing away from wo (its mirror may still point up, but the BSDF would see wo from
        // behind): the geometric normal is the only sensible frame.
        return ng;
    }
    let r = reflect(wo, ns);
    let rn = r.dot(ng);
    if rn >= q {
        return ns;
    }
    // Aim a little above q so rounding in normalize/reflect cannot land below it.
    let target = (0.95 * cos_o).min(0.0105);
    let tangent = r - ng * rn;
    let len = tangent.length();
    let lowered = if len > 0.0 {
        tangent * ((1.0 - target * target).max(0.0).sqrt() / len) + ng * target
    } else {
        ng
    };
    let n = (wo + lowered).normalize();
    if n.is_finite() { n } else { ng }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::sampling::warp::uniform_cone;

    fn uniform_sphere(u: (f32, f32)) -> Vec3 {
        uniform_cone(u, Vec3::Z, -1.0)
    }

    #[test]
    fn valid_normals_are_kept_bit_identical() {
        let ng = Vec3::Z;
        let ns = Vec3::new(0.1, 0.0, 1.0).normalize();
        let wo = Vec3::new(0.0, 0.3, 1.0).normalize();
        assert_eq!(usable_shading_normal(ns, ng, wo), ns);
        assert_eq!(usable_shading_normal(ng, ng, wo), ng);
    }

    /// 10⁶ random (ns, wo) pairs, ns up to 85° from ng and wo·ng ∈ [1e-4, 1] (hard case B.10).
    #[test]
    fn mirror_directions_always_leave_the_surface_and_wo_is_in_front() {
        let ng = Vec3::Z;
        let mut rng = Rng::new(10, 10);
        let (mut bent, mut bad) = (0, 0);
        let max_tilt = 85f32.to_radians().cos();
        let mut n = 0;
        while n < 1_000_000 {
            let ns = uniform_sphere(rng.next_2d());
            let wo = uniform_sphere(rng.next_2d());
            if ns.z < max_tilt || wo.z < 1e-4 {
                continue;
            }
            n += 1;
            let m = usable_shading_normal(ns, ng, wo);
            if m != ns {
                bent += 1;
            }
            let r = reflect(wo, m);
            let q = (0.9 * wo.z).min(0.01);
            if !(r.dot(ng) >= q) || !(m.dot(wo) > 0.0) || (m.length() - 1.0).abs() > 1e-5 {
                bad += 1;
            }
        }
        assert_eq!(bad, 0, "{bad} invalid of 1e6 ({bent} bent)");
        // The case is exercised: many normals needed bending.
        assert!(bent > 50_000, "{bent}");
    }

    #[test]
    fn degenerate_inputs_fall_back_to_the_geometric_normal() {
        let ng = Vec3::Z;
        let m = usable_shading_normal(Vec3::NAN, ng, Vec3::Z);
        assert_eq!(m, ng);
        // Shading normal pointing straight back: the result is still in front of wo.
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let m = usable_shading_normal(-wo, ng, wo);
        assert!(m.dot(wo) > 0.0 && m.is_finite());
    }
}
