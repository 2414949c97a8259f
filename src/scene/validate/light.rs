//! Checks of the `lights` list.

use super::*;
use crate::scene::schema::SkySun;

impl<'a> Validator<'a> {
    pub(super) fn light(&mut self, path: &str, l: &LightSpec) {
        let (power, power_path) = match l {
            LightSpec::Point {
                position, power, ..
            } => {
                self.finite3(&format!("{path}.position"), *position);
                (power, format!("{path}.power"))
            }
            LightSpec::Sphere {
                center,
                radius,
                power,
                ..
            } => {
                self.finite3(&format!("{path}.center"), *center);
                self.positive(&format!("{path}.radius"), *radius, "radius");
                (power, format!("{path}.power"))
            }
            LightSpec::Spot {
                position,
                direction,
                intensity,
                inner_angle,
                outer_angle,
                ..
            } => {
                self.finite3(&format!("{path}.position"), *position);
                self.direction(&format!("{path}.direction"), *direction);
                let outer_path = format!("{path}.outer_angle");
                if self.finite(&outer_path, *outer_angle)
                    && !(*outer_angle > 0.0 && *outer_angle <= 180.0)
                {
                    self.out.push(
                        Diagnostic::error(
                            &outer_path,
                            format!("the cone's half-angle must be within (0, 180] degrees, found {outer_angle}"),
                        )
                        .with_help("a spot light's `outer_angle` is the half-angle of its cone in degrees, e.g. 30; use a `Point` light to light every direction"),
                    );
                }
                let inner_path = format!("{path}.inner_angle");
                if self.finite(&inner_path, *inner_angle)
                    && !(*inner_angle >= 0.0 && *inner_angle <= *outer_angle)
                {
                    self.out.push(
                        Diagnostic::error(
                            &inner_path,
                            format!(
                                "must be within [0, outer_angle = {outer_angle}] degrees, found {inner_angle}"
                            ),
                        )
                        .with_help("`inner_angle` is the half-angle of the full-intensity cone, inside the `outer_angle` cone; equal angles give a hard edge"),
                    );
                }
                self.radiometric(&format!("{path}.intensity"), *intensity);
                return;
            }
            LightSpec::Distant {
                direction,
                irradiance,
                angular_radius,
                ..
            } => {
                self.direction(&format!("{path}.direction"), *direction);
                let at = format!("{path}.angular_radius");
                if self.finite(&at, *angular_radius)
                    && !(*angular_radius >= 0.0 && *angular_radius < 90.0)
                {
                    self.out.push(
                        Diagnostic::error(
                            &at,
                            format!("must be within [0, 90) degrees, found {angular_radius}"),
                        )
                        .with_help("the sun's angular radius is 0.2665; 0 is a delta direction"),
                    );
                }
                self.radiometric(&format!("{path}.irradiance"), *irradiance);
                return;
            }
            LightSpec::Sky {
                sun,
                turbidity,
                ground_albedo,
                scale,
                ..
            } => {
                if let SkySun::Direction(d) = sun {
                    let at = format!("{path}.sun");
                    self.direction(&at, *d);
                    if d.iter().all(|c| c.is_finite()) && !(d[1] > 0.0) {
                        self.out.push(
                            Diagnostic::error(
                                &at,
                                format!(
                                    "the sun must be above the horizon (y > 0), found {}",
                                    fmt3(*d)
                                ),
                            )
                            .with_help("the sky model holds for a sun above the horizon; +y is up"),
                        );
                    }
                }
                let at = format!("{path}.turbidity");
                if self.finite(&at, *turbidity) && !(2.0..=10.0).contains(turbidity) {
                    self.out.push(
                        Diagnostic::error(&at, format!("must be within [2, 10], found {turbidity}"))
                            .with_help("the range Preetham et al. fitted: 2 very clear, 3 clear, 6 hazy, 10 thin fog"),
                    );
                }
                let at = format!("{path}.ground_albedo");
                if self.finite3(&at, *ground_albedo)
                    && ground_albedo.iter().any(|c| !(0.0..=1.0).contains(c))
                {
                    self.err(
                        &at,
                        format!(
                            "must be within [0, 1] per channel, found {}",
                            fmt3(*ground_albedo)
                        ),
                    );
                }
                self.positive(&format!("{path}.scale"), *scale, "scale");
                return;
            }
            LightSpec::Environment {
                radiance,
                file,
                rotation,
                ..
            } => {
                self.finite(&format!("{path}.rotation"), *rotation);
                if file.as_ref().is_some_and(|f| f.trim().is_empty()) {
                    self.err(
                        &format!("{path}.file"),
                        "must name an OpenEXR file, found an empty string".into(),
                    );
                }
                self.radiometric(&format!("{path}.radiance"), *radiance);
                return;
            }
        };
        if self.finite3(&power_path, *power) && power.iter().any(|c| *c < 0.0) {
            self.err(
                &power_path,
                format!("must not be negative, found {}", fmt3(*power)),
            );
        } else if power.iter().any(|c| *c > MAX_LIGHT_POWER) {
            self.out.push(
                Diagnostic::error(
                    &power_path,
                    format!(
                        "must be at most {MAX_LIGHT_POWER:e} W per channel (single-precision radiance overflows beyond), found {}",
                        fmt3(*power)
                    ),
                )
                .with_help("divide every light's power by a constant and multiply `render.exposure` by it: the image is the same"),
            );
        }
    }

