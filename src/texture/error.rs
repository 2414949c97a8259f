//! Why a texture could not be built.

/// A texture that cannot be built from the given data.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    /// The image or texel array has zero width or height.
    #[error("texture has zero size ({width}x{height})")]
    Empty {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
    },
    /// The texel array does not hold `width × height` texels.
    #[error("texture of {width}x{height} needs {} texels, got {got}", u64::from(*width) * u64::from(*height))]
    SizeMismatch {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// Texels supplied.
        got: usize,
    },
    /// The image's header claims a size over the texture limits
    /// ([`MAX_IMAGE_SIDE`](super::limits::MAX_IMAGE_SIDE) per side,
    /// [`MAX_IMAGE_BYTES`](super::limits::MAX_IMAGE_BYTES) to load); nothing was allocated for it.
    #[error(
        "image is {width}x{height} pixels: too large for a texture (at most {max_side} pixels per side and {limit_mib} MiB to load; this one needs {needed_mib} MiB)",
        max_side = super::limits::MAX_IMAGE_SIDE,
        limit_mib = super::limits::MAX_IMAGE_BYTES >> 20,
        needed_mib = needed.div_ceil(1 << 20),
    )]
    TooLarge {
        /// Width in pixels, from the header.
        width: u32,
        /// Height in pixels, from the header.
        height: u32,
        /// Bytes loading it would take: decoded image, float conversion and pyramid.
        needed: u64,
    },
    /// The image holds NaN or infinite values (float formats such as EXR can), which no
    /// reflectance or height can be.
    #[error(
        "the image has {count} texel{} with NaN or infinite values, the first at x = {x}, y = {y} (from the top-left) with {value}",
        if *count == 1 { "" } else { "s" }
    )]
    NonFinite {
        /// Column of the first such texel.
        x: u32,
        /// Row of the first such texel (0 at the top).
        y: u32,
        /// Its first non-finite channel value.
        value: f32,
        /// How many texels have a non-finite channel.
        count: usize,
    },
    /// The image file could not be read or decoded.
    #[error("cannot load texture image: {0}")]
    Image(#[from] image::ImageError),
}
