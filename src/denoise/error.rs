//! Why the denoiser refused its input.

/// Why [`super::denoise`] cannot run. Each message names the buffer (and pixel) at fault and
/// what is valid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DenoiseError {
    /// No feature buffers were given.
    #[error(
        "the denoiser needs the feature buffers (albedo, normal, depth) as its guide, and none were given"
    )]
    MissingFeatures,
    /// The image is too small to filter.
    #[error("cannot denoise a {0}×{1} image: it needs at least 2×2 pixels")]
    TooSmall(usize, usize),
    /// The two halves of the samples are not both present.
    #[error(
        "cannot denoise without two halves of the samples: half {0} has none (a render needs at least 2 samples per pixel to be denoised)"
    )]
    EmptyHalf(usize),
    /// A buffer has another number of pixels than the image.
    #[error("the {buffer} buffer has {len} pixels; a {width}×{height} image has {expected}")]
    Size {
        /// Which buffer.
        buffer: String,
        /// Its length.
        len: usize,
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
        /// `width × height`.
        expected: usize,
    },
    /// A value is NaN or infinite, or a variance is negative.
    #[error(
        "the {buffer} buffer is {what} at pixel ({x}, {y}): the denoiser needs finite values and non-negative variances"
    )]
    BadValue {
        /// Which buffer.
        buffer: String,
        /// What is wrong (`NaN`, `infinite`, `negative`).
        what: &'static str,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
    },
}
