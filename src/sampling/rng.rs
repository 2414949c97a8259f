//! A small, fast, seedable generator whose streams are keyed by what they sample (pixel and
//! sample index, photon index), never by thread, so images do not depend on scheduling.

/// SplitMix64 finaliser: a bijective 64-bit hash.
#[inline]
#[must_use]
pub const fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// PCG32 (XSH-RR) generator.
#[derive(Debug, Clone)]
pub struct Rng {
    state: u64,
    inc: u64,
}

impl Rng {
    /// A stream identified by `(seed, key)`; distinct keys give independent-looking streams.
    #[must_use]
    pub fn new(seed: u64, key: u64) -> Self {
        let mut r = Self {
            state: 0,
            inc: (mix64(key ^ 0xDA94_2042_E4DD_58B5) << 1) | 1,
        };
        r.next_u32();
        r.state = r
            .state
            .wrapping_add(mix64(seed.wrapping_add(key.rotate_left(32))));
        r.next_u32();
        r
    }

    /// The stream of camera sample `sample` of pixel `(x, y)`.
    #[must_use]
    pub fn for_pixel_sample(seed: u64, x: u32, y: u32, sample: u32) -> Self {
        let pixel = (u64::from(y) << 32) | u64::from(x);
        Self::new(
            seed ^ mix64(u64::from(sample).wrapping_add(0x5851_F42D_4C95_7F2D)),
            pixel,
        )
    }

    /// Next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in `[0, 1)`.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Two uniforms in `[0, 1)`.
    #[inline]
    pub fn next_2d(&mut self) -> (f32, f32) {
        (self.next_f32(), self.next_f32())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u32> = (0..8)
            .map(|_| 0)
            .scan(Rng::for_pixel_sample(7, 3, 4, 0), |r, _| Some(r.next_u32()))
            .collect();
        let b: Vec<u32> = (0..8)
            .map(|_| 0)
            .scan(Rng::for_pixel_sample(7, 3, 4, 0), |r, _| Some(r.next_u32()))
            .collect();
        let c: Vec<u32> = (0..8)
            .map(|_| 0)
            .scan(Rng::for_pixel_sample(7, 4, 3, 0), |r, _| Some(r.next_u32()))
            .collect();
        let d: Vec<u32> = (0..8)
            .map(|_| 0)
            .scan(Rng::for_pixel_sample(8, 3, 4, 0), |r, _| Some(r.next_u32()))
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_ne!(a, d);
    }

    #[test]
    fn uniforms_are_in_range_and_roughly_uniform() {
        let mut r = Rng::new(1, 2);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let u = r.next_f32();
            assert!((0.0..1.0).contains(&u));
            sum += f64::from(u);
        }
        assert!((sum / f64::from(n) - 0.5).abs() < 0.005);
    }
}
