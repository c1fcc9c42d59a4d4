//! The `yat` command: render (in-process or over workers), worker, check.

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "yat", version, about = "YAT: a path tracer for LuxRender scenes, on one machine or many")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Parse a scene and report what it contains, without rendering.
    Check {
        /// The main .lxs file.
        scene: std::path::PathBuf,
    },
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { scene } => {
            anyhow::bail!("check {} is not implemented yet", scene.display())
        }
    }
}
