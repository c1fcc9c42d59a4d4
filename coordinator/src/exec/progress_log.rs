//! A render's progress for logs: where standard error is no terminal (Slurm's and Kubernetes'
//! logs, a farm manager, `nohup`), the bar is hidden, so a line at a steady interval says how
//! far the render is (percent, samples/s, ETA, units, workers, requeues); `--progress-json`
//! writes the same figures as one JSON object a line, to standard error or a file, for
//! machines. Both read the job's status board, so every executor reports alike.

use std::io::Write;
use std::path::PathBuf;
use std::sync::mpsc;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use serde::Serialize;

use crate::status::snapshot::{ProgressFigures, RenderState, Snapshot, WorkerState};
use crate::status::StatusBoard;

/// The interval of progress lines when none is given.
pub const DEFAULT_PROGRESS_EVERY: Duration = Duration::from_secs(10);

/// What a render logs of its progress besides the bar.
#[derive(Clone, Debug)]
pub struct ProgressLog {
    /// How often a line (and a JSON object) is written.
    pub every: Duration,
    /// Where JSON lines go, if anywhere.
    pub json: Option<JsonTarget>,
}

impl Default for ProgressLog {
    fn default() -> Self {
        Self {
            every: DEFAULT_PROGRESS_EVERY,
            json: None,
        }
    }
}

#[derive(Clone, Debug)]
pub enum JsonTarget {
    Stderr,
    File(PathBuf),
}

/// One JSON progress line: the board's figures, the render's state and the workers connected.
#[derive(Serialize)]
struct JsonLine<'a> {
    state: RenderState,
    #[serde(flatten)]
    progress: &'a ProgressFigures,
    workers_connected: usize,
}

/// The thread writing progress lines until [`LogThread::stop`].
pub struct LogThread {
    stop: mpsc::Sender<()>,
    thread: JoinHandle<()>,
}

impl LogThread {
    /// Starts writing `log`'s lines from `board`: text lines on standard error when `lines`,
    /// JSON lines where `log.json` says. None when neither is asked for, or when the JSON file
    /// cannot be created (said on standard error: the render goes on without it).
    pub fn start(board: Arc<StatusBoard>, log: &ProgressLog, lines: bool) -> Option<Self> {
        let mut json: Option<Box<dyn Write + Send>> = match &log.json {
            None => None,
            Some(JsonTarget::Stderr) => Some(Box::new(std::io::stderr())),
            Some(JsonTarget::File(path)) => match std::fs::File::create(path) {
                Ok(file) => Some(Box::new(std::io::LineWriter::new(file))),
                Err(e) => {
                    eprintln!("cannot write the progress to {}: {e}", path.display());
                    None
                }
            },
        };
        if !lines && json.is_none() {
            return None;
        }
        let (stop, stopped) = mpsc::channel();
        let every = log.every.max(Duration::from_millis(10));
        let thread = std::thread::spawn(move || loop {
            let last = !matches!(
                stopped.recv_timeout(every),
                Err(mpsc::RecvTimeoutError::Timeout)
            );
            let snapshot = board.snapshot();
            // The last line is the summary's to write; JSON readers get a last object.
            if lines && !last {
                eprintln!("{}", progress_line(&snapshot));
            }
            if let Some(out) = json.as_mut() {
                let line = JsonLine {
                    state: snapshot.state,
                    progress: &snapshot.progress,
                    workers_connected: connected(&snapshot),
                };
                let written = serde_json::to_writer(&mut *out, &line)
                    .map_err(std::io::Error::from)
                    .and_then(|()| out.write_all(b"\n"));
                if let Err(e) = written {
                    eprintln!("cannot write the progress: {e}; no more progress lines");
                    json = None;
                }
            }
            if last {
                break;
            }
        });
        Some(Self { stop, thread })
    }

    /// Writes the last JSON object and ends the thread.
    pub fn stop(self) {
        let _ = self.stop.send(());
        let _ = self.thread.join();
    }
}

fn connected(snapshot: &Snapshot) -> usize {
    snapshot
        .workers
        .iter()
        .filter(|w| w.state == WorkerState::Connected)
        .count()
}

/// "progress 42.0% | 1.20 M of 3.10 M samples | 0.85 M samples/s | ETA 2 s | units 40 of 96",
/// then the round, the workers and the requeued units where there are any.
fn progress_line(snapshot: &Snapshot) -> String {
    let p = &snapshot.progress;
    let millions = |n: f64| n / 1e6;
    let eta = p
        .eta_seconds
        .map_or_else(|| "unknown".to_string(), |s| format!("{s:.0} s"));
    let mut line = format!(
        "progress {:.1}% | {:.2} M of {:.2} M samples | {:.2} M samples/s | ETA {eta} | units {} of {}",
        100.0 * p.ratio,
        millions(p.samples_done as f64),
        millions(p.samples_total as f64),
        millions(p.samples_per_second),
        p.units_done,
        p.units_total,
    );
    if let (Some(round), Some(rounds)) = (p.round, p.rounds) {
        line.push_str(&format!(" | round {round} of {rounds}"));
    }
    if !snapshot.workers.is_empty() {
        line.push_str(&format!(
            " | workers {} connected of {}",
            connected(snapshot),
            snapshot.workers.len()
        ));
    }
    if p.units_requeued > 0 {
        line.push_str(&format!(" | {} units requeued", p.units_requeued));
    }
    line
}
