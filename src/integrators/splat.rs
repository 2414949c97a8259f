//! The splat buffer: a film-sized buffer that an estimator adds to at pixels other than the one
//! it was called for (light tracing's camera connections, BDPT's t = 1 strategy, the photon
//! viewer's projected photons), from many workers at once.
//!
//! **Contract.** A splat `add(x, y, v)` is a radiance contribution (W sr⁻¹ m⁻², linear RGB) of
//! one camera sample — whichever pixel that sample was taken for — to pixel `(x, y)`. When the
//! buffer is merged into the film (`PixelSums::add_splats`, in the renderer), the splats are
//! added to the pixel's sum of samples and, like the film's own samples, divided by the pixel's
//! sample count (the render's samples per pixel): a splat of `v` stands for a sample of value `v`
//! taken for that pixel, and a pixel's value is `(Σ samples + Σ splats) / spp`. Splats carry no
//! sample count and do not enter the sums of squares (the variance layer sees camera samples
//! only). Non-finite values and pixels outside the film are dropped and counted
//! ([`SplatBuffer::dropped`]), as the renderer drops non-finite samples.
//!
//! **Determinism.** Values are accumulated in the film's fixed-point representation
//! ([`to_fixed`] at [`SUM_SCALE`]: multiples of 2⁻⁶⁴) as integer sums on atomics, so addition is
//! exact and the order of splats never matters: the buffer holds the same bytes for any thread
//! count and any order, and buffers (of tiles, passes or farm shards) merge exactly. Each
//! channel's 128-bit sum is two `u64` atomics, the low word's carry added to the high word;
//! sums wrap (two's complement) beyond ±2¹²⁷ · 2⁻⁶⁴ ≈ 9.2e18, far past any radiance.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec3, Vec3};

use super::LightPath;

/// Fixed-point scale of the film's sums and of splats: values are rounded to multiples of
/// 2⁻⁶⁴ (about 5.4e-20) before summing.
pub const SUM_SCALE: f64 = 18_446_744_073_709_551_616.0;

/// `v · scale` rounded to the nearest integer (ties away from zero), saturating at the `i128`
/// range: the fixed-point value the film and the splat buffer sum. Inputs are finite.
#[inline]
#[must_use]
pub fn to_fixed(v: f64, scale: f64) -> i128 {
    // `as` saturates; inputs are finite (the renderer drops NaN/Inf before they get here).
    let x = (v * scale).round();
    // Most samples fit an i64, whose conversion is one instruction; the i128 conversion is a
    // library call. Both are exact for an integral `x` in range, so the result is the same.
    if x.abs() < 9.0e18 {
        x as i64 as i128
    } else {
        x as i128
    }
}

/// `v · 2^k` rounded to the nearest integer (ties away from zero), exactly as
/// [`to_fixed`]`(v, 2^k)` computes it, for finite `v` with `|v · 2^k| < 2¹²⁶` (the film's
/// samples below its wide-sum limit), without the float-to-`i128` conversion (a library
/// routine) for magnitudes of 2⁶³ and more.
#[inline]
#[must_use]
pub fn to_fixed_exp2(v: f64, k: i32) -> i128 {
    // 2^k exactly (k is small), so the product is exact.
    let x = v * f64::from_bits(((1023 + k) as u64) << 52);
    if x.abs() < 9.0e18 {
        x.round() as i64 as i128
    } else {
        // |x| ≥ 9e18 is an integer: split its magnitude at 2⁶⁴ into a high word (< 2⁶², as
        // |x| < 2¹²⁶) and a low word in [0, 2⁶⁴), both exact (the low word is a multiple of
        // x's unit in the last place and below 2⁶⁴, so it has at most 53 significant bits).
        let a = x.abs();
        let hi = (a * TWO_POW_MINUS_64).floor();
        let lo = a - hi * SUM_SCALE;
        let magnitude = (i128::from(hi as u64) << 64) + i128::from(lo as u64);
        if x < 0.0 { -magnitude } else { magnitude }
    }
}

/// 2⁻⁶⁴.
const TWO_POW_MINUS_64: f64 = 1.0 / SUM_SCALE;

