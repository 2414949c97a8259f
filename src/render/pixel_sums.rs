//! The mergeable film: per-pixel sums of radiance samples, sums of their squares and sample
//! counts, in fixed point so that addition is exact and associative. Two renders of the same
//! scene over disjoint sample ranges therefore merge into the very bytes of one render of all
//! the samples, in any order (the basis of `--checkpoint`, `--time` and farm shards). Written to
//! disk losslessly (`.part` files) with a checksum.
//!
//! A sample channel of magnitude [`MAIN_LIMIT`] or more (a light of radiance 1e9 seen directly)
//! would overflow the 128-bit sums over 2³² samples: such channels are summed, just as exactly,
//! in 384-bit integers ([`WideSum`]) kept for the few pixels that have them, so any finite
//! radiance keeps its value in the mean and in the variance (before, sums saturated at 2⁶³ and
//! squares at 4e28, silently: issue 47, exr-huge-radiance).

use std::collections::BTreeMap;
use std::path::Path;

use glam::{DVec3, Vec3};

use super::Film;
use super::wide_sum::WideSum;
use crate::binfile::{Reader, fnv1a};
use crate::integrators::splat::{SUM_SCALE as SCALE, SplatBuffer, to_fixed_exp2};

// The fixed-point scale of the sums (`SCALE`, shared with the splat buffer): samples are rounded
// to multiples of 2⁻⁶⁴ (about 5.4e-20) before summing, so even a light of a microwatt keeps 11
// significant digits.
/// Fixed-point scale of the sums of squares: 2⁻³² resolution.
const SCALE_SQ: f64 = 4_294_967_296.0;
/// log₂ of [`SCALE`] (the integrators' `SUM_SCALE`, 2⁶⁴).
const SCALE_EXP: i32 = 64;
/// log₂ of [`SCALE_SQ`].
const SCALE_SQ_EXP: i32 = 32;
/// Sample channels of at least this magnitude (2³⁰ ≈ 1.07e9) go to the wide sums: below it,
/// 2³² samples sum to less than 2¹²⁷ at both fixed-point scales.
pub const MAIN_LIMIT: f64 = 1_073_741_824.0;
/// File signature of a `.part` film without wide sums (as every film before them).
const MAGIC: &[u8; 16] = b"caustic-film-v1\n";
/// File signature of a `.part` film with wide sums: after the counts, the number of pixels with
/// wide sums (u64) and, per such pixel in increasing order, its index (u32) and its three sums
/// and three sums of squares (48 bytes each, little-endian two's complement).
const MAGIC_WIDE: &[u8; 16] = b"caustic-film-v2\n";
/// Bytes of one wide entry in a v2 file.
const WIDE_ENTRY: usize = 4 + 6 * WideSum::BYTES;

/// The exact sums of one pixel's sample channels too large for the 128-bit sums.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct WideSums {
    /// Σ sample · 2⁶⁴ per channel.
    sums: [WideSum; 3],
    /// Σ sample² · 2³² per channel.
    squares: [WideSum; 3],
}

impl WideSums {
    fn add(&mut self, other: &WideSums) {
        for c in 0..3 {
            self.sums[c] = self.sums[c] + other.sums[c];
            self.squares[c] = self.squares[c] + other.squares[c];
        }
    }
}

/// Why a film file could not be read or merged.
#[derive(Debug, thiserror::Error)]
pub enum FilmError {
    /// Not a film file, an unsupported version, or a truncated/corrupt one.
    #[error("`{path}` is not a valid caustic film file: {reason}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// Reading failed.
    #[error("cannot read `{path}`: {source}")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The two films differ in size.
    #[error("films of different sizes ({0}×{1} and {2}×{3}) cannot be merged")]
    Size(u32, u32, u32, u32),
}

/// Per-pixel sample statistics, row-major from the top-left of the rendered region.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PixelSums {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Σ sample · 2⁶⁴ per pixel and channel.
    sums: Vec<[i128; 3]>,
    /// Σ sample² · 2³² per pixel and channel.
    squares: Vec<[i128; 3]>,
    /// Samples added per pixel (finite samples only; NaN/Inf are counted by the renderer).
    counts: Vec<u32>,
    /// The wide sums of the pixels (by index) that received a channel of [`MAIN_LIMIT`] or more.
    wide: BTreeMap<u32, WideSums>,
}

