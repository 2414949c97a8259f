//! Seeded 3-d gradient noise (Perlin's "improved noise"), fractal sums and their gradients.

use glam::Vec3;

use crate::sampling::rng::mix64;

/// Perlin's 12 cube-edge gradients, padded to 16 with four repeats (Perlin 2002).
const GRADIENTS: [Vec3; 16] = [
    Vec3::new(1.0, 1.0, 0.0),
    Vec3::new(-1.0, 1.0, 0.0),
    Vec3::new(1.0, -1.0, 0.0),
    Vec3::new(-1.0, -1.0, 0.0),
    Vec3::new(1.0, 0.0, 1.0),
    Vec3::new(-1.0, 0.0, 1.0),
    Vec3::new(1.0, 0.0, -1.0),
    Vec3::new(-1.0, 0.0, -1.0),
    Vec3::new(0.0, 1.0, 1.0),
    Vec3::new(0.0, -1.0, 1.0),
    Vec3::new(0.0, 1.0, -1.0),
    Vec3::new(0.0, -1.0, -1.0),
    Vec3::new(1.0, 1.0, 0.0),
    Vec3::new(-1.0, 1.0, 0.0),
    Vec3::new(0.0, -1.0, 1.0),
    Vec3::new(0.0, -1.0, -1.0),
];

/// Shift between octaves, so the lattice points of successive octaves (where each is 0) do not
/// line up at the origin.
const OCTAVE_SHIFT: Vec3 = Vec3::new(19.19, 7.31, 3.77);

/// Gradient noise over ℝ³ with period 256 per axis, determined by a seed: 0 at every integer
/// lattice point, C² (quintic fade), values in about [−1, 1], mean 0.
///
/// Fractal sums use lacunarity 2 and gain ½: octave `i` is `0.5^i · noise(2^i p + i·shift)`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Noise {
    perm: [u8; 256],
    seed: u64,
}

#[inline]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline]
fn fade_deriv(t: f32) -> f32 {
    30.0 * t * t * (t * (t - 2.0) + 1.0)
}

