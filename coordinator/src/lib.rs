//! YAT's coordinator as a library: the `yat` subcommands ([`cli`]), and what a render is made
//! of: the scene and its files by content ([`manifest`]), the checkpoint and the interim
//! outputs, the executors ([`exec`]: in-process, or over gRPC workers), and interrupt handling.
//! The `yat` binary (`main.rs`) only parses the command line and dispatches.

pub mod checkpoint;
pub mod cli;
pub mod exec;
pub mod interim;
pub mod job;
pub mod manifest;
pub mod render_report;
pub mod scene;
pub mod shutdown;
