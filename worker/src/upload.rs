//! One blob as it arrives in chunks: its declared name and size checked before anything is
//! allocated, its bytes checked against both as they come.

use yat_proto::hash::{is_sha256_hex, Sha256Stream};

use crate::error::NodeError;

pub struct BlobUpload {
    hash: String,
    size: u64,
    data: Vec<u8>,
    hasher: Sha256Stream,
}

impl BlobUpload {
    /// An upload of `size` bytes hashing to `hash`, refused unless the hash is well formed and
    /// the size at most `max_size`.
    pub fn begin(hash: String, size: u64, max_size: u64) -> Result<Self, NodeError> {
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
            // The declared size bounds the allocation; the stream may not exceed it.
            data: Vec::with_capacity(size as usize),
            hasher: Sha256Stream::default(),
        })
    }

    /// The next bytes of the blob.
    pub fn push(&mut self, bytes: &[u8]) -> Result<(), NodeError> {
        if (self.data.len() + bytes.len()) as u64 > self.size {
            return Err(NodeError::BlobTooLong {
                hash: self.hash.clone(),
                size: self.size,
            });
        }
        self.hasher.update(bytes);
        self.data.extend_from_slice(bytes);
        Ok(())
    }

    /// The blob's name and bytes, once every declared byte has come and they hash to the name.
    pub fn finish(self) -> Result<(String, Vec<u8>), NodeError> {
        if self.data.len() as u64 != self.size {
            return Err(NodeError::BlobTooShort {
                hash: self.hash,
                size: self.size,
                received: self.data.len() as u64,
            });
        }
        let actual = self.hasher.finish_hex();
        if actual != self.hash {
            return Err(NodeError::BlobHashMismatch {
                declared: self.hash,
                actual,
            });
        }
        Ok((self.hash, self.data))
    }
}
