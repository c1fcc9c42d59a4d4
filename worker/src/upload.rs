//! One blob as it arrives in chunks: its declared name and size checked before anything is
//! allocated, its bytes checked against both as they come. Memory grows with the bytes
//! received, never with the size a peer declares, and every upload in progress draws on one
//! [`UploadBudget`], so many unfinished uploads cannot hold more than the budget together.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use yat_proto::hash::{is_sha256_hex, Sha256Stream};

use crate::error::NodeError;

/// The bytes all uploads in progress may hold together.
#[derive(Clone)]
pub struct UploadBudget {
    held: Arc<AtomicU64>,
    budget: u64,
}

impl UploadBudget {
    pub fn new(budget: u64) -> Self {
        Self {
            held: Arc::new(AtomicU64::new(0)),
            budget,
        }
    }

    /// Bytes held by uploads in progress.
    pub fn held(&self) -> u64 {
        self.held.load(Ordering::Relaxed)
    }

    /// Takes `more` bytes from the budget, or refuses if that would pass it.
    fn take(&self, more: u64) -> Result<(), NodeError> {
        self.held
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |held| {
                held.checked_add(more).filter(|total| *total <= self.budget)
            })
            .map(drop)
            .map_err(|held| NodeError::UploadBudget {
                held,
                more,
                budget: self.budget,
            })
    }

    fn give_back(&self, bytes: u64) {
        self.held.fetch_sub(bytes, Ordering::Relaxed);
    }
}

pub struct BlobUpload {
    hash: String,
    size: u64,
    data: Vec<u8>,
    hasher: Sha256Stream,
    budget: UploadBudget,
    /// Bytes taken from the budget: the buffer's capacity.
    held: u64,
}

impl BlobUpload {
    /// An upload of `size` bytes hashing to `hash`, refused unless the hash is well formed and
    /// the size at most `max_size`.
    pub fn begin(
        hash: String,
        size: u64,
        max_size: u64,
        budget: UploadBudget,
    ) -> Result<Self, NodeError> {
        if !is_sha256_hex(&hash) {
            return Err(NodeError::UnnamedBlob);
        }
        if size > max_size {
            return Err(NodeError::BlobTooLarge {
                hash,
                size,
                max: max_size,
            });
        }
        Ok(Self {
            hash,
            size,
            data: Vec::new(),
            hasher: Sha256Stream::default(),
            budget,
            held: 0,
        })
    }

    /// The blob's declared name.
    pub fn hash(&self) -> &str {
        &self.hash
    }

    /// The next bytes of the blob.
    pub fn push(&mut self, bytes: &[u8]) -> Result<(), NodeError> {
        if (self.data.len() + bytes.len()) as u64 > self.size {
            return Err(NodeError::BlobTooLong {
                hash: self.hash.clone(),
                size: self.size,
            });
        }
        // The buffer doubles as it fills, never past the declared size, and the budget counts
        // its capacity: the memory truly held.
        let capacity = self.data.capacity();
        let needed = self.data.len() + bytes.len();
        if needed > capacity {
            let doubled = (2 * capacity).min(self.size as usize);
            self.data
                .reserve_exact(doubled.max(needed) - self.data.len());
        }
        let grown = (self.data.capacity() - capacity) as u64;
        if let Err(error) = self.budget.take(grown) {
            self.data.shrink_to(capacity);
            return Err(error);
        }
        self.held += grown;
        self.hasher.update(bytes);
        self.data.extend_from_slice(bytes);
        Ok(())
    }

    /// The blob's name and bytes, once every declared byte has come and they hash to the name.
    pub fn finish(mut self) -> Result<(String, Vec<u8>), NodeError> {
        if self.data.len() as u64 != self.size {
            return Err(NodeError::BlobTooShort {
                hash: std::mem::take(&mut self.hash),
                size: self.size,
                received: self.data.len() as u64,
            });
        }
        let actual = std::mem::take(&mut self.hasher).finish_hex();
        if actual != self.hash {
            return Err(NodeError::BlobHashMismatch {
                declared: std::mem::take(&mut self.hash),
                actual,
            });
        }
        Ok((
            std::mem::take(&mut self.hash),
            std::mem::take(&mut self.data),
        ))
    }
}

impl Drop for BlobUpload {
    fn drop(&mut self) {
        self.budget.give_back(self.held);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use yat_proto::hash::sha256_hex;

    #[test]
    fn uploads_share_one_budget_and_give_it_back() {
        let budget = UploadBudget::new(1 << 20);
        let hash = sha256_hex(b"x");
        let mut first = BlobUpload::begin(hash.clone(), 1 << 60, u64::MAX, budget.clone())
            .expect("a huge declared size allocates nothing");
        assert_eq!(budget.held(), 0);
        first.push(&[0; 600 << 10]).unwrap();
        let mut second =
            BlobUpload::begin(hash.clone(), 1 << 60, u64::MAX, budget.clone()).unwrap();
        let refused = second.push(&[0; 600 << 10]).unwrap_err();
        assert!(
            matches!(refused, NodeError::UploadBudget { .. }),
            "{refused}"
        );
        assert!(budget.held() <= 1 << 20);
        drop(first);
        assert_eq!(budget.held(), 0);
        second.push(&[0; 600 << 10]).unwrap();
    }
}
