//! Reading a mesh file's bytes honestly: regular files only, within a size bound, and its kind
//! told by its first bytes (then its extension), so a device, a pipe, a zero-filled or sparse
//! file, or a file of another format gives a clear error naming the file, in bounded memory.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The largest mesh file caustic reads (4 GiB): about 40 million triangles of OBJ with normals
/// and texture coordinates, or 100 million of binary PLY. The whole file is held in memory while
/// it is parsed, so this bounds what a mesh path can cost before any check of its contents.
pub const MAX_MESH_FILE_BYTES: u64 = 4 << 30;

/// Bytes read at a time; text formats are checked for zero bytes chunk by chunk, so a sparse or
/// binary file given as OBJ fails after one chunk, not after the whole file.
const CHUNK: usize = 1 << 20;

/// The kinds of 3D file a mesh path can hold, told by [`sniff`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (text); the default when nothing else matches.
    Obj,
    /// Stanford PLY (`ply` on the first line).
    Ply,
    /// glTF 2.0 JSON (`.gltf`, a JSON object).
    Gltf,
    /// glTF 2.0 binary container (magic `glTF`).
    Glb,
    /// STL, text (`solid …facet`) or binary (80-byte header, count, 50 bytes per triangle).
    Stl,
    /// Autodesk FBX (`Kaydara FBX Binary` or a `; FBX` text header).
    Fbx,
    /// A Blender scene (`BLENDER` magic).
    Blend,
}

impl MeshFormat {
    /// The format's name as users know it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Obj => "an OBJ file",
            MeshFormat::Ply => "a PLY file",
            MeshFormat::Gltf => "a glTF file",
            MeshFormat::Glb => "a binary glTF file (GLB)",
            MeshFormat::Stl => "an STL file",
            MeshFormat::Fbx => "an FBX file",
            MeshFormat::Blend => "a Blender file",
        }
    }

    /// Whether the format is text, so that a zero byte in it means the file is something else.
    fn is_text(self) -> bool {
        matches!(self, MeshFormat::Obj | MeshFormat::Gltf)
    }
}

/// Why a mesh file's bytes could not be read. Each message names the file and says what it is.
#[derive(Debug, thiserror::Error)]
pub enum MeshFileError {
    /// The OS refused to read the file (missing, no permission, …).
    #[error("cannot read mesh file `{}`: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The path is not a regular file.
    #[error("`{}` is {kind}, not a regular file: a mesh must be a file on disk", path.display())]
    NotRegular {
        /// The path.
        path: PathBuf,
        /// `a directory`, `a character device (such as /dev/zero)`, `a named pipe (FIFO)`, …
        kind: &'static str,
    },
    /// The file is larger than [`MAX_MESH_FILE_BYTES`].
    #[error(
        "`{}` is {}, larger than the {} caustic reads for one mesh file",
        path.display(),
        bytes_text(*len),
        bytes_text(*max)
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its length in bytes (as far as read, for a file that grows while read).
        len: u64,
        /// The limit.
        max: u64,
    },
    /// The file begins with nothing but zero bytes.
    #[error("`{}` begins with {zeros} zero bytes: it holds no mesh data (a sparse, truncated or zero-filled file)", path.display())]
    ZeroFilled {
        /// The file.
        path: PathBuf,
        /// Zero bytes at its start (all that was looked at).
        zeros: usize,
    },
    /// A text format holds a zero byte.
    #[error("`{}` has a zero byte at offset {at}: {} is text, so this is a binary, sparse or damaged file", path.display(), format.name())]
    ZeroInText {
        /// The file.
        path: PathBuf,
        /// Offset of the first zero byte.
        at: u64,
        /// The format the file claimed to be.
        format: MeshFormat,
    },
    /// The file is a kind the node cannot read.
    #[error("`{}`: this is {}; {what}", path.display(), format.name())]
    WrongKind {
        /// The file.
        path: PathBuf,
        /// What it is.
        format: MeshFormat,
        /// What caustic reads instead, and how to get there.
        what: &'static str,
    },
}

/// `n` bytes as a short quantity (`2.0 GiB`, `512 B`).
fn bytes_text(n: u64) -> String {
    const UNITS: [&str; 4] = ["KiB", "MiB", "GiB", "TiB"];
    if n < 1024 {
        return format!("{n} B");
    }
    let mut v = n as f64 / 1024.0;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    format!("{v:.1} {}", UNITS[unit])
}

/// What a path that is not a regular file is, for [`MeshFileError::NotRegular`].
fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "a character device (such as /dev/zero or a terminal)";
        }
        if t.is_block_device() {
            return "a block device (a disk)";
        }
        if t.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

