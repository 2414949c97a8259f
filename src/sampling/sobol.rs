//! The first two dimensions of the Sobol sequence and hash-based Owen scrambling
//! (B. Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020).
//!
//! Points are 32-bit fixed-point fractions (`x / 2³²`). Dimensions 0 and 1 of Sobol's sequence
//! form a (0, 2)-sequence in base 2: every aligned block of 2ᵏ consecutive points is a
//! (0, k, 2)-net, with exactly one point in each elementary box of area 2⁻ᵏ. Owen scrambling and
//! Burley's nested shuffle of the index both keep that property while randomising the points.

/// Generator matrix of Sobol dimension 1, as 32 column vectors (column j is the contribution of
/// index bit j, most significant output bit first).
///
/// Its primitive polynomial is x + 1 (degree 1, no inner coefficients) with initial direction
/// number m₁ = 1 (Joe & Kuo's first entry), so the recurrence mᵢ = 2mᵢ₋₁ ⊕ mᵢ₋₁ gives
/// m = 1, 3, 5, 15, 17, 51, … (Pascal's triangle mod 2), and column i−1 is mᵢ · 2^(32−i).
const SOBOL_DIM1: [u32; 32] = dim1_matrix();

const fn dim1_matrix() -> [u32; 32] {
    let mut columns = [0u32; 32];
    let mut m: u32 = 1;
    let mut i = 1;
    while i <= 32 {
        columns[i - 1] = m << (32 - i);
        m ^= m << 1;
        i += 1;
    }
    columns
}

/// Sobol dimension 0 of point `index`: the van der Corput radical inverse (bit reversal).
#[inline]
#[must_use]
pub fn sobol_dim0(index: u32) -> u32 {
    index.reverse_bits()
}

/// [`SOBOL_DIM1`] folded per index byte: entry `[b][v]` is the XOR of the columns of the set
/// bits of byte value `v` in byte `b` of the index (4 KiB), so a point costs four lookups
/// instead of a loop over up to 32 bits (the shuffled indices use all 32).
const SOBOL_DIM1_BYTES: [[u32; 256]; 4] = byte_tables(SOBOL_DIM1);

/// The map `t ↦ reverse(sobol_dim1(reverse(t)))` folded per byte of `t` like
/// [`SOBOL_DIM1_BYTES`]: it is linear over GF(2), with column `k` equal to the bit reversal of
/// generator column `31 − k`. [`shuffled_scrambled_2d_reversed`] uses it to skip two bit
/// reversals.
const SOBOL_DIM1_REVERSED_BYTES: [[u32; 256]; 4] = byte_tables(reversed_columns(SOBOL_DIM1));

/// The columns of `t ↦ reverse(M · reverse(t))` for the matrix `M` with `columns`.
const fn reversed_columns(columns: [u32; 32]) -> [u32; 32] {
    let mut r = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        r[k] = columns[31 - k].reverse_bits();
        k += 1;
    }
    r
}

/// A GF(2) matrix given by its 32 `columns` folded per byte of its input: entry `[b][v]` is
/// the XOR of the columns of the set bits of value `v` in byte `b`.
const fn byte_tables(columns: [u32; 32]) -> [[u32; 256]; 4] {
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut v = 0;
        while v < 256 {
            let mut x = 0;
            let mut j = 0;
            while j < 8 {
                if v & (1 << j) != 0 {
                    x ^= columns[b * 8 + j];
                }
                j += 1;
            }
            t[b][v] = x;
            v += 1;
        }
        b += 1;
    }
    t
}

/// Sobol dimension 1 of point `index`: the XOR of the generator columns of its set bits.
#[inline]
#[must_use]
pub fn sobol_dim1(index: u32) -> u32 {
    let [b0, b1, b2, b3] = index.to_le_bytes();
    SOBOL_DIM1_BYTES[0][b0 as usize]
        ^ SOBOL_DIM1_BYTES[1][b1 as usize]
        ^ SOBOL_DIM1_BYTES[2][b2 as usize]
        ^ SOBOL_DIM1_BYTES[3][b3 as usize]
}

/// The column-by-column definition of [`sobol_dim1`], for the test that the tables equal it.
#[cfg(test)]
fn sobol_dim1_by_columns(index: u32) -> u32 {
    let mut x = 0;
    let mut bits = index;
    let mut j = 0;
    while bits != 0 {
        if bits & 1 != 0 {
            x ^= SOBOL_DIM1[j];
        }
        bits >>= 1;
        j += 1;
    }
    x
}

/// Laine & Karras's hash as tuned by Burley (2020, listing 2): a bijection on 32-bit words in
/// which output bit k depends only on input bits 0..=k (adding a seed and XOR-ing with a
/// multiple by an even constant both have that property), so on bit-reversed values it is a
/// nested (Owen) permutation.
#[inline]
#[must_use]
fn laine_karras_permutation(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen scrambling of the fixed-point fraction `x` keyed by `seed`: each output bit is the input
/// bit flipped by a hash of all more significant input bits (a nested uniform scramble).
#[inline]
#[must_use]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras_permutation(x.reverse_bits(), seed).reverse_bits()
}

