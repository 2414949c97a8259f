//! Binary files, the lowest layer: the FNV-1a hash that keys caches and checksums files
//! ([`Fnv`], [`fnv1a`]), a little-endian [`Reader`] that reports truncation, and the atomic
//! writer ([`AtomicWrite`]: a temporary file beside the target, renamed over it) that every file
//! caustic writes goes through. Used by the `.part` films, the image writer and the photon cache.

pub mod atomic;
pub mod fnv;
pub mod key;
pub mod meta_text;
pub mod reader;

pub use atomic::{AtomicWrite, parent_dir};
pub use fnv::{Fnv, fnv1a};
pub use key::KeyHash;
pub use meta_text::MetaText;
pub use reader::{Reader, Truncated};
