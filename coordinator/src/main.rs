//! The `yat` command: parses the command line and dispatches to the subcommand (`yat::cli`).
//! Started under the name `luxconsole`, it reads its command line as `yat luxconsole`'s.

use std::ffi::OsString;
use std::process::ExitCode;

use clap::Parser;
use yat::cli::luxconsole::{self, LUXCONSOLE};
use yat::cli::{self, Cli, Command};
use yat::logging;
use yat::shutdown::{Interrupted, INTERRUPTED_EXIT_CODE};

fn main() -> ExitCode {
    let mut args: Vec<OsString> = std::env::args_os().collect();
    let as_luxconsole = args
        .first()
        .is_some_and(|argv0| luxconsole::is_luxconsole_name(argv0));
    if as_luxconsole {
        args.insert(1, LUXCONSOLE.into());
    }
    let command = Cli::parse_from(args).command;
    // A worker is a server: its start, its sessions and its drain are worth a line each.
    logging::init(match &command {
        Command::Worker(_) => "warn,yat_worker=info",
        Command::Luxconsole(args) => args.log_filter(),
        _ => "warn",
    });
    let result = run(command, as_luxconsole);
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

fn run(command: Command, as_luxconsole: bool) -> anyhow::Result<()> {
    if as_luxconsole {
        luxconsole::start_isa()
    } else {
        yat::isa::start()
    }
    .map_err(anyhow::Error::msg)?;
    match command {
        Command::Render(args) => cli::render::run(*args).map(drop),
        Command::Worker(args) => cli::worker::run(*args),
        Command::Check(args) => cli::check::run(args),
        Command::ExportLuxcore(args) => cli::export::run(args),
        Command::Luxconsole(args) => luxconsole::run(args),
    }
}