/// The two's-complement halves of a fixed-point value: (low word, high word).
#[inline]
fn halves(f: i128) -> (u64, u64) {
    (f as u64, (f >> 64) as u64)
}

/// A film-sized buffer of splatted radiance, summed exactly in fixed point (module docs for the
/// contract). `add` takes `&self`: share it among workers by reference.
#[derive(Debug)]
pub struct SplatBuffer {
    width: u32,
    height: u32,
    /// Low words of the sums, three channels per pixel, row-major.
    lo: Vec<AtomicU64>,
    /// High words of the sums, likewise.
    hi: Vec<AtomicU64>,
    /// Splats dropped: non-finite, or outside the film.
    dropped: AtomicU64,
}

impl SplatBuffer {
    /// An empty buffer for a `width × height` film.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        let n = 3 * width as usize * height as usize;
        let zeros = || (0..n).map(|_| AtomicU64::new(0)).collect();
        Self {
            width,
            height,
            lo: zeros(),
            hi: zeros(),
            dropped: AtomicU64::new(0),
        }
    }

    /// Width in pixels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Adds the radiance contribution `value` to pixel `(x, y)` (from the top-left). Safe from
    /// any number of threads at once; the result does not depend on their order. A non-finite
    /// `value` or a pixel outside the film is dropped and counted.
    #[inline]
    pub fn add(&self, x: u32, y: u32, value: Vec3) {
        if x >= self.width || y >= self.height || !value.is_finite() {
            self.dropped.fetch_add(1, Ordering::Relaxed);
            return;
        }
        let at = 3 * (y as usize * self.width as usize + x as usize);
        let v = value.as_dvec3();
        for c in 0..3 {
            let (lo, hi) = halves(to_fixed(v[c], SUM_SCALE));
            let old = self.lo[at + c].fetch_add(lo, Ordering::Relaxed);
            let carry = u64::from(old.overflowing_add(lo).1);
            let hi = hi.wrapping_add(carry);
            if hi != 0 {
                self.hi[at + c].fetch_add(hi, Ordering::Relaxed);
            }
        }
    }

    /// Sets every sum to zero (the dropped count stays).
    pub fn clear(&mut self) {
        for w in self.lo.iter_mut().chain(self.hi.iter_mut()) {
            *w.get_mut() = 0;
        }
    }

    /// Splats dropped so far (non-finite values, pixels outside the film).
    #[must_use]
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// The fixed-point sums (value · [`SUM_SCALE`]) of pixel `index` (row-major), per channel.
    /// Takes `&mut self`, so no worker is still adding.
    #[must_use]
    pub fn fixed_sum(&mut self, index: usize) -> [i128; 3] {
        let at = 3 * index;
        std::array::from_fn(|c| {
            let lo = *self.lo[at + c].get_mut();
            let hi = *self.hi[at + c].get_mut();
            ((u128::from(hi) << 64) | u128::from(lo)) as i128
        })
    }

    /// The summed splats of pixel `(x, y)` (black outside the film).
    #[must_use]
    pub fn sum(&mut self, x: u32, y: u32) -> Vec3 {
        if x >= self.width || y >= self.height {
            return Vec3::ZERO;
        }
        let s = self.fixed_sum(y as usize * self.width as usize + x as usize);
        (DVec3::new(s[0] as f64, s[1] as f64, s[2] as f64) / SUM_SCALE).as_vec3()
    }

    /// Adds every splat of `other` (same size) into `self`, exactly: merging buffers in any
    /// order gives the bytes of one buffer that took all their splats.
    ///
    /// # Errors
    /// [`SplatSizeMismatch`] when the sizes differ (nothing is added).
    pub fn merge(&mut self, other: &mut SplatBuffer) -> Result<(), SplatSizeMismatch> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(SplatSizeMismatch {
                ours: (self.width, self.height),
                theirs: (other.width, other.height),
            });
        }
        let pixels = self.width as usize * self.height as usize;
        for i in 0..pixels {
            let (mine, theirs) = (self.fixed_sum(i), other.fixed_sum(i));
            for c in 0..3 {
                let (lo, hi) = halves(mine[c].wrapping_add(theirs[c]));
                *self.lo[3 * i + c].get_mut() = lo;
                *self.hi[3 * i + c].get_mut() = hi;
            }
        }
        *self.dropped.get_mut() += *other.dropped.get_mut();
        Ok(())
    }
}

