//! What a worker is started with, as plain values (the `yat worker` flags map onto it), and the
//! defaults of its limits, which the flags' `--help` shows.

use std::path::PathBuf;
use std::time::Duration;

use tonic::transport::{Certificate, Identity};
use yat_tracer::budget::BuildBudget;

/// Bytes in a MiB, the unit of the size flags.
pub const MIB: u64 = 1 << 20;

/// The limits' defaults, shared by `yat worker`'s flags and [`WorkerConfig::default`].
pub mod defaults {
    /// Largest scene file accepted.
    pub const MAX_BLOB_MIB: u64 = 2048;
    /// Scene files kept in memory.
    pub const MEMORY_CACHE_MIB: u64 = 4096;
    /// Scene files kept in the cache folder.
    pub const CACHE_DIR_MIB: u64 = 10240;
    /// Bytes of unfinished uploads held at once, all connections together.
    pub const UPLOAD_BUDGET_MIB: u64 = 1024;
    /// How long units already rendering may take to finish after SIGTERM. Kubernetes waits 30 s
    /// before it kills a pod, so the worker is done well before.
    pub const DRAIN_SECONDS: u64 = 20;
    /// How long a PutBlob stream may go without a chunk.
    pub const BLOB_IDLE_SECONDS: u64 = 30;
    /// How long a connection may go without receiving a byte. The worker pings every peer every
    /// 10 s (HTTP/2 keepalive) and a live peer answers, so only dead or silent peers reach it.
    pub const CONNECTION_IDLE_SECONDS: u64 = 60;
    /// The longest a request may take, whatever it is (a huge scene's build included).
    pub const REQUEST_TIMEOUT_SECONDS: u64 = 3600;
    /// Connections served at once; further ones wait in the listen backlog. The worker lowers
    /// it to what its descriptor limit leaves room for.
    pub const MAX_CONNECTIONS: usize = 256;
    /// How long a new connection has to send a request that passes the token check.
    pub const HANDSHAKE_SECONDS: u64 = 10;
    /// Connections from one address (an IPv6 /64) that have not authenticated yet.
    pub const MAX_UNAUTHENTICATED_PER_ADDRESS: usize = 8;

    /// Connections that have not authenticated yet, all addresses together: a quarter of the
    /// connection cap, so strangers cannot take the slots of token holders.
    pub fn max_unauthenticated(max_connections: usize) -> usize {
        (max_connections / 4).max(1)
    }
    /// Requests served at once on one connection (a coordinator keeps 2 per render thread).
    pub const MAX_STREAMS_PER_CONNECTION: u32 = 256;

    /// Units waiting for a render thread, beyond which RenderUnit is refused: enough for a few
    /// coordinators keeping two units per thread in flight.
    pub fn max_queued_units(threads: usize) -> usize {
        4 * threads + 16
    }
}

pub struct WorkerConfig {
    /// Units rendered at the same time (at least one).
    pub threads: usize,
    /// Keep received scene files in this folder too, so they survive a restart.
    pub cache_dir: Option<PathBuf>,
    /// Bytes of scene files the cache folder holds (least recently used deleted first).
    pub cache_dir_bytes: u64,
    /// Scene files kept in memory, in bytes (least recently used dropped first).
    pub memory_cache_bytes: u64,
    /// Largest scene file accepted, in bytes.
    pub max_blob_bytes: u64,
    /// Bytes of unfinished uploads held at once; an upload that would pass it is refused.
    pub upload_budget_bytes: u64,
    /// Units waiting for a render thread at most; more are refused.
    pub max_queued_units: usize,
    /// After the shutdown signal, how long units already rendering may take to finish.
    pub drain: Duration,
    /// Network limits: connections, streams, timeouts.
    pub network: NetworkLimits,
    /// Refuse requests that do not carry this token.
    pub token: Option<String>,
    /// Serve TLS with this certificate and key.
    pub tls: Option<Identity>,
    /// What a scene may cost to parse and build (bytes, Include visits, primitives, texels).
    pub build_budget: BuildBudget,
    /// With TLS, accept only clients whose certificate this CA issued.
    pub tls_client_ca: Option<Certificate>,
    /// Serve beyond loopback without a token or client certificates.
    pub insecure: bool,
    /// Testing aid: a pause before each unit, to make a worker slow on purpose.
    pub throttle: Duration,
}

/// How many connections and requests a worker serves at once, how many of those may be
/// strangers still, and when it gives up on a silent or unauthenticated peer.
#[derive(Clone, Debug)]
pub struct NetworkLimits {
    pub max_connections: usize,
    /// Connections not yet authenticated, in total; `None`: [`defaults::max_unauthenticated`]
    /// of the connection cap in force.
    pub max_unauthenticated: Option<usize>,
    pub max_unauthenticated_per_address: usize,
    pub handshake_timeout: Duration,
    pub max_streams_per_connection: u32,
    pub connection_idle: Duration,
    pub blob_idle: Duration,
    pub request_timeout: Duration,
}

impl Default for NetworkLimits {
    fn default() -> Self {
        Self {
            max_connections: defaults::MAX_CONNECTIONS,
            max_unauthenticated: None,
            max_unauthenticated_per_address: defaults::MAX_UNAUTHENTICATED_PER_ADDRESS,
            handshake_timeout: Duration::from_secs(defaults::HANDSHAKE_SECONDS),
            max_streams_per_connection: defaults::MAX_STREAMS_PER_CONNECTION,
            connection_idle: Duration::from_secs(defaults::CONNECTION_IDLE_SECONDS),
            blob_idle: Duration::from_secs(defaults::BLOB_IDLE_SECONDS),
            request_timeout: Duration::from_secs(defaults::REQUEST_TIMEOUT_SECONDS),
        }
    }
}

/// One render thread, no cache folder, no token or TLS, and the default limits.
impl Default for WorkerConfig {
    fn default() -> Self {
        Self {
            threads: 1,
            cache_dir: None,
            cache_dir_bytes: defaults::CACHE_DIR_MIB * MIB,
            memory_cache_bytes: defaults::MEMORY_CACHE_MIB * MIB,
            max_blob_bytes: defaults::MAX_BLOB_MIB * MIB,
            upload_budget_bytes: defaults::UPLOAD_BUDGET_MIB * MIB,
            max_queued_units: defaults::max_queued_units(1),
            drain: Duration::from_secs(defaults::DRAIN_SECONDS),
            network: NetworkLimits::default(),
            token: None,
            tls: None,
            tls_client_ca: None,
            insecure: false,
            build_budget: BuildBudget::default(),
            throttle: Duration::ZERO,
        }
    }
}
