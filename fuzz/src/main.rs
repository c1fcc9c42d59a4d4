//! `yat-fuzz`: runs a fuzz target for a number of inputs and reports inputs/s and the panics
//! found; exits non-zero if any input panicked.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Parser, Subcommand};
use yat_fuzz::campaign::{self, Report, Settings, Target};
use yat_fuzz::parser_target::{Case, ParserTarget, SeedFolders};
use yat_fuzz::wire_target::{Session, WireTarget};
use yat_fuzz::workspace::{seed_scenes, workspace_root};

#[derive(Parser)]
#[command(
    name = "yat-fuzz",
    about = "Mutation fuzzer for YAT's scene parser and wire message handlers",
    long_about = "Mutation fuzzer for YAT's scene parser and wire message handlers. Runs a \
                  target for --inputs inputs, prints inputs run, inputs/s and each distinct \
                  panic (its location, message and the minimized input saved in --crashes), \
                  and exits with status 1 if any input panicked."
)]
struct Cli {
    #[command(subcommand)]
    target: TargetCommand,
}

#[derive(Subcommand)]
enum TargetCommand {
    /// .lxs scenes (with includes, PLY meshes, images) mutated, parsed, built, one unit rendered.
    Parser {
        #[command(flatten)]
        run: RunArgs,
        /// Seed project scene folder searched for more .lxs seeds (default: $YAT_SEED_SCENES,
        /// else <workspace>/../shared/seed-project/scenes, skipped when absent).
        #[arg(long)]
        seed_scenes: Option<PathBuf>,
    },
    /// Protobuf messages of render.proto and gRPC metadata, mutated and handled as each end does.
    Wire {
        #[command(flatten)]
        run: RunArgs,
    },
}

#[derive(Args)]
struct RunArgs {
    /// Inputs to run.
    #[arg(long, default_value_t = 100_000)]
    inputs: u64,
    /// Seed of the random mutations: the same seed and inputs give the same run.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Folder for the inputs that panicked or ran slow (default: <workspace>/fuzz/crashes).
    #[arg(long)]
    crashes: Option<PathBuf>,
    /// An input running longer than this many seconds is counted and saved as slow.
    #[arg(long, default_value_t = 2.0)]
    slow_seconds: f64,
    /// Print progress every this many inputs (0: never).
    #[arg(long, default_value_t = 50_000)]
    progress: u64,
    /// Seconds spent minimizing the input of each new panic.
    #[arg(long, default_value_t = 20.0)]
    minimize_seconds: f64,
    /// Run this saved input once instead; if it panics, print where and save it minimized
    /// beside it (<name>-min.case or .session).
    #[arg(long)]
    replay: Option<PathBuf>,
}

fn main() -> anyhow::Result<ExitCode> {
    let cli = Cli::parse();
    let report = match cli.target {
        TargetCommand::Parser {
            run,
            seed_scenes: dir,
        } => {
            let root = workspace_root();
            let mut folders = SeedFolders {
                scenes: vec![root.join("scenes")],
                snippets: Some(root.join("fuzz/corpus")),
            };
            folders.scenes.extend(dir.or_else(seed_scenes));
            let mut target = ParserTarget::new(&folders).context("loading the parser seeds")?;
            eprintln!("parser: {} seed scenes", target.seed_count());
            if let Some(path) = &run.replay {
                let bytes = read(path)?;
                let case = Case::decode(&bytes).context("not a saved parser case")?;
                return replay(&target, case, path, &run);
            }
            campaign::run(&mut target, &run.settings())
        }
        TargetCommand::Wire { run } => {
            let mut target = WireTarget::new();
            if let Some(path) = &run.replay {
                let bytes = read(path)?;
                let session = Session::decode(&bytes).context("not a saved wire session")?;
                return replay(&target, session, path, &run);
            }
            campaign::run(&mut target, &run.settings())
        }
    };
    Ok(finish(&report))
}

impl RunArgs {
    fn settings(&self) -> Settings {
        Settings {
            inputs: self.inputs,
            seed: self.seed,
            crash_dir: Some(
                self.crashes
                    .clone()
                    .unwrap_or_else(|| workspace_root().join("fuzz/crashes")),
            ),
            slow: Duration::from_secs_f64(self.slow_seconds),
            progress_every: self.progress,
            minimize_for: Duration::from_secs_f64(self.minimize_seconds),
        }
    }
}

fn read(path: &Path) -> anyhow::Result<Vec<u8>> {
    std::fs::read(path).with_context(|| format!("reading {}", path.display()))
}

/// Runs one saved input; a panicking one is minimized and saved beside it as `<name>-min`.
fn replay<T: Target>(
    target: &T,
    input: T::Input,
    path: &Path,
    run: &RunArgs,
) -> anyhow::Result<ExitCode> {
    let minimize_for = Duration::from_secs_f64(run.minimize_seconds);
    match campaign::replay(target, input, minimize_for) {
        Ok(outcome) => {
            println!("no panic ({} outcome features)", outcome.features.len());
            Ok(ExitCode::SUCCESS)
        }
        Err((location, message, small)) => {
            let stem = path.file_stem().unwrap_or_default().to_string_lossy();
            let saved = target.save(&small, &path.with_file_name(format!("{stem}-min")))?;
            println!("panic at {location}: {message}");
            println!("minimized input: {}", saved.display());
            Ok(ExitCode::FAILURE)
        }
    }
}

fn finish(report: &Report) -> ExitCode {
    print!("{report}");
    if report.findings.is_empty() {
        ExitCode::SUCCESS
    } else {
        println!("{} distinct panics found", report.findings.len());
        ExitCode::FAILURE
    }
}
