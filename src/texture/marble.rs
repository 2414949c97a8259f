//! Marble: turbulence-distorted sine veins, a solid (3-d) texture.

use glam::Vec3;

use super::noise::{Noise, octaves_for};

/// Marble veins as a solid texture: with `q = p ⊙ scale`,
///
/// ```text
/// φ = q.x + turbulence · turb(q, octaves)        (veins run across x, bent by turbulence)
/// w = smoothstep(0.5, 1, 1 − |sin φ|)            (vein weight in [0, 1]: 1 at a vein's centre,
///                                                 0 once |sin φ| ≥ ½, i.e. ⅓ of each period)
/// colour = base + (vein − base) · w
/// ```
///
/// with `smoothstep(a, b, x) = t²(3 − 2t)`, `t = clamp((x − a)/(b − a), 0, 1)`, so the ramp is
/// C¹ and every output channel lies between `base` and `vein`. Deterministic for a seed.
#[derive(Debug, Clone, PartialEq)]
pub struct Marble {
    /// Frequency per axis (radians of the vein sine per world unit along x; the noise lattice
    /// spacing is `1/scale` per axis).
    pub scale: Vec3,
    /// Octaves of turbulence (0 gives straight veins).
    pub octaves: u32,
    /// Turbulence strength: how far (in radians of phase) the veins are pushed around.
    pub turbulence: f32,
    /// Colour of the stone between veins (linear RGB).
    pub base: Vec3,
    /// Colour at the centre of a vein (linear RGB).
    pub vein: Vec3,
    noise: Noise,
}

/// `smoothstep(0.5, 1, x)` and its derivative.
#[inline]
fn ramp(x: f32) -> (f32, f32) {
    let t = ((x - 0.5) * 2.0).clamp(0.0, 1.0);
    (t * t * (3.0 - 2.0 * t), 12.0 * t * (1.0 - t))
}

impl Marble {
    /// Marble with the given parameters and the turbulence noise of `seed`.
    #[must_use]
    pub fn new(
        scale: Vec3,
        octaves: u32,
        turbulence: f32,
        base: Vec3,
        vein: Vec3,
        seed: u64,
    ) -> Self {
        Self {
            scale,
            octaves,
            turbulence,
            base,
            vein,
            noise: Noise::new(seed),
        }
    }

    /// The seed of the turbulence noise.
    #[must_use]
    pub fn seed(&self) -> u64 {
        self.noise.seed()
    }

    /// Colour at `p` (object or world space, as the caller chooses).
    #[inline]
    #[must_use]
    pub fn eval(&self, p: Vec3) -> Vec3 {
        self.eval_filtered(p, 0.0)
    }

    /// Colour at `p` seen through a footprint `width` units wide: turbulence octaves finer than
    /// the footprint are replaced by their mean (see `Noise::turbulence_octaves`). Equal to
    /// [`eval`](Self::eval) for width 0.
    #[inline]
    #[must_use]
    pub fn eval_filtered(&self, p: Vec3, width: f32) -> Vec3 {
        self.base.lerp(
            self.vein,
            self.vein_weight_resolved(p, self.resolved(width)),
        )
    }

    /// Turbulence octaves resolved by a footprint `width` units wide.
    fn resolved(&self, width: f32) -> f32 {
        octaves_for(width * self.scale.abs().max_element(), self.octaves)
    }

    /// Vein weight `w` at `p`, in [0, 1]; also a height for bump mapping.
    #[must_use]
    pub fn vein_weight(&self, p: Vec3) -> f32 {
        self.vein_weight_resolved(p, self.octaves as f32)
    }

    fn vein_weight_resolved(&self, p: Vec3, resolved: f32) -> f32 {
        let q = p * self.scale;
        let phi = q.x + self.turbulence * self.noise.turbulence_octaves(q, self.octaves, resolved);
        ramp(1.0 - phi.sin().abs()).0
    }

