//! Files a node keeps for itself (a coordinator's checkpoint and preview, a worker's disk cache
//! of scene files), safe from what another local user plants in their folder: they are written
//! to a temporary file the `tempfile` crate creates exclusively beside the destination (mode
//! 0600, `O_EXCL`, a random name, removed unless kept) and renamed over it, so a crash leaves the
//! previous file whole and a symlink or a FIFO planted at the name is replaced, never followed;
//! and they are read only from a regular file of the expected size, not through a link, without
//! blocking on a FIFO.

use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// Whether `name` is one of [`StagedFile`]'s temporary names (`.NAME.RANDOM.tmp`): what a crash
/// in the middle of a write leaves behind.
pub fn is_staged_name(name: &str) -> bool {
    name.starts_with('.') && name.ends_with(".tmp")
}

/// A temporary file beside its destination, created exclusively with mode 0600; removed unless
/// committed.
pub struct StagedFile {
    file: tempfile::NamedTempFile,
    path: PathBuf,
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
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let file = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".tmp")
            .tempfile_in(folder)?;
        let mut out = BufWriter::new(file.as_file());
        write(&mut out)?;
        out.flush()?;
        drop(out);
        Ok(Self {
            file,
            path: path.to_path_buf(),
        })
    }

    /// Where the file goes when committed.
    pub fn destination(&self) -> &Path {
        &self.path
    }

    /// Syncs the file to disk and renames it over the destination.
    pub fn commit(self) -> std::io::Result<()> {
        self.file.as_file().sync_all()?;
        self.file.persist(&self.path).map_err(|e| e.error)?;
        Ok(())
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
        let temporary = staged.file.path().to_path_buf();
        let mode = std::fs::metadata(&temporary).unwrap().mode();
        assert_eq!(mode & 0o777, 0o600);
        assert_eq!(
            temporary.parent(),
            Some(dir.path()),
            "staged beside its destination"
        );
        let temporary_name = temporary.file_name().unwrap().to_str().unwrap();
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
    fn staged_names_differ() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.png");
        let staged: Vec<StagedFile> = (0..64)
            .map(|_| StagedFile::write(&path, |out| out.write_all(b"x")).unwrap())
            .collect();
        let names: std::collections::HashSet<&Path> =
            staged.iter().map(|s| s.file.path()).collect();
        assert_eq!(names.len(), 64);
    }
}
