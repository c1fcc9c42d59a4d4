//! The `yat` subcommands: each maps its flags onto the library's plain types and runs.

pub mod budget;
pub mod check;
pub mod distributed;
pub mod export;
pub mod latlong;
pub mod render;
pub mod seconds;
pub mod worker;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "yat",
    version,
    about = "YAT: a path tracer for LuxRender scenes, on one machine or many"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Render a scene in-process, or over gRPC workers with --workers / --local-workers.
    Render(Box<render::RenderArgs>),
    /// Serve renders to a coordinator over gRPC.
    Worker(Box<worker::WorkerArgs>),
    /// Parse a scene and report what it contains, without rendering.
    Check(check::CheckArgs),
    /// Write a scene as LuxCoreRender SDL and PLY meshes (for side-by-side benchmarks).
    ExportLuxcore(export::ExportArgs),
}