/// The fixed-point fraction `x / 2³²` as an `f32` in `[0, 1)` (top 24 bits, exact).
#[inline]
#[must_use]
pub fn to_unit_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Point `index` of a shuffled, Owen-scrambled 2-D Sobol sequence: Burley's construction. The
/// index itself is nested-uniform scrambled with `seeds[0]` (a random aligned block of the
/// sequence, in a random order that keeps prefixes of length 2ᵏ as nets), then dimensions 0 and
/// 1 are Owen-scrambled with `seeds[1]` and `seeds[2]`.
#[inline]
#[must_use]
pub fn shuffled_scrambled_2d(index: u32, seeds: [u32; 3]) -> (u32, u32) {
    let i = nested_uniform_scramble(index, seeds[0]);
    (
        nested_uniform_scramble(sobol_dim0(i), seeds[1]),
        nested_uniform_scramble(sobol_dim1(i), seeds[2]),
    )
}

/// [`shuffled_scrambled_2d`] of the index whose bit reversal is `reversed_index` (the same
/// two numbers), with the bit reversals that cancel left out: x86 has no instruction for them,
/// and the direct form makes seven. With `t` the Laine–Karras permutation of the reversed
/// index, the shuffled index is `reverse(t)`, so its dimension 0 is `t` itself and its
/// dimension 1, reversed, is a linear map of `t` ([`SOBOL_DIM1_REVERSED_BYTES`]), which is
/// what the Owen scramble of dimension 1 takes. Three reversals remain.
#[inline]
#[must_use]
pub fn shuffled_scrambled_2d_reversed(reversed_index: u32, seeds: [u32; 3]) -> (u32, u32) {
    let t = laine_karras_permutation(reversed_index, seeds[0]);
    let [b0, b1, b2, b3] = t.to_le_bytes();
    let y_reversed = SOBOL_DIM1_REVERSED_BYTES[0][b0 as usize]
        ^ SOBOL_DIM1_REVERSED_BYTES[1][b1 as usize]
        ^ SOBOL_DIM1_REVERSED_BYTES[2][b2 as usize]
        ^ SOBOL_DIM1_REVERSED_BYTES[3][b3 as usize];
    (
        laine_karras_permutation(t.reverse_bits(), seeds[1]).reverse_bits(),
        laine_karras_permutation(y_reversed, seeds[2]).reverse_bits(),
    )
}

/// The first coordinate of [`shuffled_scrambled_2d_reversed`] alone.
#[inline]
#[must_use]
pub fn shuffled_scrambled_1d_reversed(reversed_index: u32, seeds: [u32; 2]) -> u32 {
    let t = laine_karras_permutation(reversed_index, seeds[0]);
    laine_karras_permutation(t.reverse_bits(), seeds[1]).reverse_bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_tables_equal_the_generator_columns() {
        let mut r = crate::sampling::Rng::new(5, 6);
        for i in (0..4096u32)
            .chain((0..100_000).map(|_| r.next_u32()))
            .chain([u32::MAX])
        {
            assert_eq!(sobol_dim1(i), sobol_dim1_by_columns(i), "index {i}");
        }
    }

    #[test]
    fn direction_numbers_are_joe_kuo_dimension_two() {
        // Joe & Kuo's (and Sobol's) second dimension starts m = 1, 3, 5, 15, 17, 51, 85, 255.
        let m: Vec<u32> = (1..=8).map(|i| SOBOL_DIM1[i - 1] >> (32 - i)).collect();
        assert_eq!(m, [1, 3, 5, 15, 17, 51, 85, 255]);
        // The first points, by hand: index 1 → (½, ½), 2 → (¼, ¾), 3 → (¾, ¼).
        let f = |i| (to_unit_f32(sobol_dim0(i)), to_unit_f32(sobol_dim1(i)));
        assert_eq!(f(0), (0.0, 0.0));
        assert_eq!(f(1), (0.5, 0.5));
        assert_eq!(f(2), (0.25, 0.75));
        assert_eq!(f(3), (0.75, 0.25));
    }

    #[test]
    fn the_reversed_forms_equal_the_direct_construction() {
        let mut r = crate::sampling::Rng::new(11, 12);
        for k in 0..200_000u32 {
            let i = if k < 4096 { k } else { r.next_u32() };
            let s = [r.next_u32(), r.next_u32(), r.next_u32()];
            let direct = shuffled_scrambled_2d(i, s);
            assert_eq!(
                shuffled_scrambled_2d_reversed(i.reverse_bits(), s),
                direct,
                "{i}"
            );
            assert_eq!(
                shuffled_scrambled_1d_reversed(i.reverse_bits(), [s[0], s[1]]),
                direct.0,
                "{i}"
            );
        }
    }

    #[test]
    fn owen_scrambling_is_nested() {
        // Points that share their top k bits still share them after scrambling (and the map is
        // a bijection on those k-bit prefixes): this is what keeps nets nets.
        for seed in [0u32, 1, 0xdead_beef, 77_777] {
            for k in [1u32, 3, 8] {
                let mut seen = vec![false; 1 << k];
                for prefix in 0..(1u32 << k) {
                    let a = nested_uniform_scramble(prefix << (32 - k), seed) >> (32 - k);
                    let b = nested_uniform_scramble((prefix << (32 - k)) | 0x1234 >> k, seed)
                        >> (32 - k);
                    assert_eq!(a, b);
                    assert!(!seen[a as usize]);
                    seen[a as usize] = true;
                }
            }
        }
    }
}
