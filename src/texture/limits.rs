//! The decoding limits of texture images: how large an image file may be before it is refused
//! from its header, without allocating for it (a hostile or mistaken 100000 × 100000 PNG is an
//! error message, not an out-of-memory abort).

/// Largest image side, in pixels, that [`MipMap::open`](super::MipMap::open),
/// [`MipMap::from_bytes`](super::MipMap::from_bytes) and their grey twins accept.
pub const MAX_IMAGE_SIDE: u32 = 16_384;

/// Most memory, in bytes, that decoding one image file into a pyramid may take: the decoded image
/// plus, per pixel, twice the texel size (the float conversion and then the pyramid, which is at
/// most 4/3 of level 0 plus a half-level of scratch). It is checked against the file's header
/// before any pixel buffer is allocated, and is also the `image` decoders' own allocation limit.
///
/// 4 GiB admits 8-bit colour images up to about 12600 × 12600 (27 bytes per pixel, so 8K
/// textures load) and grey ones up to the side limit (9 bytes per pixel).
pub const MAX_IMAGE_BYTES: u64 = 4 << 30;
