//! `yat worker`: serve renders to coordinators on `--listen` (and the worker's Prometheus
//! metrics on `--metrics-addr`) until Ctrl-C or SIGTERM, then drain (a second signal stops at
//! once).

use std::io::Write;
use std::net::{Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::time::Duration;

use yat_proto::flags::{ServerTlsFlags, TokenFlag};
use yat_worker::{defaults, NetworkLimits, Worker, WorkerConfig, MIB};

use super::budget::BudgetArgs;
use crate::cpus::threads_or_usable_cpus;
use crate::shutdown::{signalled, INTERRUPTED_EXIT_CODE};

/// The port `yat worker` listens on by default, and the one a worker address without a port
/// is taken to have (`yat luxconsole -u HOST`).
pub const DEFAULT_PORT: u16 = 7878;

#[derive(clap::Args, Debug)]
pub struct WorkerArgs {
    /// Address to listen on, IP:PORT. Port 0 picks a free port; the first line printed on
    /// stdout, `listening on IP:PORT`, names the real address. Beyond loopback the worker
    /// needs a token or TLS client certificates, or --insecure.
    #[arg(long, default_value_t = SocketAddr::from((Ipv4Addr::LOCALHOST, DEFAULT_PORT)))]
    pub listen: SocketAddr,
    /// Serve the worker's Prometheus metrics at http://IP:PORT/metrics (nothing else), e.g.
    /// 127.0.0.1:7879 or 0.0.0.0:7879 (port 0: any free port; the second line printed on
    /// stdout, `metrics on http://IP:PORT/metrics`, names it). With a token every request must
    /// carry `Authorization: Bearer TOKEN`; beyond loopback a token (or --insecure) is
    /// needed. See docs/status.md.
    #[arg(long, value_name = "IP:PORT")]
    pub metrics_addr: Option<SocketAddr>,
    /// Units rendered at the same time [default: the CPUs this process may use, as its
    /// affinity mask and cgroup quota allow].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Keep received scene files in this folder too, so they survive a restart. It is
    /// created private (0700); an existing folder others may use is made private, or refused
    /// when it is another user's.
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Scene files kept in --cache-dir, in MiB (least recently used deleted first).
    #[arg(long, default_value_t = defaults::CACHE_DIR_MIB)]
    pub cache_dir_mib: u64,
    #[command(flatten)]
    pub token: TokenFlag,
    #[command(flatten)]
    pub tls: ServerTlsFlags,
    /// Serve beyond loopback without a token or TLS client certificates: anyone who reaches
    /// the port can use this worker.
    #[arg(long)]
    pub insecure: bool,
    /// Largest scene file accepted, in MiB (at most --upload-budget-mib).
    #[arg(long, default_value_t = defaults::MAX_BLOB_MIB)]
    pub max_blob_mib: u64,
    /// Scene files kept in memory, in MiB (least recently used dropped first).
    #[arg(long, default_value_t = defaults::MEMORY_CACHE_MIB)]
    pub memory_cache_mib: u64,
    /// Memory all unfinished uploads may hold together, in MiB; an upload that would pass it
    /// fails with RESOURCE_EXHAUSTED.
    #[arg(long, default_value_t = defaults::UPLOAD_BUDGET_MIB)]
    pub upload_budget_mib: u64,
    /// Units waiting for a render thread at most; more fail with RESOURCE_EXHAUSTED
    /// [default: 4 x threads + 16].
    #[arg(long)]
    pub max_queued_units: Option<usize>,
    /// After SIGTERM or Ctrl-C, how long units already rendering may take to finish.
    #[arg(long, default_value_t = defaults::DRAIN_SECONDS)]
    pub drain_seconds: u64,
    /// Connections served at once; more wait until one closes. Lowered to what the file
    /// descriptor limit leaves room for (the limit less the descriptors open at start and 64
    /// kept for files), and said so at start.
    #[arg(long, default_value_t = defaults::MAX_CONNECTIONS)]
    pub max_connections: usize,
    /// Connections that have not yet sent a request with the token, all addresses together;
    /// at the cap, a new one closes the oldest of the address with the most [default: a
    /// quarter of the connection cap].
    #[arg(long)]
    pub max_unauthenticated: Option<usize>,
    /// Connections from one address (an IPv6 /64) that have not yet sent a request with the
    /// token; more are closed at once.
    #[arg(long, default_value_t = defaults::MAX_UNAUTHENTICATED_PER_ADDRESS)]
    pub max_unauthenticated_per_address: usize,
    /// Close a connection that has not sent a request with the token within this many seconds
    /// of its accept (health probes need none; they close sooner).
    #[arg(long, default_value_t = defaults::HANDSHAKE_SECONDS, value_parser = clap::value_parser!(u64).range(1..))]
    pub handshake_seconds: u64,
    /// Requests served at once on one connection.
    #[arg(long, default_value_t = defaults::MAX_STREAMS_PER_CONNECTION)]
    pub max_streams_per_connection: u32,
    /// Close a connection whose peer sends nothing for this many seconds (live peers answer
    /// the worker's pings every 10 s).
    #[arg(long, default_value_t = defaults::CONNECTION_IDLE_SECONDS, value_parser = clap::value_parser!(u64).range(1..))]
    pub connection_idle_seconds: u64,
    /// Fail an upload that sends no chunk for this many seconds.
    #[arg(long, default_value_t = defaults::BLOB_IDLE_SECONDS, value_parser = clap::value_parser!(u64).range(1..))]
    pub blob_idle_seconds: u64,
    /// Fail any request still running after this many seconds.
    #[arg(long, default_value_t = defaults::REQUEST_TIMEOUT_SECONDS, value_parser = clap::value_parser!(u64).range(1..))]
    pub request_timeout_seconds: u64,
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
    let threads = threads_or_usable_cpus(args.threads, "worker");
    let config = WorkerConfig {
        threads,
        cache_dir: args.cache_dir,
        cache_dir_bytes: args.cache_dir_mib.saturating_mul(MIB),
        memory_cache_bytes: args.memory_cache_mib.saturating_mul(MIB),
        max_blob_bytes: args.max_blob_mib.saturating_mul(MIB),
        upload_budget_bytes: args.upload_budget_mib.saturating_mul(MIB),
        max_queued_units: args
            .max_queued_units
            .unwrap_or_else(|| defaults::max_queued_units(threads)),
        drain: Duration::from_secs(args.drain_seconds),
        network: NetworkLimits {
            max_connections: args.max_connections,
            max_unauthenticated: args.max_unauthenticated,
            max_unauthenticated_per_address: args.max_unauthenticated_per_address,
            handshake_timeout: Duration::from_secs(args.handshake_seconds),
            max_streams_per_connection: args.max_streams_per_connection,
            connection_idle: Duration::from_secs(args.connection_idle_seconds),
            blob_idle: Duration::from_secs(args.blob_idle_seconds),
            request_timeout: Duration::from_secs(args.request_timeout_seconds),
        },
        token: args.token.resolve()?,
        tls: args.tls.identity()?,
        tls_client_ca: args.tls.client_ca()?,
        insecure: args.insecure,
        throttle: Duration::from_millis(args.throttle_ms),
        build_budget: args.budget.budget(),
    };
    let insecure = config.insecure;
    let no_token = config.token.is_none();
    // Fails here, before the address is announced, when the cache folder is unusable.
    let worker = Worker::new(config)?;
    worker.check_exposure(args.listen)?;
    if insecure && !args.listen.ip().is_loopback() {
        tracing::warn!(
            "--insecure: listening on {} without a token or client certificates; anyone who \
             reaches this port can use this worker",
            args.listen
        );
    }
    if let Some(address) = args.metrics_addr {
        worker.check_metrics_exposure(address)?;
        if insecure && no_token && !address.ip().is_loopback() {
            tracing::warn!(
                "--insecure: serving metrics on {address} without a token; anyone who reaches \
                 this port can read them"
            );
        }
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
        let worker = match args.metrics_addr {
            Some(address) => {
                let metrics = tokio::net::TcpListener::bind(address).await.map_err(|e| {
                    anyhow::anyhow!("cannot listen on {address} (--metrics-addr): {e}")
                })?;
                let mut stdout = std::io::stdout().lock();
                writeln!(
                    stdout,
                    "metrics on http://{}/metrics",
                    metrics.local_addr()?
                )?;
                stdout.flush()?;
                worker.with_metrics(metrics)
            }
            None => worker,
        };
        worker.serve(listener, first_signal()).await?;
        Ok(())
    })
}

/// Resolves at the first Ctrl-C or SIGTERM, the cue to drain, and makes the second one end the
/// process at once.
async fn first_signal() {
    signalled().await;
    tokio::spawn(async {
        signalled().await;
        tracing::warn!("second signal: stopping without finishing the drain");
        crate::logging::exit(i32::from(INTERRUPTED_EXIT_CODE));
    });
}

/// Watches stdin on a thread of its own and ends the process at end of file.
fn exit_when_stdin_closes() {
    std::thread::spawn(|| {
        let _ = std::io::copy(&mut std::io::stdin().lock(), &mut std::io::sink());
        tracing::info!("standard input closed, exiting");
        crate::logging::exit(0);
    });
}
