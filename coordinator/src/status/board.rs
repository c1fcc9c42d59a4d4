//! The status board: where a render publishes what the status page shows. The executors call
//! it where things already happen (a unit merged, the workers' figures read on the render
//! loop's tick, the interim outputs staged); the server reads a [`Snapshot`] of it. One short
//! lock per call, at most once per unit: nothing here is on the per-sample path.
//!
//! Events are derived from what is published rather than pushed from deep inside the sessions:
//! a worker whose state turns connected has joined, one that turns gone has left, a rise in
//! its requeued count is units going back to the queue. So the executors need one call per
//! tick, not a hook at every place a worker can fail.

use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::snapshot::{
    Event, EventKind, ImageInfo, ProgressFigures, RenderState, SceneInfo, SettingsInfo, Snapshot,
    Summary, WorkerRow, WorkerState, SNAPSHOT_VERSION,
};

/// Events kept for the page; older ones are dropped.
pub const MAX_EVENTS: usize = 50;
/// A new image is made at most this often (tone mapping the film costs the render a moment).
pub const IMAGE_EVERY: Duration = Duration::from_secs(1);
/// And at most once per this many times what the last one cost to make (tone mapping and PNG
/// encoding), so the page takes at most ~1% of a core however large the film (docs/status.md,
/// "What it costs the render").
pub const IMAGE_COST_FACTOR: u32 = 100;
/// New images are made only while someone fetched one within this time: an unwatched page
/// costs nothing.
pub const IMAGE_INTEREST: Duration = Duration::from_secs(30);
/// A connected worker is stalled when it returned nothing for this long, at least (the
/// executor may say longer: how long a unit may take).
pub const MIN_STALLED_AFTER: Duration = Duration::from_secs(10);
/// Longest text of an event (worker errors can be long).
const MAX_EVENT_CHARS: usize = 300;

pub struct StatusBoard {
    started: Instant,
    /// Whether a server reads the board: without one, no image is ever made.
    serving: bool,
    state: Mutex<BoardState>,
}

/// The image so far, as the preview would write it.
#[derive(Clone)]
pub struct PublishedImage {
    pub generation: u64,
    pub image: Arc<image::RgbImage>,
}

#[derive(Default)]
struct BoardState {
    scene: SceneInfo,
    settings: SettingsInfo,
    render_state: RenderState,
    progress: ProgressFigures,
    /// When this run's counting began, and the samples merged before it (a resumed render's).
    counting_since: Option<Instant>,
    samples_at_start: u64,
    workers: Vec<WorkerRow>,
    /// Per worker address: its units merged and when that count last rose.
    last_progress: HashMap<String, (u64, Instant)>,
    events: VecDeque<Event>,
    image: Option<PublishedImage>,
    image_at: Option<Instant>,
    /// What the last image cost: tone mapping (the executor's) and encoding (the server's).
    image_cost: Duration,
    encode_cost: Duration,
    units_at_image: u64,
    image_asked: Option<Instant>,
    summary: Option<Summary>,
}

impl StatusBoard {
    pub fn new(scene: SceneInfo, settings: SettingsInfo, serving: bool) -> Self {
        Self {
            started: Instant::now(),
            serving,
            state: Mutex::new(BoardState {
                scene,
                settings,
                ..BoardState::default()
            }),
        }
    }

    /// A board nobody reads (tests, renders without `--status-addr`).
    pub fn unserved() -> Arc<Self> {
        Arc::new(Self::new(
            SceneInfo::default(),
            SettingsInfo::default(),
            false,
        ))
    }

    fn state(&self) -> std::sync::MutexGuard<'_, BoardState> {
        // A panic elsewhere while publishing leaves figures that are still worth showing.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The plan: its units and samples, and how many of them a resumed checkpoint holds.
    pub fn plan(&self, units_total: usize, units_done: usize, samples_total: u64, done: u64) {
        let mut s = self.state();
        s.progress.units_total = units_total as u64;
        s.progress.units_done = units_done as u64;
        s.progress.samples_total = samples_total;
        s.progress.samples_done = done;
        s.samples_at_start = done;
        s.counting_since = Some(Instant::now());
    }

    /// An adaptive round starts (`rounds` is how many there can be at most): `units_left` units
    /// to render in it, and the render's samples now estimated at `samples_total`.
    pub fn round(&self, index: u32, rounds: u32, units_left: usize, samples_total: u64) {
        let mut s = self.state();
        s.progress.round = Some(index);
        s.progress.rounds = Some(rounds);
        s.progress.units_total = s.progress.units_done + units_left as u64;
        s.progress.samples_total = samples_total;
    }

