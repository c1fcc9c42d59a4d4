//! The worker's content-addressed blob cache: scene files received from coordinators, keyed by
//! their SHA-256, held in memory (bounded, least recently used evicted first) and, with a cache
//! folder, on disk so a restarted worker keeps them (bounded too). A blob's name is a validated
//! hex digest, never a path a peer chose.
//!
//! The cache folder is private: created 0700 (a folder others may enter or write to is made
//! private, or refused when it is not ours), files 0600, written through temporary files
//! created exclusively under random names, and opened without following symbolic links. An
//! entry is read only if it is a regular file of the expected size whose content hashes to its
//! name; anything else found there is ignored or dropped.

use std::collections::HashMap;
use std::io::Write;
use std::os::unix::fs::{DirBuilderExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use yat_proto::hash::{is_sha256_hex, sha256_hex};
use yat_tracer::private_file::{is_staged_name, read_regular_file, ReadFileError, StagedFile};

use crate::error::NodeError;

pub struct BlobStore {
    memory: Mutex<MemoryCache>,
    disk: Option<DiskCache>,
}

impl BlobStore {
    /// A store holding up to `max_memory_bytes` in memory, and up to `max_disk_bytes` in
    /// `disk_dir` if given (created when missing).
    pub fn new(
        max_memory_bytes: u64,
        disk_dir: Option<&Path>,
        max_disk_bytes: u64,
    ) -> std::io::Result<Self> {
        Ok(Self {
            memory: Mutex::new(MemoryCache::new(max_memory_bytes)),
            disk: disk_dir
                .map(|dir| DiskCache::open(dir, max_disk_bytes))
                .transpose()?,
        })
    }

    pub fn contains(&self, hash: &str) -> bool {
        self.memory.lock().unwrap().contains(hash)
            || self.disk.as_ref().is_some_and(|d| d.contains(hash))
    }

    /// Distinct blobs held in memory or on disk.
    pub fn len(&self) -> usize {
        let memory = self.memory.lock().unwrap();
        match &self.disk {
            Some(disk) => {
                let disk = disk.entries.lock().unwrap();
                let memory_only = memory.map.keys().filter(|h| !disk.map.contains_key(*h));
                disk.map.len() + memory_only.count()
            }
            None => memory.map.len(),
        }
    }

    /// Bytes held in memory, and in the cache folder when there is one.
    pub fn held_bytes(&self) -> HeldBytes {
        HeldBytes {
            memory: self.memory.lock().unwrap().bytes,
            disk: self.disk.as_ref().map(|d| d.entries.lock().unwrap().bytes),
        }
    }

    /// The blob's bytes, from memory or from disk. A disk file whose content no longer hashes
    /// to its name is dropped and reported missing.
    pub fn get(&self, hash: &str) -> std::io::Result<Option<Arc<[u8]>>> {
        if let Some(bytes) = self.memory.lock().unwrap().get(hash) {
            return Ok(Some(bytes));
        }
        let Some(disk) = &self.disk else {
            return Ok(None);
        };
        let Some(bytes) = disk.read(hash)? else {
            return Ok(None);
        };
        self.memory.lock().unwrap().insert(hash, bytes.clone());
        Ok(Some(bytes))
    }

    /// Stores a blob whose hash the caller has verified; refused when it cannot fit the cache
    /// folder at all.
    pub fn insert(&self, hash: &str, bytes: Arc<[u8]>) -> Result<(), NodeError> {
        debug_assert!(is_sha256_hex(hash));
        if let Some(disk) = &self.disk {
            disk.write(hash, &bytes)?;
        }
        self.memory.lock().unwrap().insert(hash, bytes);
        Ok(())
    }
}

/// What a [`BlobStore`] holds, in bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HeldBytes {
    pub memory: u64,
    /// `None` without a cache folder.
    pub disk: Option<u64>,
}

