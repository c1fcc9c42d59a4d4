//! What a distributed render is given, as plain values (the `yat render` flags map onto it).

use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

use tonic::transport::ClientTlsConfig;

use super::local::LocalWorkers;

/// The default: no worker, names resolved once, no token, TLS, timeout or report file.
#[derive(Default)]
pub struct DistributedConfig {
    /// Workers to render on, HOST:PORT each: an IP literal is one worker, a DNS name is a
    /// worker at every address it resolves to.
    pub workers: Vec<String>,
    /// Resolve the names again this often, following workers that join and leave; zero
    /// resolves them once.
    pub resolve_every: Duration,
    /// The name server to ask instead of the system's (tests).
    pub dns_server: Option<SocketAddr>,
    /// Workers to start on this machine, sharing its cores.
    pub local_workers: LocalWorkers,
    /// The token the (remote) workers were started with.
    pub token: Option<String>,
    /// TLS towards the (remote) workers.
    pub tls: Option<ClientTlsConfig>,
    /// Whether `--tls-domain` was given; otherwise a worker found under a DNS name must present
    /// a certificate for that name.
    pub tls_domain_given: bool,
    /// Give up when no unit has been merged this long [default: wait].
    pub timeout: Option<Duration>,
    /// Presume a unit lost after this long instead of adapting to the slowest unit (tests).
    pub unit_deadline: Option<Duration>,
    /// Where to write each worker's figures as JSON.
    pub workers_json: Option<PathBuf>,
}