    /// Render threads of an in-process render.
    pub fn set_threads(&self, threads: usize) {
        self.state().settings.threads = Some(threads);
    }

    /// A unit's result merged.
    pub fn unit_merged(&self, samples: u64) {
        let mut s = self.state();
        s.progress.units_done += 1;
        s.progress.samples_done += samples;
    }

    /// The workers' figures now. Each row says connecting, connected or gone; the board marks
    /// a connected worker stalled when its merged units have not risen for `stalled_after`
    /// (at least [`MIN_STALLED_AFTER`]), fills in samples per second, and records the events
    /// the change from the last rows shows.
    pub fn set_workers(&self, mut rows: Vec<WorkerRow>, stalled_after: Duration) {
        let now = Instant::now();
        let stalled_after = stalled_after.max(MIN_STALLED_AFTER);
        let elapsed = self.started.elapsed().as_secs_f64().max(1e-9);
        let mut s = self.state();
        let mut last_progress = HashMap::with_capacity(rows.len());
        let mut events = Vec::new();
        for row in &mut rows {
            let since = match s.last_progress.get(&row.address) {
                Some(&(units, since)) if units == row.units => since,
                _ => now,
            };
            last_progress.insert(row.address.clone(), (row.units, since));
            if row.state == WorkerState::Connected && now - since >= stalled_after {
                row.state = WorkerState::Stalled;
            }
            row.samples_per_second = row.samples as f64 / elapsed;
            let before = s.workers.iter().find(|w| w.address == row.address);
            events.extend(worker_events(before, row));
        }
        s.progress.units_requeued = rows.iter().map(|r| r.units_requeued).sum();
        s.workers = rows;
        s.last_progress = last_progress;
        for (kind, worker, text) in events {
            self.push_event(&mut s, kind, Some(worker), text);
        }
    }

    /// An event that no figure shows (a checkpoint written).
    pub fn event(&self, kind: EventKind, text: String) {
        let mut s = self.state();
        self.push_event(&mut s, kind, None, text);
    }

    fn push_event(
        &self,
        s: &mut BoardState,
        kind: EventKind,
        worker: Option<String>,
        text: String,
    ) {
        if s.events.len() == MAX_EVENTS {
            s.events.pop_front();
        }
        s.events.push_back(Event {
            at_seconds: self.started.elapsed().as_secs_f64(),
            kind,
            worker,
            text: text.chars().take(MAX_EVENT_CHARS).collect(),
        });
    }

    /// Whether a server shows this board (else nothing needs its image).
    pub fn serving(&self) -> bool {
        self.serving
    }

    /// Whether the executor should publish a new image now: the first one, then at most every
    /// [`IMAGE_EVERY`] (or [`IMAGE_COST_FACTOR`] times its cost) while someone watches and the
    /// film has changed.
    pub fn image_due(&self) -> bool {
        if !self.serving {
            return false;
        }
        let s = self.state();
        match s.image_at {
            None => true,
            Some(at) => {
                let cost = (s.image_cost + s.encode_cost).saturating_mul(IMAGE_COST_FACTOR);
                at.elapsed() >= IMAGE_EVERY.max(cost)
                    && s.units_at_image != s.progress.units_done
                    && s.image_asked.is_some_and(|t| t.elapsed() < IMAGE_INTEREST)
            }
        }
    }

    /// The image so far, tone mapped as the preview is, which took `cost`.
    pub fn publish_image(&self, image: image::RgbImage, cost: Duration) {
        let mut s = self.state();
        let generation = s.image.as_ref().map_or(0, |i| i.generation) + 1;
        s.image = Some(PublishedImage {
            generation,
            image: Arc::new(image),
        });
        s.image_at = Some(Instant::now());
        s.image_cost = cost;
        s.units_at_image = s.progress.units_done;
    }

    /// What encoding the last image took the server.
    pub fn note_encode_cost(&self, cost: Duration) {
        self.state().encode_cost = cost;
    }

    /// The newest image, for the server; asking counts as watching.
    pub fn image(&self) -> Option<PublishedImage> {
        let mut s = self.state();
        s.image_asked = Some(Instant::now());
        s.image.clone()
    }