/// Blobs in memory, evicted least recently used first beyond a byte budget. A blob larger than
/// the whole budget is still kept until the next insertion, so a render can use it.
struct MemoryCache {
    map: HashMap<String, (Arc<[u8]>, u64)>,
    bytes: u64,
    max_bytes: u64,
    clock: u64,
}

impl MemoryCache {
    fn new(max_bytes: u64) -> Self {
        Self {
            map: HashMap::new(),
            bytes: 0,
            max_bytes,
            clock: 0,
        }
    }

    fn contains(&self, hash: &str) -> bool {
        self.map.contains_key(hash)
    }

    fn get(&mut self, hash: &str) -> Option<Arc<[u8]>> {
        self.clock += 1;
        let clock = self.clock;
        self.map.get_mut(hash).map(|(bytes, used)| {
            *used = clock;
            bytes.clone()
        })
    }

    fn insert(&mut self, hash: &str, bytes: Arc<[u8]>) {
        self.clock += 1;
        let size = bytes.len() as u64;
        if let Some((old, _)) = self.map.insert(hash.to_string(), (bytes, self.clock)) {
            self.bytes -= old.len() as u64;
        }
        self.bytes += size;
        while self.bytes > self.max_bytes && self.map.len() > 1 {
            let oldest = self
                .map
                .iter()
                .filter(|(h, _)| h.as_str() != hash)
                .min_by_key(|(_, (_, used))| *used)
                .map(|(h, _)| h.clone())
                .expect("more than one blob");
            let (evicted, _) = self.map.remove(&oldest).expect("present");
            self.bytes -= evicted.len() as u64;
        }
    }
}

/// Blobs as files named by their digest in one folder, within a byte budget.
struct DiskCache {
    dir: PathBuf,
    entries: Mutex<DiskEntries>,
}

/// The files in the folder: size and last use of each, their total, the budget.
struct DiskEntries {
    map: HashMap<String, (u64, u64)>,
    bytes: u64,
    max_bytes: u64,
    clock: u64,
}

impl DiskEntries {
    fn add(&mut self, hash: &str, size: u64) {
        self.clock += 1;
        if let Some((old, _)) = self.map.insert(hash.to_string(), (size, self.clock)) {
            self.bytes -= old;
        }
        self.bytes += size;
    }

    fn remove(&mut self, hash: &str) {
        if let Some((size, _)) = self.map.remove(hash) {
            self.bytes -= size;
        }
    }

    /// The size of `hash`'s file, marked as used now.
    fn touch(&mut self, hash: &str) -> Option<u64> {
        self.clock += 1;
        let clock = self.clock;
        self.map.get_mut(hash).map(|(size, used)| {
            *used = clock;
            *size
        })
    }

    fn least_recently_used(&self) -> Option<String> {
        let oldest = self.map.iter().min_by_key(|(_, (_, used))| *used);
        oldest.map(|(hash, _)| hash.clone())
    }
}

impl DiskCache {
    fn open(dir: &Path, max_bytes: u64) -> std::io::Result<Self> {
        make_private_folder(dir)?;
        let mut entries = DiskEntries {
            map: HashMap::new(),
            bytes: 0,
            max_bytes,
            clock: 0,
        };
        let mut found: Vec<(std::time::SystemTime, String, u64)> = Vec::new();
        for entry in std::fs::read_dir(dir)? {
            let entry = entry?;
            let Some(name) = entry.file_name().to_str().map(str::to_string) else {
                continue;
            };
            // Not followed: a symbolic link is not a regular file here.
            let metadata = entry.metadata()?;
            if is_staged_name(&name) && metadata.is_file() {
                // Left by a crash in the middle of a write.
                std::fs::remove_file(entry.path())?;
            } else if is_sha256_hex(&name) && metadata.is_file() {
                found.push((metadata.modified()?, name, metadata.len()));
            }
        }
        // Oldest first, so the files written last count as the most recently used.
        found.sort();
        for (_, hash, size) in found {
            entries.add(&hash, size);
        }
        let cache = Self {
            dir: dir.to_path_buf(),
            entries: Mutex::new(entries),
        };
        cache.evict_for(0)?;
        Ok(cache)
    }

