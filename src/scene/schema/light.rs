//! Light sources of the scene format.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::values::exact_floats;
use super::{Rgb, Vec3Spec};

/// Light sources; `power` is the emitted radiant flux in watts per RGB channel. (Area lights on
/// shapes are not listed here: a node carries them as `emission`.)
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
    /// A spot light: a point light emitting inside a cone, full intensity within `inner_angle`
    /// of `direction`, none beyond `outer_angle`, pbrt-v4's smooth step in cos θ between.
    Spot {
        /// Position.
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        position: Vec3Spec,
        /// Direction the cone points (any length > 0).
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        direction: Vec3Spec,
        /// Radiant intensity on the axis (W/sr per channel).
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        intensity: Rgb,
        /// Half-angle of the full-intensity cone, degrees, in [0, `outer_angle`].
        #[serde(default)]
        inner_angle: f32,
        /// Half-angle beyond which no light leaves, degrees, in (0, 180].
        outer_angle: f32,
        /// Caustic photons this light emits, instead of its power share of
        /// `photons.caustic` (0: none).
        #[serde(default)]
        caustic_photons: Option<u32>,
    },
    /// A distant light (the sun): parallel light from `direction`, of irradiance `irradiance` on
    /// a surface facing it; with `angular_radius` > 0, uniform radiance `E / (π sin²α)` over
    /// the cone of that half-angle (the sun: 0.2665°), which gives penumbrae.
    Distant {
        /// Direction from the scene towards the light (any length > 0).
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        direction: Vec3Spec,
        /// Irradiance (W/m² per channel) on a surface facing the light.
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        irradiance: Rgb,
        /// Angular radius of the source, degrees, in [0, 90) (0: a delta direction).
        #[serde(default)]
        angular_radius: f32,
        /// Caustic photons this light emits, instead of its power share of
        /// `photons.caustic` (0: none).
        #[serde(default)]
        caustic_photons: Option<u32>,
    },
    /// Light arriving from every direction at infinity: a constant `radiance`, or an
    /// equirectangular linear HDR image (`file`, OpenEXR, Mitsuba's `envmap` convention: +y up,
    /// the top row at the zenith) scaled by `radiance` and turned by `rotation` degrees about
    /// +y. Rays leaving the scene see it; `render.background` must then be black. At most one
    /// per scene.
    Environment {
        /// Radiance (W/(m²·sr) per channel) of the constant environment, or the factor the
        /// image's texels are multiplied by.
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        radiance: Rgb,
        /// Equirectangular OpenEXR image, relative to the scene file.
        #[serde(default)]
        file: Option<String>,
        /// Rotation of the map about +y, degrees (right-handed).
        #[serde(default)]
        rotation: f32,
        /// Caustic photons this light emits, instead of its power share of
        /// `photons.caustic` (0: none).
        #[serde(default)]
        caustic_photons: Option<u32>,
    },
    /// A physical clear sky above a flat ground: the analytic daylight model of Preetham,
    /// Shirley & Smits (1999) for the sun's direction and the air's `turbidity`. Its luminance
    /// (cd/m² in the model) is scaled so that, beside the `Distant` sun it follows, sun and sky
    /// keep the ratio of a clear atmosphere (see `docs/lights.md`). Below the horizon, a
    /// Lambertian ground of `ground_albedo` lit by sky and sun. Rays leaving the scene see it;
    /// `render.background` must then be black; at most one sky or environment per scene. The
    /// sun's disc itself is the `Distant` light's.
    Sky {
        /// The sun the sky follows: `Light(i)`, the `Distant` light `lights[i]` (its direction,
        /// and its irradiance sets the sky's brightness), or `Direction((x, y, z))` towards the
        /// sun (then 1 scene radiance unit per kcd/m²). Above the horizon (+y up).
        sun: SkySun,
        /// Atmospheric turbidity, in [2, 10] (2: very clear, 3: clear, 6: hazy, 10: thin fog).
        #[serde(default = "three")]
        turbidity: f32,
        /// Reflectance of the ground below the horizon, per channel in [0, 1].
        #[serde(default = "ground")]
        #[serde(deserialize_with = "exact_floats::<_, 3>")]
        ground_albedo: Rgb,
        /// Factor on the sky's (and ground's) radiance (> 0).
        #[serde(default = "unit")]
        scale: f32,
        /// Caustic photons this light emits, instead of its power share of
        /// `photons.caustic` (0: none).
        #[serde(default)]
        caustic_photons: Option<u32>,
    },
}

/// The sun a `Sky` follows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub enum SkySun {
    /// The `Distant` light at this index of the `lights` list.
    Light(usize),
    /// A direction towards the sun (any length > 0, with y > 0).
    Direction(#[serde(deserialize_with = "exact_floats::<_, 3>")] Vec3Spec),
}

fn three() -> f32 {
    3.0
}

fn unit() -> f32 {
    1.0
}

fn ground() -> Rgb {
    [0.3; 3]
}

/// Light emitted by a shape (a node's `emission`): the node becomes an area light of uniform
/// `radiance`, emitting on the side its normal faces (outwards for spheres and cubes, +z for a
/// quad, the winding's side for a mesh), or on both sides with `two_sided`. An emissive shape
/// has no material: it absorbs the light that reaches it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EmissionSpec {
    /// Emitted radiance, W/(m²·sr) per channel (> 0 in some channel).
    #[serde(deserialize_with = "exact_floats::<_, 3>")]
    pub radiance: Rgb,
    /// Emit on both sides (twice the power of a one-sided light). Not for spheres.
    #[serde(default)]
    pub two_sided: bool,
}

fn white() -> Rgb {
    [1.0; 3]
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
            }
            | LightSpec::Spot {
                caustic_photons, ..
            }
            | LightSpec::Distant {
                caustic_photons, ..
            }
            | LightSpec::Environment {
                caustic_photons, ..
            }
            | LightSpec::Sky {
                caustic_photons, ..
            } => caustic_photons,
        }
    }

    /// The light's own caustic photon budget, to set or clear (`--caustic-photons` drops them
    /// all).
    #[must_use]
    pub fn caustic_photons_mut(&mut self) -> &mut Option<u32> {
        match self {
            LightSpec::Point {
                caustic_photons, ..
            }
            | LightSpec::Sphere {
                caustic_photons, ..
            }
            | LightSpec::Spot {
                caustic_photons, ..
            }
            | LightSpec::Distant {
                caustic_photons, ..
            }
            | LightSpec::Environment {
                caustic_photons, ..
            }
            | LightSpec::Sky {
                caustic_photons, ..
            } => caustic_photons,
        }
    }

    /// True for the lights that every escaping ray sees, which fill the sky: environment and
    /// sky (at most one per scene, and no background beside it).
    #[must_use]
    pub fn fills_sky(&self) -> bool {
        match self {
            LightSpec::Environment { .. } | LightSpec::Sky { .. } => true,
            LightSpec::Point { .. }
            | LightSpec::Sphere { .. }
            | LightSpec::Spot { .. }
            | LightSpec::Distant { .. } => false,
        }
    }

    /// The light's kind as written in the file.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self {
            LightSpec::Point { .. } => "Point",
            LightSpec::Sphere { .. } => "Sphere",
            LightSpec::Spot { .. } => "Spot",
            LightSpec::Distant { .. } => "Distant",
            LightSpec::Environment { .. } => "Environment",
            LightSpec::Sky { .. } => "Sky",
        }
    }
}
