//! Farm shards: "shard i of N" as a contiguous range of sample indices. Every shard covers the
//! whole image (a set of samples per pixel, never a set of tiles), so a shard that fails or is
//! late lowers the sample count of the merged image and never leaves a hole; the ranges of the
//! N shards partition `0..S` exactly, so merging all of them gives the bytes of one render
//! ([`crate::render::PixelSums::merge`] is exact).

use std::ops::Range;

/// Why a shard specification or its sample range is unusable.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShardError {
    /// Not of the form `i/N` with integers.
    #[error(
        "--shard `{0}`: expected `i/N` with whole numbers 1 ≤ i ≤ N (shard i of N), e.g. `--shard 3/16`"
    )]
    Syntax(String),
    /// `i` is 0 or larger than `N`, or `N` is 0.
    #[error("--shard `{0}`: shards are numbered 1 to N, so i must be between 1 and N (N ≥ 1)")]
    OutOfRange(String),
    /// More shards than samples per pixel: some shard would take no sample.
    #[error(
        "{count} shards of {spp} samples per pixel: some shards would get no sample; use at most {spp} shards or raise --spp to at least {count}"
    )]
    Empty {
        /// Shards in all.
        count: u32,
        /// Samples per pixel of the whole render.
        spp: u32,
    },
}

/// Shard `index` of `count` (1-based: `1 ≤ index ≤ count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which shard, from 1.
    pub index: u32,
    /// How many shards in all.
    pub count: u32,
}

impl Shard {
    /// Parses `i/N` (spaces around the numbers are allowed).
    ///
    /// # Errors
    /// [`ShardError::Syntax`] when it is not two whole numbers around a `/`;
    /// [`ShardError::OutOfRange`] when `N` is 0 or `i` is not in `1..=N`.
    pub fn parse(text: &str) -> Result<Self, ShardError> {
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| ShardError::Syntax(text.to_string()))?;
        let (Ok(index), Ok(count)) = (i.trim().parse::<u32>(), n.trim().parse::<u32>()) else {
            return Err(ShardError::Syntax(text.to_string()));
        };
        if count == 0 || index == 0 || index > count {
            return Err(ShardError::OutOfRange(text.to_string()));
        }
        Ok(Self { index, count })
    }

    /// The sample indices of this shard when the whole render takes `spp` samples per pixel:
    /// `[⌊(i−1)·S/N⌋, ⌊i·S/N⌋)`, so shard sizes differ by at most one and the N ranges tile
    /// `0..S` in order.
    ///
    /// # Errors
    /// [`ShardError::Empty`] when there are more shards than samples (`N > S`): some shard
    /// (maybe not this one) would be empty, so the set of shards is refused whichever is asked.
    /// With `N ≤ S` every range holds at least ⌊S/N⌋ ≥ 1 samples.
    pub fn samples(self, spp: u32) -> Result<Range<u32>, ShardError> {
        if self.count > spp {
            return Err(ShardError::Empty {
                count: self.count,
                spp,
            });
        }
        let bound = |i: u32| (u64::from(i) * u64::from(spp) / u64::from(self.count)) as u32;
        Ok(bound(self.index - 1)..bound(self.index))
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_i_of_n_and_refuses_the_rest() {
        assert_eq!(
            Shard::parse("3/16"),
            Ok(Shard {
                index: 3,
                count: 16
            })
        );
        assert_eq!(
            Shard::parse(" 1 / 1 ").map(|s| s.to_string()),
            Ok("1/1".into())
        );
        for bad in ["", "3", "3/", "/4", "a/4", "3/b", "-1/4", "1.5/4", "1/2/3"] {
            assert_eq!(
                Shard::parse(bad),
                Err(ShardError::Syntax(bad.into())),
                "{bad}"
            );
        }
        for bad in ["0/4", "5/4", "0/0", "1/0"] {
            assert_eq!(
                Shard::parse(bad),
                Err(ShardError::OutOfRange(bad.into())),
                "{bad}"
            );
        }
    }

    /// Every sample index of `0..S` falls in exactly one shard, shards are in order and their
    /// sizes differ by at most one, for every S ≤ 70 and N ≤ S (a brute-force count).
    #[test]
    fn shards_cover_every_sample_exactly_once() {
        for spp in 1..=70u32 {
            for count in 1..=spp {
                let mut hits = vec![0u32; spp as usize];
                let mut sizes = Vec::new();
                let mut next = 0;
                for index in 1..=count {
                    let r = Shard { index, count }.samples(spp).expect("non-empty");
                    assert_eq!(r.start, next, "S={spp} N={count} i={index}");
                    next = r.end;
                    sizes.push(r.len());
                    for s in r {
                        hits[s as usize] += 1;
                    }
                }
                assert!(hits.iter().all(|&h| h == 1), "S={spp} N={count}: {hits:?}");
                let (lo, hi) = (sizes.iter().min(), sizes.iter().max());
                assert!(hi.zip(lo).is_some_and(|(h, l)| h - l <= 1), "{sizes:?}");
            }
        }
    }

    #[test]
    fn more_shards_than_samples_is_an_error_naming_the_fix() {
        // S = 3, N = 4: ⌊0·3/4⌋ = 0 = ⌊1·3/4⌋, so shard 1 would be empty; shard 2 (0..1)
        // is refused too, since the set of four shards cannot be rendered.
        for index in 1..=4 {
            let e = Shard { index, count: 4 }.samples(3).unwrap_err();
            assert_eq!(e, ShardError::Empty { count: 4, spp: 3 });
            assert!(e.to_string().contains("at most 3 shards"), "{e}");
        }
        assert_eq!(Shard { index: 3, count: 3 }.samples(3), Ok(2..3));
        // Large counts do not overflow: the bounds are computed in 64 bits.
        let big = Shard {
            index: u32::MAX,
            count: u32::MAX,
        };
        assert_eq!(big.samples(u32::MAX), Ok(u32::MAX - 1..u32::MAX));
    }
}