    fn contains(&self, hash: &str) -> bool {
        self.entries.lock().unwrap().map.contains_key(hash)
    }

    fn read(&self, hash: &str) -> std::io::Result<Option<Arc<[u8]>>> {
        let Some(size) = self.entries.lock().unwrap().touch(hash) else {
            return Ok(None);
        };
        let path = self.dir.join(hash);
        match read_regular_file(&path, size) {
            Ok(Some(bytes)) if sha256_hex(&bytes) == hash => Ok(Some(bytes.into())),
            Ok(Some(_)) => {
                tracing::warn!("cache file {} is corrupt; dropping it", path.display());
                self.drop_entry(hash)?;
                Ok(None)
            }
            Ok(None) => {
                self.entries.lock().unwrap().remove(hash);
                Ok(None)
            }
            Err(ReadFileError::Io(e)) => Err(e),
            Err(e) => {
                tracing::warn!("cache file {}: {e}; dropping it", path.display());
                self.drop_entry(hash)?;
                Ok(None)
            }
        }
    }

    /// Forgets an entry and deletes what is under its name (a file or a link, never what a link
    /// points to).
    fn drop_entry(&self, hash: &str) -> std::io::Result<()> {
        self.entries.lock().unwrap().remove(hash);
        match std::fs::remove_file(self.dir.join(hash)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        }
    }

    /// Deletes the least recently used files until `more` bytes fit the budget.
    fn evict_for(&self, more: u64) -> std::io::Result<()> {
        loop {
            let oldest = {
                let entries = self.entries.lock().unwrap();
                if entries.bytes + more <= entries.max_bytes {
                    return Ok(());
                }
                entries.least_recently_used()
            };
            let Some(oldest) = oldest else {
                return Ok(());
            };
            self.drop_entry(&oldest)?;
        }
    }

    /// Writes through a temporary file and a rename, so a crash never leaves a partial blob
    /// under a valid name.
    fn write(&self, hash: &str, bytes: &[u8]) -> Result<(), NodeError> {
        if self.contains(hash) {
            return Ok(());
        }
        let size = bytes.len() as u64;
        let budget = self.entries.lock().unwrap().max_bytes;
        if size > budget {
            return Err(NodeError::CacheFull {
                hash: hash.to_string(),
                size,
                budget,
            });
        }
        self.evict_for(size).map_err(NodeError::BlobCache)?;
        StagedFile::write(&self.dir.join(hash), |out| out.write_all(bytes))
            .and_then(StagedFile::commit)
            .map_err(NodeError::BlobCache)?;
        self.entries.lock().unwrap().add(hash, size);
        Ok(())
    }
}

