//! Image pyramids with bilinear and trilinear lookup, repeat wrapping.
//!
//! Texture space: `uv = (0, 0)` is the top-left corner of the image (first row, like
//! `sphere_uv`, whose v = 0 is the north pole), `u` grows to the right and `v` downwards; texel
//! `(i, j)` of a `w × h` level has its centre at `((i + ½)/w, (j + ½)/h)`. Coordinates wrap with
//! period 1 on both axes (repeat), so `u = 1.0` is `u = 0.0` and `u = −0.25` is `u = 0.75`.
//! Meshes whose `v` points up (OBJ, OpenGL) need `v ↦ 1 − v` at the call site.

use std::ops::{Add, Mul};
use std::path::Path;

use glam::{Vec2, Vec3};

use super::error::TextureError;

/// What a pyramid can store: anything that can be weighted and summed (`Vec3` colours, `f32`
/// heights).
pub trait Texel: Copy + Default + Add<Output = Self> + Mul<f32, Output = Self> {}

impl<T: Copy + Default + Add<Output = T> + Mul<f32, Output = T>> Texel for T {}

/// One resolution of a pyramid, row-major, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
struct Level<T> {
    width: u32,
    height: u32,
    texels: Vec<T>,
}

/// A box-filtered image pyramid of linear texels: level 0 is the image, each next level halves
/// each side (rounding down, at least 1) until 1×1.
///
/// Built once (allocating); lookups never allocate.
#[derive(Debug, Clone, PartialEq)]
pub struct MipMap<T = Vec3> {
    levels: Vec<Level<T>>,
}

/// A single-channel pyramid, for height maps.
pub type GreyMipMap = MipMap<f32>;

/// The sRGB decoding curve: an encoded value in [0, 1] to linear.
#[inline]
#[must_use]
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

impl<T: Texel> MipMap<T> {
    /// A pyramid over `width × height` row-major texels (row 0 at the top, already linear).
    ///
    /// # Errors
    /// [`TextureError::Empty`] for a zero side, [`TextureError::SizeMismatch`] when `texels` does
    /// not hold `width × height` values.
    pub fn new(width: u32, height: u32, texels: Vec<T>) -> Result<Self, TextureError> {
        if width == 0 || height == 0 {
            return Err(TextureError::Empty { width, height });
        }
        if texels.len() as u64 != u64::from(width) * u64::from(height) {
            return Err(TextureError::SizeMismatch {
                width,
                height,
                got: texels.len(),
            });
        }
        let mut levels = vec![Level {
            width,
            height,
            texels,
        }];
        loop {
            let last = &levels[levels.len() - 1];
            if last.width == 1 && last.height == 1 {
                break;
            }
            let next = downsample(last);
            levels.push(next);
        }
        Ok(Self { levels })
    }

    /// Number of levels (1 for a 1×1 image).
    #[must_use]
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// `(width, height)` of `level` (clamped to the last level).
    #[must_use]
    pub fn level_size(&self, level: usize) -> (u32, u32) {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        (l.width, l.height)
    }

    /// Width of the full-resolution image.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.levels[0].width
    }

    /// Height of the full-resolution image.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.levels[0].height
    }

    /// Texel `(x, y)` of `level`, with both indices wrapped (repeat); `level` is clamped.
    #[must_use]
    pub fn texel(&self, level: usize, x: i64, y: i64) -> T {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        let x = x.rem_euclid(i64::from(l.width)) as usize;
        let y = y.rem_euclid(i64::from(l.height)) as usize;
        l.texels[y * l.width as usize + x]
    }

    /// The continuous pyramid level for a footprint: `log2(footprint × max(width, height))`
    /// clamped to `[0, levels − 1]`. `footprint` is the width of a pixel in texture space (uv
    /// units, after tiling): `1/width` selects level 0, `2/width` level 1, `1` the last level.
    /// Zero, negative or NaN footprints select level 0.
    #[must_use]
    pub fn level_for(&self, footprint: f32) -> f32 {
        let size = self.width().max(self.height()) as f32;
        let l = (footprint * size).log2();
        if !(l > 0.0) {
            0.0
        } else {
            l.min((self.levels.len() - 1) as f32)
        }
    }

    /// Bilinear interpolation of the four texels around `uv` in `level` (clamped), repeat wrap.
    /// Non-finite coordinates read as 0.
    #[must_use]
    pub fn bilinear(&self, level: usize, uv: Vec2) -> T {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        let (x0, x1, fx) = wrap_coord(uv.x, l.width);
        let (y0, y1, fy) = wrap_coord(uv.y, l.height);
        let w = l.width as usize;
        let t = &l.texels;
        let top = t[y0 * w + x0] * (1.0 - fx) + t[y0 * w + x1] * fx;
        let bottom = t[y1 * w + x0] * (1.0 - fx) + t[y1 * w + x1] * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// Trilinear lookup: bilinear in the two levels around [`level_for`](Self::level_for)`(footprint)`,
    /// blended linearly between them (a convex combination of texels).
    #[must_use]
    pub fn lookup(&self, uv: Vec2, footprint: f32) -> T {
        let l = self.level_for(footprint);
        let lo = l.floor();
        let t = l - lo;
        let lo = lo as usize;
        let a = self.bilinear(lo, uv);
        if t == 0.0 || lo + 1 >= self.levels.len() {
            a
        } else {
            a * (1.0 - t) + self.bilinear(lo + 1, uv) * t
        }
    }
}

