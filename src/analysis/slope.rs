//! The convergence-slope fit of `caustic converge` and `caustic plot`: the least-squares slope of
//! log error against log time (or samples), which is −1/2 for an unbiased Monte Carlo estimator
//! whose cost per sample is constant (RMSE ∝ N^−1/2), and shallower for consistent biased ones
//! such as progressive photon mapping.

/// Least-squares slope of log y against log x over the points where both are positive and
/// finite; `None` with fewer than two such points or no spread in x.
#[must_use]
pub fn log_log_slope(points: impl Iterator<Item = (f64, f64)>) -> Option<f64> {
    let v: Vec<(f64, f64)> = points
        .filter(|(x, y)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if v.len() < 2 {
        return None;
    }
    let n = v.len() as f64;
    let (mx, my) = (
        v.iter().map(|p| p.0).sum::<f64>() / n,
        v.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = v.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = v.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// A fitted slope as tables print it: three decimals, or `n/a` when none could be fitted.
#[must_use]
pub fn fmt_slope(s: Option<f64>) -> String {
    s.map_or_else(|| "n/a".into(), |s| format!("{s:.3}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slope_fit_recovers_a_power_law_and_refuses_too_few_points() {
        // y = 3 x^-0.5 exactly: slope -0.5; points with x or y ≤ 0 are ignored.
        let pts = [1.0f64, 2.0, 4.0, 8.0, 16.0].map(|x| (x, 3.0 / x.sqrt()));
        let s = log_log_slope(pts.into_iter().chain([(0.0, 1.0), (5.0, 0.0)])).unwrap();
        assert!((s + 0.5).abs() < 1e-12, "{s}");
        // By hand, with l = ln 2: ln-points (0, 0), (l, 0), (2l, −2l); x̄ = l, ȳ = −2l/3,
        // Sxx = 2l², Sxy = (−l)(2l/3) + 0 + (l)(−4l/3) = −2l², slope −1.
        let s = log_log_slope([(1.0, 1.0), (2.0, 1.0), (4.0, 0.25)].into_iter()).unwrap();
        assert!((s + 1.0).abs() < 1e-12, "{s}");
        assert!(log_log_slope([(1.0, 1.0)].into_iter()).is_none());
        assert!(log_log_slope([(2.0, 1.0), (2.0, 3.0)].into_iter()).is_none());
    }
}
