//! Tail probabilities and quantiles of the standard normal and χ² distributions, for the
//! thresholds of the golden-image test ([`super::block_test`]).
//!
//! The normal tail uses the Chebyshev-fitted complementary error function of Press et al.,
//! *Numerical Recipes* §6.2 (fractional error below 1.2·10⁻⁷ everywhere); the χ² tail is the
//! regularized upper incomplete gamma function Q(k/2, x/2), by its series below a + 1 and by
//! Lentz's continued fraction above — the one implementation the χ² tests of the samplers use
//! too (`sampling::special`). Quantiles invert the tails by bisection (to a relative
//! 10⁻¹², far below the tails' own error).

use crate::sampling::special::gamma_q;

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
}