/// The splats of one render job: a buffer over the job's region for the beauty image and, when
/// the job keeps the light-path layers (`--layers`), one per [`LightPath`], so that the layers
/// still sum to the image. Estimators add to it through
/// [`Context::splat`](super::context::Context::splat) in image pixel coordinates (from the
/// top-left of the whole image); the job merges it into its film after each sweep
/// (`RenderJob`'s sweep, through `PixelSums::add_splats`), exactly, so splatting estimators keep the film's determinism
/// and its mergeability (passes, `.part` shards). A splat onto a pixel outside the job's region
/// is dropped and counted (a region render holds only its own pixels).
#[derive(Debug)]
pub struct FilmSplats {
    /// Top-left pixel of the region, in image coordinates.
    origin: (u32, u32),
    /// The beauty image's splats.
    total: SplatBuffer,
    /// Per light-path layer, in [`LightPath`] order, when the job keeps layers.
    parts: Option<[SplatBuffer; 4]>,
}

impl FilmSplats {
    /// Empty buffers for the `width × height` region whose top-left pixel is `origin`, with
    /// per-layer buffers when `layers`.
    #[must_use]
    pub fn new(origin: (u32, u32), width: u32, height: u32, layers: bool) -> Self {
        Self {
            origin,
            total: SplatBuffer::new(width, height),
            parts: layers.then(|| std::array::from_fn(|_| SplatBuffer::new(width, height))),
        }
    }

    /// Adds `value` (W·m⁻²·sr⁻¹ per channel, a camera sample's contribution) of light-path
    /// kind `kind` to image pixel `(x, y)`. Safe from any number of workers at once.
    #[inline]
    pub fn add(&self, x: u32, y: u32, kind: LightPath, value: Vec3) {
        // Left of or above the region wraps to a huge index, which `add` drops as outside.
        let (rx, ry) = (x.wrapping_sub(self.origin.0), y.wrapping_sub(self.origin.1));
        self.total.add(rx, ry, value);
        if let Some(parts) = &self.parts {
            parts[kind as usize].add(rx, ry, value);
        }
    }

    /// Splats dropped so far (non-finite, or outside the region).
    #[must_use]
    pub fn dropped(&self) -> u64 {
        self.total.dropped()
    }

    /// The beauty buffer and the per-layer buffers (for the job's merge into its films; see
    /// `PixelSums::add_splats` and [`SplatBuffer::clear`]).
    pub fn buffers_mut(&mut self) -> (&mut SplatBuffer, Option<&mut [SplatBuffer; 4]>) {
        (&mut self.total, self.parts.as_mut())
    }
}

/// Two splat buffers (or a buffer and a film) of different sizes cannot be merged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("a {}×{} splat buffer cannot be merged with a {}×{} one", theirs.0, theirs.1, ours.0, ours.1)]
pub struct SplatSizeMismatch {
    /// Width and height of the buffer merged into.
    pub ours: (u32, u32),
    /// Width and height of the buffer merged.
    pub theirs: (u32, u32),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PixelSums;
    use crate::sampling::Rng;
    use rayon::prelude::*;

