//! The stored photon and its packing: 24 bytes per photon (position as three `f32`, power as
//! shared-exponent RGB, incident direction and surface normal as 16-bit octahedral pairs).
//!
//! - Directions use the octahedral map of Meyer, Sander, Bálint, Cigolle & Lengyel, "On
//!   floating-point normal vectors" (EGSR 2010), surveyed by Cigolle et al., "A Survey of
//!   Efficient Representations for Independent Unit Vectors" (JCGT 3(2), 2014): the unit vector is
//!   projected onto the octahedron `|x| + |y| + |z| = 1`, the lower half folded over the upper,
//!   and the resulting square `[-1, 1]²` quantised to 16 bits per coordinate (65535 levels, so
//!   0 and the axes are exact). The angular error is at most `asin(√18 / 65534) ≈ 6.5·10⁻⁵` rad
//!   (0.0037°): rounding each coordinate by at most `δ = 1/65534` moves the octahedron point by
//!   at most `δ√6`, and that point's length is at least `1/√3`.
//! - Power uses Ward's shared-exponent RGBE ("Real Pixels", Graphics Gems II, 1991) with rounding
//!   to nearest: three 8-bit mantissas and one 8-bit exponent. Each channel is within
//!   `max(r, g, b) / 255` of its value; the error is unbiased, so it averages out over the tens
//!   or hundreds of photons a density estimate sums.

use glam::Vec3;

use super::kdtree::HasPosition;

/// One photon as the photon map stores it: where it landed, the direction it travelled when it
/// arrived, the geometric normal of the surface it landed on, and its power (flux, watts per RGB
/// channel). 24 bytes; see the module documentation for the encodings and their errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(C)]
pub struct Photon {
    /// World-space position, bit for bit as given (only directions and power are quantised).
    position: [u32; 3],
    /// Power as RGBE (see [`encode_rgbe`]).
    power: u32,
    /// Direction of travel on arrival, octahedral (see [`encode_octahedral`]).
    direction: u32,
    /// Geometric surface normal at the landing point, octahedral.
    normal: u32,
}

impl Photon {
    /// Packs a photon. `direction` and `normal` need not be normalised (a zero or non-finite
    /// vector is stored as +z); `power` components that are negative or NaN are stored as 0.
    #[must_use]
    pub fn new(position: Vec3, direction: Vec3, normal: Vec3, power: Vec3) -> Self {
        Self {
            position: position.to_array().map(f32::to_bits),
            power: encode_rgbe(power.to_array()),
            direction: encode_octahedral(direction),
            normal: encode_octahedral(normal),
        }
    }

    /// World-space position, exactly as given to [`Photon::new`].
    #[inline]
    #[must_use]
    pub fn position(&self) -> Vec3 {
        Vec3::from_array(self.position.map(f32::from_bits))
    }

    /// Unit direction the photon was travelling when it landed (pointing into the surface).
    #[inline]
    #[must_use]
    pub fn direction(&self) -> Vec3 {
        decode_octahedral(self.direction)
    }

    /// Unit geometric normal of the surface the photon landed on.
    #[inline]
    #[must_use]
    pub fn normal(&self) -> Vec3 {
        decode_octahedral(self.normal)
    }

    /// Power (flux) per RGB channel, in watts.
    #[inline]
    #[must_use]
    pub fn power(&self) -> Vec3 {
        Vec3::from_array(decode_rgbe(self.power))
    }
}

impl Photon {
    /// The packed record as six words (position bits x, y, z, power, direction, normal), for
    /// storing photon maps on disk losslessly.
    #[must_use]
    pub fn to_words(&self) -> [u32; 6] {
        let [x, y, z] = self.position;
        [x, y, z, self.power, self.direction, self.normal]
    }

    /// The photon whose [`Photon::to_words`] is `w` (any words make a photon; positions are
    /// checked by the kd-tree).
    #[must_use]
    pub fn from_words(w: [u32; 6]) -> Self {
        Self {
            position: [w[0], w[1], w[2]],
            power: w[3],
            direction: w[4],
            normal: w[5],
        }
    }
}

impl HasPosition for Photon {
    #[inline]
    fn position(&self) -> [f32; 3] {
        self.position.map(f32::from_bits)
    }
}

/// The square `[-1, 1]` maps onto codes `0 ..= Q`: an even `Q` puts 0 on a code, so the axes
/// (and with them the most common normals) are exact. Code 65535 is unused (decodes as 65534).
const Q: f32 = 65534.0;

/// `±1` with the sign of `x`, taking `+1` for both zeros (the octahedral fold needs a side).
#[inline]
fn sign_not_zero(x: f32) -> f32 {
    if x < 0.0 { -1.0 } else { 1.0 }
}

