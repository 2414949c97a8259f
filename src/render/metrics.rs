//! Image error metrics, for reporting speed against accuracy relative to a converged reference.

use glam::Vec3;

use super::Film;
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

/// Reads a PNG (decoded from sRGB to linear) or EXR (linear) into a film.
pub fn read_film(path: &std::path::Path) -> Result<Film, image::ImageError> {
    let img = image::open(path)?;
    let linear = matches!(path.extension().and_then(|e| e.to_str()), Some(e) if e.eq_ignore_ascii_case("exr"));
    let rgb = img.into_rgb32f();
    let decode = |c: f32| if linear { c } else { srgb_to_linear(c) };
    let pixels = rgb
        .pixels()
        .map(|p| Vec3::new(decode(p.0[0]), decode(p.0[1]), decode(p.0[2])))
        .collect();
    Ok(Film {
        width: rgb.width(),
        height: rgb.height(),
        pixels,
    })
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
}