/// The format of a file from its first bytes, then its extension; OBJ when nothing matches
/// (OBJ has no magic number).
#[must_use]
pub fn sniff(head: &[u8], path: &Path) -> MeshFormat {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let text_start = head
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .map_or(&[][..], |i| &head[i..]);
    if head.starts_with(b"ply\n") || head.starts_with(b"ply\r") {
        return MeshFormat::Ply;
    }
    if head.starts_with(b"glTF") {
        return MeshFormat::Glb;
    }
    if head.starts_with(b"Kaydara FBX Binary") || text_start.starts_with(b"; FBX") {
        return MeshFormat::Fbx;
    }
    if head.starts_with(b"BLENDER") {
        return MeshFormat::Blend;
    }
    if text_start.starts_with(b"{") && contains(head, b"\"asset\"") {
        return MeshFormat::Gltf;
    }
    if text_start.starts_with(b"solid") && contains(head, b"facet") {
        return MeshFormat::Stl;
    }
    match ext.as_deref() {
        Some("ply") => MeshFormat::Ply,
        Some("gltf") => MeshFormat::Gltf,
        Some("glb") => MeshFormat::Glb,
        Some("stl") => MeshFormat::Stl,
        Some("fbx") => MeshFormat::Fbx,
        Some("blend") => MeshFormat::Blend,
        _ => MeshFormat::Obj,
    }
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}

/// Reads the mesh file at `path` whole, refusing anything but a regular file of at most `max`
/// bytes: a device, pipe or directory fails before it is opened, a file larger than `max`
/// before it is read (and a file that grows past `max` while read, after `max` + 1 bytes); a
/// file whose first megabyte is all zero bytes, or a text format with a zero byte, fails at
/// the first such chunk. Returns the format [`sniff`] tells and the bytes.
///
/// # Errors
/// A [`MeshFileError`] naming the file.
pub fn read_mesh_file(path: &Path, max: u64) -> Result<(MeshFormat, Vec<u8>), MeshFileError> {
    let read_err = |source| MeshFileError::Read {
        path: path.to_path_buf(),
        source,
    };
    // `metadata` follows symbolic links and opens nothing (opening a FIFO would block).
    let meta = std::fs::metadata(path).map_err(read_err)?;
    if !meta.is_file() {
        return Err(MeshFileError::NotRegular {
            path: path.to_path_buf(),
            kind: kind_of(&meta),
        });
    }
    let too_large = |len| MeshFileError::TooLarge {
        path: path.to_path_buf(),
        len,
        max,
    };
    if meta.len() > max {
        return Err(too_large(meta.len()));
    }
    let file = File::open(path).map_err(read_err)?;
    let mut reader = file.take(max + 1);
    let mut bytes = Vec::with_capacity(CHUNK.min(usize::try_from(meta.len()).unwrap_or(0)));
    let mut format = None;
    loop {
        let start = bytes.len();
        let got = (&mut reader)
            .take(CHUNK as u64)
            .read_to_end(&mut bytes)
            .map_err(read_err)?;
        let chunk = &bytes[start..];
        let f = *format.get_or_insert_with(|| sniff(chunk, path));
        if start == 0 && !chunk.is_empty() && chunk.iter().all(|b| *b == 0) {
            return Err(MeshFileError::ZeroFilled {
                path: path.to_path_buf(),
                zeros: chunk.len(),
            });
        }
        if f.is_text()
            && let Some(i) = chunk.iter().position(|b| *b == 0)
        {
            return Err(MeshFileError::ZeroInText {
                path: path.to_path_buf(),
                at: (start + i) as u64,
                format: f,
            });
        }
        if bytes.len() as u64 > max {
            return Err(too_large(bytes.len() as u64));
        }
        if start == 0 {
            // The start looks like mesh data: room for the rest at once.
            bytes.reserve(
                usize::try_from(meta.len())
                    .unwrap_or(0)
                    .saturating_sub(bytes.len()),
            );
        }
        if got == 0 {
            break;
        }
    }
    Ok((format.unwrap_or(MeshFormat::Obj), bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_by_their_first_bytes_before_their_extension() {
        let p = Path::new("model.obj");
        assert_eq!(sniff(b"ply\nformat ascii 1.0\n", p), MeshFormat::Ply);
        assert_eq!(sniff(b"glTF\x02\0\0\0", p), MeshFormat::Glb);
        assert_eq!(
            sniff(b" {\n \"asset\": {\"version\": \"2.0\"}}", p),
            MeshFormat::Gltf
        );
        assert_eq!(
            sniff(b"solid cube\n facet normal 0 0 1\n", p),
            MeshFormat::Stl
        );
        assert_eq!(sniff(b"Kaydara FBX Binary  \0\x1a\0", p), MeshFormat::Fbx);
        assert_eq!(sniff(b"BLENDER-v300", p), MeshFormat::Blend);
        // OBJ has no magic: a `solid` object name without facets stays OBJ.
        assert_eq!(sniff(b"o solid\nv 0 0 0\n", p), MeshFormat::Obj);
        assert_eq!(
            sniff(b"\x00\x01binary", Path::new("a.STL")),
            MeshFormat::Stl
        );
        assert_eq!(sniff(b"", Path::new("a.glb")), MeshFormat::Glb);
    }

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(bytes_text(512), "512 B");
        assert_eq!(bytes_text(2 << 30), "2.0 GiB");
        assert_eq!(bytes_text(1536), "1.5 KiB");
    }
}

/// Why a PLY file could not be read: the file, where (header line, element and property, or
/// byte offset), what was found and what is valid.
#[derive(Debug, thiserror::Error)]
#[error("`{}` (PLY): {problem}", path.display())]
pub struct PlyError {
    /// The PLY file.
    pub path: PathBuf,
    /// What is wrong, and where.
    pub problem: String,
}