    /// The render ended: `output` written, or `error`.
    pub fn finish(&self, output: Option<String>, error: Option<String>) {
        let mut s = self.state();
        let seconds = self.started.elapsed().as_secs_f64();
        let samples = s.progress.samples_done - s.samples_at_start;
        let rate = rate(&s);
        let (state, kind, text) = match &error {
            None => (
                RenderState::Finished,
                EventKind::RenderFinished,
                format!("render finished in {seconds:.1} s"),
            ),
            Some(e) => (
                RenderState::Failed,
                EventKind::RenderFailed,
                format!("render failed: {e}"),
            ),
        };
        s.render_state = state;
        // Whoever was still rendering stayed to the end.
        for worker in &mut s.workers {
            if matches!(worker.state, WorkerState::Connected | WorkerState::Stalled) {
                worker.state = WorkerState::Done;
            }
        }
        s.summary = Some(Summary {
            seconds,
            samples,
            samples_per_second: rate,
            output,
            error,
        });
        self.push_event(&mut s, kind, None, text);
    }

    pub fn snapshot(&self) -> Snapshot {
        let s = self.state();
        let mut progress = s.progress.clone();
        progress.elapsed_seconds = match &s.summary {
            Some(summary) => summary.seconds,
            None => self.started.elapsed().as_secs_f64(),
        };
        progress.ratio = progress.samples_done as f64 / progress.samples_total.max(1) as f64;
        progress.samples_per_second = s
            .summary
            .as_ref()
            .map_or_else(|| rate(&s), |summary| summary.samples_per_second);
        let left = progress.samples_total.saturating_sub(progress.samples_done);
        progress.eta_seconds = (s.render_state == RenderState::Rendering
            && progress.samples_per_second > 0.0)
            .then(|| left as f64 / progress.samples_per_second);
        Snapshot {
            version: SNAPSHOT_VERSION,
            scene: s.scene.clone(),
            settings: s.settings.clone(),
            state: s.render_state,
            progress,
            workers: s.workers.clone(),
            events: s.events.iter().cloned().collect(),
            image: s
                .image
                .as_ref()
                .map_or_else(ImageInfo::default, |i| ImageInfo {
                    generation: i.generation,
                    width: i.image.width(),
                    height: i.image.height(),
                }),
            summary: s.summary.clone(),
        }
    }
}

/// Samples this run merged per second since it began counting.
fn rate(s: &BoardState) -> f64 {
    let Some(since) = s.counting_since else {
        return 0.0;
    };
    let samples = s.progress.samples_done - s.samples_at_start;
    samples as f64 / since.elapsed().as_secs_f64().max(1e-9)
}

