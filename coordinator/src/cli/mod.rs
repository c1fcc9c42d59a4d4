//! The `yat` subcommands: each maps its flags onto the library's plain types and runs.

pub mod budget;
pub mod check;
pub mod distributed;
pub mod export;
pub mod latlong;
pub mod luxconsole;
pub mod render;
pub mod seconds;
pub mod worker;

use std::sync::LazyLock;

use clap::{Parser, Subcommand};

/// `yat --version`: the package version and the renderer build, which every machine of a
/// distributed render must share (a coordinator refuses workers of another).
static VERSION: LazyLock<String> = LazyLock::new(|| {
    format!(
        "{} (renderer build {})",
        env!("CARGO_PKG_VERSION"),
        yat_tracer::RENDERER_BUILD
    )
});

#[derive(Parser)]
#[command(
    name = "yat",
    version = VERSION.as_str(),
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
    /// Read LuxRender 1.x's luxconsole command line (threads, output, servers, verbosity, the
    /// scene on standard input...) and render as `yat render` does; `yat luxconsole --help`
    /// lists every luxconsole option and what YAT does with it. The `yat` binary started under
    /// the name `luxconsole` reads its command line so too.
    #[command(disable_help_flag = true)]
    Luxconsole(luxconsole::LuxconsoleArgs),
}
