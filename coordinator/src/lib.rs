//! YAT's coordinator as a library; the `yat` binary (`main.rs`) only parses the command line
//! and dispatches to [`cli`].
//!
//! A render goes: [`scene`] loads the scene, [`cli::render`] makes a [`job`] of it (settings,
//! outputs, the [`checkpoint`] and the [`interim`] outputs, the scene's files by content in
//! [`manifest`]), an executor in [`exec`] renders it (in-process, or over gRPC workers), and
//! [`render_report`] says what it cost; [`status`] serves a live page of it. [`shutdown`] turns Ctrl-C and SIGTERM into a stop. [`isa`] hands the process to a
//! build for the CPU's instruction set when one is installed beside it.

pub mod checkpoint;
pub mod cli;
pub mod cpus;
pub mod exec;
pub mod interim;
pub mod isa;
pub mod job;
pub mod logging;
pub mod manifest;
pub mod render_report;
pub mod sanitize;
pub mod scene;
pub mod shutdown;
pub mod status;
