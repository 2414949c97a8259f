//! Marble: turbulence-distorted sine veins, a solid (3-d) texture.

use glam::Vec3;

use super::noise::{Noise, octaves_for, unresolved_turbulence_variance};

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
    /// The vein profile's Fourier coefficients ([`vein_harmonics`]), for the filter.
    harmonics: [f32; HARMONICS + 1],
    /// Turbulence octaves always evaluated, however wide the footprint ([`MAX_PHASE_VARIANCE`]).
    min_resolved: f32,
}

/// Most phase variance (radians²) a filtered lookup may replace by its mean and the spread
/// profile ([`spread_vein_weight`]): octaves whose left-out variance would exceed it are always
/// evaluated. The Gaussian model of the left-out phase is good for small spreads only (the
/// coarse octaves of `|noise|` are skewed), and a coarse octave replaced by its mean moves the
/// veins by a large part of their period, so such octaves are evaluated as they are: a wide
/// footprint then reads the point value, noisier but exact in the mean, which is what matters
/// after diffuse bounces, where footprints are widest. Measured (`texture::marble` tests and
/// `tests/it/textures.rs`): 0.0025 keeps a wall's mean within 0.0003 but takes away the
/// filter's antialiasing of distant marble; 0.03 keeps it within 0.0032 and the antialiasing.
const MAX_PHASE_VARIANCE: f32 = 0.03;

/// Harmonics of the vein profile whose attenuation the filter models (the rest, about 10⁻³ of
/// the profile, stay as they are).
const HARMONICS: usize = 24;

/// The Fourier cosine coefficients of the vein profile `f(φ) = smoothstep(0.5, 1, 1 − |sin φ|)`,
/// π-periodic and even: `f(φ) = c₀ + Σₖ cₖ cos(2kφ)`; index 0 is the mean `c₀`. Computed by the
/// midpoint rule on 4096 points (the profile is C¹, so the error is far below f32's).
fn vein_harmonics() -> [f32; HARMONICS + 1] {
    const N: usize = 4096;
    let mut c = [0.0f64; HARMONICS + 1];
    for j in 0..N {
        let phi = std::f64::consts::PI * (j as f64 + 0.5) / N as f64;
        let f = f64::from(ramp(1.0 - (phi.sin().abs() as f32)).0);
        for (k, ck) in c.iter_mut().enumerate() {
            *ck += f * (2.0 * k as f64 * phi).cos();
        }
    }
    let mut out = [0.0f32; HARMONICS + 1];
    for (k, ck) in c.iter().enumerate() {
        let scale = if k == 0 { 1.0 } else { 2.0 };
        out[k] = (scale * ck / N as f64) as f32;
    }
    out
}

