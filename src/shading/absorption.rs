//! Beer–Lambert absorption inside a dielectric (water, coloured glass): light travelling a
//! distance `d` through the medium keeps the fraction `T(d) = exp(−σ d)` per channel, `σ` the
//! absorption coefficient (Beer 1852; Lambert 1760; pbrt-v4 §11.1). No scattering inside the
//! medium is modelled: a clear, coloured medium.
//!
//! Users give either `σ` itself (per unit of scene length; scenes are in metres, so per metre)
//! or the easier "colour `c` reached at depth `d`": the transmittance after `d` is `c`, so
//! `σ = −ln(c)/d`. Both are converted to the one stored `σ`; negative, non-finite or
//! out-of-range values are a typed [`AbsorptionError`].

use glam::Vec3;
use thiserror::Error;

/// The RGB channels' names, for error messages.
const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// Why a user's absorption is invalid (the scene validator adds file, line and field).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AbsorptionError {
    /// A coefficient is negative (the medium would amplify light).
    #[error(
        "absorption coefficient of the {channel} channel is {value}; it must be ≥ 0 (per metre)"
    )]
    NegativeCoefficient {
        /// "red", "green" or "blue".
        channel: &'static str,
        /// The value given.
        value: f32,
    },
    /// A coefficient is NaN or infinite.
    #[error(
        "absorption coefficient of the {channel} channel is {value}; it must be a finite number ≥ 0 (per metre)"
    )]
    NonFiniteCoefficient {
        /// "red", "green" or "blue".
        channel: &'static str,
        /// The value given.
        value: f32,
    },
    /// A colour-at-depth channel is outside `(0, 1]` (0 would absorb everything in no
    /// distance, above 1 would amplify).
    #[error(
        "absorption colour of the {channel} channel is {value}; it must be in (0, 1] (the fraction of light left at the given depth)"
    )]
    ColourOutOfRange {
        /// "red", "green" or "blue".
        channel: &'static str,
        /// The value given.
        value: f32,
    },
    /// The depth of a colour-at-depth is not a positive finite length.
    #[error("absorption depth is {0}; it must be a finite length > 0 (metres)")]
    DepthNotPositive(f32),
}

/// A homogeneous absorbing medium: its absorption coefficient `σ` per channel (per metre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Absorption {
    sigma: Vec3,
}

impl Absorption {
    /// A medium that absorbs nothing.
    pub const CLEAR: Self = Self { sigma: Vec3::ZERO };

    /// From the coefficient `σ` per metre, each channel finite and ≥ 0.
    ///
    /// # Errors
    /// [`AbsorptionError::NonFiniteCoefficient`] or [`AbsorptionError::NegativeCoefficient`]
    /// naming the first bad channel.
    pub fn from_coefficient(sigma: [f32; 3]) -> Result<Self, AbsorptionError> {
        for (value, channel) in sigma.into_iter().zip(CHANNELS) {
            if !value.is_finite() {
                return Err(AbsorptionError::NonFiniteCoefficient { channel, value });
            }
            if value < 0.0 {
                return Err(AbsorptionError::NegativeCoefficient { channel, value });
            }
        }
        // −0.0 is ≥ 0; store +0 so that equal media compare (and hash) equal.
        Ok(Self {
            sigma: Vec3::from(sigma.map(|s| s + 0.0)),
        })
    }

    /// From the colour `colour` (each channel in `(0, 1]`) that white light has after
    /// travelling `depth` metres: `σ = −ln(colour)/depth`.
    ///
    /// # Errors
    /// [`AbsorptionError::DepthNotPositive`] for a depth that is not finite and > 0,
    /// [`AbsorptionError::ColourOutOfRange`] naming the first channel outside `(0, 1]`.
    pub fn from_colour_at_depth(colour: [f32; 3], depth: f32) -> Result<Self, AbsorptionError> {
        if !(depth > 0.0 && depth.is_finite()) {
            return Err(AbsorptionError::DepthNotPositive(depth));
        }
        for (value, channel) in colour.into_iter().zip(CHANNELS) {
            if !(value > 0.0 && value <= 1.0) {
                return Err(AbsorptionError::ColourOutOfRange { channel, value });
            }
        }
        Self::from_coefficient(colour.map(|c| -c.ln() / depth))
    }

    /// The absorption coefficient σ per metre.
    #[inline]
    #[must_use]
    pub fn sigma(&self) -> Vec3 {
        self.sigma
    }

