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
    /// The image file could not be read or decoded.
    #[error("cannot load texture image: {0}")]
    Image(#[from] image::ImageError),
}
