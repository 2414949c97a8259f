//! A ray with a maximum parametric distance.

use glam::Vec3;

/// A half-line `origin + t·dir` for `t` in `(0, t_max)`; `dir` need not be normalised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Start point in world space.
    pub origin: Vec3,
    /// Direction (unit length for camera and scattered rays).
    pub dir: Vec3,
    /// Upper end of the valid parametric interval.
    pub t_max: f32,
}

impl Ray {
    /// A ray with an unbounded `t_max`.
    #[inline]
    #[must_use]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir,
            t_max: f32::INFINITY,
        }
    }

    /// The point at parameter `t`.
    #[inline]
    #[must_use]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    /// True when origin, direction and `t_max` are usable (finite, non-zero direction, `t_max` not NaN).
    #[inline]
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite()
            && self.dir.is_finite()
            && self.dir != Vec3::ZERO
            && !self.t_max.is_nan()
    }
}
