//! Water ripples: a procedural height field over uv, used as a bump (normal perturbation).

use glam::{Vec2, Vec3};

use super::bump::perturb_normal;

/// Circular ripples spreading from `centers` in uv space. With `r = |uv − c|`, `A` the
/// amplitude, `f` the frequency and `d` the decay:
///
/// ```text
/// h(uv) = Σ_c A · (1 + d·r) · e^(−d·r) · cos(f·r)
/// ∇h(uv) = Σ_c A · [ −d² · e^(−d·r) · cos(f·r) − (1 + d·r) · e^(−d·r) · f² · sinc(f·r) ] · (uv − c)
/// ```
///
/// with `sinc x = sin x / x` (1 at 0). The envelope `(1 + d·r)e^(−d·r)` decays like `e^(−d·r)`
/// far away but is flat at the centre, and `cos` is even in `r`, so the surface has no cone tip:
/// h is C² in uv everywhere, the gradient formula has no division (no 0/0 at `r = 0`, where the
/// gradient is exactly 0) and is finite at any distance.
#[derive(Debug, Clone, PartialEq)]
pub struct Ripples {
    /// Ripple centres in uv.
    pub centers: Vec<Vec2>,
    /// Angular frequency `f`, radians per uv unit (wavelength `2π/f`).
    pub frequency: f32,
    /// Peak height `A` at a centre, in world units (the bump depth).
    pub amplitude: f32,
    /// Radial decay `d` per uv unit, ≥ 0 (0: no decay).
    pub decay: f32,
}

/// `sin x / x`, accurate near 0.
#[inline]
fn sinc(x: f32) -> f32 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

impl Ripples {
    /// Ripples around `centers`.
    #[must_use]
    pub fn new(centers: Vec<Vec2>, frequency: f32, amplitude: f32, decay: f32) -> Self {
        Self {
            centers,
            frequency,
            amplitude,
            decay,
        }
    }

    /// Height `h(uv)` in world units.
    #[must_use]
    pub fn height(&self, uv: Vec2) -> f32 {
        let (f, d) = (self.frequency, self.decay);
        self.centers
            .iter()
            .map(|&c| {
                let r = (uv - c).length();
                (1.0 + d * r) * (-d * r).exp() * (f * r).cos()
            })
            .sum::<f32>()
            * self.amplitude
    }

    /// Exact gradient `(∂h/∂u, ∂h/∂v)` in world units per uv unit; exactly zero for zero
    /// amplitude and at a lone centre.
    #[must_use]
    pub fn gradient(&self, uv: Vec2) -> Vec2 {
        if self.amplitude == 0.0 {
            return Vec2::ZERO;
        }
        let (f, d) = (self.frequency, self.decay);
        let g = self.centers.iter().fold(Vec2::ZERO, |g, &c| {
            let x = uv - c;
            let r = x.length();
            let e = (-d * r).exp();
            let fr = f * r;
            g + x * (-d * d * e * fr.cos() - (1.0 + d * r) * e * f * f * sinc(fr))
        });
        g * self.amplitude
    }

    /// The unit normal `n` perturbed by the ripples at `uv` (see
    /// [`perturb_normal`](super::perturb_normal)); `n` bit-identical when the gradient is 0.
    #[must_use]
    pub fn perturb(&self, n: Vec3, dpdu: Vec3, dpdv: Vec3, uv: Vec2) -> Vec3 {
        let g = self.gradient(uv);
        perturb_normal(n, dpdu, dpdv, g.x, g.y)
    }
}

