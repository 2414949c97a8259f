//! Image error metrics, for reporting speed against accuracy relative to a converged reference.

use glam::Vec3;

use std::path::{Path, PathBuf};

use super::Film;
use super::output::to_srgb8;
use crate::texture::srgb_to_linear;

/// Differences between a test image and a reference of the same size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    /// Root-mean-square error over all channels.
    pub rmse: f64,
    /// Mean relative squared error, Σ (a−b)² / (b² + 0.01), averaged over channels.
    pub rel_mse: f64,
    /// Largest absolute channel difference.
    pub max_abs: f64,
    /// Mean of the test image minus mean of the reference (luminance-free channel average).
    pub mean_bias: f64,
}

/// Compares `test` with `reference`; `None` if their sizes differ.
#[must_use]
pub fn compare(test: &Film, reference: &Film) -> Option<ImageError> {
    if (test.width, test.height) != (reference.width, reference.height) || test.pixels.is_empty() {
        return None;
    }
    let (mut se, mut rel, mut max, mut bias) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (a, b) in test.pixels.iter().zip(&reference.pixels) {
        for (x, y) in a.to_array().into_iter().zip(b.to_array()) {
            let (x, y) = (f64::from(x), f64::from(y));
            let d = x - y;
            se += d * d;
            rel += d * d / (y * y + 0.01);
            max = max.max(d.abs());
            bias += d;
        }
    }
    let n = (test.pixels.len() * 3) as f64;
    Some(ImageError {
        rmse: (se / n).sqrt(),
        rel_mse: rel / n,
        max_abs: max,
        mean_bias: bias / n,
    })
}

/// How an image file stores its values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// 8-bit sRGB (PNG, JPEG): display values, `exposure` applied, clamped to [0, 1].
    Srgb8,
    /// Linear float (EXR): radiance as rendered, unclamped.
    Linear,
}

/// Reads a PNG (decoded from sRGB to linear) or EXR (linear) into a film, with its encoding.
pub fn read_image(path: &Path) -> Result<(Film, Encoding), image::ImageError> {
    let img = image::open(path)?;
    let encoding = match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("exr") => Encoding::Linear,
        _ => Encoding::Srgb8,
    };
    let rgb = img.into_rgb32f();
    let decode = |c: f32| match encoding {
        Encoding::Linear => c,
        Encoding::Srgb8 => srgb_to_linear(c),
    };
    let pixels = rgb
        .pixels()
        .map(|p| Vec3::new(decode(p.0[0]), decode(p.0[1]), decode(p.0[2])))
        .collect();
    let film = Film {
        width: rgb.width(),
        height: rgb.height(),
        pixels,
    };
    Ok((film, encoding))
}

/// Reads a PNG (decoded from sRGB to linear) or EXR (linear) into a film.
pub fn read_film(path: &Path) -> Result<Film, image::ImageError> {
    read_image(path).map(|(film, _)| film)
}

/// A linear film as an 8-bit sRGB PNG of it (exposure 1) would hold it, decoded back to linear:
/// clamped to [0, 1] and quantised exactly as `caustic render -o x.png` writes pixels.
#[must_use]
pub fn as_srgb8(film: &Film) -> Film {
    let img = to_srgb8(film, 1.0);
    let pixels = img
        .pixels()
        .map(|p| Vec3::from(p.0.map(|c| srgb_to_linear(f32::from(c) / 255.0))))
        .collect();
    Film {
        width: film.width,
        height: film.height,
        pixels,
    }
}

/// Why two image files cannot be compared.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// A file could not be read or decoded.
    #[error("cannot read `{}`: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The decoder's error.
        source: image::ImageError,
    },
    /// The two images differ in size.
    #[error("`{}` is {}×{} but `{}` is {}×{}", test.display(), size.0, size.1, reference.display(), size.2, size.3)]
    Size {
        /// The image under test.
        test: PathBuf,
        /// The reference.
        reference: PathBuf,
        /// Test width and height, then reference width and height.
        size: (u32, u32, u32, u32),
    },
}

