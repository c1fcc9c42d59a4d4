//! One worker as the coordinator sees it: how to reach it, the process behind it when this
//! coordinator started it, and what it did in this render.

use std::sync::{Arc, Mutex};

use super::client::ClientConfig;
use super::local::LocalWorker;
use crate::status::snapshot::{WorkerRow, WorkerState};

/// What a worker did in this render (the final summary and `--workers-json`).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct NodeReport {
    pub address: String,
    /// The DNS name this worker was found under (`None` for a listed address).
    pub dns_name: Option<String>,
    pub hostname: String,
    pub threads: u32,
    /// Units whose results were merged.
    pub units: u64,
    pub samples: u64,
    /// Sessions lost (connection errors, deadlines, bad replies) and units given back.
    pub failures: u64,
    pub units_requeued: u64,
    /// Scene-file bytes uploaded.
    pub blob_bytes_sent: u64,
    /// Every request's encoded bytes, blobs included.
    pub bytes_sent: u64,
    /// Every reply's encoded bytes.
    pub bytes_received: u64,
    /// Sample-buffer bytes and the pixels they cover, for bytes per pixel.
    pub result_bytes: u64,
    pub result_pixels: u64,
    #[serde(skip)]
    pub connected: bool,
    /// Its sessions ended because the render did (or it was asked to leave).
    #[serde(skip)]
    pub finished: bool,
    /// Why this worker is not used (any more), if so: refused, exited, removed from DNS.
    pub gone: Option<String>,
    pub last_error: Option<String>,
}

impl NodeReport {
    /// Its row on the status page: connecting until its first handshake (which names its
    /// host), connected while a session renders, done when the render ended with it there,
    /// gone when retired, removed or lost.
    pub fn status_row(&self) -> WorkerRow {
        let state = match (self.connected, &self.gone) {
            (_, Some(_)) => WorkerState::Gone,
            (true, None) => WorkerState::Connected,
            (false, None) if self.finished => WorkerState::Done,
            (false, None) if self.hostname.is_empty() => WorkerState::Connecting,
            (false, None) => WorkerState::Gone,
        };
        WorkerRow {
            address: self.address.clone(),
            hostname: self.hostname.clone(),
            threads: self.threads,
            state,
            units: self.units,
            samples: self.samples,
            samples_per_second: 0.0,
            failures: self.failures,
            units_requeued: self.units_requeued,
            bytes_sent: self.bytes_sent,
            bytes_received: self.bytes_received,
            reason: self.gone.clone().or_else(|| self.last_error.clone()),
        }
    }
}

pub struct Node {
    /// How to reach it.
    pub config: ClientConfig,
    /// The process, for a worker this coordinator started.
    pub local: Option<Arc<LocalWorker>>,
    pub report: Mutex<NodeReport>,
}

impl Node {
    pub fn new(config: ClientConfig, local: Option<Arc<LocalWorker>>) -> Self {
        let report = NodeReport {
            address: config.address.clone(),
            ..NodeReport::default()
        };
        Self {
            config,
            local,
            report: Mutex::new(report),
        }
    }

    pub fn address(&self) -> &str {
        &self.config.address
    }

    pub fn update(&self, f: impl FnOnce(&mut NodeReport)) {
        f(&mut self.report.lock().unwrap());
    }
}