    /// The shift-built conversion against the float one it replaces on the film's main path:
    /// random magnitudes over 2⁻⁴⁰ … 2³⁰, exact ties at both scales, subnormals, zeros, and the
    /// extremes of the range.
    #[test]
    fn exp2_conversion_equals_the_float_one() {
        let mut r = Rng::new(41, 3);
        let mut values = vec![
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            1e-310,
            2f64.powi(30) - 1.0,
            -(2f64.powi(30) - 1.0),
            1.0,
            0.5,
            0.49,
            0.51,
        ];
        for k in [32, 64] {
            // v · 2^k = n + 1/2 exactly: ties, either sign, and their neighbours.
            for n in [0.0, 1.0, 2.0, 7.0, 1e6, 12345.0] {
                let t = (n + 0.5) / 2f64.powi(k);
                values.extend([t, -t, t.next_up(), t.next_down(), -t.next_up()]);
            }
        }
        for _ in 0..400_000 {
            // Full 53-bit mantissas in [1, 2) (the low bits matter for exactness), any sign.
            let bits = (u64::from(r.next_u32()) << 32 | u64::from(r.next_u32())) >> 12;
            let m = f64::from_bits(0x3ff0_0000_0000_0000 | bits);
            let e = (r.next_u32() % 71) as i32 - 41;
            let sign = if r.next_u32().is_multiple_of(2) {
                1.0
            } else {
                -1.0
            };
            values.push(sign * m * 2f64.powi(e));
        }
        // Around ±9e18 at 2⁶⁴ (the conversion's switch), every low mantissa bit set.
        for t in [0.4878, 0.49, 0.4999, 0.5, 0.75] {
            let v = f64::from_bits(f64::to_bits(t) | 0xfff);
            values.extend([v, -v, v.next_up(), -v.next_down()]);
        }
        for v in values {
            for k in [32, 64] {
                if (v * 2f64.powi(k)).abs() >= 2f64.powi(126) {
                    continue;
                }
                assert_eq!(
                    to_fixed_exp2(v, k),
                    to_fixed(v, 2f64.powi(k)),
                    "{v:e} · 2^{k}"
                );
            }
        }
    }

    /// Random splats over a 7 × 5 film, many on the same pixels, of both signs and a wide range
    /// of magnitudes (low-word carries and borrows happen).
    fn splats(n: usize) -> Vec<(u32, u32, Vec3)> {
        let mut r = Rng::new(23, 4);
        (0..n)
            .map(|_| {
                let mut v = || (r.next_f32() - 0.3) * 10f32.powi(r.next_u32() as i32 % 10 - 5);
                let value = Vec3::new(v(), v(), v());
                (r.next_u32() % 7, r.next_u32() % 5, value)
            })
            .collect()
    }

