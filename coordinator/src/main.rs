//! The `yat` command: parses the command line and dispatches to the subcommand (`yat::cli`).

use std::process::ExitCode;

use clap::Parser;
use yat::cli::{self, Cli, Command};
use yat::shutdown::{Interrupted, INTERRUPTED_EXIT_CODE};

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_env("YAT_LOG")
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn")),
        )
        .with_writer(std::io::stderr)
        .init();
    if let Err(e) = yat::isa::start() {
        eprintln!("Error: {e}");
        return ExitCode::FAILURE;
    }
    let result = match Cli::parse().command {
        Command::Render(args) => cli::render::run(*args),
        Command::Worker(args) => cli::worker::run(*args),
        Command::Check(args) => cli::check::run(args),
        Command::ExportLuxcore(args) => cli::export::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e:?}");
            ExitCode::from(if e.is::<Interrupted>() {
                INTERRUPTED_EXIT_CODE
            } else {
                1
            })
        }
    }
}
