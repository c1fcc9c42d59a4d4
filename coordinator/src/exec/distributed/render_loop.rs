//! The render loop of a distributed render: merges results into the checkpoint as they come,
//! writes the interim outputs as often as the job asks, and watches that some worker is there
//! to render.

use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::bail;
use tokio::sync::mpsc;
use yat_tracer::render::UnitStats;

use super::discovery::Roster;
use super::session_context::{SessionContext, SessionEvent};
use crate::checkpoint::Checkpoint;
use crate::exec::progress::Progress;
use crate::interim::InterimClock;
use crate::job::{RenderJob, RenderOutcome, TimeLimitReached};

/// How long the render waits without any worker before saying so (and again after each such
/// period).
const WAITING_NOTICE_EVERY: Duration = Duration::from_secs(5);

pub struct RenderLoop<'a> {
    pub job: &'a RenderJob,
    pub roster: &'a Roster,
    pub context: &'a Arc<SessionContext>,
    pub timeout: Option<Duration>,
}

impl RenderLoop<'_> {
    /// Merges results into `checkpoint` as they come until every unit is in (of every round:
    /// once a round is in, the next is decided from the merged film and handed to the
    /// schedule), watching that some worker is there to render and saving the checkpoint as
    /// often as the job asks.
    pub async fn run(
        self,
        mut checkpoint: Checkpoint,
        mut events: mpsc::UnboundedReceiver<SessionEvent>,
    ) -> anyhow::Result<RenderOutcome> {
        let settings = &self.job.settings;
        let progress = Progress::start(self.job, &checkpoint);
        let mut completed = None;
        let mut stats = UnitStats::default();
        let mut clock = InterimClock::default();
        let mut alone_since = Some(Instant::now());
        let mut last_merged = Instant::now();
        let mut waiting_noticed = Instant::now();
        let mut tick = tokio::time::interval(Duration::from_millis(250));
        let result = loop {
            if checkpoint.is_complete() {
                // The next round's decision (and the copy of this round's film a time limit
                // keeps) reads the whole film: off the async workers.
                if let Some(round) =
                    tokio::task::block_in_place(|| self.job.keep_round(&checkpoint))
                {
                    completed = Some(round);
                }
                if self.job.out_of_time() {
                    break Err(TimeLimitReached.into());
                }
                let film_desc = &self.job.scene.desc.film;
                if !tokio::task::block_in_place(|| checkpoint.advance(settings, film_desc)) {
                    self.context.schedule.finish();
                    break Ok(());
                }
                self.context
                    .schedule
                    .start_round(checkpoint.units(settings));
                progress.round(self.job, &checkpoint);
                progress.set_status(self.status(&checkpoint));
                continue;
            }
            tokio::select! {
                event = events.recv() => match event.expect("the context state holds a sender") {
                    SessionEvent::Result { buffer, stats: unit_stats } => {
                        if let Err(e) = checkpoint.add(&buffer) {
                            break Err(e.into());
                        }
                        stats += unit_stats;
                        last_merged = Instant::now();
                        progress.unit_merged(unit_stats.samples);
                        progress.set_status(self.status(&checkpoint));
                    }
                    SessionEvent::Notice(line) => progress.say(&line),
                },
                _ = tick.tick() => {
                    if self.job.interrupt.is_set() {
                        break Err(anyhow::anyhow!("interrupted"));
                    }
                    if self.job.out_of_time() {
                        break Err(TimeLimitReached.into());
                    }
                    progress.set_status(self.status(&checkpoint));
                    self.publish_workers();
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
                    if let Err(e) = self.check_workers_remain(last_merged) {
                        break Err(e);
                    }
                    if self.alive() > 0 {
                        alone_since = None;
                        continue;
                    }
                    let since = *alone_since.get_or_insert_with(Instant::now);
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
        self.roster.stop_all();
        self.publish_workers();
        progress.finish();
        match result {
            Err(why) if why.is::<TimeLimitReached>() => {
                self.job.timed_out(&checkpoint, completed, stats, None)
            }
            Err(why) => Err(self.job.stopped(&checkpoint, why)),
            Ok(()) => Ok(RenderOutcome {
                round: checkpoint.adaptive_round().cloned(),
                ended: checkpoint.ended(),
                film: checkpoint.into_film(),
                stats,
                build: None,
                complete: true,
            }),
        }
    }

    /// The round, units merged and workers connected, after the progress bar's ETA.
    fn status(&self, checkpoint: &Checkpoint) -> String {
        format!(
            "| {}units {}/{}, workers {}/{}",
            checkpoint
                .rounds()
                .index()
                .map_or(String::new(), |i| format!("round {i}, ")),
            checkpoint.done_count(),
            checkpoint.unit_count(),
            self.alive(),
            self.roster.current_count()
        )
    }

    /// The workers' figures for the status page; a worker is stalled after half the time a
    /// unit may take without a result.
    fn publish_workers(&self) {
        let rows = self
            .roster
            .nodes()
            .iter()
            .map(|n| n.report.lock().unwrap().status_row())
            .collect();
        let stalled_after = self.context.deadline.current() / 2;
        self.job.interim.status.set_workers(rows, stalled_after);
    }

    fn alive(&self) -> usize {
        self.roster
            .nodes()
            .iter()
            .filter(|n| n.report.lock().unwrap().connected)
            .count()
    }

    /// Fails when no worker can come back, or when no unit was merged for --timeout.
    fn check_workers_remain(&self, last_merged: Instant) -> anyhow::Result<()> {
        let reports: Vec<_> = self
            .roster
            .nodes()
            .iter()
            .map(|n| n.report.lock().unwrap().clone())
            .collect();
        // A followed DNS name may still bring workers: wait for them (or --timeout).
        if reports.iter().all(|r| r.gone.is_some()) && !self.roster.may_grow() {
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
            if last_merged.elapsed() >= timeout {
                let connected = match self.alive() {
                    0 => "no worker connected".to_string(),
                    n => format!("{n} connected but not returning results"),
                };
                bail!(
                    "no unit merged for {:.1} s (--timeout), {connected}; workers: {}",
                    timeout.as_secs_f64(),
                    self.last_errors()
                );
            }
        }
        Ok(())
    }

    fn last_errors(&self) -> String {
        let nodes = self.roster.nodes();
        if nodes.is_empty() {
            return "no worker address found yet under the --workers names".into();
        }
        nodes
            .iter()
            .map(|n| {
                let r = n.report.lock().unwrap();
                let why = r
                    .gone
                    .as_deref()
                    .or(r.last_error.as_deref())
                    .unwrap_or(if r.connected {
                        "connected"
                    } else {
                        "connecting"
                    });
                format!("{}: {why}", r.address)
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}
