//! Writing images: 8-bit sRGB PNG or linear float EXR by extension, atomically (a temporary file
//! in the target directory renamed into place, so a failed or interrupted write leaves nothing).

use std::io::Write;
use std::path::{Path, PathBuf};

use image::{ImageFormat, Rgb32FImage, RgbImage};

use super::Film;

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The extension is not one we write.
    #[error("cannot write `{}`: the output must end in `.png` or `.exr`", path.display())]
    UnknownFormat {
        /// The requested path.
        path: PathBuf,
    },
    /// The file system refused.
    #[error("cannot write `{}`: {source}", path.display())]
    Io {
        /// The requested path.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Encoding failed.
    #[error("cannot encode `{}`: {source}", path.display())]
    Encode {
        /// The requested path.
        path: PathBuf,
        /// The encoder's error.
        source: image::ImageError,
    },
}

/// Output file kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// 8-bit sRGB PNG.
    Png,
    /// 32-bit float linear OpenEXR.
    Exr,
}

impl OutputFormat {
    /// The format for `path`'s extension.
    pub fn for_path(path: &Path) -> Result<Self, OutputError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            _ => Err(OutputError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// The sRGB transfer function of a linear value in [0, 1].
#[inline]
#[must_use]
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The film as 8-bit sRGB: radiance × `exposure`, clamped to [0, 1], encoded, rounded.
#[must_use]
pub fn to_srgb8(film: &Film, exposure: f32) -> RgbImage {
    let mut img = RgbImage::new(film.width, film.height);
    for (px, v) in img.pixels_mut().zip(&film.pixels) {
        let c = (*v * exposure).to_array().map(|c| {
            let c = if c.is_finite() {
                c.clamp(0.0, 1.0)
            } else {
                0.0
            };
            (srgb_encode(c) * 255.0 + 0.5) as u8
        });
        *px = image::Rgb(c);
    }
    img
}

/// Encodes the film for `path`'s format into bytes.
pub fn encode(film: &Film, path: &Path, exposure: f32) -> Result<Vec<u8>, OutputError> {
    let format = OutputFormat::for_path(path)?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    let result = match format {
        OutputFormat::Png => to_srgb8(film, exposure).write_to(&mut bytes, ImageFormat::Png),
        OutputFormat::Exr => {
            let data: Vec<f32> = film.pixels.iter().flat_map(|p| p.to_array()).collect();
            match Rgb32FImage::from_raw(film.width, film.height, data) {
                Some(img) => img.write_to(&mut bytes, ImageFormat::OpenExr),
                None => Ok(()),
            }
        }
    };
    result.map_err(|source| OutputError::Encode {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(bytes.into_inner())
}

/// Writes the film to `path` atomically; an existing file is replaced only on success.
pub fn write_image(film: &Film, path: &Path, exposure: f32) -> Result<(), OutputError> {
    let bytes = encode(film, path, exposure)?;
    write_atomic(path, &bytes)
}

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".caustic-").suffix(".tmp");
    // Like any newly created file (0o666 less the umask), not tempfile's owner-only 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(&dir).map_err(io)?;
    tmp.write_all(bytes).map_err(io)?;
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_endpoints() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.5) - 0.735_357).abs() < 1e-5);
    }

    #[cfg(unix)]
    #[test]
    fn written_images_get_the_permissions_of_any_new_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("tmp");
        let plain = dir.path().join("plain");
        std::fs::write(&plain, b"x").expect("write");
        let image = dir.path().join("image.png");
        write_image(&Film::new(2, 2), &image, 1.0).expect("written");
        let mode = |p: &Path| std::fs::metadata(p).expect("meta").permissions().mode() & 0o777;
        assert_eq!(mode(&image), mode(&plain));
    }

    #[test]
    fn nan_and_negative_pixels_encode_as_black() {
        let mut f = Film::new(2, 1);
        f.pixels[0] = glam::Vec3::new(f32::NAN, -1.0, f32::INFINITY);
        let img = to_srgb8(&f, 1.0);
        assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0]);
    }
}
