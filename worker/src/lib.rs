//! The render node: a gRPC server that receives a scene as content-addressed blobs, builds it
//! once, and renders work units for coordinators (`yat worker`).

mod blobs;
mod scenes;
mod service;

use std::io::Write;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::server::TcpIncoming;
use tonic::transport::{Identity, Server, ServerTlsConfig};
use yat_proto::auth::RequireToken;
use yat_proto::{RenderNodeServer, DEFAULT_MAX_MESSAGE_BYTES};

use crate::blobs::BlobStore;
use crate::service::{Capabilities, RenderNodeService};

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
    /// Refuse requests that do not carry this token.
    #[arg(long, env = "YAT_TOKEN", hide_env_values = true)]
    pub token: Option<String>,
    /// Serve TLS with this PEM certificate (chain).
    #[arg(long, requires = "tls_key")]
    pub tls_cert: Option<PathBuf>,
    /// The PEM private key of --tls-cert.
    #[arg(long, requires = "tls_cert")]
    pub tls_key: Option<PathBuf>,
    /// Largest scene file accepted, in MiB.
    #[arg(long, default_value_t = 2048)]
    pub max_blob_mib: u64,
    /// Scene files kept in memory, in MiB (least recently used dropped first).
    #[arg(long, default_value_t = 4096)]
    pub memory_cache_mib: u64,
    /// Exit when standard input closes: a parent that dies takes its workers with it.
    #[arg(long)]
    pub exit_with_stdin: bool,
    /// Testing aid: pause this many milliseconds before each unit.
    #[arg(long, hide = true, default_value_t = 0)]
    pub throttle_ms: u64,
}

pub fn run(args: WorkerArgs) -> anyhow::Result<()> {
    let threads = args
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let tls = match (&args.tls_cert, &args.tls_key) {
        (Some(cert), Some(key)) => {
            let read = |p: &PathBuf| {
                std::fs::read(p).with_context(|| format!("cannot read {}", p.display()))
            };
            Some(ServerTlsConfig::new().identity(Identity::from_pem(read(cert)?, read(key)?)))
        }
        _ => None,
    };
    let blobs = BlobStore::new(args.memory_cache_mib * MIB, args.cache_dir.as_deref())
        .with_context(|| match &args.cache_dir {
            Some(dir) => format!("cannot use the cache folder {}", dir.display()),
            None => "cannot create the blob cache".to_string(),
        })?;
    let mut features = Vec::new();
    if args.cache_dir.is_some() {
        features.push("disk-cache".to_string());
    }
    if tls.is_some() {
        features.push("tls".to_string());
    }
    let capabilities = Capabilities {
        threads: threads as u32,
        max_message_bytes: DEFAULT_MAX_MESSAGE_BYTES as u64,
        max_blob_bytes: args.max_blob_mib * MIB,
        features,
    };
    let service =
        RenderNodeService::new(capabilities, blobs, Duration::from_millis(args.throttle_ms))?;
    if args.token.is_none() && !args.listen.ip().is_loopback() {
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
        let incoming = TcpIncoming::bind(args.listen)
            .map_err(|e| anyhow::anyhow!("cannot listen on {}: {e}", args.listen))?
            .with_nodelay(Some(true));
        let local = incoming.local_addr()?;
        // The parent of a local worker reads the port from this line: print it first, at once.
        let mut stdout = std::io::stdout().lock();
        writeln!(stdout, "listening on {local}")?;
        stdout.flush()?;
        drop(stdout);
        tracing::info!(
            "{threads} thread(s){}{}",
            if tls.is_some() { ", TLS" } else { "" },
            if args.token.is_some() {
                ", token required"
            } else {
                ""
            }
        );

        let node = RenderNodeServer::new(service)
            .max_decoding_message_size(DEFAULT_MAX_MESSAGE_BYTES)
            .max_encoding_message_size(DEFAULT_MAX_MESSAGE_BYTES);
        let node = InterceptedService::new(node, RequireToken::new(args.token.as_deref()));
        let mut server = Server::builder()
            .http2_keepalive_interval(Some(Duration::from_secs(10)))
            .http2_keepalive_timeout(Some(Duration::from_secs(20)));
        if let Some(tls) = tls {
            server = server
                .tls_config(tls)
                .context("invalid TLS certificate or key")?;
        }
        server
            .add_service(node)
            .serve_with_incoming_shutdown(incoming, async {
                let _ = tokio::signal::ctrl_c().await;
            })
            .await
            .context("the gRPC server failed")
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