impl Noise {
    /// The noise of `seed`: a permutation of 0..256 shuffled (Fisher–Yates) by a SplitMix64
    /// stream (`mix64`) started from the seed.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        let mut perm = [0u8; 256];
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i as u8;
        }
        let mut state = seed;
        for i in (1..256usize).rev() {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let j = (mix64(state) % (i as u64 + 1)) as usize;
            perm.swap(i, j);
        }
        Self { perm, seed }
    }

    /// The seed this noise was built from.
    #[must_use]
    pub fn seed(&self) -> u64 {
        self.seed
    }

    #[inline]
    fn gradient_at(&self, x: i32, y: i32, z: i32) -> Vec3 {
        // Only the low 8 bits of each sum matter, so wrapping keeps any lattice index valid
        // (huge coordinates saturate to i32::MAX on the cast) without changing the result.
        let p = |i: i32| i32::from(self.perm[(i & 255) as usize]);
        GRADIENTS[(p(p(p(x).wrapping_add(y)).wrapping_add(z)) & 15) as usize]
    }

    /// Lattice cell of `p`, position in it, and the eight corner gradients (x fastest).
    #[inline]
    fn cell(&self, p: Vec3) -> (Vec3, [Vec3; 8]) {
        let c = p.floor();
        let f = p - c;
        let (x, y, z) = (c.x as i32, c.y as i32, c.z as i32);
        let mut g = [Vec3::ZERO; 8];
        for (k, g) in g.iter_mut().enumerate() {
            let (i, j, l) = ((k & 1) as i32, ((k >> 1) & 1) as i32, (k >> 2) as i32);
            *g = self.gradient_at(x.wrapping_add(i), y.wrapping_add(j), z.wrapping_add(l));
        }
        (f, g)
    }

    /// Noise at `p`: the quintic-faded trilinear blend of `g_c · (p − c)` over the 8 corners `c`.
    /// Non-finite `p` gives a non-finite result.
    #[must_use]
    pub fn noise(&self, p: Vec3) -> f32 {
        let (f, g) = self.cell(p);
        let s = f.map(fade);
        let mut v = 0.0;
        for (k, g) in g.iter().enumerate() {
            let o = Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, (k >> 2) as f32);
            let w = |a: f32, sa: f32| if a == 0.0 { 1.0 - sa } else { sa };
            v += w(o.x, s.x) * w(o.y, s.y) * w(o.z, s.z) * g.dot(f - o);
        }
        v
    }

    /// Noise at `p` and its exact gradient ∂noise/∂p.
    #[must_use]
    pub fn noise_with_gradient(&self, p: Vec3) -> (f32, Vec3) {
        let (f, g) = self.cell(p);
        let s = f.map(fade);
        let ds = f.map(fade_deriv);
        let mut v = 0.0;
        let mut grad = Vec3::ZERO;
        for (k, g) in g.iter().enumerate() {
            let o = Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, (k >> 2) as f32);
            // Weight per axis and its derivative: 1 − s, −s' for the low corner; s, s' high.
            let w = |a: f32, sa: f32, dsa: f32| {
                if a == 0.0 {
                    (1.0 - sa, -dsa)
                } else {
                    (sa, dsa)
                }
            };
            let (wx, dwx) = w(o.x, s.x, ds.x);
            let (wy, dwy) = w(o.y, s.y, ds.y);
            let (wz, dwz) = w(o.z, s.z, ds.z);
            let d = g.dot(f - o);
            let wxyz = wx * wy * wz;
            v += wxyz * d;
            grad += Vec3::new(dwx * wy * wz, wx * dwy * wz, wx * wy * dwz) * d + *g * wxyz;
        }
        (v, grad)
    }

    /// Fractal Brownian motion: `Σ_{i<octaves} 0.5^i · noise(2^i p + i·shift)`; |fbm| < 2 · max|noise|.
    #[must_use]
    pub fn fbm(&self, p: Vec3, octaves: u32) -> f32 {
        self.fbm_octaves(p, octaves as f32)
    }

    /// [`fbm`](Self::fbm) over a possibly fractional number of octaves: octave `i` is weighted
    /// by `clamp(octaves − i, 0, 1)`, so detail fades in continuously as `octaves` grows (see
    /// [`octaves_for`]). Identical to `fbm` for whole numbers.
    #[must_use]
    pub fn fbm_octaves(&self, p: Vec3, octaves: f32) -> f32 {
        let (mut sum, mut amp, mut freq) = (0.0, 1.0, 1.0);
        for i in 0..octaves.ceil().max(0.0) as u32 {
            let w = (octaves - i as f32).min(1.0);
            sum += amp * w * self.noise(p * freq + OCTAVE_SHIFT * i as f32);
            amp *= 0.5;
            freq *= 2.0;
        }
        sum
    }

    /// Exact gradient of [`fbm`](Self::fbm) with respect to `p` (a bump source: see
    /// `perturb_normal_by_gradient`).
    #[must_use]
    pub fn fbm_gradient(&self, p: Vec3, octaves: u32) -> Vec3 {
        self.fbm_gradient_octaves(p, octaves as f32)
    }

    /// Exact gradient of [`fbm_octaves`](Self::fbm_octaves).
    #[must_use]
    pub fn fbm_gradient_octaves(&self, p: Vec3, octaves: f32) -> Vec3 {
        let (mut grad, mut amp, mut freq) = (Vec3::ZERO, 1.0, 1.0);
        for i in 0..octaves.ceil().max(0.0) as u32 {
            let w = (octaves - i as f32).min(1.0);
            let (_, g) = self.noise_with_gradient(p * freq + OCTAVE_SHIFT * i as f32);
            grad += g * (amp * w * freq);
            amp *= 0.5;
            freq *= 2.0;
        }
        grad
    }

    /// Turbulence: `Σ_{i<octaves} 0.5^i · |noise(2^i p + i·shift)|`, ≥ 0.
    #[must_use]
    pub fn turbulence(&self, p: Vec3, octaves: u32) -> f32 {
        self.turbulence_octaves(p, octaves, octaves as f32)
    }

    /// Turbulence of `octaves` octaves of which only the first `resolved` (possibly fractional)
    /// are evaluated: octave `i` is `w·|noise| + (1 − w)·MEAN_ABS_NOISE` with
    /// `w = clamp(resolved − i, 0, 1)`, so octaves too fine to see are replaced by their mean
    /// rather than dropped (the sum keeps its average brightness). Identical to `turbulence`
    /// when `resolved ≥ octaves`.
    #[must_use]
    pub fn turbulence_octaves(&self, p: Vec3, octaves: u32, resolved: f32) -> f32 {
        let (mut sum, mut amp, mut freq) = (0.0, 1.0, 1.0);
        for i in 0..octaves {
            let w = (resolved - i as f32).clamp(0.0, 1.0);
            let v = if w > 0.0 {
                self.noise(p * freq + OCTAVE_SHIFT * i as f32).abs()
            } else {
                0.0
            };
            sum += amp * (w * v + (1.0 - w) * MEAN_ABS_NOISE);
            amp *= 0.5;
            freq *= 2.0;
        }
        sum
    }

    /// Turbulence and its gradient (exact except on the zero set of an octave, where `|·|` has
    /// a crease and the one-sided gradient of the positive side is returned).
    #[must_use]
    pub fn turbulence_with_gradient(&self, p: Vec3, octaves: u32) -> (f32, Vec3) {
        self.turbulence_with_gradient_octaves(p, octaves, octaves as f32)
    }

    /// [`turbulence_octaves`](Self::turbulence_octaves) and its gradient (unresolved octaves
    /// are constant, so they add none).
    #[must_use]
    pub fn turbulence_with_gradient_octaves(
        &self,
        p: Vec3,
        octaves: u32,
        resolved: f32,
    ) -> (f32, Vec3) {
        let (mut sum, mut grad, mut amp, mut freq) = (0.0, Vec3::ZERO, 1.0, 1.0);
        for i in 0..octaves {
            let w = (resolved - i as f32).clamp(0.0, 1.0);
            if w > 0.0 {
                let (v, g) = self.noise_with_gradient(p * freq + OCTAVE_SHIFT * i as f32);
                sum += amp * (w * v.abs() + (1.0 - w) * MEAN_ABS_NOISE);
                grad += g * (amp * w * freq * if v < 0.0 { -1.0 } else { 1.0 });
            } else {
                sum += amp * MEAN_ABS_NOISE;
            }
            amp *= 0.5;
            freq *= 2.0;
        }
        (sum, grad)
    }
}

