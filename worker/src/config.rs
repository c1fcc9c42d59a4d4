//! What a worker is started with, as plain values (the `yat worker` flags map onto it).

use std::path::PathBuf;
use std::time::Duration;

use tonic::transport::Identity;
use yat_tracer::budget::BuildBudget;

pub struct WorkerConfig {
    /// Units rendered at the same time (at least one).
    pub threads: usize,
    /// Keep received scene files in this folder too, so they survive a restart.
    pub cache_dir: Option<PathBuf>,
    /// Scene files kept in memory, in bytes (least recently used dropped first).
    pub memory_cache_bytes: u64,
    /// Largest scene file accepted, in bytes.
    pub max_blob_bytes: u64,
    /// Refuse requests that do not carry this token.
    pub token: Option<String>,
    /// Serve TLS with this certificate and key.
    pub tls: Option<Identity>,
    /// What a scene may cost to parse and build (bytes, Include visits, primitives, texels).
    pub build_budget: BuildBudget,
    /// Testing aid: a pause before each unit, to make a worker slow on purpose.
    pub throttle: Duration,
}
