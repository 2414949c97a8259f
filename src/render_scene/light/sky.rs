//! A physical clear sky: the analytic daylight model of Preetham, Shirley & Smits, "A Practical
//! Analytic Model for Daylight" (SIGGRAPH 1999), for a sun direction and an atmospheric
//! turbidity, above a uniform ground; tabulated into an equirectangular map and then sampled,
//! looked up and emitted exactly as an [`EnvironmentLight`] (its distribution over the map).
//!
//! The model (the paper's section 3 and appendix A.2), for a view direction at zenith angle θ
//! whose angle to the sun is γ, the sun at zenith angle θs:
//! - Perez et al.'s distribution `F(θ, γ) = (1 + A e^{B / cos θ}) (1 + C e^{D γ} + E cos² γ)`,
//!   one set of coefficients `A … E` for each of the luminance `Y` and the chromaticities `x`,
//!   `y`, each linear in the turbidity T (the paper's table in appendix A.2, [`perez_y`],
//!   [`perez_x`], [`perez_yc`]).
//! - Each quantity is its zenith value times `F(θ, γ) / F(0, θs)`, so the zenith value is exact
//!   at the zenith.
//! - The zenith luminance `Y_z = (4.0453 T − 4.9710) tan χ − 0.2155 T + 2.4192` kcd/m², with
//!   `χ = (4/9 − T/120)(π − 2 θs)` ([`zenith_luminance`]); the zenith chromaticities are cubics
//!   in θs with coefficients quadratic in T ([`zenith_chromaticity`]).
//!
//! The paper fits turbidities 2 to 10 with the sun above the horizon; the scene checks both.
//! `x, y, Y` become CIE XYZ and then linear Rec. 709 RGB (the renderer's working space, D65).
//!
//! Units (one factor ties the sky to the sun light): the model's luminance is in cd/m². A sky
//! tied to a [`Distant`](super::DistantLight) light of irradiance `E` (scene units) scales it by
//! `k = Y(E) / E_dn`, where `Y(E)` is the Rec. 709 luminance of `E` and `E_dn` the clear-sky
//! direct-normal illuminance of the sun at its zenith angle, `127.5 klux · exp(−0.21 m)` with air
//! mass `m = 1 / cos θs` (the IES Lighting Handbook's daylight-availability formula: solar
//! illuminance constant 127.5 klux, clear-sky extinction 0.21): sun and sky then keep the ratio
//! of their illuminances in a clear atmosphere, whatever unit the sun is written in. A sky
//! given only a direction has no sun to follow: `k = 1/1000` (1 scene unit per kcd/m²).
//! `scale` multiplies either.
//!
//! Below the horizon is the ground: a Lambertian plane of albedo ρ lit by the sky and the sun,
//! `L = ρ (E_sky + E_sun cos θs) / π`, where `E_sky` is the tabulated sky's irradiance on a
//! horizontal plane (a sky given only a direction has `E_sun = 0`).

use glam::{DVec3, Vec3};
use std::f64::consts::PI;

use super::environment::{EnvironmentError, EnvironmentLight};
use super::infinite::SceneSphere;

/// Columns of the tabulated sky (the rows are half as many): texels of 0.7°, so the sun's glow
/// (`e^{Dγ}` with `D ≈ −2`, a scale of ~30°) is smooth across them; even rows put the horizon on
/// a row boundary.
pub const SKY_WIDTH: usize = 512;

/// Rows of the tabulated sky.
pub const SKY_HEIGHT: usize = SKY_WIDTH / 2;

/// Solar illuminance constant of the IES daylight-availability formula (lux).
pub const SOLAR_ILLUMINANCE: f64 = 127.5e3;

/// Clear-sky extinction coefficient of the IES daylight-availability formula.
pub const CLEAR_SKY_EXTINCTION: f64 = 0.21;

