//! Textures: mipmapped bitmaps, height-map bump mapping, tangent-space normal maps, seeded noise,
//! marble and water ripples.
//!
//! Self-contained building blocks for materials to call; nothing here allocates on lookup.
//!
//! Conventions shared by the image textures:
//! - **uv**: `(0, 0)` is the image's top-left corner, v grows downwards (row order, like the
//!   sphere's `sphere_uv`); everything repeats with period 1. A `tile` of `(a, b)` shows the image
//!   `a × b` times over the surface's uv square.
//! - **footprint**: the width of one pixel on the surface, in the surface's uv units (e.g.
//!   `max(|∂uv/∂x|, |∂uv/∂y|)` from ray differentials). 0 means "sharpest" (level 0).
//! - Colours are linear RGB; heights are in world units (depth × grey value).

pub mod bitmap;
pub mod bump;
pub mod error;
pub mod footprint;
pub mod limits;
pub mod marble;
pub mod mipmap;
pub mod noise;
pub mod normal_map;
pub mod ripple;

pub use bitmap::BitmapTexture;
pub use bump::{HeightMap, perturb_normal, perturb_normal_by_gradient};
pub use error::TextureError;
pub use footprint::{Footprint, lookup_anisotropic};
pub use marble::Marble;
pub use mipmap::{GreyMipMap, MipMap, Texel, srgb_to_linear};
pub use noise::Noise;
pub use normal_map::NormalMap;
pub use ripple::Ripples;