    /// Exact gradient of [`vein_weight`](Self::vein_weight) with respect to `p` (away from the
    /// creases of `|sin|` and of the turbulence); pass `depth × gradient` to
    /// `perturb_normal_by_gradient` to emboss the veins.
    #[must_use]
    pub fn vein_weight_gradient(&self, p: Vec3) -> Vec3 {
        self.vein_weight_gradient_filtered(p, 0.0)
    }

    /// [`vein_weight_gradient`](Self::vein_weight_gradient) with the octaves finer than a
    /// footprint `width` units wide replaced by their (constant) mean.
    #[must_use]
    pub fn vein_weight_gradient_filtered(&self, p: Vec3, width: f32) -> Vec3 {
        let q = p * self.scale;
        let (t, dt) =
            self.noise
                .turbulence_with_gradient_octaves(q, self.octaves, self.resolved(width));
        let phi = q.x + self.turbulence * t;
        let dphi = (Vec3::X + dt * self.turbulence) * self.scale;
        let (s, c) = phi.sin_cos();
        let (_, dw) = ramp(1.0 - s.abs());
        dphi * (-dw * c * if s < 0.0 { -1.0 } else { 1.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn sample() -> Marble {
        Marble::new(
            Vec3::new(4.0, 2.0, 2.0),
            5,
            3.0,
            Vec3::new(0.9, 0.85, 0.8),
            Vec3::new(0.1, 0.3, 0.2),
            17,
        )
    }

    #[test]
    fn colours_stay_between_base_and_vein_and_use_the_whole_ramp() {
        let m = sample();
        let (lo, hi) = (m.base.min(m.vein), m.base.max(m.vein));
        let mut rng = Rng::new(6, 6);
        let (mut wmin, mut wmax, mut veiny) = (1.0f32, 0.0f32, 0);
        for _ in 0..10_000 {
            let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
            let c = m.eval(p);
            assert!(
                c.cmpge(lo - 1e-6).all() && c.cmple(hi + 1e-6).all(),
                "{p}: {c}"
            );
            let w = m.vein_weight(p);
            wmin = wmin.min(w);
            wmax = wmax.max(w);
            veiny += usize::from(w > 0.0);
        }
        assert_eq!(wmin, 0.0);
        assert!(wmax > 0.99, "{wmax}");
        // Veins (w > 0) cover roughly a third of space.
        assert!((2000..5000).contains(&veiny), "{veiny}");
    }

    #[test]
    fn deterministic_per_seed() {
        let (a, b) = (sample(), sample());
        let mut c = sample();
        c.noise = Noise::new(18);
        let p = Vec3::new(0.3, 0.7, -0.2);
        assert_eq!(a.eval(p), b.eval(p));
        assert_eq!(a.seed(), 17);
        let mut rng = Rng::new(8, 8);
        let differ = (0..200)
            .filter(|_| {
                let q = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0;
                a.eval(q) != c.eval(q)
            })
            .count();
        assert!(differ > 20, "{differ}");
    }

    #[test]
    fn vein_gradient_matches_central_differences_almost_everywhere() {
        let m = sample();
        let mut rng = Rng::new(12, 0);
        let h = 1e-4;
        let mut bad = 0;
        for _ in 0..1000 {
            let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
            let g = m.vein_weight_gradient(p);
            let f = |d: Vec3| m.vein_weight(p + d);
            let fd = Vec3::new(
                f(Vec3::X * h) - f(-Vec3::X * h),
                f(Vec3::Y * h) - f(-Vec3::Y * h),
                f(Vec3::Z * h) - f(-Vec3::Z * h),
            ) / (2.0 * h);
            assert!(g.is_finite());
            // Points within h of a crease (|sin φ| = 0, an octave's zero, the ramp's ends) differ.
            if (g - fd).abs().max_element() > 2e-2 * (1.0 + g.length()) {
                bad += 1;
            }
        }
        assert!(bad < 20, "{bad} of 1000");
    }
}