/// The result of comparing two image files.
#[derive(Debug, Clone, PartialEq)]
pub struct FileComparison {
    /// The error figures, in linear units.
    pub error: ImageError,
    /// Set when the two files were encoded differently and the linear one was brought into the
    /// 8-bit one's range first; says which file and how.
    pub note: Option<String>,
}

/// Compares an image file with a reference file (PNG or EXR, in any combination). Like is
/// compared with like: when one is 8-bit sRGB and the other linear float, the linear one is
/// clamped and quantised as a PNG of it would be (exposure 1), because an 8-bit file cannot hold
/// values above 1 (a light seen directly would otherwise dominate the figures).
pub fn compare_files(test: &Path, reference: &Path) -> Result<FileComparison, CompareError> {
    let read = |path: &Path| {
        read_image(path).map_err(|source| CompareError::Read {
            path: path.to_path_buf(),
            source,
        })
    };
    let ((mut a, ea), (mut b, eb)) = (read(test)?, read(reference)?);
    let note = match (ea, eb) {
        (Encoding::Linear, Encoding::Srgb8) => {
            a = as_srgb8(&a);
            Some(mixed_note(test, reference))
        }
        (Encoding::Srgb8, Encoding::Linear) => {
            b = as_srgb8(&b);
            Some(mixed_note(reference, test))
        }
        _ => None,
    };
    let error = compare(&a, &b).ok_or_else(|| CompareError::Size {
        test: test.to_path_buf(),
        reference: reference.to_path_buf(),
        size: (a.width, a.height, b.width, b.height),
    })?;
    Ok(FileComparison { error, note })
}

fn mixed_note(linear: &Path, srgb: &Path) -> String {
    format!(
        "note: `{}` is linear and `{}` is 8-bit sRGB: `{}` was clamped to [0, 1] and quantised \
         to 8 bits first (as a PNG at exposure 1); compare two EXR files for unclamped figures",
        linear.display(),
        srgb.display(),
        linear.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_zero_error_and_offsets_are_measured() {
        let mut a = Film::new(2, 2);
        a.pixels.iter_mut().for_each(|p| *p = Vec3::splat(0.5));
        let e = compare(&a, &a).unwrap();
        assert_eq!((e.rmse, e.max_abs, e.mean_bias), (0.0, 0.0, 0.0));
        let mut b = a.clone();
        b.pixels[0] = Vec3::splat(0.7);
        let e = compare(&b, &a).unwrap();
        assert!((e.max_abs - 0.2).abs() < 1e-6);
        assert!((e.rmse - (0.04f64 * 3.0 / 12.0).sqrt()).abs() < 1e-6);
        assert!(compare(&Film::new(1, 2), &a).is_none());
    }

    #[test]
    fn srgb_round_trip() {
        for v in [0.0f32, 0.002, 0.2, 0.5, 1.0] {
            let e = crate::render::output::srgb_encode(v);
            assert!((srgb_to_linear(e) - v).abs() < 1e-5);
        }
    }

    #[test]
    fn a_linear_film_in_8_bit_range_matches_the_png_writer() {
        // Values as the PNG writer would store them, checked by hand: 2.0 and 1.0 clamp to 255,
        // -0.5 to 0; linear 0.3185 encodes to sRGB 0.6000 (= 153.0 / 255), so it is stored as 153
        // and decodes to ((0.6 + 0.055) / 1.055)^2.4 = 0.318547.
        let mut f = Film::new(2, 2);
        f.pixels = vec![
            Vec3::new(2.0, 1.0, -0.5),
            Vec3::splat(0.3185),
            Vec3::ZERO,
            Vec3::splat(f32::NAN),
        ];
        let q = as_srgb8(&f);
        assert_eq!(q.pixels[0], Vec3::new(1.0, 1.0, 0.0));
        assert!((q.pixels[1].x - srgb_to_linear(153.0 / 255.0)).abs() < 1e-7);
        assert!(
            (q.pixels[1].x - 0.318_547).abs() < 1e-5,
            "{}",
            q.pixels[1].x
        );
        assert_eq!(q.pixels[2], Vec3::ZERO);
        assert_eq!(q.pixels[3], Vec3::ZERO);
    }
}