/// The vein weight of phase `phi` averaged over a Gaussian spread of the phase with variance
/// `var` (radians²), from the profile's coefficients `c` ([`vein_harmonics`]): the profile minus the part of each harmonic that the spread averages away
/// (harmonic `k` keeps `exp(−2k²·var)` of its amplitude). Equal to the profile for `var = 0`;
/// tends to the profile's mean as `var` grows.
#[inline]
fn spread_vein_weight(c: &[f32; HARMONICS + 1], phi: f32, var: f32) -> f32 {
    let f = ramp(1.0 - phi.sin().abs()).0;
    if !(var > 0.0) {
        return f;
    }
    let c2 = (2.0 * phi).cos();
    let g = (-2.0 * var).exp();
    // cos(2kφ) by the Chebyshev recurrence, g^(k²) by g^((k+1)²) = g^(k²)·g^(2k+1).
    let (mut prev, mut cur) = (1.0f32, c2);
    let (mut gk2, mut g_step) = (g, g * g * g);
    let mut lost = 0.0;
    for ck in &c[1..] {
        lost += ck * (1.0 - gk2) * cur;
        (prev, cur) = (cur, 2.0 * c2 * cur - prev);
        gk2 *= g_step;
        g_step *= g * g;
    }
    (f - lost).clamp(0.0, 1.0)
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
            harmonics: vein_harmonics(),
            min_resolved: (0..=octaves)
                .find(|&r| {
                    turbulence * turbulence * unresolved_turbulence_variance(octaves, r as f32)
                        <= MAX_PHASE_VARIANCE
                })
                .unwrap_or(octaves) as f32,
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

    /// Colour at `p` seen through a footprint `width` units wide, keeping the colour's mean over
    /// any region however wide the footprint. Turbulence octaves finer than the footprint are
    /// replaced by their mean (see `Noise::turbulence_octaves`) only while the phase they would
    /// have added is small ([`MAX_PHASE_VARIANCE`]; coarser octaves are always evaluated), and the
    /// vein profile is averaged over that phase (taken as Gaussian with the variance the octaves
    /// leave out, `unresolved_turbulence_variance`). Replacing every unresolved octave by its
    /// mean, as before 5 December 2026, evaluated the vein at the mean phase: on a wall of
    /// constant `x` (where only the turbulence moves the phase) that paints the whole wall one
    /// colour, and the bath's image, whose camera paths read its marble through wide footprints
    /// after diffuse bounces, came out 1.3 % darker than with point lookups (and than photon
    /// paths, which read textures at points). Equal to [`eval`](Self::eval) for width 0.
    #[inline]
    #[must_use]
    pub fn eval_filtered(&self, p: Vec3, width: f32) -> Vec3 {
        let resolved = self.resolved(width).max(self.min_resolved);
        let phi = self.phase(p, resolved);
        let var = self.turbulence
            * self.turbulence
            * unresolved_turbulence_variance(self.octaves, resolved);
        self.base
            .lerp(self.vein, spread_vein_weight(&self.harmonics, phi, var))
    }

    /// Turbulence octaves resolved by a footprint `width` units wide.
    fn resolved(&self, width: f32) -> f32 {
        octaves_for(width * self.scale.abs().max_element(), self.octaves)
    }

    /// Vein weight `w` at `p`, in [0, 1]; also a height for bump mapping.
    #[must_use]
    pub fn vein_weight(&self, p: Vec3) -> f32 {
        ramp(1.0 - self.phase(p, self.octaves as f32).sin().abs()).0
    }

    /// The vein phase `φ` at `p` with the first `resolved` turbulence octaves evaluated and the
    /// rest at their mean.
    #[inline]
    fn phase(&self, p: Vec3, resolved: f32) -> f32 {
        let q = p * self.scale;
        q.x + self.turbulence * self.noise.turbulence_octaves(q, self.octaves, resolved)
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

// Every field, the derived ones too (cheap, and a derived field is never wrongly left out).
crate::key_hash_struct!(Marble {
    scale,
    octaves,
    turbulence,
    base,
    vein,
    noise,
    harmonics,
    min_resolved
});

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

    /// The bath's wall marble (`scenes/bath.ron`): base and vein as grey levels 1 and 0, so the
    /// colour's first channel is one minus the vein weight.
    fn bath_marble() -> Marble {
        Marble::new(Vec3::new(8.0, 2.5, 2.5), 6, 2.5, Vec3::ONE, Vec3::ZERO, 7)
    }

    #[test]
    fn the_harmonics_rebuild_the_vein_profile() {
        let m = bath_marble();
        for i in 0..200 {
            let phi = i as f32 * 0.0314;
            let series: f32 = m
                .harmonics
                .iter()
                .enumerate()
                .map(|(k, c)| c * (2.0 * k as f32 * phi).cos())
                .sum();
            let f = ramp(1.0 - phi.sin().abs()).0;
            assert!((series - f).abs() < 0.02, "phi {phi}: {series} vs {f}");
        }
        // The mean: the profile is 0 where |sin φ| ≥ ½ (two thirds of each period).
        let mean = (0..10_000)
            .map(|j| ramp(1.0 - ((j as f32 + 0.5) * std::f32::consts::PI / 1e4).sin().abs()).0)
            .sum::<f32>()
            / 1e4;
        assert!(
            (m.harmonics[0] - mean).abs() < 1e-4,
            "{} {mean}",
            m.harmonics[0]
        );
        // No spread: the profile itself; a wide one: its mean at every phase; a small one: the
        // average of the profile over the phase's Gaussian (midpoint rule over ±5σ).
        for i in 0..100 {
            let phi = i as f32 * 0.0628;
            let f = ramp(1.0 - phi.sin().abs()).0;
            assert_eq!(spread_vein_weight(&m.harmonics, phi, 0.0), f);
            let wide = spread_vein_weight(&m.harmonics, phi, 10.0);
            assert!((wide - mean).abs() < 3e-3, "phi {phi}: {wide} vs {mean}");
            let sigma = 0.05f32;
            let (mut sum, mut norm) = (0.0f32, 0.0f32);
            for j in -500..=500 {
                let d = j as f32 * sigma / 100.0;
                let w = (-0.5 * (d / sigma).powi(2)).exp();
                sum += w * ramp(1.0 - (phi + d).sin().abs()).0;
                norm += w;
            }
            let small = spread_vein_weight(&m.harmonics, phi, sigma * sigma);
            assert!(
                (small - sum / norm).abs() < 0.01,
                "phi {phi}: {small} vs {}",
                sum / norm
            );
        }
    }

    #[test]
    fn wide_footprints_keep_the_colours_mean_over_a_wall() {
        // The area mean of the filtered colour over a wall equals the point colour's (the truth)
        // at every footprint width, on a wall of constant x (the bath's side walls: there only
        // the turbulence moves the phase, so evaluating the vein at the mean phase painted the
        // whole wall one colour) and on one of constant z (the phase sweeps along x).
        let m = bath_marble();
        let mut rng = Rng::new(3, 9);
        type Wall = fn(f32, f32) -> Vec3;
        let walls: [(&str, Wall); 2] = [
            ("x = -0.9", |a, b| Vec3::new(-0.9, 2.4 * a, 3.0 * b - 1.0)),
            ("z = -1", |a, b| Vec3::new(1.8 * a - 0.9, 2.4 * b, -1.0)),
        ];
        for (name, wall) in walls {
            let points: Vec<Vec3> = (0..40_000)
                .map(|_| wall(rng.next_f32(), rng.next_f32()))
                .collect();
            let mean = |w: f32| {
                points
                    .iter()
                    .map(|&p| f64::from(m.eval_filtered(p, w).x))
                    .sum::<f64>()
                    / points.len() as f64
            };
            let truth = mean(0.0);
            for w in [0.003, 0.03, 0.3, 3.0, 30.0] {
                let filtered = mean(w);
                eprintln!("{name}: width {w}: mean {filtered:.4} (point lookups {truth:.4})");
                assert!(
                    (filtered - truth).abs() < 0.01,
                    "{name}: width {w}: mean {filtered} against {truth}"
                );
            }
        }
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
