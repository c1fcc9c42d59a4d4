//! The `yat` command: render (in-process or over workers), worker, check, export-luxcore.

mod check;
mod checkpoint;
mod cli;
mod distributed;
mod export_cmd;
mod interim;
mod manifest;
mod render_cmd;
mod shutdown;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "yat",
    version,
    about = "YAT: a path tracer for LuxRender scenes, on one machine or many"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene in-process, or over gRPC workers with --workers / --local-workers.
    Render(render_cmd::RenderArgs),
    /// Serve renders to a coordinator over gRPC.
    Worker(cli::worker::WorkerArgs),
    /// Parse a scene and report what it contains, without rendering.
    Check(check::CheckArgs),
    /// Write a scene as LuxCoreRender SDL and PLY meshes (for side-by-side benchmarks).
    ExportLuxcore(export_cmd::ExportArgs),
}

fn main() -> std::process::ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_env("YAT_LOG")
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn")),
        )
        .with_writer(std::io::stderr)
        .init();
    let result = match Cli::parse().command {
        Command::Render(args) => render_cmd::run(args),
        Command::Worker(args) => cli::worker::run(args),
        Command::Check(args) => check::run(args),
        Command::ExportLuxcore(args) => export_cmd::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e:?}");
            let interrupted = e.is::<checkpoint::Interrupted>();
            std::process::ExitCode::from(if interrupted {
                checkpoint::INTERRUPTED_EXIT_CODE as u8
            } else {
                1
            })
        }
    }
}
