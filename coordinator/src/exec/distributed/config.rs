//! What a distributed render is given, as plain values (the `yat render` flags map onto it).

use std::path::PathBuf;
use std::time::Duration;

use tonic::transport::ClientTlsConfig;

pub struct DistributedConfig {
    /// Workers to render on, HOST:PORT each.
    pub workers: Vec<String>,
    /// Workers to start on this machine, sharing its cores.
    pub local_workers: usize,
    /// The token the (remote) workers were started with.
    pub token: Option<String>,
    /// TLS towards the (remote) workers.
    pub tls: Option<ClientTlsConfig>,
    /// Give up when no worker has been connected this long [default: wait].
    pub timeout: Option<Duration>,
    /// Presume a unit lost after this long instead of adapting to the slowest unit (tests).
    pub unit_deadline: Option<Duration>,
    /// Where to write each worker's figures as JSON.
    pub workers_json: Option<PathBuf>,
}
