//! The camera: maps film positions (and, for a thin lens, a point on the lens) to primary rays.
//!
//! Pinhole (the default): every ray starts at the eye. Thin lens (depth of field; Kolb,
//! Mitchell & Hanrahan 1995, pbrt-v4 §5.2.3): rays start at a point of the lens disc (radius
//! `A`, centred on the eye, perpendicular to `forward`) and pass through the point the pinhole
//! ray of the same film position meets on the plane of focus (perpendicular to `forward`, at
//! distance `f_d`), so that plane is sharp. A point at depth `d` (along `forward`) is spread
//! over a circle of confusion of diameter `c = 2A |d − f_d| / (d · f_d)` on the image plane at
//! unit distance, i.e. `c · H / (2 tan(fov_y/2))` pixels for an image `H` pixels high.
//!
//! Ray cones (texture footprints) need no change for the thin lens: one camera sample is one
//! lens point, and the rays of the pixel's footprint through that point converge on the
//! pixel's patch of the focal plane like a pinhole's, so their cone starts with zero width at
//! the lens and spreads by the pixel's angle (`RenderScene::pixel_spread`, to first order in
//! `A/f_d`). The defocus blur is the average over lens samples, not a wider filter per sample.

use glam::Vec3;

use crate::geometry::Ray;
use crate::sampling::warp::concentric_disk;

/// The lens model of a [`Camera`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Lens {
    /// All rays from the eye; everything sharp.
    #[default]
    Pinhole,
    /// A thin lens of radius `radius` (world units, > 0) focused at `focus_distance` (> 0,
    /// measured along the view direction from the eye).
    Thin {
        /// Aperture radius.
        radius: f32,
        /// Distance from the lens to the plane of focus.
        focus_distance: f32,
    },
}

/// A camera in world space.
#[derive(Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position (the lens centre).
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit right vector scaled by `tan(fov_y/2)·aspect`.
    pub right: Vec3,
    /// Unit up vector scaled by `tan(fov_y/2)`.
    pub up: Vec3,
    /// The lens: [`Lens::Pinhole`] unless [`Camera::with_thin_lens`] set one.
    pub lens: Lens,
}

/// Prints like the derived `Debug` of the pinhole camera's four fields, and adds `lens` only
/// for a thin lens: the farm's settings hash formats the camera, and pinhole renders must keep
/// the hash (and their `.part` files) they had before lenses existed.
impl std::fmt::Debug for Camera {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("Camera");
        s.field("eye", &self.eye)
            .field("forward", &self.forward)
            .field("right", &self.right)
            .field("up", &self.up);
        if self.lens != Lens::Pinhole {
            s.field("lens", &self.lens);
        }
        s.finish()
    }
}

impl Camera {
    /// A camera at `eye` looking at `look_at`; `fov_y` in degrees; `aspect` = width / height.
    #[must_use]
    pub fn pinhole(eye: Vec3, look_at: Vec3, up: Vec3, fov_y: f32, aspect: f32) -> Self {
        let forward = (look_at - eye).normalize();
        let right = forward.cross(up).normalize();
        let true_up = right.cross(forward);
        let th = (fov_y.to_radians() * 0.5).tan();
        Self {
            eye,
            forward,
            right: right * th * aspect,
            up: true_up * th,
            lens: Lens::Pinhole,
        }
    }

    /// This camera with a thin lens of aperture radius `radius` focused at `focus_distance`
    /// (both world units). A radius of 0 keeps the pinhole. Validation rejects negative or
    /// non-finite values and a focus distance ≤ 0 before this.
    #[must_use]
    pub fn with_thin_lens(mut self, radius: f32, focus_distance: f32) -> Self {
        self.lens = if radius > 0.0 {
            Lens::Thin {
                radius,
                focus_distance,
            }
        } else {
            Lens::Pinhole
        };
        self
    }

    /// The pinhole ray through film position `(fx, fy)` in pixels (origin top-left) of a
    /// `width × height` image.
    #[inline]
    #[must_use]
    pub fn ray(&self, fx: f32, fy: f32, width: u32, height: u32) -> Ray {
        let u = 2.0 * fx / width as f32 - 1.0;
        let v = 1.0 - 2.0 * fy / height as f32;
        Ray::new(
            self.eye,
            (self.forward + self.right * u + self.up * v).normalize(),
        )
    }

    /// The primary ray through film position `(fx, fy)` and the lens point given by
    /// `u_lens ∈ [0, 1)²` (the camera's 2-D lens dimensions, mapped to the disc by the
    /// concentric map). Pinhole: exactly [`Camera::ray`] (`u_lens` unused). Thin lens: from
    /// `eye + A (x r̂ + y û)` towards `eye + f_d · (forward + u·right + v·up)`, the pinhole
    /// ray's point on the plane of focus.
    #[inline]
    #[must_use]
    pub fn ray_lens(&self, fx: f32, fy: f32, width: u32, height: u32, u_lens: (f32, f32)) -> Ray {
        match self.lens {
            Lens::Pinhole => self.ray(fx, fy, width, height),
            Lens::Thin {
                radius,
                focus_distance,
            } => {
                let u = 2.0 * fx / width as f32 - 1.0;
                let v = 1.0 - 2.0 * fy / height as f32;
                let focus =
                    self.eye + (self.forward + self.right * u + self.up * v) * focus_distance;
                let (lx, ly) = concentric_disk(u_lens);
                let origin =
                    self.eye + (self.right.normalize() * lx + self.up.normalize() * ly) * radius;
                Ray::new(origin, (focus - origin).normalize())
            }
        }
    }

    /// True when primary rays need lens samples (a thin lens).
    #[inline]
    #[must_use]
    pub fn needs_lens_sample(&self) -> bool {
        !matches!(self.lens, Lens::Pinhole)
    }
}

#[cfg(test)]
mod tests;
