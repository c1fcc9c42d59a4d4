//! The flags of a distributed render, flattened into `yat render`.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

use yat_proto::flags::{ClientTlsFlags, TokenFlag};

use super::seconds::seconds;
use crate::exec::distributed::config::DistributedConfig;
use crate::exec::distributed::local::LocalWorkers;

#[derive(clap::Args, Debug, Default)]
pub struct DistributedArgs {
    /// Render on these workers, HOST:PORT[,HOST:PORT...] (each started with `yat worker`). An
    /// IP address is one worker; a DNS name is a worker at every address it resolves to (e.g.
    /// a Kubernetes headless Service), followed during the render (--resolve-every).
    #[arg(long, value_delimiter = ',', value_name = "HOST:PORT,...")]
    pub workers: Vec<String>,
    /// Resolve the DNS names of --workers again every this many seconds: new addresses join
    /// the render, vanished ones leave it (their units go to the others); 0 resolves once.
    #[arg(long, value_name = "SECONDS", default_value_t = 5.0)]
    pub resolve_every: f64,
    /// Testing aid: ask this name server (UDP and TCP) instead of the system's.
    #[arg(long, hide = true, env = "YAT_DNS_SERVER", value_name = "IP:PORT")]
    pub dns_server: Option<SocketAddr>,
    /// Start N workers on this machine, sharing its cores, and render on them too.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub local_workers: usize,
    #[command(flatten)]
    pub token: TokenFlag,
    #[command(flatten)]
    pub tls: ClientTlsFlags,
    /// Give up when no unit's result has been merged for this many seconds, whether no worker
    /// is connected or the connected ones return nothing usable [default: wait].
    #[arg(long, value_name = "SECONDS")]
    pub timeout: Option<f64>,
    /// Write each worker's figures (units, failures, bytes) and the coordinator's CPU time as
    /// JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub workers_json: Option<PathBuf>,
    /// Testing aid: presume a unit lost after this many seconds instead of
    /// max(30 s, 4 x the slowest unit seen).
    #[arg(long, hide = true, env = "YAT_UNIT_DEADLINE")]
    pub unit_deadline: Option<f64>,
}

/// Re-resolving more often than this would only load the name servers.
const MIN_RESOLVE_EVERY: Duration = Duration::from_millis(100);

/// `--resolve-every`: zero (resolve once) or at least `MIN_RESOLVE_EVERY`.
fn resolve_every(value: f64) -> anyhow::Result<Duration> {
    let every = seconds("resolve-every", value)?;
    if !every.is_zero() && every < MIN_RESOLVE_EVERY {
        anyhow::bail!(
            "--resolve-every must be 0 (resolve once) or at least {} s",
            MIN_RESOLVE_EVERY.as_secs_f64()
        );
    }
    Ok(every)
}

impl DistributedArgs {
    /// The distributed render these flags ask for, or `None` for an in-process render.
    pub fn config(&self) -> anyhow::Result<Option<DistributedConfig>> {
        if self.workers.is_empty() && self.local_workers == 0 {
            return Ok(None);
        }
        Ok(Some(DistributedConfig {
            workers: self.workers.clone(),
            resolve_every: resolve_every(self.resolve_every)?,
            dns_server: self.dns_server,
            local_workers: LocalWorkers::new(self.local_workers),
            token: self.token.resolve()?,
            tls: self.tls.config()?,
            tls_domain_given: self.tls.tls_domain.is_some(),
            timeout: self.timeout.map(|t| seconds("timeout", t)).transpose()?,
            unit_deadline: self
                .unit_deadline
                .map(|t| seconds("unit-deadline", t))
                .transpose()?,
            workers_json: self.workers_json.clone(),
        }))
    }
}