/// Packs a direction into 32 bits with the octahedral map (x in the low 16 bits, y in the high),
/// rounding each coordinate to the nearest code. Zero-length or non-finite input encodes +z.
#[must_use]
pub fn encode_octahedral(v: Vec3) -> u32 {
    let l1 = v.x.abs() + v.y.abs() + v.z.abs();
    let (mut x, mut y) = if l1 > 0.0 && l1.is_finite() {
        (v.x / l1, v.y / l1)
    } else {
        (0.0, 0.0)
    };
    if l1 > 0.0 && l1.is_finite() && v.z < 0.0 {
        (x, y) = (
            (1.0 - y.abs()) * sign_not_zero(x),
            (1.0 - x.abs()) * sign_not_zero(y),
        );
    }
    let q = |c: f32| ((c.clamp(-1.0, 1.0) * 0.5 + 0.5) * Q).round() as u32;
    q(x) | (q(y) << 16)
}

/// Unpacks an [`encode_octahedral`] word into a unit vector.
#[must_use]
pub fn decode_octahedral(code: u32) -> Vec3 {
    let d = |c: u32| ((c & 0xFFFF) as f32 * (2.0 / Q) - 1.0).min(1.0);
    let (x, y) = (d(code), d(code >> 16));
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z < 0.0 {
        (
            (1.0 - y.abs()) * sign_not_zero(x),
            (1.0 - x.abs()) * sign_not_zero(y),
        )
    } else {
        (x, y)
    };
    // Never zero: on the octahedron |x| + |y| + |z| = 1, so the length is at least 1/√3.
    Vec3::new(x, y, z).normalize()
}

/// Exponent bias of the RGBE word: stored exponent byte = `e + BIAS`.
const BIAS: i32 = 128;

/// Packs non-negative RGB into Ward's RGBE (red mantissa in the low byte, exponent in the high
/// byte), rounding to nearest. With `m = max(r, g, b)` and `m ∈ [2^(e−1), 2^e)`, channel `c` is
/// stored as `round(c · 2^(8−e))`. Negative and NaN components become 0; values below `2^-120`
/// are stored as 0 and values at or above `2^127` (including +∞) saturate.
#[must_use]
pub fn encode_rgbe(rgb: [f32; 3]) -> u32 {
    let c = rgb.map(|v| if v > 0.0 { f64::from(v) } else { 0.0 });
    let m = c[0].max(c[1]).max(c[2]);
    if !(m >= 2f64.powi(-120)) {
        return 0;
    }
    let m = m.min(2f64.powi(127) * (255.0 / 256.0));
    // m ∈ [2^(e−1), 2^e): e = floor(log2 m) + 1, exact from the f64 exponent field.
    let mut e = ((m.to_bits() >> 52) & 0x7FF) as i32 - 1022;
    if (m * 2f64.powi(8 - e)).round() >= 256.0 {
        e += 1;
    }
    let scale = 2f64.powi(8 - e);
    let mant = c.map(|v| ((v.min(m) * scale).round() as u32).min(255));
    mant[0] | (mant[1] << 8) | (mant[2] << 16) | (((e + BIAS) as u32) << 24)
}