    /// A direction: finite and not zero.
    fn direction(&mut self, path: &str, d: [f32; 3]) {
        if self.finite3(path, d) && d.iter().all(|c| *c == 0.0) {
            self.out.push(
                Diagnostic::error(path, "must not be the zero vector, found (0, 0, 0)")
                    .with_help("give any non-zero vector along the direction, e.g. `(0, 1, 0)` (its length does not matter)"),
            );
        }
    }

    /// A sky's sun `Light(index)`: an index of `lights` holding a `Distant` light above the
    /// horizon.
    fn sky_sun(&mut self, at: &str, lights: &[LightSpec], index: usize) {
        match lights.get(index) {
            Some(LightSpec::Distant { direction, .. }) => {
                if direction.iter().all(|c| c.is_finite()) && !(direction[1] > 0.0) {
                    self.out.push(
                        Diagnostic::error(
                            at,
                            format!(
                                "the sky's sun, lights[{index}], must be above the horizon (y > 0), its direction is {}",
                                fmt3(*direction)
                            ),
                        )
                        .with_help("the sky model holds for a sun above the horizon; +y is up"),
                    );
                }
            }
            Some(other) => self.out.push(
                Diagnostic::error(
                    at,
                    format!(
                        "must name a `Distant` light, but lights[{index}] is a `{}` light",
                        other.kind()
                    ),
                )
                .with_help(
                    "give the index of the sun's `Distant` light, or `Direction((x, y, z))`",
                ),
            ),
            None => self.out.push(
                Diagnostic::error(
                    at,
                    format!(
                        "lights[{index}] does not exist: the scene has {} lights",
                        lights.len()
                    ),
                )
                .with_help(
                    "give the index of the sun's `Distant` light, or `Direction((x, y, z))`",
                ),
            ),
        }
    }

    /// An intensity, irradiance or radiance of a new light: finite, not negative, positive in
    /// some channel (a black light is a mistake; remove it instead), at most
    /// [`MAX_LIGHT_POWER`].
    fn radiometric(&mut self, path: &str, v: [f32; 3]) {
        if !self.finite3(path, v) {
            return;
        }
        if v.iter().any(|c| *c < 0.0) || v.iter().all(|c| *c == 0.0) {
            self.out.push(
                Diagnostic::error(
                    path,
                    format!(
                        "must be positive in some channel and negative in none, found {}",
                        fmt3(v)
                    ),
                )
                .with_help("remove a light that should not shine"),
            );
        } else if v.iter().any(|c| *c > MAX_LIGHT_POWER) {
            self.err(
                path,
                format!(
                    "must be at most {MAX_LIGHT_POWER:e} per channel, found {}",
                    fmt3(v)
                ),
            );
        }
    }

    /// At most one environment or sky light, no background beside it, and a sky's `Light(i)`
    /// sun a `Distant` light above the horizon.
    pub(super) fn environments(&mut self, scene: &SceneFile) {
        for (i, l) in scene.lights.iter().enumerate() {
            if let LightSpec::Sky {
                sun: SkySun::Light(s),
                ..
            } = l
            {
                self.sky_sun(&format!("lights[{i}].sun"), &scene.lights, *s);
            }
        }
        let envs: Vec<usize> = (scene.lights.iter().enumerate())
            .filter(|(_, l)| l.fills_sky())
            .map(|(i, _)| i)
            .collect();
        if let [_, second, ..] = envs[..] {
            self.out.push(
                Diagnostic::error(
                    format!("lights[{second}]"),
                    format!(
                        "a scene has at most one environment or sky light, found {} (lights {envs:?})",
                        envs.len()
                    ),
                )
                .with_help("merge them into one map"),
            );
        }
        if !envs.is_empty()
            && let Some(background) = scene.render.background
            && background.iter().any(|c| *c != 0.0)
        {
            self.out.push(
                Diagnostic::error(
                    "render.background",
                    format!(
                        "must be black with an environment or sky light (which is what escaping rays see), found {}",
                        fmt3(background)
                    ),
                )
                .with_help("remove `background`, or add it to the environment's `radiance`"),
            );
        }
    }
}
