//! The render node: a gRPC server that receives a scene as content-addressed blobs, builds it
//! once, and renders work units for coordinators. [`serve`] runs one on a listener the caller
//! bound until a shutdown future the caller passes resolves (`yat worker` binds its `--listen`
//! address and passes Ctrl-C/SIGTERM; tests bind port 0 and pass what they like).

mod admission;
mod availability;
mod blobs;
mod config;
mod connection;
mod descriptors;
mod error;
mod grpc;
mod loaded_scene;
mod log_limit;
mod node;
mod pool;
mod scenes;
mod server;
mod upload;

pub use config::{defaults, NetworkLimits, WorkerConfig, MIB};
pub use error::{NodeError, ServeError};
pub use server::{serve, Worker};