/// What changed for one worker between two publications.
fn worker_events(before: Option<&WorkerRow>, now: &WorkerRow) -> Vec<(EventKind, String, String)> {
    let address = &now.address;
    let mut events = Vec::new();
    let was_up =
        before.is_some_and(|b| matches!(b.state, WorkerState::Connected | WorkerState::Stalled));
    let is_up = matches!(now.state, WorkerState::Connected | WorkerState::Stalled);
    if is_up && !was_up {
        events.push((
            EventKind::WorkerJoined,
            address.clone(),
            format!(
                "worker {address} ({}, {} thread{}) joined",
                now.hostname,
                now.threads,
                if now.threads == 1 { "" } else { "s" }
            ),
        ));
    }
    let requeued =
        now.units_requeued - before.map_or(0, |b| b.units_requeued.min(now.units_requeued));
    if requeued > 0 {
        events.push((
            EventKind::UnitsRequeued,
            address.clone(),
            format!("{requeued} unit(s) of worker {address} went back to the queue"),
        ));
    }
    if was_up && now.state == WorkerState::Gone {
        events.push((
            EventKind::WorkerLeft,
            address.clone(),
            format!(
                "worker {address} left: {}",
                now.reason.as_deref().unwrap_or("connection lost")
            ),
        ));
    }
    events
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(address: &str, state: WorkerState, units: u64, requeued: u64) -> WorkerRow {
        WorkerRow {
            address: address.into(),
            hostname: "h".into(),
            threads: 2,
            state,
            units,
            samples: units * 100,
            samples_per_second: 0.0,
            failures: 0,
            units_requeued: requeued,
            bytes_sent: 0,
            bytes_received: 0,
            reason: None,
        }
    }

    #[test]
    fn progress_counts_units_and_this_runs_samples() {
        let board = StatusBoard::unserved();
        board.plan(10, 2, 1000, 200);
        board.unit_merged(100);
        board.unit_merged(100);
        let snap = board.snapshot();
        assert_eq!(snap.progress.units_done, 4);
        assert_eq!(snap.progress.samples_done, 400);
        assert!((snap.progress.ratio - 0.4).abs() < 1e-12);
        assert!(snap.progress.eta_seconds.unwrap() > 0.0);
        assert_eq!(snap.state, RenderState::Rendering);
        board.finish(Some("x.png".into()), None);
        let snap = board.snapshot();
        assert_eq!(snap.state, RenderState::Finished);
        let summary = snap.summary.unwrap();
        assert_eq!(
            summary.samples, 200,
            "the resumed samples are not this run's"
        );
        assert_eq!(snap.progress.eta_seconds, None);
        assert_eq!(snap.events.last().unwrap().kind, EventKind::RenderFinished);
    }

    #[test]
    fn worker_transitions_become_events() {
        let board = StatusBoard::unserved();
        let d = Duration::from_secs(60);
        board.set_workers(vec![row("a:1", WorkerState::Connecting, 0, 0)], d);
        assert!(board.snapshot().events.is_empty());
        board.set_workers(vec![row("a:1", WorkerState::Connected, 1, 0)], d);
        board.set_workers(vec![row("a:1", WorkerState::Gone, 3, 2)], d);
        let kinds: Vec<_> = board.snapshot().events.iter().map(|e| e.kind).collect();
        assert_eq!(
            kinds,
            [
                EventKind::WorkerJoined,
                EventKind::UnitsRequeued,
                EventKind::WorkerLeft
            ]
        );
        let snap = board.snapshot();
        assert_eq!(snap.progress.units_requeued, 2);
        assert!(snap.events[1].text.starts_with("2 unit(s)"));
    }

    #[test]
    fn a_connected_worker_without_results_is_stalled() {
        let board = StatusBoard::unserved();
        board.set_workers(
            vec![row("a:1", WorkerState::Connected, 5, 0)],
            Duration::ZERO,
        );
        // The floor keeps a fresh worker connected.
        assert_eq!(board.snapshot().workers[0].state, WorkerState::Connected);
        let mut s = board.state();
        let since = s.last_progress.get_mut("a:1").unwrap();
        since.1 -= MIN_STALLED_AFTER;
        drop(s);
        board.set_workers(
            vec![row("a:1", WorkerState::Connected, 5, 0)],
            Duration::ZERO,
        );
        assert_eq!(board.snapshot().workers[0].state, WorkerState::Stalled);
        board.set_workers(
            vec![row("a:1", WorkerState::Connected, 6, 0)],
            Duration::ZERO,
        );
        assert_eq!(board.snapshot().workers[0].state, WorkerState::Connected);
    }

    #[test]
    fn events_are_bounded() {
        let board = StatusBoard::unserved();
        for i in 0..MAX_EVENTS + 7 {
            board.event(
                EventKind::CheckpointWritten,
                format!("{i} {}", "x".repeat(1000)),
            );
        }
        let events = board.snapshot().events;
        assert_eq!(events.len(), MAX_EVENTS);
        assert!(events[0].text.starts_with("7 "), "the oldest went first");
        assert!(events
            .iter()
            .all(|e| e.text.chars().count() <= MAX_EVENT_CHARS));
    }

    #[test]
    fn images_are_made_only_when_served_watched_and_changed() {
        assert!(!StatusBoard::unserved().image_due());
        let board = StatusBoard::new(SceneInfo::default(), SettingsInfo::default(), true);
        assert!(board.image_due(), "the first one");
        board.publish_image(image::RgbImage::new(4, 3), Duration::ZERO);
        assert!(!board.image_due(), "not again at once");
        board.state().image_at = Some(Instant::now() - IMAGE_EVERY);
        assert!(!board.image_due(), "the film has not changed");
        board.unit_merged(1);
        assert!(!board.image_due(), "nobody has asked for one");
        let first = board.image().unwrap();
        assert_eq!((first.generation, first.image.width()), (1, 4));
        assert!(board.image_due());
        // An image that cost 20 ms to make and 5 ms to encode waits 2.5 s for the next.
        board.publish_image(image::RgbImage::new(4, 3), Duration::from_millis(20));
        board.note_encode_cost(Duration::from_millis(5));
        assert_eq!(board.snapshot().image.generation, 2);
        board.unit_merged(1);
        board.state().image_at = Some(Instant::now() - IMAGE_EVERY);
        assert!(!board.image_due(), "1 s is not enough for a costly image");
        board.state().image_at = Some(Instant::now() - Duration::from_millis(2500));
        assert!(board.image_due());
    }
}
