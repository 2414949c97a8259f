//! Checks of the `lights` list.

use super::*;

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
}