impl PixelSums {
    /// Empty statistics for a `width × height` film.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            sums: vec![[0; 3]; n],
            squares: vec![[0; 3]; n],
            counts: vec![0; n],
            wide: BTreeMap::new(),
        }
    }

    /// Adds one finite radiance sample to pixel `index` (row-major).
    #[inline(always)]
    pub fn add(&mut self, index: usize, l: Vec3) {
        let l = l.as_dvec3();
        if l.abs().max_element() < MAIN_LIMIT {
            for c in 0..3 {
                self.add_main(index, c, l[c]);
            }
            self.counts[index] += 1;
        } else {
            self.add_wide(index, l);
        }
    }

    /// Adds sample channel value `v` (magnitude below [`MAIN_LIMIT`]) to channel `c` of pixel
    /// `index`'s 128-bit sums. The same integers as [`to_fixed`](crate::integrators::splat::to_fixed) at both scales, computed
    /// with integer shifts ([`to_fixed_exp2`]). The additions cannot overflow: each adds less
    /// than 2⁹⁴ (sums) or 2⁹² (squares), and a pixel holds fewer than 2³² samples, so a sum of
    /// samples stays below 2¹²⁶; they wrap rather than test for it.
    #[inline(always)]
    fn add_main(&mut self, index: usize, c: usize, v: f64) {
        let (s, q) = (
            to_fixed_exp2(v, SCALE_EXP),
            to_fixed_exp2(v * v, SCALE_SQ_EXP),
        );
        self.sums[index][c] = self.sums[index][c].wrapping_add(s);
        self.squares[index][c] = self.squares[index][c].wrapping_add(q);
    }

    /// [`PixelSums::add`] for a sample with a channel of magnitude [`MAIN_LIMIT`] or more: such
    /// channels go to the pixel's wide sums, the others to its 128-bit sums as usual. Out of
    /// line, so that the common path stays small enough to inline into the tile loop.
    #[cold]
    #[inline(never)]
    fn add_wide(&mut self, index: usize, l: DVec3) {
        for c in 0..3 {
            if l[c].abs() < MAIN_LIMIT {
                self.add_main(index, c, l[c]);
            } else {
                // Integral at both scales (|l| ≥ 2³⁰), so the conversion is exact.
                let w = self.wide.entry(index as u32).or_default();
                w.sums[c] = w.sums[c] + WideSum::from_integral_f64(l[c] * SCALE);
                w.squares[c] = w.squares[c] + WideSum::from_integral_f64(l[c] * l[c] * SCALE_SQ);
            }
        }
        self.counts[index] += 1;
    }

    /// Adds pixel `from` of `other` into pixel `to` of `self` (tiles into the whole film).
    #[inline]
    pub fn add_pixel(&mut self, to: usize, other: &PixelSums, from: usize) {
        for c in 0..3 {
            self.sums[to][c] = self.sums[to][c].saturating_add(other.sums[from][c]);
            self.squares[to][c] = self.squares[to][c].saturating_add(other.squares[from][c]);
        }
        self.counts[to] += other.counts[from];
        if other.wide.is_empty() {
            return;
        }
        if let Some(w) = other.wide.get(&(from as u32)) {
            self.wide.entry(to as u32).or_default().add(w);
        }
    }

    /// Adds every pixel of `other` (same size) into `self`. Exact: the order of merges never
    /// changes the result.
    ///
    /// # Errors
    /// [`FilmError::Size`] when the sizes differ.
    pub fn merge(&mut self, other: &PixelSums) -> Result<(), FilmError> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(FilmError::Size(
                self.width,
                self.height,
                other.width,
                other.height,
            ));
        }
        for i in 0..self.counts.len() {
            self.add_pixel(i, other, i);
        }
        Ok(())
    }

    /// Adds the splats of `splats` (same size) into the pixels' sums: each splat counts as a
    /// sample's value of its pixel, divided by the pixel's sample count like the samples (the
    /// contract in [`crate::integrators::splat`]); counts and sums of squares are unchanged.
    /// Exact, so films with splats merge as films without.
    ///
    /// # Errors
    /// [`FilmError::Size`] when the sizes differ.
    pub fn add_splats(&mut self, splats: &mut SplatBuffer) -> Result<(), FilmError> {
        if (self.width, self.height) != (splats.width(), splats.height()) {
            return Err(FilmError::Size(
                self.width,
                self.height,
                splats.width(),
                splats.height(),
            ));
        }
        for (i, s) in self.sums.iter_mut().enumerate() {
            let add = splats.fixed_sum(i);
            for c in 0..3 {
                s[c] = s[c].saturating_add(add[c]);
            }
        }
        Ok(())
    }

    /// Samples added to pixel `index`.
    #[must_use]
    pub fn count(&self, index: usize) -> u32 {
        self.counts[index]
    }

    /// Mean radiance of pixel `index` (black with no samples).
    #[must_use]
    pub fn mean(&self, index: usize) -> Vec3 {
        let n = self.counts[index];
        if n == 0 {
            return Vec3::ZERO;
        }
        let s = self.total(index, |w| w.sums, &self.sums);
        (DVec3::new(s[0], s[1], s[2]) / (SCALE * f64::from(n))).as_vec3()
    }

    /// The fixed-point sums of pixel `index` in `main`, with its wide sums (`part` of them) if
    /// any, as f64: `i128 as f64` when the total fits an i128 (so films without wide sums read
    /// as they always did).
    fn total(
        &self,
        index: usize,
        part: impl Fn(&WideSums) -> [WideSum; 3],
        main: &[[i128; 3]],
    ) -> [f64; 3] {
        let m = main[index];
        match self.wide.get(&(index as u32)) {
            None => m.map(|v| v as f64),
            Some(w) => {
                let w = part(w);
                [0, 1, 2].map(|c| (WideSum::from_i128(m[c]) + w[c]).to_f64())
            }
        }
    }

    /// True when pixel `index` received a sample channel of [`MAIN_LIMIT`] or more.
    #[must_use]
    pub fn has_wide_sums(&self, index: usize) -> bool {
        self.wide.contains_key(&(index as u32))
    }

    /// Sum of pixel `index`'s samples (and splats) per channel, exact to the fixed-point
    /// resolution: differences of sums taken between passes are each pass's own sums (the
    /// golden test's batch means, `render::golden::batch_means`).
    #[must_use]
    pub fn sum(&self, index: usize) -> DVec3 {
        let s = self.sums[index];
        DVec3::new(s[0] as f64, s[1] as f64, s[2] as f64) / SCALE
    }

    /// Unbiased sample variance of pixel `index`'s samples per channel (0 with fewer than two);
    /// the variance of the pixel's mean is this over its count.
    #[must_use]
    pub fn variance(&self, index: usize) -> Vec3 {
        let n = f64::from(self.counts[index]);
        if n < 2.0 {
            return Vec3::ZERO;
        }
        let s = self.total(index, |w| w.sums, &self.sums);
        let q = self.total(index, |w| w.squares, &self.squares);
        let v = |c: usize| {
            let mean = s[c] / SCALE / n;
            ((q[c] / SCALE_SQ - n * mean * mean) / (n - 1.0)).max(0.0)
        };
        DVec3::new(v(0), v(1), v(2)).as_vec3()
    }

    /// The image: each pixel's mean.
    #[must_use]
    pub fn to_film(&self) -> Film {
        let mut film = Film::new(self.width, self.height);
        for (i, p) in film.pixels.iter_mut().enumerate() {
            *p = self.mean(i);
        }
        film
    }

    /// The statistics as bytes: signature, a metadata string (e.g. the scene and sample range,
    /// so merges can check that parts belong together), the arrays little-endian, and an
    /// FNV-1a 64 checksum of all that.
    #[must_use]
    pub fn to_bytes(&self, metadata: &str) -> Vec<u8> {
        let n = self.counts.len();
        let mut out =
            Vec::with_capacity(72 + metadata.len() + n * 100 + self.wide.len() * WIDE_ENTRY);
        out.extend_from_slice(if self.wide.is_empty() {
            MAGIC
        } else {
            MAGIC_WIDE
        });
        out.extend_from_slice(&self.width.to_le_bytes());
        out.extend_from_slice(&self.height.to_le_bytes());
        out.extend_from_slice(&(metadata.len() as u64).to_le_bytes());
        out.extend_from_slice(metadata.as_bytes());
        for s in &self.sums {
            for c in s {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        for s in &self.squares {
            for c in s {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        for c in &self.counts {
            out.extend_from_slice(&c.to_le_bytes());
        }
        if !self.wide.is_empty() {
            out.extend_from_slice(&(self.wide.len() as u64).to_le_bytes());
            for (index, w) in &self.wide {
                out.extend_from_slice(&index.to_le_bytes());
                for v in w.sums.iter().chain(&w.squares) {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        let sum = fnv1a(&out);
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    /// Reads what [`PixelSums::to_bytes`] wrote, with its metadata string; `name` is used in
    /// errors.
    ///
    /// # Errors
    /// [`FilmError::Invalid`] for a wrong signature, a truncated file or a checksum mismatch.
    pub fn from_bytes(bytes: &[u8], name: &str) -> Result<(Self, String), FilmError> {
        let bad = |reason: &str| FilmError::Invalid {
            path: name.to_string(),
            reason: reason.to_string(),
        };
        if bytes.len() < MAGIC.len() + 24 || !bytes.starts_with(b"caustic-film-v") {
            return Err(bad("no caustic film signature"));
        }
        let wide = match &bytes[..MAGIC.len()] {
            m if m == MAGIC => false,
            m if m == MAGIC_WIDE => true,
            _ => {
                return Err(bad(
                    "a film version this caustic does not know (it reads v1 and v2): written by a newer caustic?",
                ));
            }
        };
        let (body, tail) = bytes.split_at(bytes.len() - 8);
        let stored = u64::from_le_bytes(tail.try_into().map_err(|_| bad("truncated"))?);
        if fnv1a(body) != stored {
            return Err(bad("checksum mismatch (truncated or corrupt)"));
        }
        let mut r = Reader::new(body);
        let truncated = |_| bad("truncated");
        r.take(MAGIC.len()).map_err(truncated)?;
        let width = r.u32().map_err(truncated)?;
        let height = r.u32().map_err(truncated)?;
        let meta_len = r.u64().map_err(truncated)?;
        let n = width as usize * height as usize;
        let expected = (meta_len as usize)
            .checked_add(n.checked_mul(100).ok_or_else(|| bad("absurd size"))?)
            .and_then(|x| x.checked_add(r.position()))
            .ok_or_else(|| bad("absurd size"))?;
        // v2: the wide entries follow, their number first.
        let entries = if wide {
            let at = expected;
            let count = body
                .get(at..at + 8)
                .and_then(|b| b.try_into().ok())
                .map(u64::from_le_bytes)
                .ok_or_else(|| bad("truncated"))?;
            if count == 0 || count > n as u64 {
                return Err(bad("wrong number of wide pixel sums"));
            }
            count as usize
        } else {
            0
        };
        let expected = if wide {
            expected
                .checked_add(8)
                .and_then(|x| x.checked_add(entries.checked_mul(WIDE_ENTRY)?))
                .ok_or_else(|| bad("absurd size"))?
        } else {
            expected
        };
        if expected != body.len() {
            return Err(bad("size does not match its header"));
        }
        let meta = std::str::from_utf8(r.take(meta_len as usize).map_err(truncated)?)
            .map_err(|_| bad("metadata is not UTF-8"))?
            .to_string();
        let mut film = Self::new(width, height);
        for s in &mut film.sums {
            for c in s.iter_mut() {
                *c = r.i128().map_err(truncated)?;
            }
        }
        for s in &mut film.squares {
            for c in s.iter_mut() {
                *c = r.i128().map_err(truncated)?;
            }
        }
        for c in &mut film.counts {
            *c = r.u32().map_err(truncated)?;
        }
        if wide {
            r.u64().map_err(truncated)?;
            let mut last = None;
            for _ in 0..entries {
                let index = r.u32().map_err(truncated)?;
                if index as usize >= n || last.is_some_and(|l| l >= index) {
                    return Err(bad("wide pixel sums out of order or outside the film"));
                }
                last = Some(index);
                let mut w = WideSums::default();
                for v in w.sums.iter_mut().chain(w.squares.iter_mut()) {
                    let b = r.take(WideSum::BYTES).map_err(truncated)?;
                    let mut a = [0u8; WideSum::BYTES];
                    a.copy_from_slice(b);
                    *v = WideSum::from_le_bytes(a);
                }
                film.wide.insert(index, w);
            }
        }
        Ok((film, meta))
    }

    /// Reads a `.part` film file.
    ///
    /// # Errors
    /// As [`PixelSums::from_bytes`], or [`FilmError::Io`].
    pub fn read(path: &Path) -> Result<(Self, String), FilmError> {
        let bytes = std::fs::read(path).map_err(|source| FilmError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_bytes(&bytes, &path.display().to_string())
    }

    /// Writes the film atomically (temporary file + rename) to `path`.
    ///
    /// # Errors
    /// When the file cannot be written.
    pub fn write(&self, path: &Path, metadata: &str) -> Result<(), super::output::OutputError> {
        super::output::write_atomic(path, &self.to_bytes(metadata))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::splat::to_fixed as fixed;

    #[test]
    fn scale_exponents_match_the_scales() {
        assert_eq!(SCALE, 2f64.powi(SCALE_EXP));
        assert_eq!(SCALE_SQ, 2f64.powi(SCALE_SQ_EXP));
    }

    #[test]
    fn fixed_point_conversion_equals_the_plain_i128_cast_on_both_paths() {
        let mut r = crate::sampling::Rng::new(8, 1);
        let specials = [
            0.0,
            -0.0,
            0.49,
            0.5,
            0.51,
            1.0,
            40.0,
            1e6,
            1e20,
            -3.7,
            9.0e18 / SCALE,
        ];
        for v in specials.into_iter().chain(
            (0..100_000)
                .map(|_| f64::from(r.next_f32() - 0.3) * 10f64.powi(r.next_u32() as i32 % 12 - 4)),
        ) {
            for scale in [SCALE, SCALE_SQ] {
                assert_eq!(
                    fixed(v, scale),
                    (v * scale).round() as i128,
                    "{v} × {scale}"
                );
            }
        }
    }

    fn filled(values: &[(usize, Vec3)]) -> PixelSums {
        let mut f = PixelSums::new(3, 2);
        for (i, v) in values {
            f.add(*i, *v);
        }
        f
    }

    #[test]
    fn merging_is_exact_in_any_order_and_means_are_right() {
        let samples = [
            (0, Vec3::new(0.1, 0.2, 0.3)),
            (0, Vec3::new(1e-7, 3.0, 1234.5)),
            (0, Vec3::new(0.7, 0.0, 1e-3)),
            (4, Vec3::new(5.0, 5.0, 5.0)),
            (4, Vec3::new(0.3333, 0.1, 0.0)),
        ];
        let all = filled(&samples);
        let mut a = filled(&samples[..2]);
        let b = filled(&samples[2..]);
        let mut b2 = b.clone();
        a.merge(&b).unwrap();
        b2.merge(&filled(&samples[..2])).unwrap();
        assert_eq!(a, all);
        assert_eq!(b2, all);
        let m = all.mean(0);
        let expected = (0.1 + 1e-7 + 0.7) / 3.0;
        assert!((f64::from(m.x) - expected).abs() < 1e-7, "{m}");
        // Sample variance of {5, 0.3333} in x.
        let v = all.variance(4).x as f64;
        let mean = (5.0 + 0.3333) / 2.0;
        let expected = ((5.0f64 - mean).powi(2) + (0.3333f64 - mean).powi(2)) / 1.0;
        assert!((v - expected).abs() < 1e-5, "{v} vs {expected}");
        assert_eq!(all.mean(1), Vec3::ZERO);
        assert_eq!(all.count(0), 3);
    }

    #[test]
    fn bytes_round_trip_and_corruption_is_detected() {
        let f = filled(&[(2, Vec3::new(0.5, 1.5, 2.5)), (5, Vec3::splat(1e6))]);
        let bytes = f.to_bytes("scene=abc");
        let (g, meta) = PixelSums::from_bytes(&bytes, "t").unwrap();
        assert_eq!((g, meta.as_str()), (f.clone(), "scene=abc"));
        for cut in [0, 10, bytes.len() / 2, bytes.len() - 1] {
            assert!(
                PixelSums::from_bytes(&bytes[..cut], "t").is_err(),
                "cut {cut}"
            );
        }
        let mut flipped = bytes.clone();
        flipped[40] ^= 1;
        assert!(PixelSums::from_bytes(&flipped, "t").is_err());
        let mut other = PixelSums::new(2, 2);
        assert!(matches!(other.merge(&f), Err(FilmError::Size(2, 2, 3, 2))));
        // No wide sums: the v1 format, as every film before them.
        assert!(bytes.starts_with(MAGIC));
    }

    #[test]
    fn huge_samples_keep_their_mean_and_variance_in_any_order() {
        // 1e30 (far beyond the 128-bit sums' 9.2e18), f32::MAX and a value just over the limit,
        // mixed with ordinary ones in one pixel; per channel the exact mean and variance.
        let big = [1e30f32, f32::MAX / 4.0, MAIN_LIMIT as f32 * 1.5, 0.25, 3.0];
        let samples: Vec<(usize, Vec3)> = big
            .iter()
            .map(|&v| (1, Vec3::new(v, 0.5, -v)))
            .chain([(0, Vec3::splat(2e20)), (0, Vec3::splat(2e20))])
            .collect();
        let all = filled(&samples);
        let n = big.len() as f64;
        let exact_mean = big.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let m = all.mean(1);
        assert!(
            (f64::from(m.x) / exact_mean - 1.0).abs() < 1e-6,
            "{m} vs {exact_mean:e}"
        );
        assert!((f64::from(m.z) / -exact_mean - 1.0).abs() < 1e-6, "{m}");
        assert_eq!(m.y, 0.5);
        let exact_var = big
            .iter()
            .map(|&v| (f64::from(v) - exact_mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        // In f32 the variance of f32::MAX/4 overflows: infinite, never a small wrong number.
        assert_eq!(all.variance(1).x, exact_var as f32);
        assert_eq!(all.variance(1).y, 0.0);
        assert_eq!(all.mean(0), Vec3::splat(2e20));
        assert_eq!(all.variance(0), Vec3::ZERO);
        // Any split and merge order: the same sums, so the same bytes.
        for split in 0..samples.len() {
            let mut a = filled(&samples[..split]);
            let b = filled(&samples[split..]);
            let mut b2 = b.clone();
            a.merge(&b).unwrap();
            b2.merge(&filled(&samples[..split])).unwrap();
            assert_eq!(a, all, "split {split}");
            assert_eq!(b2, all, "split {split}");
        }
        // The wide sums travel in the v2 format, and a damaged one is refused.
        let bytes = all.to_bytes("m");
        assert!(bytes.starts_with(MAGIC_WIDE));
        let (back, _) = PixelSums::from_bytes(&bytes, "t").unwrap();
        assert_eq!(back, all);
        assert!(back.has_wide_sums(1) && !back.has_wide_sums(5));
        for cut in [bytes.len() - 9, bytes.len() - 300] {
            assert!(PixelSums::from_bytes(&bytes[..cut], "t").is_err());
        }
        let mut future = bytes.clone();
        future[14] = b'9';
        let e = PixelSums::from_bytes(&future, "t").unwrap_err().to_string();
        assert!(e.contains("version"), "{e}");
    }
}
