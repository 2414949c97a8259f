//! Image pyramids with bilinear and trilinear lookup, repeat wrapping.
//!
//! Texture space: `uv = (0, 0)` is the top-left corner of the image (first row, like
//! `sphere_uv`, whose v = 0 is the north pole), `u` grows to the right and `v` downwards; texel
//! `(i, j)` of a `w × h` level has its centre at `((i + ½)/w, (j + ½)/h)`. Coordinates wrap with
//! period 1 on both axes (repeat), so `u = 1.0` is `u = 0.0` and `u = −0.25` is `u = 0.75`.
//! Meshes whose `v` points up (OBJ, OpenGL) need `v ↦ 1 − v` at the call site.

use std::io::{BufRead, Cursor, Seek};
use std::ops::{Add, Mul};
use std::path::Path;

use glam::{Vec2, Vec3};
use image::{DynamicImage, ImageDecoder, ImageReader, Limits};

use super::error::TextureError;
pub use super::limits::{MAX_IMAGE_BYTES, MAX_IMAGE_SIDE};

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

/// Magnitude to which decoded float texels (EXR) are clamped, the largest half-float: values
/// beyond it mean nothing as a reflectance or a height, and keeping texels well inside `f32`
/// keeps every filtered lookup finite. Non-finite texels are an error
/// ([`TextureError::NonFinite`]).
pub const MAX_TEXEL: f32 = 65_504.0;

/// A decoded channel value made safe to filter: clamped to ±[`MAX_TEXEL`] (callers have
/// refused non-finite values with [`check_finite`]).
#[inline]
fn sanitize(v: f32) -> f32 {
    v.clamp(-MAX_TEXEL, MAX_TEXEL)
}

/// Refuses decoded channel values (`channels` per texel, rows of `width` texels) that are NaN
/// or infinite, naming the first such texel and how many there are.
pub(super) fn check_finite(raw: &[f32], width: u32, channels: usize) -> Result<(), TextureError> {
    let Some(first) = raw.iter().position(|v| !v.is_finite()) else {
        return Ok(());
    };
    let texel = first / channels;
    let count = raw
        .chunks_exact(channels)
        .filter(|t| t.iter().any(|v| !v.is_finite()))
        .count();
    Err(TextureError::NonFinite {
        x: (texel % width.max(1) as usize) as u32,
        y: (texel / width.max(1) as usize) as u32,
        value: raw[first],
        count,
    })
}

/// Decodes an image under the texture limits ([`MAX_IMAGE_SIDE`], [`MAX_IMAGE_BYTES`] with
/// `texel_bytes` bytes per texel in the final pyramid), reading only the header before refusing
/// an image that is too large.
pub(super) fn decode_limited<R: BufRead + Seek>(
    mut reader: ImageReader<R>,
    texel_bytes: u64,
) -> Result<DynamicImage, TextureError> {
    let mut limits = Limits::default();
    limits.max_alloc = Some(MAX_IMAGE_BYTES);
    reader.limits(limits.clone());
    let mut decoder = reader.into_decoder()?;
    let (width, height) = decoder.dimensions();
    let pixels = u64::from(width) * u64::from(height);
    let needed = decoder
        .total_bytes()
        .saturating_add(pixels.saturating_mul(2 * texel_bytes));
    if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE || needed > MAX_IMAGE_BYTES {
        return Err(TextureError::TooLarge {
            width,
            height,
            needed,
        });
    }
    // The strict side limits too, for decoders that honour them while decoding.
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    decoder.set_limits(limits)?;
    Ok(DynamicImage::from_decoder(decoder)?)
}

/// An `ImageReader` over the file at `path`, format from the extension (as `image::open`).
pub(super) fn file_reader(
    path: &Path,
) -> Result<ImageReader<std::io::BufReader<std::fs::File>>, TextureError> {
    Ok(ImageReader::open(path).map_err(image::ImageError::IoError)?)
}

