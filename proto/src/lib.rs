//! YAT's gRPC protocol: the messages and the `RenderNode` service generated from
//! `render.proto`, and what both ends of a connection share: the protocol version, conversions
//! between the wire messages and the tracer's types, the sample-buffer encoding, content hashes,
//! the token check, the drain signal and the network flags.

pub mod auth;
pub mod convert;
pub mod drain;
pub mod flags;
pub mod hash;

/// The generated messages, client and server of `render.proto`.
pub mod pb {
    tonic::include_proto!("yat.render.v1");
}

pub use pb::render_node_client::RenderNodeClient;
pub use pb::render_node_server::{RenderNode, RenderNodeServer};

/// The version of `render.proto` this build speaks. Bump it on any incompatible change.
pub const PROTOCOL_VERSION: u32 = 8;

/// Bytes of a blob sent in one `BlobChunk`.
pub const BLOB_CHUNK_BYTES: usize = 1 << 20;

/// Default ceiling on one decoded gRPC message: a chunk, or the reply of a 64x64 tile (its
/// sample buffer of 64 KiB and up to 4 MiB of light splats, `MAX_SPLAT_PIXELS`), fit with a
/// margin; a hostile peer cannot make either end buffer more.
pub const DEFAULT_MAX_MESSAGE_BYTES: usize = 8 << 20;
