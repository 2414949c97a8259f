//! Whether two paths name one file: how `render` and `preview` refuse a checkpoint, layer
//! picture or output that would overwrite another.

use std::path::Path;

/// Whether two paths name the same file (lexically after making them absolute, or the same
/// existing file).
pub(super) fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(x), Ok(y)) = (a.canonicalize(), b.canonicalize()) {
        return x == y;
    }
    matches!((std::path::absolute(a), std::path::absolute(b)), (Ok(x), Ok(y)) if x == y)
}
