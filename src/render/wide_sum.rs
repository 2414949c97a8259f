//! A 384-bit two's-complement integer for the film's sums of samples too large for its 128-bit
//! fixed-point sums ([`super::PixelSums`]): any finite f32 sample, and its square, at the film's
//! fixed-point scales, summed over 2³² samples, fits without rounding or saturation, so those
//! sums stay exact and independent of the order of addition (the same bytes for any thread
//! count) whatever the radiance.

/// Little-endian 64-bit limbs.
const LIMBS: usize = 6;

/// A signed 384-bit integer (two's complement, little-endian limbs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WideSum([u64; LIMBS]);

impl WideSum {
    /// Bytes of [`WideSum::to_le_bytes`].
    pub const BYTES: usize = 8 * LIMBS;

    /// The value `v`.
    #[must_use]
    pub fn from_i128(v: i128) -> Self {
        let fill = if v < 0 { u64::MAX } else { 0 };
        let mut l = [fill; LIMBS];
        l[0] = v as u64;
        l[1] = (v >> 64) as u64;
        Self(l)
    }

    /// The integer `x` (finite and integral: |x| ≥ 2⁵³, or a whole number, as the film's scaled
    /// large samples are). A fractional part is dropped towards zero.
    #[must_use]
    pub fn from_integral_f64(x: f64) -> Self {
        let bits = x.abs().to_bits();
        let exponent = ((bits >> 52) & 0x7ff) as i32;
        if exponent == 0 || !x.is_finite() {
            return Self::default();
        }
        let mantissa = (bits & ((1 << 52) - 1)) | (1 << 52);
        // |x| = mantissa · 2^(exponent − 1075).
        let shift = exponent - 1075;
        let mut l = [0u64; LIMBS];
        if shift < 0 {
            l[0] = mantissa >> (-shift).min(63);
        } else {
            let (limb, bit) = ((shift / 64) as usize, (shift % 64) as u32);
            if limb < LIMBS {
                l[limb] = mantissa << bit;
            }
            if bit > 0 && limb + 1 < LIMBS {
                l[limb + 1] = mantissa >> (64 - bit);
            }
        }
        let v = Self(l);
        if x < 0.0 { v.negated() } else { v }
    }

    fn negated(self) -> Self {
        let mut l = self.0.map(|w| !w);
        for w in &mut l {
            let (s, carry) = w.overflowing_add(1);
            *w = s;
            if !carry {
                break;
            }
        }
        Self(l)
    }

    fn is_negative(self) -> bool {
        self.0[LIMBS - 1] >> 63 == 1
    }

    /// The value as an `i128`, if it fits.
    #[must_use]
    pub fn to_i128(self) -> Option<i128> {
        let low = (u128::from(self.0[1]) << 64 | u128::from(self.0[0])) as i128;
        let fill = if low < 0 { u64::MAX } else { 0 };
        self.0[2..].iter().all(|&w| w == fill).then_some(low)
    }

    /// The nearest f64 (exactly `i128 as f64` when the value fits an i128; else the top 128
    /// significant bits with a sticky bit for the rest, correctly rounded).
    #[must_use]
    pub fn to_f64(self) -> f64 {
        if let Some(v) = self.to_i128() {
            return v as f64;
        }
        let negative = self.is_negative();
        let m = if negative { self.negated() } else { self }.0;
        let top = (0..LIMBS).rev().find(|&i| m[i] != 0).unwrap_or(0);
        let lead = m[top].leading_zeros();
        // The 128 bits from the leading one down, and whether any bit below them is set.
        let bit = |i: i64| -> u128 {
            if i < 0 {
                return 0;
            }
            let (limb, b) = ((i / 64) as usize, (i % 64) as u32);
            u128::from((m[limb] >> b) & 1)
        };
        let msb = top as i64 * 64 + 63 - i64::from(lead);
        let mut head = 0u128;
        for i in 0..128 {
            head = head << 1 | bit(msb - i);
        }
        let sticky = (0..(msb - 127).max(0)).any(|i| bit(i) == 1);
        let v = (head | u128::from(sticky)) as f64 * 2f64.powi((msb - 127) as i32);
        if negative { -v } else { v }
    }