impl MipMap<Vec3> {
    /// A colour pyramid from an image's RGB channels (alpha is ignored). With `srgb`, 8/16-bit
    /// values are decoded from sRGB to linear (what PNG/JPEG colour textures need); without, they
    /// are taken as linear (float images such as EXR, or data textures).
    ///
    /// # Errors
    /// [`TextureError::Empty`] for a zero-sized image.
    pub fn from_image(img: &image::DynamicImage, srgb: bool) -> Result<Self, TextureError> {
        let rgb = img.to_rgb32f();
        let (w, h) = rgb.dimensions();
        let texels = rgb
            .pixels()
            .map(|p| {
                let c = Vec3::from_array(p.0);
                if srgb { c.map(srgb_to_linear) } else { c }
            })
            .collect();
        Self::new(w, h, texels)
    }

    /// [`from_image`](Self::from_image) of the file at `path` (PNG, JPEG or EXR).
    ///
    /// # Errors
    /// [`TextureError::Image`] when the file cannot be read or decoded, or as `from_image`.
    pub fn open(path: &Path, srgb: bool) -> Result<Self, TextureError> {
        Self::from_image(&image::open(path)?, srgb)
    }
}

impl MipMap<f32> {
    /// A grey pyramid of the image's **raw** grey values in [0, 1] (for 8/16-bit images), with no
    /// sRGB decoding: heights are data, and a grey ramp in the file stays a linear ramp. Colour
    /// images are reduced to the `image` crate's Rec. 709 luma of the stored values.
    ///
    /// # Errors
    /// [`TextureError::Empty`] for a zero-sized image.
    pub fn from_image_grey(img: &image::DynamicImage) -> Result<Self, TextureError> {
        let grey = img.to_luma32f();
        let (w, h) = grey.dimensions();
        Self::new(w, h, grey.into_raw())
    }

    /// [`from_image_grey`](Self::from_image_grey) of the file at `path`.
    ///
    /// # Errors
    /// [`TextureError::Image`] when the file cannot be read or decoded, or as `from_image_grey`.
    pub fn open_grey(path: &Path) -> Result<Self, TextureError> {
        Self::from_image_grey(&image::open(path)?)
    }
}

/// Wrapped texel indices `(i0, i0 + 1)` around `u` and the weight of the second.
#[inline]
fn wrap_coord(u: f32, n: u32) -> (usize, usize, f32) {
    let u = if u.is_finite() { u - u.floor() } else { 0.0 };
    let x = u * n as f32 - 0.5;
    let x0 = x.floor();
    let f = x - x0;
    // x0 lies in [−1, n − 1].
    let i0 = (x0 as i64).rem_euclid(i64::from(n)) as usize;
    let i1 = if i0 + 1 == n as usize { 0 } else { i0 + 1 };
    (i0, i1, f)
}

/// Exact box-filter weights shrinking `n` texels to `m ≤ n`: for each output texel, the input
/// texels it overlaps and their overlap fractions (summing to 1).
fn box_weights(n: u32, m: u32) -> Vec<Vec<(usize, f32)>> {
    let (n, m) = (u64::from(n), u64::from(m));
    (0..m)
        .map(|i| {
            // Output texel i covers [i·n, (i+1)·n] and input texel j covers [j·m, (j+1)·m], both
            // in units of 1/(n·m) of the image; integer arithmetic makes the overlaps exact.
            let (a, b) = (i * n, (i + 1) * n);
            (a / m..b.div_ceil(m))
                .map(|j| {
                    let overlap = b.min((j + 1) * m) - a.max(j * m);
                    (j as usize, overlap as f32 / n as f32)
                })
                .collect()
        })
        .collect()
}

