//! `yat worker`: serve renders to coordinators on `--listen` until Ctrl-C or SIGTERM.

use std::io::Write;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

use yat_proto::flags::{ServerTlsFlags, TokenFlag};
use yat_worker::{Worker, WorkerConfig};

use super::budget::BudgetArgs;

const MIB: u64 = 1 << 20;

#[derive(clap::Args, Debug)]
pub struct WorkerArgs {
    /// Address to listen on, IP:PORT. Port 0 picks a free port; the first line printed on
    /// stdout, `listening on IP:PORT`, names the real address.
    #[arg(long, default_value = "127.0.0.1:7878")]
    pub listen: SocketAddr,
    /// Units rendered at the same time [default: the number of cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Keep received scene files in this folder too, so they survive a restart.
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    #[command(flatten)]
    pub token: TokenFlag,
    #[command(flatten)]
    pub tls: ServerTlsFlags,
    /// Largest scene file accepted, in MiB.
    #[arg(long, default_value_t = 2048)]
    pub max_blob_mib: u64,
    /// Scene files kept in memory, in MiB (least recently used dropped first).
    #[arg(long, default_value_t = 4096)]
    pub memory_cache_mib: u64,
    #[command(flatten)]
    pub budget: BudgetArgs,
    /// Exit when standard input closes: a parent that dies takes its workers with it.
    #[arg(long)]
    pub exit_with_stdin: bool,
    /// Testing aid: pause this many milliseconds before each unit.
    #[arg(long, hide = true, default_value_t = 0)]
    pub throttle_ms: u64,
}

pub fn run(args: WorkerArgs) -> anyhow::Result<()> {
    let config = WorkerConfig {
        threads: args
            .threads
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        cache_dir: args.cache_dir,
        memory_cache_bytes: args.memory_cache_mib * MIB,
        max_blob_bytes: args.max_blob_mib * MIB,
        token: args.token.token,
        tls: args.tls.identity()?,
        throttle: Duration::from_millis(args.throttle_ms),
        build_budget: args.budget.budget(),
    };
    let without_token = config.token.is_none();
    // Fails here, before the address is announced, when the cache folder is unusable.
    let worker = Worker::new(config)?;
    if without_token && !args.listen.ip().is_loopback() {
        tracing::warn!(
            "listening on {} without --token: anyone who reaches this port can use this worker",
            args.listen
        );
    }
    if args.exit_with_stdin {
        exit_when_stdin_closes();
    }

    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(args.listen)
            .await
            .map_err(|e| anyhow::anyhow!("cannot listen on {}: {e}", args.listen))?;
        // The parent of a local worker reads the port from this line: print it first, at once.
        let mut stdout = std::io::stdout().lock();
        writeln!(stdout, "listening on {}", listener.local_addr()?)?;
        stdout.flush()?;
        drop(stdout);
        worker.serve(listener, crate::shutdown::signalled()).await?;
        Ok(())
    })
}

/// Watches stdin on a thread of its own and ends the process at end of file.
fn exit_when_stdin_closes() {
    std::thread::spawn(|| {
        let _ = std::io::copy(&mut std::io::stdin().lock(), &mut std::io::sink());
        tracing::info!("standard input closed, exiting");
        std::process::exit(0);
    });
}
