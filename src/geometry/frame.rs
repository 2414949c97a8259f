//! Orthonormal frames around a normal.

use glam::Vec3;

/// An orthonormal basis `(s, t, n)` with `n` the surface normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub s: Vec3,
    /// Second tangent (`n × s`).
    pub t: Vec3,
    /// Normal.
    pub n: Vec3,
}

impl Frame {
    /// A frame around the unit vector `n`, branch-free and singularity-free
    /// (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 2017).
    #[inline]
    #[must_use]
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    /// Expresses a world vector in this frame's coordinates.
    #[inline]
    #[must_use]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Maps frame coordinates back to world space.
    #[inline]
    #[must_use]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
#[allow(clippy::excessive_precision)]
mod tests {
    use super::*;

    fn orthonormality_error(f: &Frame) -> f32 {
        [
            f.s.dot(f.t).abs(),
            f.s.dot(f.n).abs(),
            f.t.dot(f.n).abs(),
            (f.s.length() - 1.0).abs(),
            (f.t.length() - 1.0).abs(),
        ]
        .into_iter()
        .fold(0.0, f32::max)
    }

    #[test]
    fn frames_are_orthonormal_including_duff_bad_normals() {
        let normals = [
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            -Vec3::X,
            -Vec3::Y,
            -Vec3::Z,
            Vec3::new(0.000_385_273_16, 0.000_384_600_16, -0.999_999_88).normalize(),
            Vec3::new(-0.000_198_135_81, -0.000_089_468_39, -0.999_999_88).normalize(),
            Vec3::new(1.0, 2.0, 3.0).normalize(),
        ];
        for n in normals {
            let f = Frame::from_normal(n);
            assert!(orthonormality_error(&f) < 1e-6, "{n:?}");
            assert!(f.s.cross(f.t).distance(n) < 1e-6, "right-handed for {n:?}");
            let v = Vec3::new(0.3, -0.2, 0.9);
            assert!(f.to_world(f.to_local(v)).distance(v) < 1e-6);
        }
        // Along an axis, the tangents have no component along that axis.
        let f = Frame::from_normal(-Vec3::Z);
        assert_eq!(f.s.z, 0.0);
        assert_eq!(f.t.z, 0.0);
    }
}
