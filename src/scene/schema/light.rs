//! Light sources of the scene format.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::values::exact_floats;
use super::{Rgb, Vec3Spec};

/// Light sources; `power` is the emitted radiant flux in watts per RGB channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub enum LightSpec {
    /// An isotropic point light with inverse-square falloff.
    Point {
        /// Position.
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        position: Vec3Spec,
        /// Total emitted flux (W).
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        power: Rgb,
        /// Caustic photons this light emits, instead of its power share of
        /// `photons.caustic` (0: none).
        #[serde(default)]
        caustic_photons: Option<u32>,
    },
    /// A spherical area light emitting uniformly from its surface; gives soft shadows.
    Sphere {
        /// Centre.
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        center: Vec3Spec,
        /// Radius (> 0).
        radius: f32,
        /// Total emitted flux (W).
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        power: Rgb,
        /// Caustic photons this light emits, instead of its power share of
        /// `photons.caustic` (0: none).
        #[serde(default)]
        caustic_photons: Option<u32>,
    },
}

impl LightSpec {
    /// The light's own caustic photon budget, if it sets one.
    #[must_use]
    pub fn caustic_photons(&self) -> Option<u32> {
        match *self {
            LightSpec::Point {
                caustic_photons, ..
            }
            | LightSpec::Sphere {
                caustic_photons, ..
            } => caustic_photons,
        }
    }
}
