//! Files a node keeps for itself (a coordinator's checkpoint and preview, a worker's disk cache
//! of scene files), safe from what another local user plants in their folder: they are written
//! to a temporary file created exclusively beside the destination (mode 0600, `O_EXCL |
//! O_NOFOLLOW`, a random name) and renamed over it, so a crash leaves the previous file whole
//! and a symlink or a FIFO planted at the name is replaced, never followed; and they are read
//! only from a regular file of the expected size, not through a link, without blocking on a
//! FIFO.

use std::fs::File;
use std::hash::{BuildHasher, Hasher};
use std::io::{BufWriter, Read, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// Attempts at a fresh temporary name before giving up (each collision is a file someone put
/// there under a name that was random).
const NAME_ATTEMPTS: u32 = 8;

/// 128 random bits as hex, from the OS-seeded keys of std's hasher.
pub fn random_hex() -> String {
    let state = std::collections::hash_map::RandomState::new();
    (0..2u64)
        .map(|i| {
            let mut h = state.build_hasher();
            h.write_u64(i);
            format!("{:016x}", h.finish())
        })
        .collect()
}

/// Whether `name` is one of [`StagedFile`]'s temporary names (`.NAME.RANDOM.tmp`): what a crash
/// in the middle of a write leaves behind.
pub fn is_staged_name(name: &str) -> bool {
    name.starts_with('.') && name.ends_with(".tmp")
}

/// A temporary file beside its destination, created exclusively with mode 0600; removed unless
/// committed.
pub struct StagedFile {
    file: File,
    temporary: PathBuf,
    path: PathBuf,
    committed: bool,
}

impl StagedFile {
    /// Creates the temporary file for `path` and fills it with `write`.
    pub fn write(
        path: &Path,
        write: impl FnOnce(&mut BufWriter<&File>) -> std::io::Result<()>,
    ) -> std::io::Result<Self> {
        let name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let mut attempt = 0;
        let (file, temporary) = loop {
            let temporary = path.with_file_name(format!(".{name}.{}.tmp", random_hex()));
            let created = File::options()
                .write(true)
                .create_new(true)
                .mode(0o600)
                .custom_flags(libc::O_NOFOLLOW)
                .open(&temporary);
            match created {
                Ok(file) => break (file, temporary),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    attempt += 1;
                    if attempt == NAME_ATTEMPTS {
                        return Err(e);
                    }
                }
                Err(e) => return Err(e),
            }
        };
        let staged = Self {
            file,
            temporary,
            path: path.to_path_buf(),
            committed: false,
        };
        let mut out = BufWriter::new(&staged.file);
        write(&mut out)?;
        out.flush()?;
        drop(out);
        Ok(staged)
    }

    /// Where the file goes when committed.
    pub fn destination(&self) -> &Path {
        &self.path
    }

    /// Syncs the file to disk and renames it over the destination.
    pub fn commit(mut self) -> std::io::Result<()> {
        self.file.sync_all()?;
        std::fs::rename(&self.temporary, &self.path)?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for StagedFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.temporary);
        }
    }
}

/// Why a file is not read.
#[derive(Debug, thiserror::Error)]
pub enum ReadFileError {
    #[error("not a regular file (a link, a FIFO, a device or a folder)")]
    NotAFile,
    #[error("{found} bytes long where {expected} were expected")]
    WrongSize { found: u64, expected: u64 },
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// Reads `path` only if it is a regular file (not through a symlink) of exactly `expected`
/// bytes: a FIFO does not block (`O_NONBLOCK`), a device or a huge file is not read.
/// `Ok(None)` when there is no file.
pub fn read_regular_file(path: &Path, expected: u64) -> Result<Option<Vec<u8>>, ReadFileError> {
    let file = File::options()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path);
    let file = match file {
        Ok(file) => file,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        // O_NOFOLLOW on a symlink.
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => return Err(ReadFileError::NotAFile),
        Err(e) => return Err(e.into()),
    };
    let metadata = file.metadata()?;
    if !metadata.is_file() {
        return Err(ReadFileError::NotAFile);
    }
    if metadata.size() != expected {
        return Err(ReadFileError::WrongSize {
            found: metadata.size(),
            expected,
        });
    }
    let mut bytes = Vec::with_capacity(expected as usize);
    file.take(expected).read_to_end(&mut bytes)?;
    Ok(Some(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_staged_file_replaces_a_planted_symlink_not_its_target() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("target");
        std::fs::write(&target, b"precious").unwrap();
        let path = dir.path().join("out.resume");
        std::os::unix::fs::symlink(&target, &path).unwrap();
        let staged = StagedFile::write(&path, |out| out.write_all(b"new")).unwrap();
        let mode = std::fs::metadata(&staged.temporary).unwrap().mode();
        assert_eq!(mode & 0o777, 0o600);
        let temporary_name = staged.temporary.file_name().unwrap().to_str().unwrap();
        assert!(is_staged_name(temporary_name), "{temporary_name}");
        staged.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"precious");
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert!(!std::fs::symlink_metadata(&path).unwrap().is_symlink());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            2,
            "no temporary left"
        );
        let abandoned = StagedFile::write(&dir.path().join("x"), |out| out.write_all(b"x"));
        drop(abandoned);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn only_a_regular_file_of_the_expected_size_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("f");
        assert!(read_regular_file(&file, 3).unwrap().is_none());
        std::fs::write(&file, b"abc").unwrap();
        assert_eq!(read_regular_file(&file, 3).unwrap().unwrap(), b"abc");
        assert!(matches!(
            read_regular_file(&file, 4),
            Err(ReadFileError::WrongSize {
                found: 3,
                expected: 4
            })
        ));
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        assert!(matches!(
            read_regular_file(&link, 3),
            Err(ReadFileError::NotAFile)
        ));
        assert!(matches!(
            read_regular_file(Path::new("/dev/zero"), 3),
            Err(ReadFileError::NotAFile)
        ));
    }

    #[test]
    fn random_names_differ() {
        let names: std::collections::HashSet<String> = (0..64).map(|_| random_hex()).collect();
        assert_eq!(names.len(), 64);
        assert!(names.iter().all(|n| n.len() == 32));
    }
}
