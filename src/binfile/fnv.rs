//! FNV-1a, 64 bits (Fowler, Noll and Vo): the hash of cache keys, settings hashes and file
//! checksums. It detects accidents (truncation, corruption, a changed scene), not adversaries.

use glam::Vec3;

/// FNV-1a, 64 bits, fed incrementally; [`Fnv::finish`] is the hash of everything fed so far.
/// Numbers are fed as their little-endian bytes, floats as their bit patterns.
#[derive(Debug, Clone, Copy)]
pub struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Self::new()
    }
}

impl Fnv {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    /// The hash of nothing (the FNV offset basis).
    #[must_use]
    pub fn new() -> Self {
        Self(Self::OFFSET)
    }

    /// Feeds `bytes`.
    #[inline]
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(Self::PRIME);
        }
    }

    /// Feeds `v`'s four little-endian bytes.
    pub fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }

    /// Feeds `v`'s eight little-endian bytes.
    pub fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }

    /// Feeds `v`'s bit pattern (so `-0.0` and `0.0`, or two NaNs, hash differently).
    pub fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }

    /// Feeds `v`'s three components as [`Fnv::f32`].
    pub fn vec3(&mut self, v: Vec3) {
        for c in v.to_array() {
            self.f32(c);
        }
    }

    /// The hash of everything fed so far.
    #[must_use]
    pub fn finish(&self) -> u64 {
        self.0
    }
}

/// The FNV-1a 64 hash of `bytes` (a file's checksum).
#[must_use]
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h = Fnv::new();
    h.bytes(bytes);
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_published_fnv1a_64_test_vectors() {
        // Landon Curt Noll's FNV test suite: "", "a" and "foobar".
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn incremental_feeding_is_the_hash_of_the_concatenated_bytes() {
        let mut h = Fnv::new();
        h.bytes(b"tag");
        h.u32(7);
        h.u64(1 << 40);
        h.f32(-0.5);
        h.vec3(Vec3::new(1.0, 2.0, 3.0));
        h.str("dx");
        let mut all = b"tag".to_vec();
        all.extend(7u32.to_le_bytes());
        all.extend((1u64 << 40).to_le_bytes());
        all.extend((-0.5f32).to_bits().to_le_bytes());
        for c in [1.0f32, 2.0, 3.0] {
            all.extend(c.to_bits().to_le_bytes());
        }
        all.extend(2u64.to_le_bytes());
        all.extend(b"dx");
        assert_eq!(h.finish(), fnv1a(&all));
    }
}
