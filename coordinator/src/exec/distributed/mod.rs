//! Rendering over gRPC workers: the coordinator ships the scene's files to every worker, hands
//! out the units of the fixed plan pull-style, re-queues what a failing worker held, and merges
//! each unit's result once. The plan and the exact film sums make the image bit-identical to an
//! in-process render whatever the workers do.

mod local;
mod node;
mod report;
mod schedule;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use tokio::sync::mpsc;
use tokio::task::JoinSet;
use tonic::transport::{Certificate, ClientTlsConfig};
use yat_tracer::render::{plan_units, UnitStats, WorkUnit};

use crate::checkpoint::Checkpoint;
use crate::cli::seconds::seconds;
use crate::exec::progress::Progress;
use crate::interim::InterimClock;
use crate::job::{RenderJob, RenderOutcome};
use crate::manifest::SceneManifest;
use local::LocalWorker;
use node::{run_node, Event, Node, NodeConfig, Shared};
use report::{process_cpu_time, DistributedReport};
use schedule::{Schedule, UnitDeadline};

/// Command-line options of a distributed render (flattened into `yat render`).
#[derive(clap::Args, Debug, Default)]
pub struct DistributedArgs {
    /// Render on these workers, HOST:PORT[,HOST:PORT...] (each started with `yat worker`).
    #[arg(long, value_delimiter = ',', value_name = "HOST:PORT,...")]
    pub workers: Vec<String>,
    /// Start N workers on this machine, sharing its cores, and render on them too.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub local_workers: usize,
    /// The token the workers were started with.
    #[arg(long, env = "YAT_TOKEN", hide_env_values = true)]
    pub token: Option<String>,
    /// Connect to the workers over TLS, trusting this PEM CA certificate.
    #[arg(long, value_name = "PEM")]
    pub tls_ca: Option<PathBuf>,
    /// The name the workers' certificates are issued to [default: the host of each address].
    #[arg(long, requires = "tls_ca")]
    pub tls_domain: Option<String>,
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
    /// True when the render should go to workers instead of in-process.
    pub fn is_active(&self) -> bool {
        !self.workers.is_empty() || self.local_workers > 0
    }
}

/// How long the render waits without any worker before saying so (and again after each such
/// period).
const WAITING_NOTICE_EVERY: Duration = Duration::from_secs(5);

pub fn render(
    args: &DistributedArgs,
    job: &RenderJob,
    manifest: SceneManifest,
) -> anyhow::Result<RenderOutcome> {
    let cpu_start = process_cpu_time();
    let started = Instant::now();
    let timeout = args.timeout.map(|t| seconds("timeout", t)).transpose()?;
    let unit_deadline = args
        .unit_deadline
        .map(|t| seconds("unit-deadline", t))
        .transpose()?;

    let tls = args
        .tls_ca
        .as_ref()
        .map(|ca| {
            let pem = std::fs::read(ca).with_context(|| format!("cannot read {}", ca.display()))?;
            let mut tls = ClientTlsConfig::new().ca_certificate(Certificate::from_pem(pem));
            if let Some(domain) = &args.tls_domain {
                tls = tls.domain_name(domain.clone());
            }
            anyhow::Ok(tls)
        })
        .transpose()?;
    let mut configs: Vec<NodeConfig> = args
        .workers
        .iter()
        .map(|address| NodeConfig {
            address: address.trim().to_string(),
            token: args.token.clone(),
            tls: tls.clone(),
            local: None,
        })
        .collect();
    for config in &configs {
        config.validate()?;
    }
    if args.local_workers > 0 {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        for worker in LocalWorker::spawn_all(args.local_workers, cores)? {
            configs.push(NodeConfig {
                address: worker.address.clone(),
                token: Some(worker.token.clone()),
                tls: None,
                local: Some(Arc::new(worker)),
            });
        }
    }

    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .thread_name("yat-net")
        .enable_all()
        .build()
        .context("cannot start the network runtime")?;
    let units = plan_units(&job.settings);
    let start = job.resume(&units);
    let (events, event_rx) = mpsc::unbounded_channel();
    let shared = Arc::new(Shared {
        schedule: Schedule::new(units.clone(), |u| start.is_done(u)),
        deadline: UnitDeadline::new(unit_deadline),
        load_request: manifest.load_request(&job.settings),
        manifest,
        events,
    });
    let nodes: Vec<Arc<Node>> = configs
        .into_iter()
        .map(|c| Arc::new(Node::new(c)))
        .collect();
    let render_loop = RenderLoop {
        job,
        units: &units,
        nodes: &nodes,
        shared: &shared,
        timeout,
    };
    let outcome = runtime.block_on(render_loop.run(start, event_rx));
    // Ends the node loops and closes connections; then `nodes` drops the local workers.
    drop(runtime);

    let report = DistributedReport::new(
        started.elapsed(),
        process_cpu_time().saturating_sub(cpu_start),
        shared.schedule.len(),
        outcome.as_ref().map_or(0, |o| o.stats.samples),
        nodes
            .iter()
            .map(|n| n.report.lock().unwrap().clone())
            .collect(),
    );
    if let Some(path) = &args.workers_json {
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let outcome = outcome?;
    if !job.quiet {
        report.print();
    }
    Ok(outcome)
}

struct RenderLoop<'a> {
    job: &'a RenderJob,
    units: &'a [WorkUnit],
    nodes: &'a [Arc<Node>],
    shared: &'a Arc<Shared>,
    timeout: Option<Duration>,
}

