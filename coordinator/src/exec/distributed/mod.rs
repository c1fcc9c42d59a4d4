//! Rendering over gRPC workers: the coordinator ships the scene's files to every worker, hands
//! out the units of the fixed plan (or of each round of an adaptive render) pull-style, re-queues
//! what a failing worker held, and merges each unit's result once. The plan and the exact film sums make the image bit-identical to an
//! in-process render whatever the workers do.

pub mod config;

mod client;
mod discovery;
pub mod local;
mod node;
mod render_loop;
pub mod report;
mod schedule;
mod session;
mod session_context;
mod session_error;

use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use tokio::sync::mpsc;
use yat_tracer::filter::PixelFilter;

use crate::job::{RenderJob, RenderOutcome};
use crate::manifest::SceneManifest;
use client::ClientConfig;
use config::DistributedConfig;
use discovery::{ClientTemplate, Discovery, Roster, WorkerTarget};
use node::Node;
use render_loop::RenderLoop;
use report::{process_cpu_time, DistributedReport};
use schedule::{Schedule, UnitDeadline};
use session_context::SessionContext;

/// Renders `job` on the workers `config` names or starts; `manifest` holds the scene's files.
/// Returns the workers' figures beside the outcome (and writes them to `config.workers_json`,
/// whether the render succeeds or not).
pub fn render(
    config: &DistributedConfig,
    job: &RenderJob,
    manifest: SceneManifest,
) -> anyhow::Result<(RenderOutcome, DistributedReport)> {
    let cpu_start = process_cpu_time();
    let started = Instant::now();
    let targets = config
        .workers
        .iter()
        .map(|entry| WorkerTarget::parse(entry))
        .collect::<Result<Vec<_>, _>>()?;
    let mut nodes = Vec::new();
    for target in &targets {
        if let WorkerTarget::Address(address) = target {
            let client = ClientConfig {
                address: address.to_string(),
                token: config.token.clone(),
                tls: config.tls.clone(),
            };
            client.validate()?;
            nodes.push(Node::new(client, None));
        }
    }
    for worker in config.local_workers.get()? {
        let client = ClientConfig {
            address: worker.address.clone(),
            token: Some(worker.token.clone()),
            tls: None,
        };
        nodes.push(Node::new(client, Some(worker)));
    }

    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .thread_name("yat-net")
        .enable_all()
        .build()
        .context("cannot start the network runtime")?;
    let start = job.resume();
    let units = start.units(&job.settings);
    let (events, event_rx) = mpsc::unbounded_channel();
    let context = Arc::new(SessionContext {
        // A round is never known to be the last before it is merged.
        schedule: Schedule::new(units, |u| start.is_done(u), !job.sampling.has_rounds()),
        deadline: UnitDeadline::new(config.unit_deadline),
        load_request: manifest.load_request(&job.settings),
        frame: start.film().frame(),
        weights: PixelFilter::new(&job.scene.desc.filter).weight_bounds(),
        manifest,
        events,
    });
    let roster = Arc::new(Roster::new(context.clone()));
    let client = ClientTemplate {
        token: config.token.clone(),
        tls: config.tls.clone(),
        tls_domain_given: config.tls_domain_given,
    };
    let outcome = runtime.block_on(async {
        for node in nodes {
            roster.add(node);
        }
        Discovery::new(&targets, client, config.resolve_every, config.dns_server)
            .context("cannot set up DNS resolution")?
            .start(&roster)
            .await?;
        let render_loop = RenderLoop {
            job,
            roster: &roster,
            context: &context,
            timeout: config.timeout,
        };
        render_loop.run(start, event_rx).await
    });
    // Ends the node loops and closes connections (the local workers live on in `config`).
    drop(runtime);

    let mut report = DistributedReport::new(
        started.elapsed(),
        process_cpu_time().saturating_sub(cpu_start),
        context.schedule.len(),
        outcome.as_ref().map_or(0, |o| o.stats.samples),
        roster
            .nodes()
            .iter()
            .map(|n| n.report.lock().unwrap().clone())
            .collect(),
    );
    report.units_copied = context.schedule.copies();
    if let Some(path) = &config.workers_json {
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok((outcome?, report))
}
