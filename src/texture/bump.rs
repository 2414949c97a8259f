//! Bump mapping: height maps and the normal perturbation they (or any height source) drive.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::mipmap::GreyMipMap;
use crate::geometry::Frame;

/// A grey image used as a height field over the surface: height = `depth` × grey value, repeated
/// `tile` times per axis over uv ∈ [0, 1]².
#[derive(Debug, Clone, PartialEq)]
pub struct HeightMap {
    /// The grey pyramid (raw grey values, typically in [0, 1]).
    pub mip: Arc<GreyMipMap>,
    /// Height of a grey value of 1, in world units (the bump depth; may be negative).
    pub depth: f32,
    /// Repeat count per axis, as for [`BitmapTexture`](super::BitmapTexture).
    pub tile: Vec2,
}

impl HeightMap {
    /// A height map of `depth` × grey, repeated `tile` times per axis.
    #[must_use]
    pub fn new(mip: impl Into<Arc<GreyMipMap>>, depth: f32, tile: Vec2) -> Self {
        Self {
            mip: mip.into(),
            depth,
            tile,
        }
    }

    /// Filtered height at surface coordinates `uv`, in world units; `footprint` is the pixel's
    /// width in surface uv units (before tiling), as for `BitmapTexture::eval`.
    #[inline]
    #[must_use]
    pub fn height(&self, uv: Vec2, footprint: f32) -> f32 {
        self.depth
            * self
                .mip
                .lookup(uv * self.tile, footprint * self.tile.abs().max_element())
    }

    /// `(∂h/∂u, ∂h/∂v)` in world units per surface uv unit (tiling included), from central
    /// differences of the filtered height read at the same footprint (so the same mip levels).
    /// The step is the footprint in texture space, and never less than one level-0 texel, so the
    /// derivative is as smooth as the colour lookups at that pixel.
    #[must_use]
    pub fn gradient(&self, uv: Vec2, footprint: f32) -> Vec2 {
        let t = uv * self.tile;
        let ft = footprint * self.tile.abs().max_element();
        let du = ft.max(1.0 / self.mip.width() as f32);
        let dv = ft.max(1.0 / self.mip.height() as f32);
        let h = |d: Vec2| self.mip.lookup(t + d, ft);
        let hu = (h(Vec2::new(du, 0.0)) - h(Vec2::new(-du, 0.0))) / (2.0 * du);
        let hv = (h(Vec2::new(0.0, dv)) - h(Vec2::new(0.0, -dv))) / (2.0 * dv);
        Vec2::new(hu, hv) * self.tile * self.depth
    }

    /// The shading normal `n` bumped by this map at `uv` (see [`perturb_normal`]).
    #[must_use]
    pub fn perturb(&self, n: Vec3, dpdu: Vec3, dpdv: Vec3, uv: Vec2, footprint: f32) -> Vec3 {
        let g = self.gradient(uv, footprint);
        perturb_normal(n, dpdu, dpdv, g.x, g.y)
    }
}

/// The unit normal of the surface displaced by a height `h(u, v)` along `n` (Blinn 1978),
/// with `n` unit and `dhdu`, `dhdv` in world units per uv unit:
///
/// ```text
/// n' = normalize( n + (h_u · (n × t_v) − h_v · (n × t_u)) / J ),   J = (t_u × t_v) · n
/// ```
///
/// where `t_u`, `t_v` are `dpdu`, `dpdv` projected onto the plane ⟂ `n`. This is the normal of
/// the displaced tangents `t_u + h_u n`, `t_v + h_v n` (dropping the `h ∂n/∂u` terms), oriented
/// to `n`'s side whatever the handedness of the uv parametrisation. For orthonormal tangents it
/// reduces to `normalize(n − h_u t_u − h_v t_v)`.
///
/// Returns `n` itself (bit-identical) when both derivatives are 0. When `dpdu`, `dpdv` are
/// degenerate (zero, parallel to each other or to `n`, non-finite), the tangents of
/// [`Frame::from_normal`]`(n)` are used instead, i.e. uv is taken as unit-speed along them.
/// A non-finite result (e.g. NaN derivatives) also gives back `n`.
#[must_use]
pub fn perturb_normal(n: Vec3, dpdu: Vec3, dpdv: Vec3, dhdu: f32, dhdv: f32) -> Vec3 {
    if dhdu == 0.0 && dhdv == 0.0 {
        return n;
    }
    let mut tu = dpdu - n * n.dot(dpdu);
    let mut tv = dpdv - n * n.dot(dpdv);
    let mut j = tu.cross(tv).dot(n);
    // |J| = |t_u||t_v| sin θ: require the tangents to be at least ~1e-6 rad from parallel.
    if !(j.abs() > 1e-6 * tu.length() * tv.length()) || !j.is_finite() {
        let f = Frame::from_normal(n);
        (tu, tv, j) = (f.s, f.t, 1.0);
    }
    let bumped = n + (n.cross(tv) * dhdu - n.cross(tu) * dhdv) / j;
    let out = bumped.normalize();
    if out.is_finite() { out } else { n }
}

