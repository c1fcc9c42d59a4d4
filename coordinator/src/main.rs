//! The `yat` command: parses the command line and dispatches to the subcommand (`yat::cli`).

use std::process::ExitCode;

use clap::Parser;
use yat::cli::{self, Cli, Command};
use yat::logging;
use yat::shutdown::{Interrupted, INTERRUPTED_EXIT_CODE};

fn main() -> ExitCode {
    let command = Cli::parse().command;
    // A worker is a server: its start, its sessions and its drain are worth a line each.
    logging::init(match command {
        Command::Worker(_) => "warn,yat_worker=info",
        _ => "warn",
    });
    let result = run(command);
    // The log's last lines before the error that ends the process.
    logging::flush();
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

fn run(command: Command) -> anyhow::Result<()> {
    yat::isa::start().map_err(anyhow::Error::msg)?;
    match command {
        Command::Render(args) => cli::render::run(*args),
        Command::Worker(args) => cli::worker::run(*args),
        Command::Check(args) => cli::check::run(args),
        Command::ExportLuxcore(args) => cli::export::run(args),
    }
}
