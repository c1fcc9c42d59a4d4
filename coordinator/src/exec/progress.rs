//! A render's progress on the terminal, the same for every executor: a bar over samples that
//! starts at what a checkpoint holds (its length an estimate an adaptive render updates each
//! round), a status after the ETA, and lines printed above it.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

pub struct Progress {
    bar: ProgressBar,
    quiet: bool,
}

impl Progress {
    /// A bar over `total_samples`, `done_samples` of them already rendered; hidden when quiet.
    pub fn new(total_samples: u64, done_samples: u64, quiet: bool) -> Self {
        if quiet {
            return Self {
                bar: ProgressBar::hidden(),
                quiet,
            };
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
        Self { bar, quiet }
    }

    /// A new estimate of all the samples the render takes (an adaptive render's, per round).
    pub fn set_total(&self, total_samples: u64) {
        self.bar.set_length(total_samples);
    }

    /// Samples rendered since the last call.
    pub fn add_samples(&self, samples: u64) {
        self.bar.inc(samples);
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
    }
}
