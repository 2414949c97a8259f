//! Image error metrics, for reporting speed against accuracy relative to a converged reference.

use glam::Vec3;

use std::path::{Path, PathBuf};

use crate::render::output::to_srgb8;
use crate::render::{Film, Region};
use crate::texture::srgb_to_linear;

/// Error figures of one colour channel (or of all three pooled), in linear radiance units.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChannelError {
    /// Root-mean-square error, √(mean (a−b)²).
    pub rmse: f64,
    /// Mean relative squared error, mean of (a−b)² / (b² + 0.01), `b` the reference (the 0.01
    /// keeps dark pixels from dominating; Rousselle et al. 2011's relMSE).
    pub rel_mse: f64,
    /// Mean absolute error, mean |a−b|.
    pub mae: f64,
    /// Bias, mean (a−b): positive when the image under test is too bright.
    pub bias: f64,
    /// Largest absolute difference.
    pub max_abs: f64,
}

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
    /// Mean absolute channel difference.
    pub mae: f64,
    /// The same figures per channel: red, green, blue.
    pub channels: [ChannelError; 3],
    /// Pixels compared.
    pub pixels: u64,
}

impl ImageError {
    /// The pooled figures of all three channels, as a [`ChannelError`].
    #[must_use]
    pub fn overall(&self) -> ChannelError {
        ChannelError {
            rmse: self.rmse,
            rel_mse: self.rel_mse,
            mae: self.mae,
            bias: self.mean_bias,
            max_abs: self.max_abs,
        }
    }
}

/// Running sums of one channel's differences.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    se: f64,
    rel: f64,
    abs: f64,
    diff: f64,
    max: f64,
}

impl Sums {
    fn add(&mut self, a: f32, b: f32) {
        let (a, b) = (f64::from(a), f64::from(b));
        let d = a - b;
        self.se += d * d;
        self.rel += d * d / (b * b + 0.01);
        self.abs += d.abs();
        self.diff += d;
        self.max = self.max.max(d.abs());
    }

    fn merged(s: &[Sums]) -> Sums {
        s.iter().fold(Sums::default(), |m, c| Sums {
            se: m.se + c.se,
            rel: m.rel + c.rel,
            abs: m.abs + c.abs,
            diff: m.diff + c.diff,
            max: m.max.max(c.max),
        })
    }

    fn finish(&self, n: f64) -> ChannelError {
        ChannelError {
            rmse: (self.se / n).sqrt(),
            rel_mse: self.rel / n,
            mae: self.abs / n,
            bias: self.diff / n,
            max_abs: self.max,
        }
    }
}

/// Compares `test` with `reference`; `None` if their sizes differ.
#[must_use]
pub fn compare(test: &Film, reference: &Film) -> Option<ImageError> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return None;
    }
    let whole = Region {
        x: 0,
        y: 0,
        width: test.width,
        height: test.height,
    };
    compare_region(test, reference, whole)
}

/// Compares the pixels of `region` (in pixels from the top-left) of `test` and `reference`;
/// `None` if the sizes differ, the region is empty or it does not fit in the images.
#[must_use]
pub fn compare_region(test: &Film, reference: &Film, region: Region) -> Option<ImageError> {
    let (w, h) = (test.width, test.height);
    let fits = u64::from(region.x) + u64::from(region.width) <= u64::from(w)
        && u64::from(region.y) + u64::from(region.height) <= u64::from(h);
    if (w, h) != (reference.width, reference.height)
        || test.pixels.len() != reference.pixels.len()
        || region.width == 0
        || region.height == 0
        || !fits
    {
        return None;
    }
    let mut sums = [Sums::default(); 3];
    for y in region.y..region.y + region.height {
        let row = (y * w) as usize;
        let span = row + region.x as usize..row + (region.x + region.width) as usize;
        for (a, b) in test.pixels[span.clone()]
            .iter()
            .zip(&reference.pixels[span])
        {
            for (c, s) in sums.iter_mut().enumerate() {
                s.add(a[c], b[c]);
            }
        }
    }
    let pixels = u64::from(region.width) * u64::from(region.height);
    let n = pixels as f64;
    let all = Sums::merged(&sums).finish(3.0 * n);
    Some(ImageError {
        rmse: all.rmse,
        rel_mse: all.rel_mse,
        max_abs: all.max_abs,
        mean_bias: all.bias,
        mae: all.mae,
        channels: sums.map(|s| s.finish(n)),
        pixels,
    })
}