/// Perez coefficients `A … E` of the luminance Y at turbidity `t` (Preetham et al. 1999,
/// appendix A.2).
#[must_use]
pub fn perez_y(t: f64) -> [f64; 5] {
    [
        0.1787 * t - 1.4630,
        -0.3554 * t + 0.4275,
        -0.0227 * t + 5.3251,
        0.1206 * t - 2.5771,
        -0.0670 * t + 0.3703,
    ]
}

/// Perez coefficients of the chromaticity x at turbidity `t` (appendix A.2).
#[must_use]
pub fn perez_x(t: f64) -> [f64; 5] {
    [
        -0.0193 * t - 0.2592,
        -0.0665 * t + 0.0008,
        -0.0004 * t + 0.2125,
        -0.0641 * t - 0.8989,
        -0.0033 * t + 0.0452,
    ]
}

/// Perez coefficients of the chromaticity y at turbidity `t` (appendix A.2).
#[must_use]
pub fn perez_yc(t: f64) -> [f64; 5] {
    [
        -0.0167 * t - 0.2608,
        -0.0950 * t + 0.0092,
        -0.0079 * t + 0.2102,
        -0.0441 * t - 1.6537,
        -0.0109 * t + 0.0529,
    ]
}

/// Perez et al.'s distribution `F(θ, γ)` with coefficients `c = [A, B, C, D, E]`, for
/// `cos θ > 0` (above the horizon) and γ in radians.
#[must_use]
pub fn perez(c: [f64; 5], cos_theta: f64, gamma: f64) -> f64 {
    let [a, b, cc, d, e] = c;
    let cos_g = gamma.cos();
    (1.0 + a * (b / cos_theta).exp()) * (1.0 + cc * (d * gamma).exp() + e * cos_g * cos_g)
}

/// Zenith luminance `Y_z` (kcd/m²) for turbidity `t` and the sun's zenith angle `theta_s`
/// (radians): `(4.0453 T − 4.9710) tan χ − 0.2155 T + 2.4192`, `χ = (4/9 − T/120)(π − 2θs)`.
#[must_use]
pub fn zenith_luminance(t: f64, theta_s: f64) -> f64 {
    let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta_s);
    (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192
}

/// Zenith chromaticity `(x_z, y_z)` for turbidity `t` and the sun's zenith angle `theta_s`:
/// `[T² T 1] M [θs³ θs² θs 1]ᵀ` with the paper's two 3×4 matrices.
#[must_use]
pub fn zenith_chromaticity(t: f64, theta_s: f64) -> (f64, f64) {
    const MX: [[f64; 4]; 3] = [
        [0.00166, -0.00375, 0.00209, 0.0],
        [-0.02903, 0.06377, -0.03202, 0.00394],
        [0.11693, -0.21196, 0.06052, 0.25886],
    ];
    const MY: [[f64; 4]; 3] = [
        [0.00275, -0.00610, 0.00317, 0.0],
        [-0.04214, 0.08970, -0.04153, 0.00516],
        [0.15346, -0.26756, 0.06670, 0.26688],
    ];
    let tt = [t * t, t, 1.0];
    let th = [theta_s.powi(3), theta_s.powi(2), theta_s, 1.0];
    let apply = |m: &[[f64; 4]; 3]| -> f64 {
        (0..3)
            .map(|i| tt[i] * (0..4).map(|j| m[i][j] * th[j]).sum::<f64>())
            .sum()
    };
    (apply(&MX), apply(&MY))
}

/// The Preetham sky for one sun direction and turbidity, in the world frame (+y up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyModel {
    /// Unit direction towards the sun (`y > 0`).
    pub sun: DVec3,
    /// Turbidity T.
    pub turbidity: f64,
    /// Zenith values `(Y_z in cd/m², x_z, y_z)`.
    pub zenith: (f64, f64, f64),
    /// Perez coefficients of Y, x and y.
    pub coefficients: [[f64; 5]; 3],
}