/// Creates `dir` (mode 0700) or makes an existing one private; refuses what is not a folder or
/// what cannot be made private (another user's).
fn make_private_folder(dir: &Path) -> std::io::Result<()> {
    std::fs::DirBuilder::new()
        .recursive(true)
        .mode(0o700)
        .create(dir)?;
    let metadata = std::fs::symlink_metadata(dir)?;
    if !metadata.is_dir() {
        return Err(std::io::Error::other("not a folder (a symbolic link?)"));
    }
    if metadata.permissions().mode() & 0o077 != 0 {
        std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o700)).map_err(|e| {
            std::io::Error::new(
                e.kind(),
                format!("other users may use it and it cannot be made private: {e}"),
            )
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blob(n: usize, fill: u8) -> (String, Arc<[u8]>) {
        let bytes = vec![fill; n];
        (sha256_hex(&bytes), bytes.into())
    }

    #[test]
    fn memory_cache_evicts_least_recently_used_beyond_its_budget() {
        let store = BlobStore::new(250, None, 0).unwrap();
        let (a, ba) = blob(100, 1);
        let (b, bb) = blob(100, 2);
        let (c, bc) = blob(100, 3);
        store.insert(&a, ba.clone()).unwrap();
        store.insert(&b, bb).unwrap();
        assert_eq!(store.get(&a).unwrap().as_deref(), Some(&ba[..]));
        store.insert(&c, bc).unwrap();
        assert!(store.contains(&a) && store.contains(&c));
        assert!(!store.contains(&b), "b was the least recently used");
        assert_eq!(store.len(), 2);
    }

    #[test]
    fn disk_cache_survives_a_restart_and_drops_corrupt_files() {
        let dir = tempfile::tempdir().unwrap();
        let (a, ba) = blob(1000, 7);
        let (b, bb) = blob(10, 8);
        {
            let store = BlobStore::new(1 << 20, Some(dir.path()), 1 << 20).unwrap();
            store.insert(&a, ba.clone()).unwrap();
            store.insert(&b, bb).unwrap();
        }
        std::fs::write(dir.path().join(&b), b"tampered").unwrap();
        // What a crash in the middle of a write leaves: gone when the cache opens.
        let leftover = dir.path().join(format!(".{a}.0123456789abcdef.tmp"));
        std::fs::write(&leftover, b"partial").unwrap();
        let store = BlobStore::new(1 << 20, Some(dir.path()), 1 << 20).unwrap();
        assert!(!leftover.exists());
        assert!(store.contains(&a));
        assert_eq!(store.get(&a).unwrap().as_deref(), Some(&ba[..]));
        assert!(store.get(&b).unwrap().is_none());
        assert!(!store.contains(&b));
        assert_eq!(store.len(), 1);
    }

    #[test]
    fn disk_cache_is_private_bounded_and_reads_only_regular_files() {
        use std::os::unix::fs::MetadataExt;
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("cache");
        std::fs::create_dir(&folder).unwrap();
        std::fs::set_permissions(&folder, std::fs::Permissions::from_mode(0o777)).unwrap();
        let store = BlobStore::new(0, Some(&folder), 2500).unwrap();
        assert_eq!(std::fs::metadata(&folder).unwrap().mode() & 0o777, 0o700);

        let blobs: Vec<_> = (1..=3).map(|i| blob(1000, i)).collect();
        for (hash, bytes) in &blobs {
            store.insert(hash, bytes.clone()).unwrap();
            assert_eq!(
                std::fs::metadata(folder.join(hash)).unwrap().mode() & 0o777,
                0o600
            );
        }
        assert!(!store.contains(&blobs[0].0), "the oldest file made room");
        let on_disk: u64 = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().metadata().unwrap().len())
            .sum();
        assert_eq!(on_disk, 2000, "within the 2500-byte budget");
        let (big, big_bytes) = blob(3000, 9);
        let full = store.insert(&big, big_bytes).unwrap_err();
        assert!(matches!(full, NodeError::CacheFull { .. }), "{full}");
        assert!(full.to_string().starts_with("cache full"));
        // The memory cache (budget 0) now holds only this one: the others come from disk.
        let (tiny, tiny_bytes) = blob(10, 10);
        store.insert(&tiny, tiny_bytes).unwrap();

        // A blob's name swapped for a link to another file is not followed.
        let (linked, _) = &blobs[1];
        let secret = dir.path().join("secret");
        std::fs::write(&secret, [2u8; 1000]).unwrap();
        std::fs::remove_file(folder.join(linked)).unwrap();
        std::os::unix::fs::symlink(&secret, folder.join(linked)).unwrap();
        assert!(store.get(linked).unwrap().is_none());
        assert!(secret.exists(), "the link's target is left alone");
        // A file of another size is dropped without reading.
        let (short, _) = &blobs[2];
        std::fs::write(folder.join(short), b"short").unwrap();
        assert!(store.get(short).unwrap().is_none());
        assert_eq!(store.len(), 1);
    }
}
