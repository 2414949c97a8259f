//! Robust spawning of secondary rays: origins pushed off the surface by the hit point's own
//! floating-point error bound, so no single global epsilon is needed at any scene scale.

use glam::Vec3;

use super::float::{next_down, next_up};

/// Moves `p` (with per-component absolute error bound `p_error`) off the surface whose geometric
/// normal is `n`, to the side `w` points to, far enough that the new origin lies strictly on that
/// side (pbrt-v4 `OffsetRayOrigin`).
#[inline]
#[must_use]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let mut offset = n * d;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_down(po[i]);
        }
    }
    po
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_goes_to_the_requested_side_at_every_scale() {
        for scale in [1e-3f32, 1.0, 1e4, 1e5] {
            let p = Vec3::new(scale, 0.5 * scale, -2.0 * scale);
            let err = p.abs() * 1e-6;
            let n = Vec3::new(1.0, 1.0, 0.0).normalize();
            let out = offset_ray_origin(p, err, n, n);
            let inn = offset_ray_origin(p, err, n, -n);
            assert!((out - p).dot(n) > 0.0, "scale {scale}");
            assert!((inn - p).dot(n) < 0.0, "scale {scale}");
        }
    }
}