impl SkyModel {
    /// The sky for the sun towards `sun` (any length; above the horizon, `y > 0`) and turbidity
    /// `turbidity` in [2, 10]. `None` outside those ranges (where the fit does not hold).
    #[must_use]
    pub fn new(sun: DVec3, turbidity: f64) -> Option<Self> {
        let sun = sun.try_normalize()?;
        if !(sun.y > 0.0 && (2.0..=10.0).contains(&turbidity)) {
            return None;
        }
        let theta_s = sun.y.clamp(-1.0, 1.0).acos();
        let (xz, yz) = zenith_chromaticity(turbidity, theta_s);
        Some(Self {
            sun,
            turbidity,
            zenith: (1000.0 * zenith_luminance(turbidity, theta_s), xz, yz),
            coefficients: [perez_y(turbidity), perez_x(turbidity), perez_yc(turbidity)],
        })
    }

    /// The sun's zenith angle θs (radians).
    #[must_use]
    pub fn theta_s(&self) -> f64 {
        self.sun.y.clamp(-1.0, 1.0).acos()
    }

    /// `(Y in cd/m², x, y)` of the sky seen along the unit `w` above the horizon (`w.y > 0`):
    /// each zenith value times `F(θ, γ) / F(0, θs)`.
    #[must_use]
    pub fn xyy(&self, w: DVec3) -> (f64, f64, f64) {
        let cos_theta = w.y;
        let gamma = w.dot(self.sun).clamp(-1.0, 1.0).acos();
        let theta_s = self.theta_s();
        let ratio = |c: [f64; 5]| perez(c, cos_theta, gamma) / perez(c, 1.0, theta_s);
        let [cy, cx, cyc] = self.coefficients;
        let (yz, xz, ycz) = self.zenith;
        (yz * ratio(cy), xz * ratio(cx), ycz * ratio(cyc))
    }

    /// Linear Rec. 709 RGB (D65) of the sky along the unit `w` above the horizon, in cd/m² of
    /// luminance (`0.2126 R + 0.7152 G + 0.0722 B = Y`).
    #[must_use]
    pub fn rgb(&self, w: DVec3) -> DVec3 {
        let (lum, x, y) = self.xyy(w);
        if !(y > 0.0) {
            return DVec3::ZERO;
        }
        let big_x = x * lum / y;
        let big_z = (1.0 - x - y) * lum / y;
        xyz_to_rgb(DVec3::new(big_x, lum, big_z)).max(DVec3::ZERO)
    }
}

/// CIE XYZ → linear Rec. 709 RGB (D65 white).
#[must_use]
pub fn xyz_to_rgb(c: DVec3) -> DVec3 {
    DVec3::new(
        3.240_454_2 * c.x - 1.537_138_5 * c.y - 0.498_531_4 * c.z,
        -0.969_266_0 * c.x + 1.876_010_8 * c.y + 0.041_556_0 * c.z,
        0.055_643_4 * c.x - 0.204_025_9 * c.y + 1.057_225_2 * c.z,
    )
}

/// Rec. 709 luminance `0.2126 R + 0.7152 G + 0.0722 B` of a linear RGB value.
#[must_use]
pub fn luminance(c: Vec3) -> f64 {
    0.2126 * f64::from(c.x) + 0.7152 * f64::from(c.y) + 0.0722 * f64::from(c.z)
}

/// Clear-sky direct-normal illuminance of the sun (lux) at zenith angle `theta_s`:
/// `127.5 klux · exp(−0.21 / cos θs)` (IES daylight availability; module docs).
#[must_use]
pub fn sun_direct_normal_illuminance(theta_s: f64) -> f64 {
    SOLAR_ILLUMINANCE * (-CLEAR_SKY_EXTINCTION / theta_s.cos()).exp()
}

/// The sun a sky follows, as the scene gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SkySun {
    /// A distant light: its direction and its irradiance (scene units) on a surface facing it.
    Light {
        /// Direction towards the sun (any length).
        direction: Vec3,
        /// Irradiance per channel.
        irradiance: Vec3,
    },
    /// Only a direction (any length): no sun light to keep the ratio with.
    Direction(Vec3),
}

