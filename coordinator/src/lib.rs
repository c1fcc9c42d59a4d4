//! YAT's coordinator as a library; the `yat` binary (`main.rs`) only parses the command line
//! and dispatches to [`cli`].
//!
//! A render goes: [`scene`] loads the scene, the caller ([`cli::render`], a test, a frame loop)
//! makes a request of it and calls [`render::render`], which makes a [`job`] of it (the
//! [`checkpoint`] and the [`interim`] outputs, the scene's files by content in [`manifest`]),
//! has an executor in [`exec`] render it (in-process, or over gRPC workers), writes the image
//! and returns what it cost ([`render_report`]); [`status`] serves a live page of it.
//! [`shutdown`] is the caller's stop, which `yat render` wires to Ctrl-C and SIGTERM. [`isa`]
//! hands the process to a build for the CPU's instruction set when one is installed beside it.
//! [`frames`] is a sequence of scenes one command renders (their files, images and journal).

pub mod checkpoint;
pub mod cli;
pub mod cpus;
pub mod exec;
pub mod frames;
pub mod interim;
pub mod isa;
pub mod job;
pub mod logging;
pub mod manifest;
pub mod render;
pub mod render_report;
pub mod sanitize;
pub mod scene;
pub mod shutdown;
pub mod status;
