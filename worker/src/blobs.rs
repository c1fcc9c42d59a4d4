//! The worker's content-addressed blob cache: scene files received from coordinators, keyed by
//! their SHA-256, held in memory (bounded, least recently used evicted first) and, with a cache
//! folder, on disk so a restarted worker keeps them. A blob's name is a validated hex digest,
//! never a path a peer chose.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use yat_proto::hash::{is_sha256_hex, sha256_hex};

pub struct BlobStore {
    memory: Mutex<MemoryCache>,
    disk: Option<DiskCache>,
}

impl BlobStore {
    /// A store holding up to `max_memory_bytes` in memory, and every blob in `disk_dir` if
    /// given (created when missing).
    pub fn new(max_memory_bytes: u64, disk_dir: Option<&Path>) -> std::io::Result<Self> {
        Ok(Self {
            memory: Mutex::new(MemoryCache::new(max_memory_bytes)),
            disk: disk_dir.map(DiskCache::open).transpose()?,
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
                let known = disk.known.lock().unwrap();
                known.len() + memory.map.keys().filter(|h| !known.contains(*h)).count()
            }
            None => memory.map.len(),
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

    /// Stores a blob whose hash the caller has verified.
    pub fn insert(&self, hash: &str, bytes: Arc<[u8]>) -> std::io::Result<()> {
        debug_assert!(is_sha256_hex(hash));
        if let Some(disk) = &self.disk {
            disk.write(hash, &bytes)?;
        }
        self.memory.lock().unwrap().insert(hash, bytes);
        Ok(())
    }
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

/// Blobs as files named by their digest in one folder.
struct DiskCache {
    dir: PathBuf,
    known: Mutex<HashSet<String>>,
}

impl DiskCache {
    fn open(dir: &Path) -> std::io::Result<Self> {
        std::fs::create_dir_all(dir)?;
        let mut known = HashSet::new();
        for entry in std::fs::read_dir(dir)? {
            if let Some(name) = entry?.file_name().to_str() {
                if is_sha256_hex(name) {
                    known.insert(name.to_string());
                }
            }
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            known: Mutex::new(known),
        })
    }

    fn contains(&self, hash: &str) -> bool {
        self.known.lock().unwrap().contains(hash)
    }

    fn read(&self, hash: &str) -> std::io::Result<Option<Arc<[u8]>>> {
        if !self.contains(hash) {
            return Ok(None);
        }
        let path = self.dir.join(hash);
        let bytes = match std::fs::read(&path) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                self.known.lock().unwrap().remove(hash);
                return Ok(None);
            }
            Err(e) => return Err(e),
        };
        if sha256_hex(&bytes) != hash {
            tracing::warn!("cache file {} is corrupt; dropping it", path.display());
            self.known.lock().unwrap().remove(hash);
            std::fs::remove_file(&path)?;
            return Ok(None);
        }
        Ok(Some(bytes.into()))
    }

    /// Writes through a temporary file and a rename, so a crash never leaves a partial blob
    /// under a valid name.
    fn write(&self, hash: &str, bytes: &[u8]) -> std::io::Result<()> {
        if self.contains(hash) {
            return Ok(());
        }
        let tmp = self.dir.join(format!("{hash}.tmp{}", std::process::id()));
        std::fs::write(&tmp, bytes)?;
        std::fs::rename(&tmp, self.dir.join(hash))?;
        self.known.lock().unwrap().insert(hash.to_string());
        Ok(())
    }
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
        let store = BlobStore::new(250, None).unwrap();
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
            let store = BlobStore::new(1 << 20, Some(dir.path())).unwrap();
            store.insert(&a, ba.clone()).unwrap();
            store.insert(&b, bb).unwrap();
        }
        std::fs::write(dir.path().join(&b), b"tampered").unwrap();
        let store = BlobStore::new(1 << 20, Some(dir.path())).unwrap();
        assert!(store.contains(&a));
        assert_eq!(store.get(&a).unwrap().as_deref(), Some(&ba[..]));
        assert!(store.get(&b).unwrap().is_none());
        assert!(!store.contains(&b));
        assert_eq!(store.len(), 1);
    }
}
