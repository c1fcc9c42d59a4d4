//! The live status page of a render (`yat render --status-addr IP:PORT`): the image so far,
//! the progress, the settings, the workers and the last events, as an HTML page, as JSON
//! (`/api/status`, documented in docs/status.md) and as Prometheus text (`/metrics`).
//!
//! A leaf the executors call: [`board`] is what they publish into, [`snapshot`] the plain
//! types it holds, [`server`] the HTTP side and [`metrics`] the Prometheus text. Nothing here
//! imports an executor, and nothing the server does can change the render.

pub mod board;
pub mod metrics;
pub mod server;
pub mod snapshot;

pub use board::StatusBoard;