/// The unit normal `n` bumped by a solid (3-d) height field with world-space gradient `grad`
/// (e.g. from noise): `normalize(n − (grad − (grad·n) n))`, i.e. `n` minus the surface gradient.
/// Equal to [`perturb_normal`] with `dhdu = grad·dpdu`, `dhdv = grad·dpdv`, but needs no uv
/// derivatives. Returns `n` bit-identical for a zero gradient, and `n` for a non-finite result.
#[must_use]
pub fn perturb_normal_by_gradient(n: Vec3, grad: Vec3) -> Vec3 {
    if grad == Vec3::ZERO {
        return n;
    }
    let surface_grad = grad - n * n.dot(grad);
    let out = (n - surface_grad).normalize();
    if out.is_finite() { out } else { n }
}

crate::key_hash_struct!(HeightMap { mip, depth, tile });

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::MipMap;

    /// 32×32 ramp: texel (i, j) = 0.01 i + 0.02 j, so in texture uv the height is
    /// 0.01·(32u − ½) + 0.02·(32v − ½) away from the wrap seam: slopes 0.32 and 0.64.
    fn ramp(depth: f32, tile: Vec2) -> HeightMap {
        let texels = (0..32 * 32)
            .map(|k| 0.01 * (k % 32) as f32 + 0.02 * (k / 32) as f32)
            .collect();
        HeightMap::new(MipMap::new(32, 32, texels).unwrap(), depth, tile)
    }

    #[test]
    fn ramp_gradient_includes_depth_and_tiling() {
        let hm = ramp(0.5, Vec2::new(2.0, 3.0));
        let expect = Vec2::new(0.5 * 0.32 * 2.0, 0.5 * 0.64 * 3.0); // (0.32, 0.96)
        let mut rng = crate::sampling::Rng::new(5, 1);
        for _ in 0..200 {
            // Texture uv within [0.1, 0.9], away from the seam.
            let uv = Vec2::new(
                0.05 + 0.4 * rng.next_f32(),
                (0.1 + 0.8 * rng.next_f32()) / 3.0,
            );
            let g = hm.gradient(uv, 1e-4);
            assert!((g - expect).abs().max_element() < 1e-3, "{uv} {g}");
        }
        // Height: at texture uv (0.5, 0.5) → 0.5·(0.01·15.5 + 0.02·15.5) = 0.2325.
        let h = hm.height(Vec2::new(0.25, 0.5 / 3.0), 1e-4);
        assert!((h - 0.2325).abs() < 1e-5, "{h}");
    }

    #[test]
    fn ramp_tilts_axis_aligned_faces_analytically() {
        let hm = ramp(0.25, Vec2::ONE);
        let uv = Vec2::new(0.4, 0.6);
        let g = hm.gradient(uv, 0.0);
        assert!(
            (g - Vec2::new(0.08, 0.16)).abs().max_element() < 1e-4,
            "{g}"
        );
        // Every axis-aligned face, with both handednesses of (dpdu, dpdv).
        let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
        for n in axes {
            for dpdu in axes.into_iter().filter(|a| a.dot(n) == 0.0) {
                for dpdv in axes
                    .into_iter()
                    .filter(|a| a.dot(n) == 0.0 && a.dot(dpdu) == 0.0)
                {
                    let got = hm.perturb(n, dpdu, dpdv, uv, 0.0);
                    // In the (dpdu, dpdv, n) frame: normalize(−h_u, −h_v, 1) = (−0.08, −0.16, 1)/|·|.
                    let want = (n - 0.08 * dpdu - 0.16 * dpdv).normalize();
                    assert!(
                        got.distance(want) < 1e-3,
                        "{n} {dpdu} {dpdv}: {got} vs {want}"
                    );
                    assert!((got.length() - 1.0).abs() < 1e-6);
                    // Scaling the parametrisation by 2 halves the tilt (h_u is per uv unit).
                    let half = perturb_normal(n, 2.0 * dpdu, 2.0 * dpdv, g.x, g.y);
                    let want = (n - 0.04 * dpdu - 0.08 * dpdv).normalize();
                    assert!(half.distance(want) < 1e-3, "{half} vs {want}");
                }
            }
        }
    }

    #[test]
    fn zero_derivatives_return_n_bit_identical() {
        let n = Vec3::new(0.3, -0.5, 0.7).normalize();
        for (hu, hv) in [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0)] {
            let out = perturb_normal(n, Vec3::X, Vec3::Y, hu, hv);
            assert_eq!(
                out.to_array().map(f32::to_bits),
                n.to_array().map(f32::to_bits)
            );
        }
        let out = perturb_normal_by_gradient(n, Vec3::ZERO);
        assert_eq!(
            out.to_array().map(f32::to_bits),
            n.to_array().map(f32::to_bits)
        );
        // A flat height map gives exactly zero derivatives, hence n itself.
        let flat = HeightMap::new(MipMap::new(4, 4, vec![0.7; 16]).unwrap(), 2.0, Vec2::ONE);
        let out = flat.perturb(n, Vec3::X, Vec3::Y, Vec2::new(0.3, 0.9), 0.01);
        assert_eq!(
            out.to_array().map(f32::to_bits),
            n.to_array().map(f32::to_bits)
        );
    }

    #[test]
    fn degenerate_tangents_fall_back_to_a_frame_without_nan() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(1.0, 2.0, -3.0).normalize(),
        ] {
            let cases = [
                (Vec3::ZERO, Vec3::ZERO),
                (Vec3::ZERO, Vec3::Y),
                (Vec3::X, Vec3::X),
                (n, 2.0 * n),
                (Vec3::splat(f32::NAN), Vec3::Y),
                (Vec3::splat(f32::INFINITY), Vec3::Y),
            ];
            for (du, dv) in cases {
                let out = perturb_normal(n, du, dv, 0.3, -0.2);
                assert!(
                    out.is_finite() && (out.length() - 1.0).abs() < 1e-5,
                    "{du} {dv}"
                );
                let f = Frame::from_normal(n);
                let want = (n - 0.3 * f.s + 0.2 * f.t).normalize();
                assert!(out.distance(want) < 1e-5, "{n} {du} {dv}: {out} vs {want}");
            }
            assert_eq!(perturb_normal(n, Vec3::X, Vec3::Y, f32::NAN, 0.0), n);
        }
    }

    #[test]
    fn uv_and_solid_gradient_forms_agree_on_skewed_tangents() {
        let mut rng = crate::sampling::Rng::new(9, 9);
        let mut r3 = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        for _ in 0..500 {
            let n = r3().normalize();
            // Tangents in the plane of n, skewed and scaled, either handedness.
            let (a, b) = (r3(), r3());
            let dpdu = a - n * n.dot(a);
            let dpdv = b - n * n.dot(b);
            if dpdu.cross(dpdv).length() < 1e-2 {
                continue;
            }
            let grad = r3();
            let via_uv = perturb_normal(n, dpdu, dpdv, grad.dot(dpdu), grad.dot(dpdv));
            let via_grad = perturb_normal_by_gradient(n, grad);
            assert!(via_uv.distance(via_grad) < 1e-4, "{via_uv} vs {via_grad}");
            assert!(via_uv.dot(n) > 0.0);
        }
    }
}
