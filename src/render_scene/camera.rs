//! The pinhole camera: maps film positions to primary rays.

use glam::Vec3;

use crate::geometry::Ray;

/// A pinhole camera in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit right vector scaled by `tan(fov_y/2)·aspect`.
    pub right: Vec3,
    /// Unit up vector scaled by `tan(fov_y/2)`.
    pub up: Vec3,
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
        }
    }

    /// The primary ray through film position `(fx, fy)` in pixels (origin top-left) of a
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
}
