//! Writing images: 8-bit sRGB PNG or linear float EXR by extension, atomically (a temporary file
//! in the target directory renamed into place, so a failed or interrupted write leaves nothing).
//! [`check_output_path`] refuses an unwritable target before any rendering is done.

use std::path::{Path, PathBuf};

use image::{ImageFormat, RgbImage};

use super::Film;
use super::tonemap::Display;
use crate::binfile::{AtomicWrite, parent_dir};

/// How images (and the other files the commands write) are written: hidden `.caustic-*.tmp`
/// temporary files, and the permissions of any new file (0o666 less the umask), not tempfile's
/// owner-only 0o600.
const IMAGES: AtomicWrite = AtomicWrite {
    temp_prefix: ".caustic-",
    owner_only: false,
};

/// Why an image could not be written. Every message starts with `error:` and names the path the
/// user gave, never the temporary file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The extension is not one we write.
    #[error("error: cannot write `{}`: the output must end in `.png` or `.exr`", path.display())]
    UnknownFormat {
        /// The requested path.
        path: PathBuf,
    },
    /// The target cannot be written, found before rendering by [`check_output_path`].
    #[error("error: cannot write `{}`: {reason}", path.display())]
    Unwritable {
        /// The requested path.
        path: PathBuf,
        /// Why, as a sentence fragment naming the folder or file at fault.
        reason: String,
    },
    /// The file system refused while writing.
    #[error("error: cannot write `{}`: {source}", path.display())]
    Io {
        /// The requested path.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The EXR file (with or without layers) could not be encoded.
    #[error("error: cannot encode the EXR `{}`: {reason}", path.display())]
    Layers {
        /// The requested path.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The layers asked for cannot be written as pictures beside a PNG image (a statistics
    /// layer, or a light-path layer the render did not keep).
    #[error("error: cannot write the layer pictures of `{}`: {reason}", path.display())]
    Pictures {
        /// The image's path.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// Encoding failed.
    #[error("error: cannot encode `{}`: {source}", path.display())]
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

/// The film as 8-bit sRGB: radiance × exposure, mapped to [0, 1] by the display's tone curve
/// ([`Display::map`]; a bare `f32` is an exposure with the linear clip), encoded, rounded.
/// NaN, infinite and negative channels encode as 0.
#[must_use]
pub fn to_srgb8(film: &Film, display: impl Into<Display>) -> RgbImage {
    let display = display.into();
    let mut img = RgbImage::new(film.width, film.height);
    for (px, v) in img.pixels_mut().zip(&film.pixels) {
        let c = v
            .to_array()
            .map(|c| (srgb_encode(display.map(c)) * 255.0 + 0.5) as u8);
        *px = image::Rgb(c);
    }
    img
}

/// Encodes the film for `path`'s format into bytes: PNG through `display` (exposure and tone
/// curve), EXR linear and unscaled.
pub fn encode(
    film: &Film,
    path: &Path,
    display: impl Into<Display>,
) -> Result<Vec<u8>, OutputError> {
    let format = OutputFormat::for_path(path)?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    let result = match format {
        OutputFormat::Png => to_srgb8(film, display).write_to(&mut bytes, ImageFormat::Png),
        OutputFormat::Exr => {
            return super::exr::encode_rgb_exr(film.width as usize, film.height as usize, &|i| {
                film.pixels[i]
            })
            .map_err(|e| OutputError::Layers {
                path: path.to_path_buf(),
                reason: e.to_string(),
            });
        }
    };
    result.map_err(|source| OutputError::Encode {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(bytes.into_inner())
}

/// Writes the film to `path` atomically; an existing file is replaced only on success. PNG goes
/// through `display` (an `f32` is an exposure with the linear clip), EXR stays linear.
pub fn write_image(
    film: &Film,
    path: &Path,
    display: impl Into<Display>,
) -> Result<(), OutputError> {
    let bytes = encode(film, path, display)?;
    write_atomic(path, &bytes)
}

/// An OS error without the context `tempfile` attaches (` at path "…/.caustic-XXXX.tmp"`, which
/// means nothing to the user): the OS's own sentence, same kind.
fn bare(e: std::io::Error) -> std::io::Error {
    if e.raw_os_error().is_some() {
        return e;
    }
    let text = e.to_string();
    match text.rfind(" at path ") {
        Some(cut) => std::io::Error::new(e.kind(), &text[..cut]),
        None => e,
    }
}

/// Checks, before any rendering, that an image can be written at `path`, so a bad target is
/// refused in a moment instead of after the whole render. The extension must be `.png` or
/// `.exr`, `path` must not be a folder, its folder must exist and be a folder, and a new file
/// must be creatable there: this is probed by creating and removing a temporary file in it, which
/// catches missing permissions and read-only file systems exactly as the final write would meet
/// them. Nothing is left behind.
///
/// # Errors
/// [`OutputError::UnknownFormat`] for another extension, [`OutputError::Unwritable`] naming
/// `path` and the folder at fault otherwise.
pub fn check_output_path(path: &Path) -> Result<(), OutputError> {
    OutputFormat::for_path(path)?;
    check_writable(path)
}

/// The writability half of [`check_output_path`], for files of any kind (e.g. `.part` films).
///
/// # Errors
/// [`OutputError::Unwritable`] naming `path` and the folder at fault.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    let refuse = |reason: String| OutputError::Unwritable {
        path: path.to_path_buf(),
        reason,
    };
    if path.is_dir() {
        return Err(refuse(
            "it is a folder; give a file name such as `out.png`".into(),
        ));
    }
    let dir = parent_dir(path);
    match std::fs::metadata(&dir) {
        Ok(m) if !m.is_dir() => {
            return Err(refuse(format!("`{}` is not a folder", dir.display())));
        }
        Ok(_) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(refuse(format!(
                "the folder `{}` does not exist; create it first",
                dir.display()
            )));
        }
        Err(e) => {
            return Err(refuse(format!(
                "cannot open the folder `{}`: {e}",
                dir.display()
            )));
        }
    }
    // Dropping the probe removes it.
    IMAGES.temp_builder().tempfile_in(&dir).map_err(|e| {
        refuse(format!(
            "cannot create files in the folder `{}`: {}",
            dir.display(),
            bare(e)
        ))
    })?;
    Ok(())
}

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`. Errors name
/// `path`, not the temporary file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    IMAGES.write(path, bytes).map_err(|source| OutputError::Io {
        path: path.to_path_buf(),
        source: bare(source),
    })
}

/// Writes several files ([`AtomicWrite::write_all`]): every one goes to a temporary file beside
/// its target first, and they are renamed into place only once all are written, so a failure
/// while writing leaves every target as it was. Errors name the user's path of the file that
/// failed.
pub fn write_atomic_all(files: &[(PathBuf, Vec<u8>)]) -> Result<(), OutputError> {
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    IMAGES
        .write_all(&refs)
        .map_err(|(i, source)| OutputError::Io {
            path: files.get(i).map(|f| f.0.clone()).unwrap_or_default(),
            source: bare(source),
        })
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
    fn unwritable_targets_are_refused_naming_the_users_path() {
        let dir = tempfile::tempdir().expect("tmp");
        let d = dir.path();
        let file = d.join("plain.txt");
        std::fs::write(&file, b"x").expect("write");
        std::fs::create_dir(d.join("adir.png")).expect("mkdir");
        let cases = [
            (d.join("missing/out.png"), "does not exist"),
            (d.join("adir.png"), "it is a folder"),
            (file.join("out.png"), "is not a folder"),
        ];
        for (path, why) in cases {
            let e = check_output_path(&path).expect_err("refused").to_string();
            assert!(e.starts_with("error: cannot write `"), "{e}");
            assert!(e.contains(&format!("`{}`", path.display())), "{e}");
            assert!(e.contains(why), "{e}");
            assert!(matches!(
                check_output_path(&path),
                Err(OutputError::Unwritable { .. })
            ));
        }
        assert!(matches!(
            check_output_path(&d.join("out.jpg")),
            Err(OutputError::UnknownFormat { .. })
        ));
        // A writable target passes and the probe leaves nothing behind.
        check_output_path(&d.join("out.exr")).expect("writable");
        let left: Vec<_> = std::fs::read_dir(d).expect("ls").collect();
        assert_eq!(left.len(), 2, "only plain.txt and adir.png remain");
    }

    #[test]
    fn a_failed_write_names_the_users_path_not_the_temporary_file() {
        let dir = tempfile::tempdir().expect("tmp");
        let path = dir.path().join("gone/out.png");
        let e = write_image(&Film::new(2, 2), &path, 1.0)
            .expect_err("no such folder")
            .to_string();
        assert!(e.starts_with("error: cannot write `"), "{e}");
        assert!(e.contains(&path.display().to_string()), "{e}");
        assert!(!e.contains(".caustic-") && !e.contains("at path"), "{e}");
    }

    /// The linear curve (the default) encodes exactly as the clip-then-encode writer before tone
    /// mapping existed, written out again here, over values spanning black to far over white.
    #[test]
    fn linear_tonemap_is_byte_identical_to_the_plain_clip() {
        use crate::render::tonemap::{Display, Tonemap};
        let n = 4096u32;
        let mut f = Film::new(n, 1);
        for (i, p) in f.pixels.iter_mut().enumerate() {
            let x = (i as f32 / n as f32).powi(3) * 3.0;
            *p = glam::Vec3::new(x, x * 0.37, 1.0 - x);
        }
        for exposure in [1.0, 0.7, 2.5] {
            let old: Vec<u8> = f
                .pixels
                .iter()
                .flat_map(|v| {
                    (*v * exposure).to_array().map(|c| {
                        let c = if c.is_finite() {
                            c.clamp(0.0, 1.0)
                        } else {
                            0.0
                        };
                        (srgb_encode(c) * 255.0 + 0.5) as u8
                    })
                })
                .collect();
            let display = Display {
                exposure,
                tonemap: Tonemap::Linear,
            };
            assert_eq!(to_srgb8(&f, display).into_raw(), old);
            assert_eq!(to_srgb8(&f, exposure).into_raw(), old);
            // The filmic curve differs (darker mid-tones are lifted, highlights kept).
            let aces = Display {
                exposure,
                tonemap: Tonemap::Aces,
            };
            assert_ne!(to_srgb8(&f, aces).into_raw(), old);
        }
    }

    #[test]
    fn nan_and_negative_pixels_encode_as_black() {
        let mut f = Film::new(2, 1);
        f.pixels[0] = glam::Vec3::new(f32::NAN, -1.0, f32::INFINITY);
        let img = to_srgb8(&f, 1.0);
        assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0]);
    }
}
