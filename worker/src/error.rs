//! The worker's errors: a request's ([`NodeError`], which the gRPC layer maps to the status
//! codes `render.proto` documents) and starting or running the server ([`ServeError`]).

use std::net::SocketAddr;
use std::path::PathBuf;

use yat_proto::convert::WireError;
use yat_proto::PROTOCOL_VERSION;
use yat_tracer::parse::ParseError;
use yat_tracer::render::BuildError;

/// Why the node refused or failed a request.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    #[error(
        "protocol version mismatch: this worker speaks version {PROTOCOL_VERSION}, \
         the client ({client}) version {version}"
    )]
    ProtocolVersion { client: String, version: u32 },
    /// A message that does not describe a valid render, unit or file.
    #[error(transparent)]
    Wire(#[from] WireError),
    #[error("\"{path}\": malformed sha256 \"{sha256}\"")]
    MalformedHash { path: String, sha256: String },
    #[error("empty blob stream")]
    EmptyBlobStream,
    #[error("a blob's first chunk must name its sha256 (64 lowercase hex digits)")]
    UnnamedBlob,
    #[error(
        "blob uploads in progress hold {held} bytes; {more} more would pass this worker's \
         budget of {budget} bytes: try again later"
    )]
    UploadBudget { held: u64, more: u64, budget: u64 },
    #[error("blob {hash}: no chunk for {seconds} s, upload abandoned")]
    BlobStalled { hash: String, seconds: u64 },
    #[error("blob {hash} has {size} bytes; this worker accepts at most {max}")]
    BlobTooLarge { hash: String, size: u64, max: u64 },
    #[error("blob {hash}: more bytes than the declared {size}")]
    BlobTooLong { hash: String, size: u64 },
    #[error("blob {hash}: received {received} bytes of the declared {size}")]
    BlobTooShort {
        hash: String,
        size: u64,
        received: u64,
    },
    #[error("blob hash mismatch: declared {declared}, content hashes to {actual}")]
    BlobHashMismatch { declared: String, actual: String },
    #[error("blob {sha256} (\"{path}\") is missing: upload it first")]
    BlobMissing { sha256: String, path: String },
    #[error(
        "cache full: blob {hash} has {size} bytes, more than the cache folder's budget of \
         {budget} bytes"
    )]
    CacheFull {
        hash: String,
        size: u64,
        budget: u64,
    },
    #[error("blob cache: {0}")]
    BlobCache(#[source] std::io::Error),
    #[error("{path}: {source}")]
    SceneParse {
        path: String,
        source: Box<ParseError>,
    },
    #[error("{path}: {source}")]
    SceneBuild { path: String, source: BuildError },
    #[error("scene {0} is not loaded here: load it again")]
    SceneNotLoaded(String),
    #[error("{max} units are already waiting for a render thread: try again later")]
    QueueFull { max: usize },
    /// The worker is draining: the request was not worked on.
    #[error("worker draining: {0} refused")]
    Draining(String),
    /// The caller stopped waiting; nobody reads this error.
    #[error("unit {0} cancelled by its caller")]
    UnitCancelled(u32),
    #[error("unit {0} panicked")]
    UnitPanicked(u32),
    #[error("render thread vanished")]
    RenderThreadVanished,
    /// The task storing a blob failed (it panicked).
    #[error("{0}")]
    BlobTask(#[source] tokio::task::JoinError),
    /// The task building a scene failed (it panicked).
    #[error("scene build failed: {0}")]
    BuildTask(#[source] tokio::task::JoinError),
}

/// Why the worker could not start or stopped serving.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    #[error("cannot use the cache folder {}", .0.display())]
    CacheFolder(PathBuf, #[source] std::io::Error),
    #[error("cannot create the blob cache")]
    Cache(#[source] std::io::Error),
    #[error(
        "refusing to serve on {address} without a token or TLS client certificates: anyone \
         who reaches this port could use this worker. Give --token-file PATH (or YAT_TOKEN), or \
         --tls-cert, --tls-key and --tls-client-ca, or --insecure to serve anyway"
    )]
    Exposed { address: SocketAddr },
    #[error(
        "refusing to serve metrics on {address} without a token: anyone who reaches this port \
         could read them. Give --token-file PATH (or YAT_TOKEN), a loopback --metrics-addr, or \
         --insecure to serve anyway"
    )]
    MetricsExposed { address: SocketAddr },
    #[error("cannot read or raise the process's file descriptor limit")]
    DescriptorLimit(#[source] std::io::Error),
    #[error(
        "the file descriptor limit leaves no room for connections once the descriptors open \
         and {} kept for files are counted: raise it (ulimit -n)",
        crate::descriptors::DESCRIPTOR_HEADROOM
    )]
    NoRoomForConnections,
    #[error("cannot read the listener's address")]
    Listener(#[source] std::io::Error),
    #[error(transparent)]
    ThreadPool(#[from] rayon::ThreadPoolBuildError),
    #[error("invalid TLS certificate or key")]
    Tls(#[source] tonic::transport::Error),
    #[error("the gRPC server failed")]
    Server(#[source] tonic::transport::Error),
}
