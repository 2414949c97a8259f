//! Checks of the `render` and `camera` blocks.

use super::*;

impl<'a> Validator<'a> {
    /// `r`: the stated settings over their defaults (only the fields without a default may be
    /// `None`).
    pub(super) fn render(&mut self, r: &RenderSettings) {
        let (width, height) = (r.width.unwrap_or(1), r.height.unwrap_or(1));
        for (field, v) in [("width", width), ("height", height)] {
            let path = format!("render.{field}");
            if v == 0 {
                self.err(&path, "must be at least 1 pixel, found 0".into());
            } else if v > MAX_IMAGE_SIDE {
                self.err(
                    &path,
                    format!("must be at most {MAX_IMAGE_SIDE} pixels, found {v}"),
                );
            }
        }
        let pixels = u64::from(width) * u64::from(height);
        if width <= MAX_IMAGE_SIDE && height <= MAX_IMAGE_SIDE && pixels > MAX_IMAGE_PIXELS {
            self.err(
                "render.width",
                format!(
                    "{}×{} = {pixels} pixels exceeds the limit of {MAX_IMAGE_PIXELS} pixels (the film alone would need {:.1} GB)",
                    width,
                    height,
                    pixels as f64 * 12.0 / 1e9
                ),
            );
        }
        if let Some(spp) = r.samples_per_pixel
            && (spp == 0 || spp > MAX_SAMPLES_PER_PIXEL)
        {
            self.err(
                "render.samples_per_pixel",
                format!("must be within [1, {MAX_SAMPLES_PER_PIXEL}], found {spp}"),
            );
        }
        if let Some(depth) = r.max_depth
            && depth > MAX_DEPTH
        {
            self.err(
                "render.max_depth",
                format!("must be at most {MAX_DEPTH}, found {depth}"),
            );
        }
        if let Some(n) = r.light_samples
            && (n == 0 || n > 1024)
        {
            self.err(
                "render.light_samples",
                format!("must be within [1, 1024], found {n}"),
            );
        }
        if let Some(m) = r.min_contribution {
            self.range("render.min_contribution", m, 0.0, 1.0);
        }
        if let Some(bg) = r.background
            && self.finite3("render.background", bg)
            && bg.iter().any(|c| *c < 0.0)
        {
            self.err(
                "render.background",
                format!("must not be negative, found {}", fmt3(bg)),
            );
        }
        if let Some(exposure) = r.exposure {
            self.positive("render.exposure", exposure, "exposure");
        }
        if let Some(target) = r.target_error {
            self.positive(
                "render.target_error",
                target,
                "the target relMSE (e.g. 0.01)",
            );
        }
    }

    pub(super) fn camera(&mut self, c: &CameraSpec) {
        let (eye, look_at, up, fov_y) = c.view();
        let (eye, look_at, up, fov_y) = (&eye, &look_at, &up, &fov_y);
        self.lens(c);
        let ok = self.finite3("camera.eye", *eye)
            & self.finite3("camera.look_at", *look_at)
            & self.finite3("camera.up", *up);
        if self.finite("camera.fov_y", *fov_y) && !(*fov_y > 0.0 && *fov_y < 180.0) {
            self.err(
                "camera.fov_y",
                format!("must be within (0, 180) degrees, found {fov_y}"),
            );
        }
        if !ok {
            return;
        }
        let forward = glam::Vec3::from(*look_at) - glam::Vec3::from(*eye);
        if !(forward.length_squared() > 0.0) {
            self.err(
                "camera.look_at",
                format!("must differ from `eye`, both are {}", fmt3(*eye)),
            );
        } else if !(forward
            .normalize()
            .cross(glam::Vec3::from(*up))
            .length_squared()
            > 1e-12)
        {
            self.err(
                "camera.up",
                format!(
                    "must not be parallel to the view direction, found {}",
                    fmt3(*up)
                ),
            );
        }
    }

    /// A thin lens: exactly one of `aperture_radius` (≥ 0) and `f_number` (> 0), a positive
    /// sensor height and focus distance.
    fn lens(&mut self, c: &CameraSpec) {
        let CameraSpec::ThinLens {
            aperture_radius,
            f_number,
            sensor_height,
            focus_distance,
            ..
        } = c
        else {
            return;
        };
        match (aperture_radius, f_number) {
            (Some(_), Some(_)) | (None, None) => self.out.push(
                Diagnostic::error(
                    "camera",
                    "a thin lens needs exactly one of `aperture_radius` and `f_number`",
                )
                .with_help("e.g. `aperture_radius: 0.05` (scene units) or `f_number: 2.8`"),
            ),
            (Some(r), None) => {
                if self.finite("camera.aperture_radius", *r) && *r < 0.0 {
                    self.err(
                        "camera.aperture_radius",
                        format!("must not be negative, found {r}"),
                    );
                }
            }
            (None, Some(n)) => self.positive("camera.f_number", *n, "f-number"),
        }
        self.positive("camera.sensor_height", *sensor_height, "sensor height");
        self.positive("camera.focus_distance", *focus_distance, "focus distance");
    }
}