    /// Little-endian bytes.
    #[must_use]
    pub fn to_le_bytes(self) -> [u8; Self::BYTES] {
        let mut out = [0u8; Self::BYTES];
        for (chunk, w) in out.chunks_exact_mut(8).zip(self.0) {
            chunk.copy_from_slice(&w.to_le_bytes());
        }
        out
    }

    /// The value of [`WideSum::to_le_bytes`]'s bytes.
    #[must_use]
    pub fn from_le_bytes(bytes: [u8; Self::BYTES]) -> Self {
        let mut l = [0u64; LIMBS];
        for (w, chunk) in l.iter_mut().zip(bytes.chunks_exact(8)) {
            let mut b = [0u8; 8];
            b.copy_from_slice(chunk);
            *w = u64::from_le_bytes(b);
        }
        Self(l)
    }
}

impl std::ops::Add for WideSum {
    type Output = Self;

    /// `self + other`, exact (wrapping only past ±2³⁸³, which film sums never reach).
    fn add(self, other: Self) -> Self {
        let mut out = [0u64; LIMBS];
        let mut carry = false;
        for (o, (a, b)) in out.iter_mut().zip(self.0.iter().zip(other.0)) {
            let (s1, c1) = a.overflowing_add(b);
            let (s2, c2) = s1.overflowing_add(u64::from(carry));
            *o = s2;
            carry = c1 || c2;
        }
        Self(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_values_round_trip_through_i128() {
        for v in [0i128, 1, -1, 42, -1 << 100, i128::MAX, i128::MIN] {
            let w = WideSum::from_i128(v);
            assert_eq!(w.to_i128(), Some(v));
            assert_eq!(w.to_f64(), v as f64);
            assert_eq!(WideSum::from_le_bytes(w.to_le_bytes()), w);
        }
        assert_eq!(
            (WideSum::from_i128(i128::MAX) + WideSum::from_i128(1)).to_i128(),
            None
        );
    }

    #[test]
    fn large_values_are_exact_and_convert_back() {
        // 1e30 radiance at the film's 2⁶⁴ scale, and f32::MAX squared at 2³²: each integral.
        for x in [
            1e30 * 2f64.powi(64),
            -1e30 * 2f64.powi(64),
            f64::from(f32::MAX) * f64::from(f32::MAX) * 2f64.powi(32),
            2f64.powi(94),
            3.0,
        ] {
            let w = WideSum::from_integral_f64(x);
            assert_eq!(w.to_f64(), x, "{x}");
            // 2³² copies add up exactly (x · 2³² is exact in f64 too).
            let mut sum = WideSum::default();
            let mut add = w;
            for _ in 0..32 {
                add = add + add;
            }
            sum = sum + add;
            assert_eq!(sum.to_f64(), x * 2f64.powi(32), "{x}");
        }
        // Order does not matter, and opposite values cancel exactly.
        let (a, b) = (
            WideSum::from_integral_f64(1e40),
            WideSum::from_integral_f64(-1e40),
        );
        let c = WideSum::from_i128(7);
        assert_eq!(a + b + c, c + b + a);
        assert_eq!((a + b + c).to_i128(), Some(7));
    }

    #[test]
    fn conversion_rounds_like_the_exact_value() {
        // 2¹³⁰ + 1: the nearest f64 is 2¹³⁰; 2¹³⁰ + 2⁷⁷ + 1 rounds up past the tie.
        let big = WideSum::from_integral_f64(2f64.powi(130));
        let one = WideSum::from_i128(1);
        assert_eq!((big + one).to_f64(), 2f64.powi(130));
        let tie = WideSum::from_integral_f64(2f64.powi(77));
        let up = (big + tie + one).to_f64();
        assert_eq!(up, 2f64.powi(130) + 2f64.powi(78));
    }
}
