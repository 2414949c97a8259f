//! Tail probabilities and quantiles of the standard normal, Student-t and χ² distributions, for
//! the thresholds of the golden-image tests ([`super::batch_means`], [`super::pixel_variance`]).
//!
//! The normal tail uses the Chebyshev-fitted complementary error function of Press et al.,
//! *Numerical Recipes* §6.2 (fractional error below 1.2·10⁻⁷ everywhere); the χ² tail is the
//! regularized upper incomplete gamma function Q(k/2, x/2), by its series below a + 1 and by
//! Lentz's continued fraction above — the one implementation the χ² tests of the samplers use
//! too (`sampling::special`). The Student-t tail is the regularized incomplete beta function,
//! P(T > t) = ½ I_{ν/(ν+t²)}(ν/2, ½) (Abramowitz & Stegun 26.7.1 with 26.5.27), evaluated by
//! its continued fraction (A&S 26.5.8, with the symmetry I_x(a, b) = 1 − I_{1−x}(b, a) where
//! the fraction converges slowly) in Lentz's form. Quantiles invert the tails by bisection (to
//! a relative 10⁻¹², far below the tails' own error).

use crate::sampling::special::{gamma_q, ln_gamma};

/// The complementary error function erfc(x), fractional error < 1.2·10⁻⁷.
#[must_use]
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// P(Z > z) for a standard normal Z.
#[must_use]
pub fn normal_upper_tail(z: f64) -> f64 {
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// The z with P(Z > z) = `p`, for 0 < p < 1 (e.g. 1.96 for 0.025).
#[must_use]
pub fn normal_upper_quantile(p: f64) -> f64 {
    invert_decreasing(normal_upper_tail, p, -40.0, 40.0)
}

/// P(X > x) for X of the χ² distribution with `k` degrees of freedom.
#[must_use]
pub fn chi2_upper_tail(x: f64, k: u32) -> f64 {
    gamma_q(f64::from(k) / 2.0, x / 2.0)
}

/// The x with P(X > x) = `p` for χ² with `k` ≥ 1 degrees of freedom, 0 < p < 1.
#[must_use]
pub fn chi2_upper_quantile(p: f64, k: u32) -> f64 {
    let hi = f64::from(k) * 10.0 + 2000.0;
    invert_decreasing(|x| chi2_upper_tail(x, k), p, 0.0, hi)
}

/// The regularized incomplete beta function I_x(a, b) for a, b > 0 and 0 ≤ x ≤ 1.
#[must_use]
pub fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln();
    // The continued fraction converges fast for x < (a + 1)/(a + b + 2).
    if x < (a + 1.0) / (a + b + 2.0) {
        (ln_front.exp() * beta_fraction(x, a, b) / a).clamp(0.0, 1.0)
    } else {
        (1.0 - ln_front.exp() * beta_fraction(1.0 - x, b, a) / b).clamp(0.0, 1.0)
    }
}

/// The continued fraction of I_x(a, b) (A&S 26.5.8), by the modified Lentz method.
fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    let tiny = 1e-300;
    let clamp = |v: f64| if v.abs() < tiny { tiny } else { v };
    let mut c = 1.0;
    let mut d = 1.0 / clamp(1.0 - (a + b) * x / (a + 1.0));
    let mut h = d;
    for m in 1..10_000 {
        let m = f64::from(m);
        // Even step d_{2m}, then odd step d_{2m+1}.
        let even = m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m));
        d = 1.0 / clamp(1.0 + even * d);
        c = clamp(1.0 + even / c);
        h *= d * c;
        let odd = -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0));
        d = 1.0 / clamp(1.0 + odd * d);
        c = clamp(1.0 + odd / c);
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// P(T > t) for T of Student's t distribution with `nu` > 0 degrees of freedom (real-valued,
/// as Welch's approximation gives); an infinite `nu` is the normal tail.
#[must_use]
pub fn student_upper_tail(t: f64, nu: f64) -> f64 {
    if !nu.is_finite() {
        return normal_upper_tail(t);
    }
    let half = 0.5 * incomplete_beta(nu / (nu + t * t), 0.5 * nu, 0.5);
    if t >= 0.0 { half } else { 1.0 - half }
}

