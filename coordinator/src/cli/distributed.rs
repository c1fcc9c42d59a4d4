//! The flags of a distributed render, flattened into `yat render`.

use std::path::PathBuf;

use yat_proto::flags::{ClientTlsFlags, TokenFlag};

use super::seconds::seconds;
use crate::exec::distributed::config::DistributedConfig;

#[derive(clap::Args, Debug, Default)]
pub struct DistributedArgs {
    /// Render on these workers, HOST:PORT[,HOST:PORT...] (each started with `yat worker`).
    #[arg(long, value_delimiter = ',', value_name = "HOST:PORT,...")]
    pub workers: Vec<String>,
    /// Start N workers on this machine, sharing its cores, and render on them too.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub local_workers: usize,
    #[command(flatten)]
    pub token: TokenFlag,
    #[command(flatten)]
    pub tls: ClientTlsFlags,
    /// Give up when no worker has been connected for this many seconds [default: wait].
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

impl DistributedArgs {
    /// The distributed render these flags ask for, or `None` for an in-process render.
    pub fn config(&self) -> anyhow::Result<Option<DistributedConfig>> {
        if self.workers.is_empty() && self.local_workers == 0 {
            return Ok(None);
        }
        Ok(Some(DistributedConfig {
            workers: self.workers.clone(),
            local_workers: self.local_workers,
            token: self.token.resolve()?,
            tls: self.tls.config()?,
            timeout: self.timeout.map(|t| seconds("timeout", t)).transpose()?,
            unit_deadline: self
                .unit_deadline
                .map(|t| seconds("unit-deadline", t))
                .transpose()?,
            workers_json: self.workers_json.clone(),
        }))
    }
}