/// Each pixel's error for a false-colour error image: the root mean square over its three
/// channels of the difference, √(Σ_c (a_c−b_c)² / 3), row-major over `region` (same preconditions
/// as [`compare_region`]; `None` when they fail).
#[must_use]
pub fn pixel_errors(test: &Film, reference: &Film, region: Region) -> Option<Vec<f32>> {
    compare_region(test, reference, region)?;
    let w = test.width;
    let mut out = Vec::with_capacity((region.width * region.height) as usize);
    for y in region.y..region.y + region.height {
        for x in region.x..region.x + region.width {
            let i = (y * w + x) as usize;
            let d = test.pixels[i] - reference.pixels[i];
            out.push((d.length_squared() / 3.0).sqrt());
        }
    }
    Some(out)
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

/// An image file and its reference, read and brought to comparable values.
#[derive(Debug, Clone)]
pub struct FilePair {
    /// The image under test, linear.
    pub test: Film,
    /// The reference, linear.
    pub reference: Film,
    /// Set when the two files were encoded differently (see [`FileComparison::note`]).
    pub note: Option<String>,
}

/// Reads an image file and a reference file (PNG or EXR, in any combination) of the same size.
/// Like is compared with like: when one is 8-bit sRGB and the other linear float, the linear one
/// is clamped and quantised as a PNG of it would be (exposure 1), because an 8-bit file cannot
/// hold values above 1 (a light seen directly would otherwise dominate the figures).
pub fn read_pair(test: &Path, reference: &Path) -> Result<FilePair, CompareError> {
    let read = |path: &Path| {
        read_image(path).map_err(|source| CompareError::Read {
            path: path.to_path_buf(),
            source,
        })
    };
    let ((mut a, ea), (mut b, eb)) = (read(test)?, read(reference)?);
    if (a.width, a.height) != (b.width, b.height) {
        return Err(CompareError::Size {
            test: test.to_path_buf(),
            reference: reference.to_path_buf(),
            size: (a.width, a.height, b.width, b.height),
        });
    }
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
    Ok(FilePair {
        test: a,
        reference: b,
        note,
    })
}

/// Compares an image file with a reference file (PNG or EXR, in any combination), like with
/// like as [`read_pair`] says.
pub fn compare_files(test: &Path, reference: &Path) -> Result<FileComparison, CompareError> {
    let pair = read_pair(test, reference)?;
    let error = compare(&pair.test, &pair.reference).ok_or_else(|| CompareError::Size {
        test: test.to_path_buf(),
        reference: reference.to_path_buf(),
        size: (
            pair.test.width,
            pair.test.height,
            pair.reference.width,
            pair.reference.height,
        ),
    })?;
    Ok(FileComparison {
        error,
        note: pair.note,
    })
}

/// A reference image read once, to compare fresh renders with (golden-image checks of
/// `render --compare`, the series of `converge`).
#[derive(Debug, Clone)]
pub struct Reference {
    /// The file it was read from.
    pub path: PathBuf,
    /// Its pixels, linear.
    pub film: Film,
    /// How the file stored them.
    pub encoding: Encoding,
}

impl Reference {
    /// Reads a PNG or EXR reference.
    pub fn read(path: &Path) -> Result<Self, CompareError> {
        let (film, encoding) = read_image(path).map_err(|source| CompareError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            film,
            encoding,
        })
    }

    /// Compares a rendered linear `film` with the reference. `crop` is where the film lies in the
    /// reference when it is a crop of the image (`render --region`), `None` when it is the whole
    /// image. Against an 8-bit reference the film is first scaled by `exposure`, clamped and
    /// quantised as `render -o x.png` would write it (the result then says so in its note).
    ///
    /// # Errors
    /// [`CompareError::Size`] when the film (or the crop) does not match the reference's size;
    /// `test` names `film_name`.
    pub fn compare(
        &self,
        film: &Film,
        film_name: &Path,
        exposure: f32,
        crop: Option<Region>,
    ) -> Result<FileComparison, CompareError> {
        let size_error = || CompareError::Size {
            test: film_name.to_path_buf(),
            reference: self.path.clone(),
            size: (film.width, film.height, self.film.width, self.film.height),
        };
        let same_size = (self.film.width, self.film.height) == (film.width, film.height);
        let cropped = match crop {
            Some(r) if !same_size && (r.width, r.height) == (film.width, film.height) => {
                Some(crop_film(&self.film, r).ok_or_else(size_error)?)
            }
            _ => None,
        };
        let reference = cropped.as_ref().unwrap_or(&self.film);
        let (test, note) = match self.encoding {
            Encoding::Linear => (None, None),
            Encoding::Srgb8 => {
                let scaled = Film {
                    width: film.width,
                    height: film.height,
                    pixels: film.pixels.iter().map(|p| *p * exposure).collect(),
                };
                (
                    Some(as_srgb8(&scaled)),
                    Some(mixed_note(film_name, &self.path)),
                )
            }
        };
        let error = compare(test.as_ref().unwrap_or(film), reference).ok_or_else(size_error)?;
        Ok(FileComparison { error, note })
    }
}