/// The mean of `|noise|` over space (measured: see the tests), what an unresolved turbulence
/// octave averages to.
pub const MEAN_ABS_NOISE: f32 = 0.22;

/// The variance of `|noise|` over space (measured: see the tests): how far an unresolved
/// turbulence octave strays from [`MEAN_ABS_NOISE`], which a non-linear function of turbulence
/// (marble's veins) needs to filter without changing its mean.
pub const VAR_ABS_NOISE: f32 = 0.024;

/// The variance that [`Noise::turbulence_octaves`] leaves out when it replaces octaves by their
/// mean: `Σᵢ (ampᵢ · (1 − wᵢ))² · VAR_ABS_NOISE` over the octaves, `wᵢ` each octave's resolved
/// share and `ampᵢ = 2⁻ⁱ` (octaves taken as independent). 0 when every octave is resolved.
#[must_use]
pub fn unresolved_turbulence_variance(octaves: u32, resolved: f32) -> f32 {
    let mut sum = 0.0;
    let mut amp = 1.0f32;
    for i in 0..octaves {
        let missing = amp * (1.0 - (resolved - i as f32).clamp(0.0, 1.0));
        sum += missing * missing;
        amp *= 0.5;
    }
    sum * VAR_ABS_NOISE
}

/// How many octaves of a fractal sum whose first octave has features about 1 unit wide (the
/// lattice spacing) can be resolved by a pixel footprint `width` units wide: octave `i` (features
/// `2^−i` wide) is kept while `2^i · width ≤ ¼` and fades out by `2^i · width = ½` (Nyquist).
/// Returns `max` for a zero (or non-finite) width; never less than 0.
#[must_use]
pub fn octaves_for(width: f32, max: u32) -> f32 {
    if !(width > 0.0) || !width.is_finite() {
        return max as f32;
    }
    ((0.5 / width).log2()).clamp(0.0, max as f32)
}