/// The t with P(T > t) = `p` for Student's t with `nu` degrees of freedom, 0 < p < 1.
#[must_use]
pub fn student_upper_quantile(p: f64, nu: f64) -> f64 {
    invert_decreasing(|t| student_upper_tail(t, nu), p, -1e6, 1e6)
}

/// The x in [lo, hi] where the decreasing `f` crosses `p`, by bisection.
fn invert_decreasing(f: impl Fn(f64) -> f64, p: f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi.abs().max(1.0) {
            break;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_quantiles_match_the_printed_tables() {
        // Standard normal table values (Abramowitz & Stegun, table 26.5).
        for (p, z) in [
            (0.5, 0.0),
            (0.025, 1.959_964),
            (0.005, 2.575_829),
            (0.001, 3.090_232),
            (1e-5, 4.264_891),
        ] {
            let got = normal_upper_quantile(p);
            assert!((got - z).abs() < 2e-5, "p {p}: {got} vs {z}");
        }
        assert!((normal_upper_tail(-1.959_964) - 0.975).abs() < 1e-6);
    }

    #[test]
    fn chi2_tails_match_the_closed_form_for_even_degrees_and_the_tables() {
        // For even k, P(X > x) = e^(−x/2) Σ_{i<k/2} (x/2)^i / i! exactly.
        for k in [2u32, 4, 10, 64, 192] {
            for x in [0.5, 3.0, 20.0, 80.0, 150.0, 260.0] {
                let h = x / 2.0;
                let (mut term, mut sum) = (1.0f64, 0.0f64);
                for i in 0..k / 2 {
                    if i > 0 {
                        term *= h / f64::from(i);
                    }
                    sum += term;
                }
                let exact = (-h).exp() * sum;
                let got = chi2_upper_tail(x, k);
                assert!(
                    (got - exact).abs() <= 1e-9 + 1e-7 * exact,
                    "k {k} x {x}: {got} vs {exact}"
                );
            }
        }
        // Odd degrees against printed quantiles (NIST/SEMATECH handbook, table 1.3.6.7.4).
        for (p, k, x) in [(0.05, 1, 3.841), (0.01, 5, 15.086), (0.01, 21, 38.932)] {
            let got = chi2_upper_quantile(p, k);
            assert!((got - x).abs() < 2e-3, "k {k}: {got} vs {x}");
        }
        assert!((chi2_upper_quantile(0.01, 10) - 23.209).abs() < 2e-3);
    }

    #[test]
    fn student_t_matches_the_closed_forms_and_the_printed_tables() {
        // ν = 1 is the Cauchy law: P(T > t) = ½ − atan(t)/π; ν = 2: ½ (1 − t/√(2 + t²)).
        for t in [-3.0, -0.5, 0.0, 0.7, 2.0, 31.8, 1e3] {
            let cauchy = 0.5 - f64::atan(t) / std::f64::consts::PI;
            assert!((student_upper_tail(t, 1.0) - cauchy).abs() < 1e-12, "{t}");
            let two = 0.5 * (1.0 - t / (2.0 + t * t).sqrt());
            assert!((student_upper_tail(t, 2.0) - two).abs() < 1e-12, "{t}");
        }
        // Printed quantiles (NIST/SEMATECH handbook, table 1.3.6.7.2).
        for (p, nu, t) in [
            (0.025, 10.0, 2.228),
            (0.005, 5.0, 4.032),
            (0.001, 20.0, 3.552),
            (0.05, 100.0, 1.660),
            (0.0005, 3.0, 12.924),
        ] {
            let got = student_upper_quantile(p, nu);
            assert!((got - t).abs() < 1.5e-3, "ν {nu} p {p}: {got} vs {t}");
        }
        // Large ν approaches the normal law.
        let z = normal_upper_quantile(1e-5);
        assert!((student_upper_quantile(1e-5, 1e7) - z).abs() < 1e-3);
        assert_eq!(
            student_upper_tail(2.0, f64::INFINITY),
            normal_upper_tail(2.0)
        );
    }
}