/// An `ImageReader` over in-memory file contents, format guessed from the leading bytes.
fn bytes_reader(bytes: &[u8]) -> Result<ImageReader<Cursor<&[u8]>>, TextureError> {
    Ok(ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(image::ImageError::IoError)?)
}

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
    /// are taken as linear (float images such as EXR, or data textures). Float channels are
    /// clamped to ±[`MAX_TEXEL`].
    ///
    /// # Errors
    /// [`TextureError::Empty`] for a zero-sized image, [`TextureError::NonFinite`] for NaN or
    /// infinite values.
    pub fn from_image(img: &DynamicImage, srgb: bool) -> Result<Self, TextureError> {
        Self::from_rgb32f(img.to_rgb32f(), srgb)
    }

    /// [`from_image`](Self::from_image) of the file at `path` (PNG, JPEG or EXR, chosen by the
    /// extension), decoded under the texture limits ([`MAX_IMAGE_SIDE`], [`MAX_IMAGE_BYTES`]).
    ///
    /// # Errors
    /// [`TextureError::Image`] when the file cannot be read or decoded,
    /// [`TextureError::TooLarge`] when its header claims a size over the limits, or as
    /// `from_image`.
    pub fn open(path: &Path, srgb: bool) -> Result<Self, TextureError> {
        Self::decode(file_reader(path)?, srgb)
    }

    /// [`open`](Self::open) of a file's contents already in memory, the format recognised from
    /// the leading bytes (PNG, JPEG or EXR): the same decoding, limits and conversion.
    ///
    /// # Errors
    /// As [`open`](Self::open); an unrecognised format is a [`TextureError::Image`].
    pub fn from_bytes(bytes: &[u8], srgb: bool) -> Result<Self, TextureError> {
        Self::decode(bytes_reader(bytes)?, srgb)
    }

    fn decode<R: BufRead + Seek>(reader: ImageReader<R>, srgb: bool) -> Result<Self, TextureError> {
        let img = decode_limited(reader, size_of::<Vec3>() as u64)?;
        // Owned conversion: the decoded image is freed before the pyramid is built.
        Self::from_rgb32f(img.into_rgb32f(), srgb)
    }

    /// [`from_image`](Self::from_image) of an RGB float image, consumed.
    pub(super) fn from_rgb32f(rgb: image::Rgb32FImage, srgb: bool) -> Result<Self, TextureError> {
        let (w, h) = rgb.dimensions();
        let mut raw = rgb.into_raw();
        check_finite(&raw, w, 3)?;
        for v in &mut raw {
            *v = sanitize(if srgb { srgb_to_linear(*v) } else { *v });
        }
        let texels = raw.chunks_exact(3).map(Vec3::from_slice).collect();
        drop(raw);
        Self::new(w, h, texels)
    }
}

impl MipMap<f32> {
    /// A grey pyramid of the image's **raw** grey values in [0, 1] (for 8/16-bit images), with no
    /// sRGB decoding: heights are data, and a grey ramp in the file stays a linear ramp. Colour
    /// images are reduced to the `image` crate's Rec. 709 luma of the stored values. Float values
    /// are clamped to ±[`MAX_TEXEL`].
    ///
    /// # Errors
    /// [`TextureError::Empty`] for a zero-sized image, [`TextureError::NonFinite`] for NaN or
    /// infinite values.
    pub fn from_image_grey(img: &DynamicImage) -> Result<Self, TextureError> {
        Self::from_luma32f(img.to_luma32f())
    }

    /// [`from_image_grey`](Self::from_image_grey) of the file at `path`, decoded under the
    /// texture limits as [`MipMap::open`].
    ///
    /// # Errors
    /// [`TextureError::Image`] when the file cannot be read or decoded,
    /// [`TextureError::TooLarge`] when its header claims a size over the limits, or as
    /// `from_image_grey`.
    pub fn open_grey(path: &Path) -> Result<Self, TextureError> {
        Self::decode_grey(file_reader(path)?)
    }

