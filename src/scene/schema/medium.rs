//! Participating media of the scene format (docs/media.md): homogeneous volumes that absorb
//! and scatter, named in `media` and placed inside a material's closed surfaces (`medium` on
//! the material) or around everything (`medium` on the scene: fog).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Rgb;
use super::values::optional_rgb;

/// A homogeneous medium, given either by its coefficients (`sigma_a`, `sigma_s`) or by its
/// single-scattering `albedo` and `mean_free_path` — not both forms at once.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MediumSpec {
    /// Absorption coefficient σa per channel, per scene unit (metres), ≥ 0.
    #[serde(default, deserialize_with = "optional_rgb")]
    pub sigma_a: Option<Rgb>,
    /// Scattering coefficient σs per channel, per scene unit (metres), ≥ 0.
    #[serde(default, deserialize_with = "optional_rgb")]
    pub sigma_s: Option<Rgb>,
    /// Single-scattering albedo σs/σt per channel, in [0, 1] (with `mean_free_path`).
    #[serde(default, deserialize_with = "optional_rgb")]
    pub albedo: Option<Rgb>,
    /// Mean free path 1/σt per channel, in scene units (metres), > 0 (with `albedo`).
    #[serde(default, deserialize_with = "optional_rgb")]
    pub mean_free_path: Option<Rgb>,
    /// Henyey–Greenstein asymmetry: the mean cosine of the scattering angle, in (−1, 1)
    /// (0 isotropic, > 0 forward scattering as in fog and water).
    #[serde(default)]
    pub g: f32,
}

impl MediumSpec {
    /// The coefficients `(σa, σs)` per channel this spec states (the albedo form converted:
    /// σt = 1/mfp, σs = albedo·σt, σa = σt − σs). Unchecked: validation reports bad values.
    #[must_use]
    pub fn coefficients(&self) -> (Rgb, Rgb) {
        match (self.albedo, self.mean_free_path) {
            (Some(a), Some(m)) => {
                let st = m.map(|x| 1.0 / x);
                let ss = [a[0] * st[0], a[1] * st[1], a[2] * st[2]];
                ([st[0] - ss[0], st[1] - ss[1], st[2] - ss[2]], ss)
            }
            _ => (
                self.sigma_a.unwrap_or([0.0; 3]),
                self.sigma_s.unwrap_or([0.0; 3]),
            ),
        }
    }
}