impl RenderLoop<'_> {
    /// Merges results into `checkpoint` as they come until every unit is in, watching that
    /// some worker is there to render and saving the checkpoint as often as the job asks.
    async fn run(
        self,
        mut checkpoint: Checkpoint,
        mut events: mpsc::UnboundedReceiver<Event>,
    ) -> anyhow::Result<RenderOutcome> {
        let progress = Progress::new(
            self.shared.schedule.sample_count(),
            checkpoint.done_samples(self.units),
            self.job.quiet,
        );
        let mut tasks = JoinSet::new();
        for node in self.nodes {
            tasks.spawn(run_node(node.clone(), self.shared.clone()));
        }
        let mut stats = UnitStats::default();
        let mut clock = InterimClock::default();
        let mut alone_since = Some(Instant::now());
        let mut waiting_noticed = Instant::now();
        let mut tick = tokio::time::interval(Duration::from_millis(250));
        let result = loop {
            if checkpoint.is_complete() {
                break Ok(());
            }
            tokio::select! {
                event = events.recv() => match event.expect("the shared state holds a sender") {
                    Event::Result { buffer, stats: unit_stats } => {
                        if let Err(e) = checkpoint.add(&buffer) {
                            break Err(e.into());
                        }
                        stats += unit_stats;
                        progress.add_samples(unit_stats.samples);
                        progress.set_status(self.status(&checkpoint));
                    }
                    Event::Notice(line) => progress.say(&line),
                    Event::Fatal(e) => break Err(e),
                },
                _ = tick.tick() => {
                    if self.job.interrupt.is_set() {
                        break Err(anyhow::anyhow!("interrupted"));
                    }
                    progress.set_status(self.status(&checkpoint));
                    let due = self.job.interim.due(&mut clock);
                    if due.any() {
                        // Lets the runtime's other thread serve the workers meanwhile.
                        let failed = tokio::task::block_in_place(|| {
                            self.job.interim.stage(due, &checkpoint, &self.job.scene.desc.film).finish()
                        });
                        for e in failed {
                            progress.say(&format!("{e:#}"));
                        }
                    }
                    if self.alive() > 0 {
                        alone_since = None;
                        continue;
                    }
                    let since = *alone_since.get_or_insert_with(Instant::now);
                    if let Err(e) = self.check_workers_remain(since) {
                        break Err(e);
                    }
                    if since.elapsed() >= WAITING_NOTICE_EVERY
                        && waiting_noticed.elapsed() >= WAITING_NOTICE_EVERY
                    {
                        waiting_noticed = Instant::now();
                        progress.say(&format!(
                            "waiting for workers: none connected for {:.0} s ({}){}",
                            since.elapsed().as_secs_f64(),
                            self.last_errors(),
                            self.timeout.map_or(String::new(), |t| format!(
                                "; giving up after {:.0} s", t.as_secs_f64()))
                        ));
                    }
                }
            }
        };
        tasks.abort_all();
        progress.finish();
        if let Err(why) = result {
            return Err(self.job.stopped(&checkpoint, self.units, why));
        }
        Ok(RenderOutcome {
            film: checkpoint.into_film(),
            stats,
            build: None,
        })
    }

    /// Units merged and workers connected, after the progress bar's ETA.
    fn status(&self, checkpoint: &Checkpoint) -> String {
        format!(
            "| units {}/{}, workers {}/{}",
            checkpoint.done_count(),
            self.units.len(),
            self.alive(),
            self.nodes.len()
        )
    }

    fn alive(&self) -> usize {
        self.nodes
            .iter()
            .filter(|n| n.report.lock().unwrap().connected)
            .count()
    }

    /// Fails when no worker can come back, or when the wait has exceeded --timeout.
    fn check_workers_remain(&self, alone_since: Instant) -> anyhow::Result<()> {
        let reports: Vec<_> = self
            .nodes
            .iter()
            .map(|n| n.report.lock().unwrap().clone())
            .collect();
        if reports.iter().all(|r| r.gone.is_some()) {
            let reasons: Vec<_> = reports
                .iter()
                .map(|r| format!("{}: {}", r.address, r.gone.as_deref().unwrap_or_default()))
                .collect();
            bail!(
                "no worker can render this scene:\n  {}",
                reasons.join("\n  ")
            );
        }
        if let Some(timeout) = self.timeout {
            if alone_since.elapsed() >= timeout {
                bail!(
                    "no worker connected for {:.0} s (--timeout); last errors: {}",
                    timeout.as_secs_f64(),
                    self.last_errors()
                );
            }
        }
        Ok(())
    }

    fn last_errors(&self) -> String {
        self.nodes
            .iter()
            .map(|n| {
                let r = n.report.lock().unwrap();
                let why = r
                    .gone
                    .as_deref()
                    .or(r.last_error.as_deref())
                    .unwrap_or("connecting");
                format!("{}: {why}", r.address)
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}
