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

    /// Writes several files as one step as far as a file system allows: each file's bytes go
    /// to a temporary file in its folder and are synced, and only when every one of them is
    /// written are they renamed over their targets, in order. A failure before the renames
    /// (a full disk, a folder that cannot be written) leaves every target as it was and no
    /// temporary file behind; only a rename itself failing can leave the earlier files
    /// replaced and the later ones not.
    ///
    /// # Errors
    /// The index in `files` of the file that failed, and the OS error (as `tempfile` reports
    /// it).
    pub fn write_all(&self, files: &[(&Path, &[u8])]) -> Result<(), (usize, std::io::Error)> {
        let mut staged = Vec::with_capacity(files.len());
        for (i, (path, bytes)) in files.iter().enumerate() {
            let stage = || -> std::io::Result<tempfile::NamedTempFile> {
                let mut tmp = self.temp_builder().tempfile_in(parent_dir(path))?;
                tmp.write_all(bytes)?;
                tmp.as_file().sync_all()?;
                Ok(tmp)
            };
            // On an error the files staged so far are dropped, which removes them.
            staged.push(stage().map_err(|e| (i, e))?);
        }
        for (i, (tmp, (path, _))) in staged.into_iter().zip(files).enumerate() {
            tmp.persist(path).map_err(|e| (i, e.error))?;
        }
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

    #[test]
    fn several_files_are_replaced_only_when_all_of_them_are_written() {
        let dir = tempfile::tempdir().expect("tmp");
        let (a, b) = (dir.path().join("a.bin"), dir.path().join("b.bin"));
        W.write(&a, b"old a").expect("written");
        // The second file's folder is missing: the first may not change, and no temporary
        // file may remain.
        let blocked = dir.path().join("no/such/c.bin");
        let files: [(&Path, &[u8]); 3] = [(&a, b"new a"), (&blocked, b"c"), (&b, b"b")];
        let (at, _) = W.write_all(&files).expect_err("a missing folder");
        assert_eq!(at, 1);
        assert_eq!(std::fs::read(&a).expect("read"), b"old a");
        assert_eq!(std::fs::read_dir(dir.path()).expect("ls").count(), 1);
        W.write_all(&[(&a, b"new a"), (&b, b"new b")])
            .expect("both written");
        assert_eq!(std::fs::read(&a).expect("read"), b"new a");
        assert_eq!(std::fs::read(&b).expect("read"), b"new b");
        assert_eq!(std::fs::read_dir(dir.path()).expect("ls").count(), 2);
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
