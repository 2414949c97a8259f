//! Lights as the renderer samples them: a sphere light too small to sample in single precision
//! is compiled as the point light it converges to.
//!
//! A sphere light of power Φ and radius r has radiance Φ/(4π²r²) and is sampled over the cone it
//! subtends, of solid angle ≈ πr²/d² at distance d (see `render_scene::light`). In f32 both
//! break for a small enough r: the radiance overflows to infinity, or r²/d² leaves the normal
//! range and loses its precision, then reaches 0 (infinite radiance times a zero solid angle is a
//! NaN sample). The irradiance the sphere casts, Φ cos θ/(4πd²) for a point it fully lights, is
//! exactly a point light's of the same power, and the difference for a finite sphere is of order
//! r²/d²; so below the radius f32 can sample, the point light *is* the sphere light, to every
//! digit f32 holds. It is kept rather than refused (a radius swept towards 0 keeps rendering the
//! same image) with a warning, because the point light has no surface a camera ray can hit.

use glam::Vec3;

use crate::render_scene::geometry::GeometryBuilder;
use crate::scene::Diagnostic;

/// Largest radiance, in W/(m²·sr), a sphere light may have: f32 reaches 3.4e38, and this leaves
/// eight orders of magnitude for the sums of samples and the exposure.
pub const MAX_SPHERE_RADIANCE: f64 = 1e30;

/// The smallest radius, in scene units, at which a sphere light of `power` (W per channel) can be
/// sampled in f32 from every point up to `reach` away: its radiance at most
/// [`MAX_SPHERE_RADIANCE`], and the squared sine of its cone's half-angle, r²/d², a normal f32
/// (at least `f32::MIN_POSITIVE`, about 1.2e-38) out to distance `reach`.
#[must_use]
pub fn min_sphere_light_radius(power: Vec3, reach: f64) -> f64 {
    let phi = f64::from(power.max_element().max(0.0));
    let by_radiance = (phi / (4.0 * std::f64::consts::PI.powi(2) * MAX_SPHERE_RADIANCE)).sqrt();
    let by_cone = f64::from(f32::MIN_POSITIVE).sqrt() * reach.max(1.0);
    by_radiance.max(by_cone)
}

/// The warning for `lights[index]`, a sphere light of `radius` below
/// [`min_sphere_light_radius`] for `power` and `reach`, compiled as a point light: which limit
/// it is below, and what to write instead.
#[must_use]
pub(super) fn point_fallback_warning(
    index: usize,
    radius: f32,
    power: Vec3,
    reach: f64,
) -> Diagnostic {
    let min = min_sphere_light_radius(power, reach);
    let r = f64::from(radius);
    let radiance = f64::from(power.max_element()) / (4.0 * std::f64::consts::PI.powi(2) * r * r);
    let why = if radiance > MAX_SPHERE_RADIANCE {
        format!(
            "its radiance Φ/(4π²r²) would be {radiance:.2e} W/(m²·sr), above the limit of {MAX_SPHERE_RADIANCE:e}"
        )
    } else {
        format!(
            "the cone it subtends from {reach:.3} units away is too narrow for f32 (r²/d² below {:e})",
            f32::MIN_POSITIVE
        )
    };
    Diagnostic::warning(
        format!("lights[{index}].radius"),
        format!(
            "a sphere light of radius {radius:e} is too small to sample in single precision: {why}; it is rendered as a point light of the same power, the limit it tends to (a point light is not seen by camera rays)"
        ),
    )
    .with_help(format!(
        "use a `Point` light, or a radius of at least {min:.3e}"
    ))
}

/// The farthest any point of the scene (every primitive built so far, and the camera `eye`) is
/// from `center`, in scene units: the longest distance a shaded point can be from a light there.
#[must_use]
pub(super) fn reach(builder: &GeometryBuilder, center: Vec3, eye: Vec3) -> f64 {
    let c = center.as_dvec3();
    let far = |p: Vec3| (p.as_dvec3() - c).length();
    let tris = builder.triangles.iter().flatten().map(|p| far(*p));
    let spheres = builder
        .spheres
        .iter()
        .map(|s| far(s.center) + f64::from(s.radius));
    let ellipsoids = builder.ellipsoids.iter().map(|e| {
        let m = e.world_from_object.matrix3;
        (e.world_from_object.translation - c).length()
            + m.x_axis.length()
            + m.y_axis.length()
            + m.z_axis.length()
    });
    tris.chain(spheres)
        .chain(ellipsoids)
        .fold(far(eye), f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_keeps_radiance_and_cone_inside_f32() {
        // A faint light (1 µW): the cone decides, r = 1.0842e-19 × reach.
        let power = Vec3::new(1e-6, 5e-7, 0.0);
        let reach = 10.0;
        let r = min_sphere_light_radius(power, reach);
        assert!((r / 1.084_202_2e-18 - 1.0).abs() < 1e-6, "{r:e}");
        // At the limit the radiance is finite and the cone's sin² at `reach` is a normal f32.
        let r32 = r as f32 * (1.0 + 1e-6);
        let radiance = 1e-6 / (4.0 * std::f32::consts::PI.powi(2) * r32 * r32);
        assert!(radiance.is_finite() && f64::from(radiance) <= MAX_SPHERE_RADIANCE);
        let sin2 = (r32 * r32) / (reach as f32 * reach as f32);
        assert!(sin2.is_normal(), "{sin2:e}");
        // A huge power makes the radiance decide: Φ/(4π²r²) = 1e30 at the limit.
        let r = min_sphere_light_radius(Vec3::splat(1e20), reach);
        let l = f64::from(1e20f32) / (4.0 * std::f64::consts::PI.powi(2) * r * r);
        assert!((l / MAX_SPHERE_RADIANCE - 1.0).abs() < 1e-9, "{l:e}");
    }
}
