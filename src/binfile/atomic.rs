//! The atomic file write: the bytes go to a temporary file in the target's folder, are synced,
//! and the temporary file is renamed over the target, so a reader (or a second writer of the
//! same file) only ever sees the old file or the whole new one, and a failed or interrupted
//! write leaves nothing behind.

use std::io::Write as _;
use std::path::{Path, PathBuf};

/// How the temporary files of an atomic write are named and who may read the result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AtomicWrite {
    /// Name prefix of the temporary file (hidden: it starts with a dot), e.g. `.caustic-`; the
    /// suffix is `.tmp`.
    pub temp_prefix: &'static str,
    /// `true`: owner-only permissions (0o600, `tempfile`'s default); `false`: the permissions
    /// of any new file (0o666 less the umask).
    pub owner_only: bool,
}

impl AtomicWrite {
    /// A temporary-file builder with this write's name and permissions.
    #[must_use]
    pub fn temp_builder(&self) -> tempfile::Builder<'static, 'static> {
        let mut builder = tempfile::Builder::new();
        builder.prefix(self.temp_prefix).suffix(".tmp");
        #[cfg(unix)]
        if !self.owner_only {
            builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        }
        builder
    }

    /// Writes `bytes` to a temporary file in `path`'s folder, syncs it, then renames it over
    /// `path`; an existing file is replaced only on success.
    ///
    /// # Errors
    /// The OS error of creating, writing, syncing or renaming (as `tempfile` reports it: the
    /// caller names `path` in its own message).
    pub fn write(&self, path: &Path, bytes: &[u8]) -> std::io::Result<()> {
        let mut tmp = self.temp_builder().tempfile_in(parent_dir(path))?;
        tmp.write_all(bytes)?;
        tmp.as_file().sync_all()?;
        tmp.persist(path).map_err(|e| e.error)?;
        Ok(())
    }
}

/// The folder a file goes in (`.` for a bare file name).
#[must_use]
pub fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: AtomicWrite = AtomicWrite {
        temp_prefix: ".t-",
        owner_only: true,
    };

    #[test]
    fn replaces_the_file_whole_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().expect("tmp");
        let path = dir.path().join("f.bin");
        W.write(&path, b"first").expect("written");
        W.write(&path, b"second").expect("replaced");
        assert_eq!(std::fs::read(&path).expect("read"), b"second");
        let names: Vec<_> = std::fs::read_dir(dir.path()).expect("ls").collect();
        assert_eq!(names.len(), 1);
        assert!(W.write(&dir.path().join("no/such/f.bin"), b"x").is_err());
        assert_eq!(parent_dir(Path::new("f.bin")), PathBuf::from("."));
        assert_eq!(parent_dir(Path::new("a/f.bin")), PathBuf::from("a"));
    }

    #[cfg(unix)]
    #[test]
    fn owner_only_files_are_private_and_shared_ones_get_the_usual_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("tmp");
        let mode = |p: &Path| std::fs::metadata(p).expect("meta").permissions().mode() & 0o777;
        let private = dir.path().join("private");
        W.write(&private, b"x").expect("written");
        assert_eq!(mode(&private), 0o600);
        let plain = dir.path().join("plain");
        std::fs::write(&plain, b"x").expect("write");
        let shared = dir.path().join("shared");
        let s = AtomicWrite {
            owner_only: false,
            ..W
        };
        s.write(&shared, b"x").expect("written");
        assert_eq!(mode(&shared), mode(&plain));
    }
}