crate::key_hash_struct!(Ripples {
    centers,
    frequency,
    amplitude,
    decay
});

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn pond() -> Ripples {
        Ripples::new(
            vec![
                Vec2::new(0.3, 0.4),
                Vec2::new(0.7, 0.6),
                Vec2::new(0.5, 0.1),
            ],
            40.0,
            0.01,
            3.0,
        )
    }

    #[test]
    fn gradient_matches_central_differences_at_1000_points() {
        let w = pond();
        let mut rng = Rng::new(21, 0);
        let h = 1e-3;
        let (mut checked, mut worst) = (0, 0.0f32);
        while checked < 1000 {
            let uv = Vec2::new(rng.next_f32(), rng.next_f32()) * 1.4 - 0.2;
            if w.centers.iter().any(|c| c.distance(uv) < 1e-3) {
                continue;
            }
            checked += 1;
            let g = w.gradient(uv);
            // Divide by the step actually taken (exact in f32), not by 2h.
            let (up, um) = (uv.x + h, uv.x - h);
            let (vp, vm) = (uv.y + h, uv.y - h);
            let fd = Vec2::new(
                (w.height(Vec2::new(up, uv.y)) - w.height(Vec2::new(um, uv.y))) / (up - um),
                (w.height(Vec2::new(uv.x, vp)) - w.height(Vec2::new(uv.x, vm))) / (vp - vm),
            );
            // Relative 1e-3, with a floor of 1e-3 of the typical slope A·f = 0.4.
            let err = (g - fd).length() / (g.length() + 0.4);
            worst = worst.max(err);
            assert!(err < 1e-3, "{uv}: {g} vs {fd}");
        }
        assert!(worst > 0.0);
    }

    #[test]
    fn centre_is_smooth_and_finite() {
        let w = Ripples::new(vec![Vec2::new(0.5, 0.5)], 40.0, 0.01, 3.0);
        let c = Vec2::new(0.5, 0.5);
        assert_eq!(w.gradient(c), Vec2::ZERO);
        assert_eq!(w.height(c), 0.01);
        // Near the centre the surface is a smooth cap: ∇h ≈ −A(d² + f²)(uv − c).
        let eps = Vec2::new(1e-4, -2e-4);
        let g = w.gradient(c + eps);
        let want = -0.01 * (9.0 + 1600.0) * eps;
        assert!((g - want).length() < 1e-3 * want.length(), "{g} vs {want}");
        let n = w.perturb(Vec3::Z, Vec3::X, Vec3::Y, c);
        assert_eq!(n, Vec3::Z);
        // Finite at any distance, including no decay at all.
        for far in [10.0, 1e3, 1e6, 1e12] {
            assert!(w.gradient(Vec2::new(far, -far)).is_finite());
            assert!(w.height(Vec2::new(far, -far)).is_finite());
        }
        let undamped = Ripples::new(vec![c], 40.0, 0.01, 0.0);
        assert!(undamped.gradient(Vec2::new(1e6, 3.0)).is_finite());
    }

    #[test]
    fn zero_amplitude_is_exactly_no_perturbation() {
        let mut w = pond();
        w.amplitude = 0.0;
        let n = Vec3::new(0.2, 0.3, 0.9).normalize();
        let mut rng = Rng::new(22, 0);
        for _ in 0..100 {
            let uv = Vec2::new(rng.next_f32(), rng.next_f32());
            assert_eq!(w.gradient(uv), Vec2::ZERO);
            let out = w.perturb(n, Vec3::X, Vec3::Y, uv);
            assert_eq!(
                out.to_array().map(f32::to_bits),
                n.to_array().map(f32::to_bits)
            );
        }
        // No centres: also flat.
        let none = Ripples::new(Vec::new(), 40.0, 0.01, 3.0);
        assert_eq!(none.gradient(Vec2::new(0.3, 0.3)), Vec2::ZERO);
    }

    #[test]
    fn ripples_tilt_the_normal_away_from_rising_height() {
        let w = Ripples::new(vec![Vec2::ZERO], 10.0, 0.05, 1.0);
        // At r = π/20 (half-way down the first crest, cos falls) the height decreases outward.
        let uv = Vec2::new(std::f32::consts::PI / 20.0, 0.0);
        let g = w.gradient(uv);
        assert!(g.x < 0.0 && g.y == 0.0, "{g}");
        let n = w.perturb(Vec3::Z, Vec3::X, Vec3::Y, uv);
        assert!(n.x > 0.0 && (n.length() - 1.0).abs() < 1e-6, "{n}");
    }
}
