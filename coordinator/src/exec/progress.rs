//! A render's progress, the same for every executor: on the terminal, a bar over samples that
//! starts at what a checkpoint holds (its length an estimate an adaptive render updates each
//! round), a status after the ETA, and lines printed above it; the same figures (units,
//! samples, rounds) on the job's status board; and, from the board, the lines of
//! [`super::progress_log`] where there is no terminal or JSON is asked for.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

use super::progress_log::LogThread;
use crate::checkpoint::Checkpoint;
use crate::job::RenderJob;
use crate::status::StatusBoard;

pub struct Progress {
    bar: ProgressBar,
    quiet: bool,
    board: Arc<StatusBoard>,
    log: Mutex<Option<LogThread>>,
}

impl Progress {
    /// The bar and the board of `job`, starting from `checkpoint` (what is already rendered
    /// counts as done); the bar is hidden when quiet.
    pub fn start(job: &RenderJob, checkpoint: &Checkpoint) -> Self {
        let settings = &job.settings;
        let (done, total) = checkpoint.samples(settings);
        let board = job.interim.status.clone();
        board.plan(
            checkpoint.units(settings).len(),
            checkpoint.done_count(),
            total,
            done,
        );
        let bar = Self::bar(total, done, job.quiet);
        // Text lines where the bar cannot be drawn (and the user did not ask for quiet).
        let lines = !job.quiet && bar.is_hidden();
        let log = LogThread::start(board.clone(), &job.progress_log, lines);
        let progress = Self {
            bar,
            quiet: job.quiet,
            board,
            log: Mutex::new(log),
        };
        progress.round(job, checkpoint);
        progress
    }

    /// The round under way of a render in rounds (nothing for a uniform one): its number and
    /// units left on the board, and the new estimate of all the samples on both.
    pub fn round(&self, job: &RenderJob, checkpoint: &Checkpoint) {
        let settings = &job.settings;
        let Some(round) = checkpoint.rounds().index() else {
            return;
        };
        let units_left = checkpoint
            .units(settings)
            .iter()
            .filter(|u| !checkpoint.is_done(u))
            .count();
        let total = checkpoint.samples(settings).1;
        self.board
            .round(round, job.sampling.round_count(settings), units_left, total);
        self.bar.set_length(total);
    }

    /// A unit's result merged.
    pub fn unit_merged(&self, samples: u64) {
        self.bar.inc(samples);
        self.board.unit_merged(samples);
    }

    /// A bar over `total_samples`, `done_samples` of them already rendered; hidden when quiet.
    fn bar(total_samples: u64, done_samples: u64, quiet: bool) -> ProgressBar {
        if quiet {
            return ProgressBar::hidden();
        }
        let bar = ProgressBar::new(total_samples).with_position(done_samples);
        // Records the resumed position, then forgets it, so samples/s and the ETA count this run.
        bar.tick();
        bar.reset_eta();
        bar.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{bar:30}] {percent:>3}% {human_pos}/{human_len} samples, {per_sec}, ETA {eta} {msg}",
            )
            .expect("static template")
            .progress_chars("=> "),
        );
        bar.enable_steady_tick(Duration::from_millis(200));
        bar
    }

    /// The text after the ETA.
    pub fn set_status(&self, status: String) {
        self.bar.set_message(status);
    }

    /// A line above the bar, or on stderr when there is no bar to draw (not a terminal);
    /// nothing when quiet.
    pub fn say(&self, line: &str) {
        if self.quiet {
            return;
        }
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
        let log = self.log.lock().ok().and_then(|mut log| log.take());
        if let Some(log) = log {
            log.stop();
        }
    }
}