    /// True when nothing is absorbed (σ = 0), so integrators can skip the medium.
    #[inline]
    #[must_use]
    pub fn is_clear(&self) -> bool {
        self.sigma == Vec3::ZERO
    }

    /// The fraction `exp(−σ d)` of light kept after `distance` metres (≥ 0; an infinite
    /// distance keeps 0 where σ > 0 and 1 where σ = 0).
    #[inline]
    #[must_use]
    pub fn transmittance(&self, distance: f32) -> Vec3 {
        if self.is_clear() {
            return Vec3::ONE;
        }
        let d = distance.max(0.0);
        Vec3::new(
            attenuate(self.sigma.x, d),
            attenuate(self.sigma.y, d),
            attenuate(self.sigma.z, d),
        )
    }
}

/// `exp(−σ d)`, with `0 · ∞` read as 0 (no absorption keeps everything).
#[inline]
fn attenuate(sigma: f32, d: f32) -> f32 {
    if sigma == 0.0 {
        1.0
    } else {
        (-sigma * d).exp()
    }
}

crate::key_hash_struct!(Absorption { sigma });

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transmittance_is_beer_lambert() {
        let m = Absorption::from_coefficient([0.5, 0.1, 0.0]).unwrap();
        let t = m.transmittance(2.0);
        assert!((t.x - (-1.0f32).exp()).abs() < 1e-7 && (t.y - (-0.2f32).exp()).abs() < 1e-7);
        assert_eq!(t.z, 1.0);
        // Multiplicative over path segments: T(a + b) = T(a) T(b).
        let (a, b) = (0.7, 1.9);
        assert!(
            (m.transmittance(a + b) - m.transmittance(a) * m.transmittance(b))
                .abs()
                .max_element()
                < 1e-6
        );
        assert_eq!(m.transmittance(0.0), Vec3::ONE);
        assert_eq!(m.transmittance(f32::INFINITY), Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(Absorption::CLEAR.transmittance(1e30), Vec3::ONE);
        assert!(Absorption::CLEAR.is_clear() && !m.is_clear());
    }

    #[test]
    fn colour_at_depth_is_reached_at_that_depth() {
        // Blue-green water: 70% red, 95% green, 98% blue left after 2 m.
        let c = [0.7, 0.95, 0.98];
        let m = Absorption::from_colour_at_depth(c, 2.0).unwrap();
        let t = m.transmittance(2.0);
        assert!(t.distance(Vec3::from(c)) < 1e-6, "{t}");
        // σ = −ln(c)/d by hand for red: −ln 0.7 / 2 = 0.178 337.
        assert!((m.sigma().x - 0.178_337).abs() < 1e-5);
        // Twice as deep: the colour squared.
        assert!(m.transmittance(4.0).distance(Vec3::from(c) * Vec3::from(c)) < 1e-6);
        // Colour 1 absorbs nothing; both forms agree.
        let clear = Absorption::from_colour_at_depth([1.0; 3], 5.0).unwrap();
        assert!(clear.is_clear());
        let same = Absorption::from_coefficient(m.sigma().to_array()).unwrap();
        assert_eq!(same, m);
    }

    #[test]
    fn bad_values_are_typed_errors_naming_the_channel() {
        use AbsorptionError as E;
        assert_eq!(
            Absorption::from_coefficient([0.1, -0.2, 0.0]),
            Err(E::NegativeCoefficient {
                channel: "green",
                value: -0.2
            })
        );
        assert!(matches!(
            Absorption::from_coefficient([0.0, 0.0, f32::NAN]),
            Err(E::NonFiniteCoefficient {
                channel: "blue",
                ..
            })
        ));
        assert!(matches!(
            Absorption::from_coefficient([f32::INFINITY, 0.0, 0.0]),
            Err(E::NonFiniteCoefficient { channel: "red", .. })
        ));
        assert_eq!(
            Absorption::from_coefficient([-0.0; 3]),
            Ok(Absorption::CLEAR)
        );
        for d in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(matches!(
                Absorption::from_colour_at_depth([0.5; 3], d),
                Err(E::DepthNotPositive(_))
            ));
        }
        for c in [0.0, -0.1, 1.01, f32::NAN] {
            assert!(matches!(
                Absorption::from_colour_at_depth([0.5, c, 0.5], 1.0),
                Err(E::ColourOutOfRange {
                    channel: "green",
                    ..
                })
            ));
        }
        let msg = Absorption::from_coefficient([0.0, 0.0, -3.0])
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("blue") && msg.contains("-3") && msg.contains("≥ 0"),
            "{msg}"
        );
    }
}