/// The pixels of `region` of `film`; `None` if it does not fit.
#[must_use]
pub fn crop_film(film: &Film, region: Region) -> Option<Film> {
    let fits = u64::from(region.x) + u64::from(region.width) <= u64::from(film.width)
        && u64::from(region.y) + u64::from(region.height) <= u64::from(film.height);
    if !fits {
        return None;
    }
    let mut pixels = Vec::with_capacity((region.width * region.height) as usize);
    for y in region.y..region.y + region.height {
        let row = (y * film.width) as usize;
        pixels.extend_from_slice(
            &film.pixels[row + region.x as usize..row + (region.x + region.width) as usize],
        );
    }
    Some(Film {
        width: region.width,
        height: region.height,
        pixels,
    })
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

    /// Two pixels whose per-channel figures were worked out by hand (below, in the comments),
    /// not by the formula under test.
    fn two_pixels() -> (Film, Film) {
        let mut test = Film::new(2, 1);
        let mut reference = Film::new(2, 1);
        test.pixels = vec![Vec3::new(1.0, 0.5, 0.0), Vec3::splat(0.2)];
        reference.pixels = vec![Vec3::new(0.5, 0.5, 0.1), Vec3::new(0.0, 0.4, 0.2)];
        // Differences: pixel 0 (0.5, 0, -0.1), pixel 1 (0.2, -0.2, 0).
        (test, reference)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-6
    }

    #[test]
    fn per_channel_and_overall_figures_match_hand_arithmetic() {
        let (t, r) = two_pixels();
        let e = compare(&t, &r).unwrap();
        let [red, green, blue] = e.channels;
        // Red: 0.5 and 0.2. RMSE √(0.29 / 2) = 0.380789; MAE = bias = 0.35;
        // relMSE (0.25 / 0.26 + 0.04 / 0.01) / 2 = (0.961538 + 4) / 2 = 2.480769.
        assert!(close(red.rmse, 0.380_789), "{red:?}");
        assert!(close(red.mae, 0.35) && close(red.bias, 0.35) && close(red.max_abs, 0.5));
        assert!(close(red.rel_mse, 2.480_769), "{red:?}");
        // Green: 0 and -0.2. RMSE √0.02 = 0.141421; MAE 0.1; bias -0.1;
        // relMSE (0 + 0.04 / 0.17) / 2 = 0.117647.
        assert!(close(green.rmse, 0.141_421) && close(green.mae, 0.1));
        assert!(
            close(green.bias, -0.1) && close(green.rel_mse, 0.117_647),
            "{green:?}"
        );
        // Blue: -0.1 and 0. RMSE √0.005 = 0.070711; MAE 0.05; bias -0.05; relMSE 0.01/0.02/2.
        assert!(close(blue.rmse, 0.070_711) && close(blue.mae, 0.05));
        assert!(
            close(blue.bias, -0.05) && close(blue.rel_mse, 0.25),
            "{blue:?}"
        );
        // All six: squares sum to 0.34 → RMSE √(0.34 / 6) = 0.238048; |d| sum 1.0 → MAE 1/6;
        // d sum 0.4 → bias 0.4 / 6; relMSE (0.961538 + 4 + 0.235294 + 0.5) / 6 = 0.949472.
        assert!(close(e.rmse, 0.238_048) && close(e.mae, 1.0 / 6.0), "{e:?}");
        assert!(
            close(e.mean_bias, 0.4 / 6.0) && close(e.rel_mse, 0.949_472),
            "{e:?}"
        );
        assert!(close(e.max_abs, 0.5) && e.pixels == 2);
        assert_eq!(e.overall().rmse, e.rmse);
    }

    #[test]
    fn a_region_measures_only_its_pixels() {
        let (t, r) = two_pixels();
        let right = Region {
            x: 1,
            y: 0,
            width: 1,
            height: 1,
        };
        // Pixel 1 alone: (0.2, -0.2, 0): RMSE √(0.08 / 3) = 0.163299, MAE 0.4 / 3, bias 0.
        let e = compare_region(&t, &r, right).unwrap();
        assert!(close(e.rmse, 0.163_299) && close(e.mae, 0.4 / 3.0), "{e:?}");
        assert!(close(e.mean_bias, 0.0) && e.pixels == 1);
        for bad in [(1, 0, 2, 1), (0, 1, 1, 1), (0, 0, 0, 1)] {
            let region = Region {
                x: bad.0,
                y: bad.1,
                width: bad.2,
                height: bad.3,
            };
            assert!(compare_region(&t, &r, region).is_none(), "{bad:?}");
        }
        // Per-pixel errors: √(0.26 / 3) = 0.294392 and √(0.08 / 3) = 0.163299.
        let whole = Region {
            x: 0,
            y: 0,
            width: 2,
            height: 1,
        };
        let p = pixel_errors(&t, &r, whole).unwrap();
        assert!(close(f64::from(p[0]), 0.294_392) && close(f64::from(p[1]), 0.163_299));
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