    /// [`open_grey`](Self::open_grey) of a file's contents already in memory, the format
    /// recognised from the leading bytes.
    ///
    /// # Errors
    /// As [`open_grey`](Self::open_grey); an unrecognised format is a [`TextureError::Image`].
    pub fn from_bytes_grey(bytes: &[u8]) -> Result<Self, TextureError> {
        Self::decode_grey(bytes_reader(bytes)?)
    }

    fn decode_grey<R: BufRead + Seek>(reader: ImageReader<R>) -> Result<Self, TextureError> {
        let img = decode_limited(reader, size_of::<f32>() as u64)?;
        let grey = img.to_luma32f();
        drop(img);
        Self::from_luma32f(grey)
    }

    fn from_luma32f(
        grey: image::ImageBuffer<image::Luma<f32>, Vec<f32>>,
    ) -> Result<Self, TextureError> {
        let (w, h) = grey.dimensions();
        let mut raw = grey.into_raw();
        check_finite(&raw, w, 1)?;
        for v in &mut raw {
            *v = sanitize(*v);
        }
        Self::new(w, h, raw)
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

impl<T: crate::binfile::KeyHash> crate::binfile::KeyHash for MipMap<T> {
    /// The finest level's size and texels; the coarser levels are filtered from it.
    fn key_hash(&self, h: &mut crate::binfile::Fnv) {
        let Self { levels } = self;
        h.u64(levels.len() as u64);
        if let Some(Level {
            width,
            height,
            texels,
        }) = levels.first()
        {
            h.u32(*width);
            h.u32(*height);
            crate::binfile::KeyHash::key_hash(texels, h);
        }
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

    /// CRC-32 (PNG's chunk checksum), bitwise.
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 == 1 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    /// A valid 1×1 RGB PNG whose IHDR is rewritten to claim `width × height` (CRC fixed up).
    fn png_claiming(width: u32, height: u32) -> Vec<u8> {
        let img = image::DynamicImage::ImageRgb8(image::RgbImage::new(1, 1));
        let mut png = Vec::new();
        img.write_to(&mut Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        // Signature (8), IHDR length (4), "IHDR" (4), width, height, 5 more bytes, CRC.
        assert_eq!(&png[12..16], b"IHDR");
        png[16..20].copy_from_slice(&width.to_be_bytes());
        png[20..24].copy_from_slice(&height.to_be_bytes());
        let crc = crc32(&png[12..29]);
        png[29..33].copy_from_slice(&crc.to_be_bytes());
        png
    }

    #[test]
    fn from_bytes_decodes_like_open() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/");
        for (file, srgb) in [("tiles_color.png", true), ("hardwood.png", false)] {
            let path = Path::new(dir).join(file);
            let bytes = std::fs::read(&path).unwrap();
            assert_eq!(
                MipMap::from_bytes(&bytes, srgb).unwrap(),
                MipMap::open(&path, srgb).unwrap()
            );
        }
        let path = Path::new(dir).join("tiles_height.png");
        let bytes = std::fs::read(&path).unwrap();
        let grey = MipMap::from_bytes_grey(&bytes).unwrap();
        assert_eq!(grey, MipMap::open_grey(&path).unwrap());
        assert_eq!((grey.width(), grey.height()), (128, 128));
        // The header rewrite keeps a 1×1 PNG decodable.
        assert_eq!(
            MipMap::from_bytes(&png_claiming(1, 1), true)
                .unwrap()
                .levels(),
            1
        );
        // Not an image, or a truncated one: decoding errors, not panics.
        for bad in [&b"not an image"[..], &bytes[..bytes.len() / 2], &[]] {
            assert!(matches!(
                MipMap::from_bytes(bad, true),
                Err(TextureError::Image(_))
            ));
            assert!(matches!(
                MipMap::from_bytes_grey(bad),
                Err(TextureError::Image(_))
            ));
        }
    }

    #[test]
    fn a_header_claiming_a_gigantic_image_is_refused_before_decoding() {
        // 100000 × 100000 RGB would be 30 GB decoded and 270 GB with the pyramid.
        let png = png_claiming(100_000, 100_000);
        let err = MipMap::from_bytes(&png, true).unwrap_err();
        let TextureError::TooLarge {
            width,
            height,
            needed,
        } = err
        else {
            panic!("{err:?}")
        };
        assert_eq!((width, height), (100_000, 100_000));
        assert_eq!(needed, 100_000u64 * 100_000 * (3 + 24));
        assert_eq!(
            err.to_string(),
            "image is 100000x100000 pixels: too large for a texture (at most 16384 pixels per \
             side and 4096 MiB to load; this one needs 257493 MiB)"
        );
        assert!(matches!(
            MipMap::from_bytes_grey(&png),
            Err(TextureError::TooLarge { .. })
        ));
        // Through a file too, as the renderer loads it.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.png");
        std::fs::write(&path, &png).unwrap();
        assert!(matches!(
            MipMap::open(&path, true),
            Err(TextureError::TooLarge { .. })
        ));
        assert!(matches!(
            MipMap::open_grey(&path),
            Err(TextureError::TooLarge { .. })
        ));
        // A side over 16384 is refused even when the pixel count is small.
        assert!(matches!(
            MipMap::from_bytes_grey(&png_claiming(MAX_IMAGE_SIDE + 1, 1)),
            Err(TextureError::TooLarge {
                width: 16_385,
                height: 1,
                ..
            })
        ));
        // Within the limits, the size is accepted and the (missing) data is the error.
        assert!(matches!(
            MipMap::from_bytes(&png_claiming(MAX_IMAGE_SIDE, 2), true),
            Err(TextureError::Image(_))
        ));
    }

    #[test]
    fn non_finite_float_texels_are_refused_and_huge_ones_clamped() {
        let exr_of = |texels: Vec<f32>| {
            let img = image::DynamicImage::ImageRgb32F(
                image::Rgb32FImage::from_raw(2, 2, texels).unwrap(),
            );
            let mut exr = Vec::new();
            img.write_to(&mut Cursor::new(&mut exr), image::ImageFormat::OpenExr)
                .unwrap();
            (img, exr)
        };
        // Texels (0,0) fine, (1,0) has +inf in green, (0,1) fine, (1,1) NaN in blue.
        let (img, exr) = exr_of(vec![
            0.5,
            0.5,
            0.5,
            1.0,
            f32::INFINITY,
            0.0,
            0.2,
            0.2,
            0.2,
            0.0,
            0.0,
            f32::NAN,
        ]);
        for result in [
            MipMap::from_image(&img, false),
            MipMap::from_bytes(&exr, false),
            MipMap::from_bytes(&exr, true),
        ] {
            let Err(TextureError::NonFinite { x, y, value, count }) = result else {
                panic!("{result:?}")
            };
            assert_eq!((x, y, value, count), (1, 0, f32::INFINITY, 2));
        }
        assert!(matches!(
            MipMap::from_bytes_grey(&exr),
            Err(TextureError::NonFinite { x: 1, y: 0, .. })
        ));
        // Finite but huge values are clamped to ±MAX_TEXEL; negative ones kept by the pyramid.
        let (img, exr) = exr_of(vec![
            1e30, -1e30, -2.0, 0.5, 0.5, 0.5, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0,
        ]);
        for m in [
            MipMap::from_image(&img, false).unwrap(),
            MipMap::from_bytes(&exr, false).unwrap(),
        ] {
            assert_eq!(m.texel(0, 0, 0), Vec3::new(MAX_TEXEL, -MAX_TEXEL, -2.0));
            assert!(m.lookup(Vec2::new(0.5, 0.5), 0.7).is_finite());
        }
        let m = MipMap::from_bytes(&exr, true).unwrap();
        assert!((0..2).all(|i| m.texel(0, i, 0).is_finite()));
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
