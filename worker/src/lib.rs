//! The render node: a gRPC server that receives a scene as content-addressed blobs, builds it
//! once, and renders work units for coordinators. [`serve`] runs one on a listener the caller
//! bound until a shutdown future the caller passes resolves (`yat worker` binds its `--listen`
//! address and passes Ctrl-C/SIGTERM; tests bind port 0 and pass what they like).
//!
//! Two modules are public for the coordinator's status page too: [`prometheus_text`] (the
//! Prometheus text format, which the worker's `/metrics` writes) and [`http`] (the bounded
//! HTTP/1 server loop both serve on).

mod admission;
mod availability;
mod blobs;
mod config;
mod connection;
mod descriptors;
mod error;
mod grpc;
pub mod http;
mod loaded_scene;
mod log_limit;
mod metrics;
mod metrics_server;
mod node;
mod pool;
pub mod prometheus_text;
mod scenes;
mod server;
mod upload;

pub use config::{defaults, NetworkLimits, WorkerConfig, MIB};
pub use error::{NodeError, ServeError};
pub use server::{serve, Worker};