/// Unpacks an [`encode_rgbe`] word.
#[must_use]
pub fn decode_rgbe(code: u32) -> [f32; 3] {
    let e = (code >> 24) as i32 - BIAS;
    if code >> 24 == 0 {
        return [0.0; 3];
    }
    let scale = 2f64.powi(e - 8);
    [0, 8, 16].map(|s| (f64::from((code >> s) & 0xFF) * scale) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// Angle between two vectors in f64 (atan2 of |a×b| and a·b: accurate at small angles).
    fn angle(a: Vec3, b: Vec3) -> f64 {
        let (a, b) = (a.as_dvec3(), b.as_dvec3());
        a.cross(b).length().atan2(a.dot(b))
    }

    fn random_unit(r: &mut Rng) -> Vec3 {
        let z = 2.0 * r.next_f32() - 1.0;
        let phi = std::f32::consts::TAU * r.next_f32();
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    }

    #[test]
    fn octahedral_error_is_within_the_derived_bound() {
        // Bound from the module docs: asin(√18 δ), δ = 1/65534, plus f32 rounding slack.
        let bound = (18f64.sqrt() / 65534.0).asin() + 2e-6;
        let mut r = Rng::new(3, 0);
        let mut worst = 0f64;
        let mut dirs: Vec<Vec3> = (0..200_000).map(|_| random_unit(&mut r)).collect();
        // The hard places: axes, the fold's seams and octant corners.
        for s in [-1.0f32, 1.0] {
            dirs.extend([Vec3::X * s, Vec3::Y * s, Vec3::Z * s]);
            dirs.push(Vec3::new(s, 1.0, -1e-7).normalize());
            dirs.push(Vec3::new(1.0, s, -1.0).normalize());
            dirs.push(Vec3::new(1e-7, s, -1.0).normalize());
        }
        for v in dirs {
            let e = angle(v, decode_octahedral(encode_octahedral(v)));
            worst = worst.max(e);
            assert!(e <= bound, "{v:?}: error {e} rad > bound {bound}");
        }
        // The quantisation really is 16-bit, not finer: the worst error is a sizeable part of
        // the bound (a coarser or broken encoding fails the bound; an unquantised one fails this).
        assert!(worst > 0.2 * bound, "worst {worst} rad, bound {bound}");
        eprintln!("octahedral: worst error {worst:.3e} rad, bound {bound:.3e}");
    }

    #[test]
    fn octahedral_decodes_to_unit_vectors_and_handles_degenerate_input() {
        for code in [
            0u32,
            0xFFFF_FFFF,
            0x7FFF_7FFF,
            0x0000_FFFF,
            0xFFFF_0000,
            12345,
        ] {
            assert!((decode_octahedral(code).length() - 1.0).abs() < 1e-6);
        }
        for v in [Vec3::ZERO, Vec3::NAN, Vec3::splat(f32::INFINITY)] {
            assert_eq!(decode_octahedral(encode_octahedral(v)), Vec3::Z);
        }
        // Length does not matter.
        let v = Vec3::new(0.3, -0.4, -0.5);
        assert_eq!(encode_octahedral(v), encode_octahedral(v * 1000.0));
    }

    #[test]
    fn rgbe_error_is_within_a_255th_of_the_largest_channel() {
        let mut r = Rng::new(5, 1);
        let mut worst = 0f64;
        for i in 0..200_000 {
            // Magnitudes over 60 octaves, channels from equal to very unequal.
            let scale = 2f32.powf(r.next_f32() * 60.0 - 40.0);
            let mut c = [r.next_f32(), r.next_f32(), r.next_f32()].map(|x| x * scale);
            if i % 7 == 0 {
                c[i % 3] = 0.0;
            }
            let d = decode_rgbe(encode_rgbe(c));
            let m = f64::from(c[0].max(c[1]).max(c[2]));
            for ch in 0..3 {
                let err = (f64::from(d[ch]) - f64::from(c[ch])).abs();
                worst = worst.max(err / m);
                assert!(err <= m / 255.0, "{c:?} → {d:?}");
            }
        }
        assert!(worst > 1.0 / 1024.0, "8-bit mantissas should show: {worst}");
    }

    #[test]
    fn rgbe_is_exact_on_representable_values_and_unbiased_on_average() {
        // Values with ≤ 8 significant bits relative to the top channel round-trip exactly.
        for c in [
            [1.0, 0.5, 0.25],
            [255.0, 1.0, 0.0],
            [0.0; 3],
            [3.0, 3.0, 3.0],
        ] {
            assert_eq!(decode_rgbe(encode_rgbe(c)), c);
        }
        // Rounding to nearest: the mean error of a channel over many photons is far below the
        // per-photon bound (truncation would bias it by about half a step, 1/512 of the top).
        let mut r = Rng::new(9, 2);
        let (mut sum, mut sum_err) = (0f64, 0f64);
        for _ in 0..100_000 {
            let c = [1.0, r.next_f32(), r.next_f32()];
            let d = decode_rgbe(encode_rgbe(c));
            sum += f64::from(c[1]);
            sum_err += f64::from(d[1]) - f64::from(c[1]);
        }
        assert!((sum_err / sum).abs() < 1e-4, "bias {}", sum_err / sum);
    }

    #[test]
    fn rgbe_clamps_what_is_not_a_power() {
        assert_eq!(
            decode_rgbe(encode_rgbe([-1.0, f32::NAN, 2.0])),
            [0.0, 0.0, 2.0]
        );
        assert_eq!(decode_rgbe(encode_rgbe([1e-38, 0.0, 0.0])), [0.0; 3]);
        let big = decode_rgbe(encode_rgbe([f32::INFINITY, 1.0, 0.0]));
        assert!(big[0].is_finite() && big[0] > 1e38, "{big:?}");
    }

    #[test]
    fn photon_is_24_bytes_and_round_trips() {
        assert_eq!(std::mem::size_of::<Photon>(), 24);
        let p = Photon::new(
            Vec3::new(1.5, -2.25, 1e-30),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::Y,
            Vec3::new(0.5, 0.25, 0.125),
        );
        assert_eq!(p.position(), Vec3::new(1.5, -2.25, 1e-30));
        assert_eq!(HasPosition::position(&p), [1.5, -2.25, 1e-30]);
        assert!(angle(p.direction(), -Vec3::Y) < 1e-6);
        assert!(angle(p.normal(), Vec3::Y) < 1e-6);
        assert_eq!(p.power(), Vec3::new(0.5, 0.25, 0.125));
        let w = p.to_words();
        assert_eq!(
            w[..3],
            [1.5f32.to_bits(), (-2.25f32).to_bits(), 1e-30f32.to_bits()]
        );
        assert_eq!(w[3], encode_rgbe([0.5, 0.25, 0.125]));
        assert_eq!(w[4], encode_octahedral(-Vec3::Y));
        assert_eq!(Photon::from_words(w), p);
    }
}