    fn splat_all(threads: usize, items: &[(u32, u32, Vec3)]) -> SplatBuffer {
        let buf = SplatBuffer::new(7, 5);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            items
                .par_iter()
                .with_max_len(1)
                .for_each(|&(x, y, v)| buf.add(x, y, v));
        });
        buf
    }

    fn all_sums(buf: &mut SplatBuffer) -> Vec<[i128; 3]> {
        (0..35).map(|i| buf.fixed_sum(i)).collect()
    }

    #[test]
    fn one_and_eight_threads_in_any_order_give_the_same_bytes() {
        let items = splats(20_000);
        let mut reversed = items.clone();
        reversed.reverse();
        let mut shuffled = items.clone();
        let mut r = Rng::new(5, 9);
        for i in (1..shuffled.len()).rev() {
            shuffled.swap(i, r.next_u32() as usize % (i + 1));
        }
        let mut one = splat_all(1, &items);
        let expected = all_sums(&mut one);
        for order in [&items, &reversed, &shuffled] {
            let mut eight = splat_all(8, order);
            assert_eq!(all_sums(&mut eight), expected);
        }
        // An independent sum: plain i128 addition of the same fixed-point values.
        let mut direct = vec![[0i128; 3]; 35];
        for &(x, y, v) in &items {
            for c in 0..3 {
                direct[(y * 7 + x) as usize][c] += to_fixed(f64::from(v[c]), SUM_SCALE);
            }
        }
        assert_eq!(expected, direct);
        // Merging two halves is the buffer of all the splats, and so are the films they make.
        let (a, b) = items.split_at(7_000);
        let mut merged = splat_all(3, b);
        merged.merge(&mut splat_all(2, a)).expect("same size");
        assert_eq!(all_sums(&mut merged), expected);
        let film = |buf: &mut SplatBuffer| {
            let mut f = PixelSums::new(7, 5);
            for i in 0..35 {
                f.add(i, Vec3::ZERO);
            }
            f.add_splats(buf).expect("same size");
            f.to_bytes("")
        };
        assert_eq!(film(&mut merged), film(&mut one));
        assert!(
            merged
                .merge(&mut SplatBuffer::new(3, 3))
                .is_err_and(|e| e.theirs == (3, 3))
        );
    }

    #[test]
    fn a_splat_equals_the_film_sample_it_stands_for() {
        let v = Vec3::new(0.3, 1e-7, 1234.5);
        // Pixel 4 of a 3 × 2 film: one camera sample of `v` ...
        let mut sampled = PixelSums::new(3, 2);
        sampled.add(4, v);
        // ... or a black camera sample plus a splat of `v` (e.g. from another pixel's path).
        let mut splatted = PixelSums::new(3, 2);
        splatted.add(4, Vec3::ZERO);
        let mut buf = SplatBuffer::new(3, 2);
        buf.add(1, 1, v);
        assert_eq!(
            buf.fixed_sum(4),
            [0.3f32, 1e-7, 1234.5].map(|c| (f64::from(c) * 2f64.powi(64)).round() as i128)
        );
        splatted.add_splats(&mut buf).expect("same size");
        assert_eq!(splatted.mean(4), sampled.mean(4));
        assert_eq!(splatted.to_film().to_bytes(), sampled.to_film().to_bytes());
        // With two samples per pixel the splat is divided by 2, as a sample is.
        splatted.add(4, Vec3::ZERO);
        assert_eq!(splatted.mean(4), v / 2.0);
        // Splats on other pixels, outside the film or not finite are not in pixel 4.
        let mut other = SplatBuffer::new(3, 2);
        other.add(0, 1, v);
        other.add(3, 0, v);
        other.add(0, 2, v);
        other.add(2, 1, Vec3::new(f32::NAN, 0.0, 0.0));
        other.add(2, 1, Vec3::splat(f32::INFINITY));
        assert_eq!(other.dropped(), 4);
        assert_eq!(other.sum(1, 1), Vec3::ZERO);
        assert_eq!(other.sum(0, 1), v);
        assert_eq!(other.fixed_sum(5), [0; 3]);
    }

    #[test]
    fn film_splats_land_in_region_coordinates_and_in_their_layer() {
        // A 3 × 2 region whose top-left is image pixel (10, 20).
        let mut f = FilmSplats::new((10, 20), 3, 2, true);
        let v = Vec3::new(0.5, 0.25, 2.0);
        f.add(12, 21, LightPath::Caustic, v); // region pixel (2, 1)
        f.add(10, 20, LightPath::Direct, v); // region pixel (0, 0)
        f.add(12, 21, LightPath::Caustic, v);
        // Left of, above, right of and below the region: dropped, not wrapped onto it.
        f.add(9, 20, LightPath::Direct, v);
        f.add(10, 19, LightPath::Direct, v);
        f.add(13, 20, LightPath::Direct, v);
        f.add(10, 22, LightPath::Direct, v);
        assert_eq!(f.dropped(), 4);
        let (total, layers) = f.buffers_mut();
        assert_eq!(total.sum(2, 1), 2.0 * v);
        assert_eq!(total.sum(0, 0), v);
        assert_eq!(total.sum(1, 0), Vec3::ZERO);
        let layers = layers.expect("layers kept");
        assert_eq!(layers[LightPath::Caustic as usize].sum(2, 1), 2.0 * v);
        assert_eq!(layers[LightPath::Caustic as usize].sum(0, 0), Vec3::ZERO);
        assert_eq!(layers[LightPath::Direct as usize].sum(0, 0), v);
        // The layers sum to the beauty at every pixel.
        for (x, y) in [(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1)] {
            let sum: Vec3 = layers.iter_mut().map(|b| b.sum(x, y)).sum();
            assert_eq!(sum, total.sum(x, y));
        }
        total.clear();
        assert_eq!(total.sum(2, 1), Vec3::ZERO);
        assert!(
            FilmSplats::new((0, 0), 3, 2, false)
                .buffers_mut()
                .1
                .is_none()
        );
    }
}
