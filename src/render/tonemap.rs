//! Tone mapping for 8-bit output: how a linear radiance value, already scaled by the exposure,
//! becomes a display value in [0, 1] before the sRGB transfer function. [`Display`] bundles the
//! exposure and the curve ([`Tonemap`], `render.tonemap` / `--tonemap`) that every 8-bit writer
//! takes; EXR output never goes through it.
//!
//! The filmic curve is Narkowicz's rational fit of the ACES reference rendering and output
//! transforms (K. Narkowicz, "ACES Filmic Tone Mapping Curve", 2015), applied per channel.

pub use crate::settings::Tonemap;

/// How a film is turned into display values: radiance × `exposure`, then `tonemap`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Display {
    /// Linear scale applied to radiance first (unitless).
    pub exposure: f32,
    /// The curve applied to each exposed channel.
    pub tonemap: Tonemap,
}

impl Display {
    /// The display value in [0, 1] of one exposed-and-mapped channel of linear radiance `c`;
    /// NaN, infinite and negative values give 0.
    #[inline]
    #[must_use]
    pub fn map(&self, c: f32) -> f32 {
        let x = c * self.exposure;
        if !x.is_finite() {
            return 0.0;
        }
        match self.tonemap {
            Tonemap::Linear => x.clamp(0.0, 1.0),
            Tonemap::Aces => aces_narkowicz(x),
        }
    }
}

impl From<f32> for Display {
    /// An exposure with today's clipping curve ([`Tonemap::Linear`]).
    fn from(exposure: f32) -> Self {
        Self {
            exposure,
            tonemap: Tonemap::Linear,
        }
    }
}

/// Narkowicz's (2015) fit of the ACES filmic curve, x (2.51 x + 0.03) / (x (2.43 x + 0.59) +
/// 0.14), clamped to [0, 1]; negative input gives 0. Monotone for x ≥ 0 (the numerator of its
/// derivative is 1.408 x² + 0.7028 x + 0.0042); reaches 1 at x ≈ 7.24.
#[inline]
#[must_use]
pub fn aces_narkowicz(x: f32) -> f32 {
    // Past x ≈ 7.24 the curve is above 1 (its asymptote is 2.51 / 2.43), so capping the input
    // changes nothing but keeps x² finite (1e30 would give ∞ / ∞ = NaN).
    let x = if x > 0.0 { x.min(1.0e6) } else { 0.0 };
    let y = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
    y.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The curve at hand-computed points (numerator and denominator evaluated by hand).
    #[test]
    fn aces_matches_hand_computed_values() {
        assert_eq!(aces_narkowicz(0.0), 0.0);
        // x = 0.18: 0.18 × 0.4818 / (0.18 × 1.0274 + 0.14) = 0.086724 / 0.324932.
        assert!((aces_narkowicz(0.18) - 0.266_899).abs() < 1e-5);
        // x = 1: 2.54 / 3.16.
        assert!((aces_narkowicz(1.0) - 0.803_797).abs() < 1e-5);
        // x = 4: 4 × 10.07 / (4 × 10.31 + 0.14) = 40.28 / 41.38.
        assert!((aces_narkowicz(4.0) - 0.973_417).abs() < 1e-5);
        // 1 is reached where 0.08 x² − 0.56 x − 0.14 = 0, x = (0.56 + √0.3584) / 0.16.
        let x1 = (0.56 + 0.3584f32.sqrt()) / 0.16;
        assert!(aces_narkowicz(x1 * 0.99) < 1.0);
        assert_eq!(aces_narkowicz(x1 * 1.01), 1.0);
        assert_eq!(aces_narkowicz(1e30), 1.0);
        assert_eq!(aces_narkowicz(-3.0), 0.0);
    }

    #[test]
    fn curves_are_monotone_and_map_zero_to_zero() {
        for tonemap in Tonemap::ALL.iter().copied() {
            let d = Display {
                exposure: 1.0,
                tonemap,
            };
            assert_eq!(d.map(0.0), 0.0, "{tonemap:?}");
            let mut last = 0.0;
            for i in 0..20_000 {
                let y = d.map(i as f32 * 1e-3);
                assert!(y >= last, "{tonemap:?} decreases at {}", i as f32 * 1e-3);
                assert!((0.0..=1.0).contains(&y));
                last = y;
            }
            for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0] {
                assert_eq!(d.map(bad), 0.0, "{tonemap:?} of {bad}");
            }
        }
    }

    #[test]
    fn exposure_is_applied_before_the_curve() {
        let d = Display {
            exposure: 2.0,
            tonemap: Tonemap::Aces,
        };
        assert_eq!(d.map(0.5), aces_narkowicz(1.0));
        let lin = Display::from(2.0);
        assert_eq!(lin.tonemap, Tonemap::Linear);
        assert_eq!(lin.map(0.3), 0.6);
        assert_eq!(lin.map(0.7), 1.0);
    }
}