crate::key_hash_struct!(Noise { perm, seed });

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn point(rng: &mut Rng, scale: f32) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * (2.0 * scale) - scale
    }

    #[test]
    fn noise_is_deterministic_per_seed_and_zero_on_the_lattice() {
        let (a, b, c) = (Noise::new(42), Noise::new(42), Noise::new(43));
        assert_eq!(a, b);
        let p = Vec3::new(1.3, -2.7, 0.45);
        assert_eq!(a.noise(p).to_bits(), b.noise(p).to_bits());
        assert_eq!(a.fbm(p, 5).to_bits(), b.fbm(p, 5).to_bits());
        // Another seed: a different permutation and different values.
        assert_ne!(a.perm, c.perm);
        let mut rng = Rng::new(1, 1);
        let differ = (0..100)
            .filter(|_| {
                let q = point(&mut rng, 10.0);
                (a.noise(q) - c.noise(q)).abs() > 1e-3
            })
            .count();
        assert!(differ > 90, "{differ}");
        // A permutation really is one.
        let mut seen = [false; 256];
        a.perm.iter().for_each(|&v| seen[v as usize] = true);
        assert!(seen.iter().all(|&s| s));
        assert_eq!(a.noise(Vec3::new(3.0, -7.0, 12.0)), 0.0);
    }

    #[test]
    fn fbm_stays_in_range_with_mean_near_zero() {
        let n = Noise::new(7);
        let mut rng = Rng::new(2, 3);
        let (mut sum, mut lo, mut hi, mut tmax) = (0.0f64, f32::MAX, f32::MIN, 0.0f32);
        let mut max_noise = 0.0f32;
        for _ in 0..10_000 {
            let p = point(&mut rng, 50.0);
            let v = n.fbm(p, 6);
            max_noise = max_noise.max(n.noise(p).abs());
            sum += f64::from(v);
            lo = lo.min(v);
            hi = hi.max(v);
            let t = n.turbulence(p, 6);
            assert!(t >= 0.0);
            // The value-only sum is the same number as the one computed with the gradient.
            assert_eq!(t.to_bits(), n.turbulence_with_gradient(p, 6).0.to_bits());
            tmax = tmax.max(t);
        }
        let mean = sum / 10_000.0;
        // Single-octave noise stays within [−1, 1]; fbm of 6 octaves within (−2, 2), and in
        // practice well inside (−1.5, 1.5).
        assert!(max_noise <= 1.0, "{max_noise}");
        assert!(lo > -1.5 && hi < 1.5, "[{lo}, {hi}]");
        assert!(hi - lo > 0.8, "fbm barely varies: [{lo}, {hi}]");
        assert!(mean.abs() < 0.03, "mean {mean}");
        assert!(tmax < 2.0 && tmax > 0.4, "{tmax}");
    }

    #[test]
    fn fractional_octaves_fade_detail_in_continuously_and_whole_ones_are_exact() {
        let n = Noise::new(9);
        let mut rng = Rng::new(7, 7);
        let (mut abs_sum, mut sq_sum, mut count) = (0.0f64, 0.0f64, 0u32);
        for _ in 0..20_000 {
            let p = point(&mut rng, 40.0);
            abs_sum += f64::from(n.noise(p).abs());
            sq_sum += f64::from(n.noise(p)).powi(2);
            count += 1;
            // Whole numbers of octaves are bit-identical to the plain sums.
            assert_eq!(n.fbm_octaves(p, 5.0).to_bits(), n.fbm(p, 5).to_bits());
            assert_eq!(
                n.turbulence_octaves(p, 5, 5.0).to_bits(),
                n.turbulence(p, 5).to_bits()
            );
            // Continuity: half an octave lies between its neighbours' values.
            let (a, m, b) = (
                n.fbm_octaves(p, 2.0),
                n.fbm_octaves(p, 2.5),
                n.fbm_octaves(p, 3.0),
            );
            assert!((m - (a + b) / 2.0).abs() < 1e-5, "{a} {m} {b}");
        }
        // The constant that replaces unresolved turbulence octaves is the measured mean |noise|.
        let mean = abs_sum / f64::from(count);
        assert!(
            (mean - f64::from(MEAN_ABS_NOISE)).abs() < 0.01,
            "mean |noise| {mean}"
        );
        // And the variance that marble's filter restores is the measured variance of |noise|.
        let var = sq_sum / f64::from(count) - mean * mean;
        assert!(
            (var - f64::from(VAR_ABS_NOISE)).abs() < 0.003,
            "variance of |noise| {var}"
        );
        // Unresolved octaves keep turbulence's average: 0 resolved of 6 is the mean of 6.
        let mut rng = Rng::new(8, 8);
        let (mut full, mut none) = (0.0f64, 0.0f64);
        for _ in 0..20_000 {
            let p = point(&mut rng, 40.0);
            full += f64::from(n.turbulence(p, 6));
            none += f64::from(n.turbulence_octaves(p, 6, 0.0));
        }
        assert!(((full - none) / full).abs() < 0.03, "{full} vs {none}");
        // Footprints: zero keeps all octaves; a footprint of 1/8 keeps 2 (log2 4).
        assert_eq!(octaves_for(0.0, 6), 6.0);
        assert_eq!(octaves_for(0.125, 6), 2.0);
        assert_eq!(octaves_for(10.0, 6), 0.0);
        assert_eq!(octaves_for(f32::NAN, 6), 6.0);
    }

    #[test]
    fn huge_coordinates_give_finite_values_without_overflow() {
        let n = Noise::new(5);
        for p in [Vec3::splat(1e33), Vec3::new(3e9, -3e9, 1e20)] {
            assert!(n.noise(p).is_finite(), "{p}");
            assert!(n.fbm(p, 4).is_finite(), "{p}");
        }
        // The largest finite coordinates still give a finite single octave (2× them would not).
        assert!(n.noise(Vec3::new(f32::MAX, f32::MIN, 0.5)).is_finite());
    }

    #[test]
    fn analytic_gradients_match_central_differences() {
        let n = Noise::new(11);
        let mut rng = Rng::new(4, 4);
        let h = 1e-3;
        let mut worst = 0.0f32;
        for _ in 0..1000 {
            let p = point(&mut rng, 20.0);
            let (v, g) = n.noise_with_gradient(p);
            assert_eq!(v.to_bits(), n.noise(p).to_bits());
            let fd = |f: &dyn Fn(Vec3) -> f32| {
                Vec3::new(
                    f(p + Vec3::X * h) - f(p - Vec3::X * h),
                    f(p + Vec3::Y * h) - f(p - Vec3::Y * h),
                    f(p + Vec3::Z * h) - f(p - Vec3::Z * h),
                ) / (2.0 * h)
            };
            worst = worst.max((g - fd(&|q| n.noise(q))).abs().max_element());
            // fbm: the 4th octave has frequency 8, so the gradient is up to ~8× larger.
            let gf = n.fbm_gradient(p, 4);
            let err = (gf - fd(&|q| n.fbm(q, 4))).abs().max_element();
            assert!(err < 2e-2 * (1.0 + gf.length()), "{p}: {gf} err {err}");
        }
        assert!(worst < 5e-3, "{worst}");
    }
}
