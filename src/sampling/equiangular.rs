//! Equiangular sampling of a distance along a ray toward a point (Kulla & Fajardo, "Importance
//! Sampling Techniques for Path Tracing in Participating Media", EGSR 2012, §4.1).
//!
//! Light from a point `c` scattered once at `x(t) = o + t ω` falls off as `1/|x(t) − c|²`, which
//! along the ray is `1/(D² + (t − Δ)²)`, `Δ = (c − o)·ω` the foot of the perpendicular from `c`
//! and `D` its length. Drawing `t` with density proportional to that factor removes it from the
//! estimate: with `θ(t) = atan((t − Δ)/D)`, `θ` is uniform between `θa = θ(a)` and `θb = θ(b)`:
//!
//! ```text
//!     t = Δ + D tan(θa + ξ (θb − θa)),     pdf(t) = D / ((θb − θa) (D² + (t − Δ)²)),   t ∈ [a, b].
//! ```
//!
//! The name comes from the sampled points being spread evenly in the angle they subtend at `c`.
//! Next to a small light the variance of distance (free-flight) sampling comes from that
//! `1/r²`, not from the transmittance, so the two are combined by multiple importance sampling
//! (the paper's §4.2; `integrators::path`).

use glam::Vec3;

/// Equiangular sampling of `t ∈ [a, b]` along the ray `o + t ω` (unit `ω`) toward a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Equiangular {
    /// `Δ`: the ray parameter of the point's projection on the ray (metres along it).
    delta: f32,
    /// `D`: the point's distance from the ray's line (metres, > 0).
    d: f32,
    /// `θa`, the angle of the interval's start seen from the point (radians).
    theta_a: f32,
    /// `θb − θa` (radians, > 0).
    theta_span: f32,
}

impl Equiangular {
    /// The sampler for `t ∈ [a, b]` (`b` may be infinite) along `origin + t dir` (`dir` unit
    /// length) toward `point`. `None` when the point lies on the ray's line (`D` below 1e-6 of
    /// the distances involved, where the density is a delta) or the interval is empty.
    #[must_use]
    pub fn new(origin: Vec3, dir: Vec3, a: f32, b: f32, point: Vec3) -> Option<Self> {
        let to = point - origin;
        let delta = to.dot(dir);
        let d = (to - dir * delta).length();
        if !(d > 1e-6 * to.length().max(1e-3)) || !(b > a) || !delta.is_finite() {
            return None;
        }
        let theta_a = ((a - delta) / d).atan();
        let theta_b = ((b - delta) / d).atan();
        let theta_span = theta_b - theta_a;
        (theta_span > 0.0 && theta_span.is_finite()).then_some(Self {
            delta,
            d,
            theta_a,
            theta_span,
        })
    }

    /// The distance for a uniform `u` in [0, 1) (module docs), within `[a, b]` up to rounding.
    #[inline]
    #[must_use]
    pub fn sample(&self, u: f32) -> f32 {
        self.delta + self.d * (self.theta_a + u * self.theta_span).tan()
    }

    /// The density of [`Self::sample`] at `t` (per metre), for `t` in `[a, b]` (the caller
    /// keeps `t` there: outside it the density is 0, not what this returns).
    #[inline]
    #[must_use]
    pub fn pdf(&self, t: f32) -> f32 {
        let x = t - self.delta;
        self.d / (self.theta_span * (self.d * self.d + x * x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn the_density_integrates_to_one_over_finite_and_infinite_intervals() {
        let o = Vec3::new(0.1, -0.2, 0.3);
        let dir = Vec3::new(1.0, 2.0, 2.0) / 3.0;
        let c = Vec3::new(1.0, 0.5, 1.5);
        for (a, b) in [(0.0f32, 3.0f32), (0.5, 1.2), (2.0, 40.0)] {
            let e = Equiangular::new(o, dir, a, b, c).expect("off the line");
            // Midpoint rule, 200 000 steps.
            let n = 200_000;
            let h = f64::from(b - a) / f64::from(n);
            let sum: f64 = (0..n)
                .map(|i| f64::from(e.pdf((f64::from(a) + (f64::from(i) + 0.5) * h) as f32)) * h)
                .sum();
            assert!((sum - 1.0).abs() < 1e-4, "[{a}, {b}]: {sum}");
        }
        // An infinite interval: the closed form of the integral, (θb − θa)/(θb − θa) = 1, and
        // the density's tail ∫_T^∞ D/(span (D² + x²)) dx = (π/2 − atan((T−Δ)/D))/span.
        let e = Equiangular::new(o, dir, 0.0, f32::INFINITY, c).expect("off the line");
        let delta = (c - o).dot(dir);
        let d = ((c - o) - dir * delta).length();
        let span = std::f32::consts::FRAC_PI_2 - (-delta / d).atan();
        assert!((e.theta_span - span).abs() < 1e-6);
    }

    #[test]
    fn samples_stay_in_the_interval_and_follow_the_density() {
        // A histogram of 400 000 samples over 20 bins against the density's integral per bin
        // (its closed form: the angle each bin's ends subtend, over the span).
        let o = Vec3::ZERO;
        let dir = Vec3::Z;
        let c = Vec3::new(0.4, 0.0, 1.1);
        let (a, b) = (0.0f32, 3.0f32);
        let e = Equiangular::new(o, dir, a, b, c).expect("off the line");
        let bins = 20usize;
        let mut hist = vec![0u32; bins];
        let n = 400_000u32;
        let mut rng = Rng::new(4, 0);
        for _ in 0..n {
            let t = e.sample(rng.next_f32());
            assert!((a - 1e-5..=b + 1e-5).contains(&t), "{t}");
            let i = (((t - a) / (b - a)) * bins as f32) as usize;
            hist[i.min(bins - 1)] += 1;
        }
        let theta = |t: f64| ((t - 1.1) / 0.4).atan();
        let span = theta(3.0) - theta(0.0);
        for (i, &count) in hist.iter().enumerate() {
            let (t0, t1) = (3.0 * i as f64 / 20.0, 3.0 * (i + 1) as f64 / 20.0);
            let want = (theta(t1) - theta(t0)) / span * f64::from(n);
            let sigma = want.sqrt();
            assert!(
                (f64::from(count) - want).abs() < 5.0 * sigma,
                "bin {i}: {count} vs {want:.0}"
            );
        }
    }

    #[test]
    fn a_point_on_the_line_or_an_empty_interval_gives_none() {
        assert!(
            Equiangular::new(Vec3::ZERO, Vec3::Z, 0.0, 1.0, Vec3::new(0.0, 0.0, 2.0)).is_none()
        );
        assert!(Equiangular::new(Vec3::ZERO, Vec3::Z, 1.0, 1.0, Vec3::X).is_none());
    }
}