/// Why a sky cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SkyError {
    /// The sun is on or below the horizon, or its direction is zero.
    #[error("the sun must be above the horizon (direction with y > 0), found {0}")]
    SunBelowHorizon(Vec3),
    /// The turbidity is outside the model's fitted range.
    #[error("the turbidity must be within [2, 10] (the range Preetham et al. fitted), found {0}")]
    Turbidity(f32),
    /// The tabulated map is not a valid environment (a NaN from extreme parameters).
    #[error("{0}")]
    Map(#[from] EnvironmentError),
}

/// A sky light: the Preetham model tabulated into an [`EnvironmentLight`] (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SkyLight {
    /// The model the map was tabulated from.
    pub model: SkyModel,
    /// Scene radiance per cd/m² of model luminance (module docs), `scale` included.
    pub k: f64,
    /// Radiance of the ground below the horizon (scene units).
    pub ground: Vec3,
    /// The tabulated sky and ground, sampled as an environment map.
    pub map: EnvironmentLight,
}

impl SkyLight {
    /// The sky following `sun` at turbidity `turbidity`, ground albedo `albedo` (per channel, in
    /// [0, 1]) and overall factor `scale`, covering the scene's bounding sphere `scene`.
    ///
    /// # Errors
    /// [`SkyError`] for a sun on or below the horizon or a turbidity outside [2, 10].
    pub fn new(
        sun: SkySun,
        turbidity: f32,
        albedo: Vec3,
        scale: f32,
        scene: SceneSphere,
    ) -> Result<Self, SkyError> {
        let dir = match sun {
            SkySun::Light { direction, .. } | SkySun::Direction(direction) => direction,
        };
        let model = SkyModel::new(dir.as_dvec3(), f64::from(turbidity)).ok_or(
            if dir.try_normalize().is_some_and(|d| d.y > 0.0) {
                SkyError::Turbidity(turbidity)
            } else {
                SkyError::SunBelowHorizon(dir)
            },
        )?;
        let theta_s = model.theta_s();
        let (k, e_sun) = match sun {
            SkySun::Light { irradiance, .. } => (
                luminance(irradiance) / sun_direct_normal_illuminance(theta_s),
                irradiance.as_dvec3() * model.sun.y,
            ),
            SkySun::Direction(_) => (1e-3, DVec3::ZERO),
        };
        let k = k * f64::from(scale);
        let (w, h) = (SKY_WIDTH, SKY_HEIGHT);
        let mut texels = vec![Vec3::ZERO; w * h];
        // The sky's irradiance on a horizontal plane, Σ L cos θ ΔΩ over the upper rows.
        let mut e_sky = DVec3::ZERO;
        for j in 0..h / 2 {
            let theta = PI * (j as f64 + 0.5) / h as f64;
            let (t0, t1) = (PI * j as f64 / h as f64, PI * (j + 1) as f64 / h as f64);
            let omega = 2.0 * PI / w as f64 * (t0.cos() - t1.cos());
            for i in 0..w {
                let phi = 2.0 * PI * (i as f64 + 0.5) / w as f64;
                // The environment map's convention: (sin θ sin φ, cos θ, −sin θ cos φ).
                let d = DVec3::new(
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    -theta.sin() * phi.cos(),
                );
                let l = model.rgb(d) * k;
                e_sky += l * theta.cos() * omega;
                texels[j * w + i] = l.as_vec3();
            }
        }
        let ground = (albedo.as_dvec3() * (e_sky + e_sun) / PI).as_vec3();
        for t in &mut texels[w * h / 2..] {
            *t = ground;
        }
        let map = EnvironmentLight::image(w, h, texels, 0.0, scene)?;
        Ok(Self {
            model,
            k,
            ground,
            map,
        })
    }
}

#[cfg(test)]
mod tests;