/// The next pyramid level: each side halved (rounding down, at least 1), box-filtered exactly
/// (odd sides spread texels over neighbouring outputs in proportion to their overlap).
fn downsample<T: Texel>(src: &Level<T>) -> Level<T> {
    let (w, h) = (src.width, src.height);
    let (w2, h2) = ((w / 2).max(1), (h / 2).max(1));
    let (wx, wy) = (box_weights(w, w2), box_weights(h, h2));
    let mut rows = Vec::with_capacity(w2 as usize * h as usize);
    for y in 0..h as usize {
        let row = &src.texels[y * w as usize..(y + 1) * w as usize];
        for ws in &wx {
            rows.push(ws.iter().fold(T::default(), |s, &(j, k)| s + row[j] * k));
        }
    }
    let mut texels = Vec::with_capacity(w2 as usize * h2 as usize);
    for ws in &wy {
        for x in 0..w2 as usize {
            texels.push(
                ws.iter()
                    .fold(T::default(), |s, &(j, k)| s + rows[j * w2 as usize + x] * k),
            );
        }
    }
    Level {
        width: w2,
        height: h2,
        texels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 4×2 grey image with texel (i, j) = i + 10 j.
    fn grey4x2() -> GreyMipMap {
        MipMap::new(4, 2, vec![0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0, 13.0]).unwrap()
    }

    #[test]
    fn bilinear_hits_texel_centres_midpoints_and_wraps() {
        let m = grey4x2();
        // Exact texel centres: ((i + ½)/4, (j + ½)/2).
        for j in 0..2 {
            for i in 0..4 {
                let uv = Vec2::new((i as f32 + 0.5) / 4.0, (j as f32 + 0.5) / 2.0);
                assert_eq!(m.bilinear(0, uv), i as f32 + 10.0 * j as f32, "{uv}");
            }
        }
        // Midpoint between texels (1,0) and (2,0): u = 0.5, v = 0.25 → 1.5.
        assert_eq!(m.bilinear(0, Vec2::new(0.5, 0.25)), 1.5);
        // Centre of the 2×2 block (1..2, 0..1): 0.25·(1 + 2 + 11 + 12) = 6.5.
        assert_eq!(m.bilinear(0, Vec2::new(0.5, 0.5)), 6.5);
        // u = 1.0 wraps to u = 0: halfway between texel 3 and texel 0 → 1.5.
        assert_eq!(m.bilinear(0, Vec2::new(1.0, 0.25)), 1.5);
        assert_eq!(m.bilinear(0, Vec2::new(0.0, 0.25)), 1.5);
        // u = −0.125 is u = 0.875, the centre of texel 3.
        assert_eq!(m.bilinear(0, Vec2::new(-0.125, 0.25)), 3.0);
        // u = −0.875 is u = 0.125, texel 0; u = 2.375 is u = 0.375, texel 1.
        assert_eq!(m.bilinear(0, Vec2::new(-0.875, 0.25)), 0.0);
        assert_eq!(m.bilinear(0, Vec2::new(2.375, 0.25)), 1.0);
        // v wraps too: v = 1.0 is halfway between row 1 and row 0.
        assert_eq!(m.bilinear(0, Vec2::new(0.125, 1.0)), 5.0);
        // Non-finite coordinates read as 0 instead of producing NaN.
        assert!(
            m.bilinear(0, Vec2::new(f32::NAN, f32::INFINITY))
                .is_finite()
        );
    }

    #[test]
    fn srgb_half_decodes_to_0_2140() {
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // Through an 8-bit image: 128/255 = 0.50196 → 0.21586; 255 → 1.
        let img = image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(2, 1, |x, _| {
            if x == 0 {
                image::Rgb([128, 128, 128])
            } else {
                image::Rgb([255, 0, 0])
            }
        }));
        let lin = MipMap::from_image(&img, true).unwrap();
        let raw = MipMap::from_image(&img, false).unwrap();
        assert!((lin.texel(0, 0, 0).x - 0.215_861).abs() < 1e-5);
        assert!((raw.texel(0, 0, 0).x - 128.0 / 255.0).abs() < 1e-6);
        assert_eq!(lin.texel(0, 1, 0), Vec3::X);
        // Height maps keep raw grey values.
        let g = MipMap::from_image_grey(&img.to_luma8().into()).unwrap();
        assert!((g.texel(0, 0, 0) - 128.0 / 255.0).abs() < 1e-6);
    }

    #[test]
    fn pyramid_of_5x3_is_5x3_2x1_1x1_and_preserves_the_mean() {
        let texels: Vec<f32> = (0..15).map(|i| (i * i % 7) as f32).collect();
        let mean = texels.iter().sum::<f32>() / 15.0;
        let m = MipMap::new(5, 3, texels).unwrap();
        assert_eq!(m.levels(), 3);
        assert_eq!(m.level_size(0), (5, 3));
        assert_eq!(m.level_size(1), (2, 1));
        assert_eq!(m.level_size(2), (1, 1));
        let l1 = (m.texel(1, 0, 0) + m.texel(1, 1, 0)) / 2.0;
        assert!((l1 - mean).abs() < 1e-5, "{l1} vs {mean}");
        assert!((m.texel(2, 0, 0) - mean).abs() < 1e-5);
        // Other shapes: 1×1 has one level, 8×8 has 4, 1×6 → 1×3 → 1×1.
        assert_eq!(MipMap::new(1, 1, vec![1.0f32]).unwrap().levels(), 1);
        assert_eq!(MipMap::new(8, 8, vec![1.0f32; 64]).unwrap().levels(), 4);
        let tall = MipMap::new(1, 6, vec![1.0f32; 6]).unwrap();
        assert_eq!(
            (0..3).map(|l| tall.level_size(l)).collect::<Vec<_>>(),
            [(1, 6), (1, 3), (1, 1)]
        );
        // A constant image stays exactly constant at every level.
        let c = MipMap::new(7, 5, vec![0.3f32; 35]).unwrap();
        for l in 0..c.levels() {
            let (w, h) = c.level_size(l);
            for i in 0..(w * h) as i64 {
                assert!((c.texel(l, i % i64::from(w), i / i64::from(w)) - 0.3).abs() < 1e-6);
            }
        }
        assert!(matches!(
            MipMap::new(0, 3, Vec::<f32>::new()),
            Err(TextureError::Empty { .. })
        ));
        assert!(matches!(
            MipMap::new(2, 2, vec![0.0f32; 3]),
            Err(TextureError::SizeMismatch { got: 3, .. })
        ));
    }

    #[test]
    fn level_selection_follows_the_footprint() {
        let m = MipMap::new(16, 8, vec![0.0f32; 128]).unwrap(); // levels 16×8 … 1×1: 5
        assert_eq!(m.levels(), 5);
        assert_eq!(m.level_for(1.0 / 16.0), 0.0);
        assert_eq!(m.level_for(2.0 / 16.0), 1.0);
        assert_eq!(m.level_for(4.0 / 16.0), 2.0);
        assert!((m.level_for(3.0 / 16.0) - 3f32.log2()).abs() < 1e-6);
        assert_eq!(m.level_for(1.0), 4.0);
        assert_eq!(m.level_for(100.0), 4.0);
        assert_eq!(m.level_for(f32::INFINITY), 4.0);
        assert_eq!(m.level_for(0.0), 0.0);
        assert_eq!(m.level_for(0.01), 0.0);
        assert_eq!(m.level_for(-1.0), 0.0);
        assert_eq!(m.level_for(f32::NAN), 0.0);
    }

    #[test]
    fn trilinear_is_a_convex_combination_of_adjacent_levels() {
        // Checkerboard 8×8: level 0 alternates 0/1, level 1 (box of 2×2) is all 0.5.
        let texels = (0..64).map(|i| ((i % 8 + i / 8) % 2) as f32).collect();
        let m = MipMap::new(8, 8, texels).unwrap();
        let uv = Vec2::new((2.0 + 0.5) / 8.0, (1.0 + 0.5) / 8.0); // texel (2,1) = 1
        assert_eq!(m.lookup(uv, 1.0 / 8.0), 1.0);
        assert_eq!(m.lookup(uv, 2.0 / 8.0), 0.5);
        // Footprint 2^0.25/8: level 0.25 → 0.75·1 + 0.25·0.5.
        let v = m.lookup(uv, 2f32.powf(0.25) / 8.0);
        assert!((v - 0.875).abs() < 1e-5, "{v}");
        // Random points and footprints: the result lies between the two level values.
        let mut rng = crate::sampling::Rng::new(3, 0);
        for _ in 0..1000 {
            let uv = Vec2::new(rng.next_f32() * 3.0 - 1.0, rng.next_f32() * 3.0 - 1.0);
            let fp = rng.next_f32() * 0.5;
            let l = m.level_for(fp);
            let (a, b) = (
                m.bilinear(l.floor() as usize, uv),
                m.bilinear(l.floor() as usize + 1, uv),
            );
            let v = m.lookup(uv, fp);
            assert!(v >= a.min(b) - 1e-6 && v <= a.max(b) + 1e-6, "{v} {a} {b}");
        }
    }
}
