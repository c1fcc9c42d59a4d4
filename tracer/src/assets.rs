//! Where scene files come from. The parser and the build step read every file through an
//! [`AssetSource`], keyed by the path as written in the scene (relative to the main file's
//! folder), so a worker can serve the same scene from blobs it received over the network
//! without ever opening a path that came over the wire.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Why a file is referenced; tells the build step how to read it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AssetKind {
    Include,
    Ply,
    Image,
    /// A metal's refractive-index data (`.nk`), which `Material "metal"` may name.
    Nk,
    /// A tabulated spectrum (`Texture ... "tabulateddata"`).
    Spectrum,
}

/// A file the scene depends on, keyed by its path as written (relative to the main file's
/// folder). The coordinator ships exactly these files to workers.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct AssetRef {
    pub path: String,
    pub kind: AssetKind,
}

/// The largest file a scene may reference: the largest blob a worker accepts by default.
pub const MAX_FILE_BYTES: u64 = 2 << 30;

#[derive(Debug, thiserror::Error)]
pub enum AssetError {
    /// A FIFO, a device or a folder where a file was expected: reading it could block or
    /// never end.
    #[error("\"{written}\" ({tried}) is not a regular file")]
    NotAFile { written: String, tried: String },
    #[error(
        "\"{written}\" ({tried}) holds {bytes} bytes, more than the limit of {MAX_FILE_BYTES}"
    )]
    TooLarge {
        written: String,
        tried: String,
        bytes: u64,
    },
    #[error("file not found: \"{written}\" (tried {tried})")]
    NotFound { written: String, tried: String },
    #[error("cannot read \"{written}\" ({tried}): {source}")]
    Io {
        written: String,
        tried: String,
        source: std::io::Error,
    },
}

pub trait AssetSource: Send + Sync {
    /// Reads the file `written` (a path as written in the scene, relative to the main file's
    /// folder; the main file itself is read with its own name).
    fn read(&self, written: &str) -> Result<Arc<[u8]>, AssetError>;
}

/// Reads from the filesystem, relative to the main scene file's folder.
#[derive(Clone, Debug)]
pub struct FsSource {
    root: PathBuf,
}

impl FsSource {
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    /// The source for a main scene file: its folder is the root.
    pub fn for_main_file(main: &Path) -> Self {
        Self::new(main.parent().unwrap_or(Path::new(".")))
    }

    /// The filesystem path a written path resolves to. Scenes written on Windows use `\`.
    pub fn resolve(&self, written: &str) -> PathBuf {
        self.root.join(written.replace('\\', "/"))
    }
}

impl AssetSource for FsSource {
    fn read(&self, written: &str) -> Result<Arc<[u8]>, AssetError> {
        use std::io::Read;
        let path = self.resolve(written);
        let tried = path.display().to_string();
        let io = |source: std::io::Error| match source.kind() {
            std::io::ErrorKind::NotFound => AssetError::NotFound {
                written: written.to_string(),
                tried: tried.clone(),
            },
            _ => AssetError::Io {
                written: written.to_string(),
                tried: tried.clone(),
                source,
            },
        };
        // The kind is checked before opening (opening a FIFO blocks until a writer comes) and
        // again on the open file; the read stops at the limit whatever the size said.
        let is_file = |metadata: std::fs::Metadata| {
            if !metadata.is_file() {
                return Err(AssetError::NotAFile {
                    written: written.to_string(),
                    tried: tried.clone(),
                });
            }
            if metadata.len() > MAX_FILE_BYTES {
                return Err(AssetError::TooLarge {
                    written: written.to_string(),
                    tried: tried.clone(),
                    bytes: metadata.len(),
                });
            }
            Ok(metadata.len())
        };
        is_file(std::fs::metadata(&path).map_err(io)?)?;
        let file = std::fs::File::open(&path).map_err(io)?;
        let len = is_file(file.metadata().map_err(io)?)?;
        let mut bytes = Vec::with_capacity(len as usize);
        file.take(MAX_FILE_BYTES)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        Ok(bytes.into())
    }
}

/// Files held in memory under their written paths (a worker's received blobs).
#[derive(Clone, Debug, Default)]
pub struct MemorySource {
    files: HashMap<String, Arc<[u8]>>,
}

impl MemorySource {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn insert(&mut self, written: impl Into<String>, bytes: Arc<[u8]>) {
        self.files.insert(written.into(), bytes);
    }
}

impl AssetSource for MemorySource {
    fn read(&self, written: &str) -> Result<Arc<[u8]>, AssetError> {
        self.files
            .get(written)
            .cloned()
            .ok_or_else(|| AssetError::NotFound {
                written: written.to_string(),
                tried: "the files received from the coordinator".to_string(),
            })
    }
}
