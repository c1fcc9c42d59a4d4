//! The fuzzing loop shared by the targets: make an input, run it under `catch_unwind`, record
//! each distinct panic (by where it happened) with a minimized input saved to the crash folder,
//! count inputs that took too long, and report the figures.

use std::collections::HashMap;
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use fastrand::Rng;

/// A fuzz target: makes inputs and runs the code under test on them.
pub trait Target {
    type Input: Clone;

    /// The target's name, for reports and crash file names.
    fn name(&self) -> &'static str;

    /// The next input to run, usually a mutation of what the target has seen.
    fn generate(&mut self, rng: &mut Rng) -> Self::Input;

    /// Runs the code under test on `input`. A panic here is a finding; the returned
    /// signature (what the code said: error kinds, warnings) lets the target keep inputs that
    /// reached something new.
    fn execute(&self, input: &Self::Input) -> Outcome;

    /// Told the outcome of an input that did not panic.
    fn learn(&mut self, input: Self::Input, outcome: Outcome);

    /// Smaller variants of `input`, tried in order when minimizing a crash.
    fn shrink(&self, input: &Self::Input) -> Vec<Self::Input>;

    /// Writes `input` under `path` (a file or a folder the target chooses the layout of).
    fn save(&self, input: &Self::Input, path: &Path) -> std::io::Result<PathBuf>;

    /// How far the inputs got so far (e.g. how many parsed, built, rendered), for the report.
    fn progress(&self) -> String;
}

/// What an input that did not panic produced: a few hashes standing for what the code did
/// (which errors, which warnings), for corpus feedback, and whether it was accepted.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    pub features: Vec<u64>,
    /// The input got past the first check (a scene parsed).
    pub parsed: bool,
}

/// A panic the campaign saw: where, what it said, how often, and the saved input.
#[derive(Clone, Debug)]
pub struct Finding {
    pub location: String,
    pub message: String,
    pub hits: u64,
    pub saved: Option<PathBuf>,
}

/// The figures of a campaign.
#[derive(Clone, Debug)]
pub struct Report {
    pub target: &'static str,
    pub inputs: u64,
    pub elapsed: Duration,
    /// Inputs that got past the first check (a scene that parsed), without a panic.
    pub accepted: u64,
    /// Distinct panics, by location.
    pub findings: Vec<Finding>,
    /// Inputs that ran longer than the slow bound, and the longest one.
    pub slow_inputs: u64,
    pub slowest: Duration,
    /// The target's account of how far inputs got.
    pub progress: String,
}

impl Report {
    pub fn inputs_per_second(&self) -> f64 {
        self.inputs as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    pub fn total_panics(&self) -> u64 {
        self.findings.iter().map(|f| f.hits).sum()
    }
}

impl std::fmt::Display for Report {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{}: {} inputs in {:.1} s ({:.0} inputs/s); {} distinct panics ({} inputs panicked); \
             {} inputs slower than the bound (slowest {:.3} s)",
            self.target,
            self.inputs,
            self.elapsed.as_secs_f64(),
            self.inputs_per_second(),
            self.findings.len(),
            self.total_panics(),
            self.slow_inputs,
            self.slowest.as_secs_f64()
        )?;
        writeln!(f, "  reached: {}", self.progress)?;
        for finding in &self.findings {
            writeln!(
                f,
                "  panic at {} ({} hits): {}",
                finding.location, finding.hits, finding.message
            )?;
            if let Some(path) = &finding.saved {
                writeln!(f, "    input: {}", path.display())?;
            }
        }
        Ok(())
    }
}

/// How a campaign runs.
#[derive(Clone, Debug)]
pub struct Settings {
    pub inputs: u64,
    pub seed: u64,
    /// Where crash inputs go (None: kept in memory only, as in tests).
    pub crash_dir: Option<PathBuf>,
    /// An input running longer than this is counted (and saved) as slow.
    pub slow: Duration,
    /// Print progress every this many inputs (0: never).
    pub progress_every: u64,
    /// Time spent minimizing each new panic's input.
    pub minimize_for: Duration,
}

/// The panic the hook saw last: location and message. A panic inside a rayon task is
/// caught on another thread and resumed on the caller's, so this is global, not per thread.
static LAST_PANIC: Mutex<Option<(String, String)>> = Mutex::new(None);

/// One campaign at a time in a process: the panic hook and [`LAST_PANIC`] are global.
static CAMPAIGN: Mutex<()> = Mutex::new(());

/// While alive, panics are recorded in [`LAST_PANIC`] instead of printed; only one exists at a
/// time in a process.
struct PanicCapture {
    _only_one: MutexGuard<'static, ()>,
}

impl PanicCapture {
    fn install() -> Self {
        let only_one = CAMPAIGN.lock().unwrap_or_else(|e| e.into_inner());
        panic::set_hook(Box::new(|info| {
            let location = info
                .location()
                .map(|l| format!("{}:{}:{}", l.file(), l.line(), l.column()))
                .unwrap_or_else(|| "unknown".into());
            let message = if let Some(s) = info.payload().downcast_ref::<&str>() {
                s.to_string()
            } else if let Some(s) = info.payload().downcast_ref::<String>() {
                s.clone()
            } else {
                "(non-text panic payload)".into()
            };
            *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = Some((location, message));
        }));
        Self {
            _only_one: only_one,
        }
    }
}

impl Drop for PanicCapture {
    fn drop(&mut self) {
        // Back to the default hook, which prints panics.
        drop(panic::take_hook());
    }
}

/// Runs one saved input; if it panics, returns where and what with the input minimized for up
/// to `minimize_for`.
pub fn replay<T: Target>(
    target: &T,
    input: T::Input,
    minimize_for: Duration,
) -> Result<Outcome, (String, String, T::Input)> {
    let _capture = PanicCapture::install();
    run_one(target, &input).map_err(|(location, message)| {
        let small = minimize(target, input, &location, minimize_for);
        (location, message, small)
    })
}

/// Runs `settings.inputs` inputs of `target` and reports what happened.
pub fn run<T: Target>(target: &mut T, settings: &Settings) -> Report {
    let capture = PanicCapture::install();
    let mut rng = Rng::with_seed(settings.seed);
    let mut findings: Vec<Finding> = Vec::new();
    let mut by_location: HashMap<String, usize> = HashMap::new();
    let (mut slow_inputs, mut slowest) = (0u64, Duration::ZERO);
    let mut accepted = 0u64;
    let started = Instant::now();
    for n in 0..settings.inputs {
        let input = target.generate(&mut rng);
        let t0 = Instant::now();
        let result = run_one(target, &input);
        let took = t0.elapsed();
        slowest = slowest.max(took);
        if took > settings.slow {
            slow_inputs += 1;
            if let Some(dir) = &settings.crash_dir {
                let name = format!("{}-slow-{n}", target.name());
                save(target, &input, dir, &name);
            }
        }
        match result {
            Ok(outcome) => {
                accepted += u64::from(outcome.parsed);
                target.learn(input, outcome);
            }
            Err((location, message)) => match by_location.get(&location) {
                Some(&i) => findings[i].hits += 1,
                None => {
                    let small = minimize(target, input, &location, settings.minimize_for);
                    let saved = settings.crash_dir.as_ref().and_then(|dir| {
                        let name = format!("{}-crash-{}", target.name(), findings.len() + 1);
                        save(target, &small, dir, &name)
                    });
                    eprintln!("new panic at {location}: {message}");
                    by_location.insert(location.clone(), findings.len());
                    findings.push(Finding {
                        location,
                        message,
                        hits: 1,
                        saved,
                    });
                }
            },
        }
        if settings.progress_every > 0 && (n + 1) % settings.progress_every == 0 {
            let secs = started.elapsed().as_secs_f64();
            eprintln!(
                "{}: {} inputs, {:.0}/s, {} distinct panics; {}",
                target.name(),
                n + 1,
                (n + 1) as f64 / secs,
                findings.len(),
                target.progress()
            );
        }
    }
    let elapsed = started.elapsed();
    drop(capture);
    Report {
        target: target.name(),
        inputs: settings.inputs,
        elapsed,
        accepted,
        findings,
        slow_inputs,
        slowest,
        progress: target.progress(),
    }
}

/// Runs one input; Err(location, message) if it panicked.
fn run_one<T: Target>(target: &T, input: &T::Input) -> Result<Outcome, (String, String)> {
    panic::catch_unwind(AssertUnwindSafe(|| target.execute(input))).map_err(|_| {
        LAST_PANIC
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()
            .unwrap_or_else(|| ("unknown".into(), "(no panic recorded)".into()))
    })
}

/// Greedily takes smaller variants of `input` that still panic at `location`.
fn minimize<T: Target>(
    target: &T,
    mut input: T::Input,
    location: &str,
    minimize_for: Duration,
) -> T::Input {
    let deadline = Instant::now() + minimize_for;
    'shrinking: while Instant::now() < deadline {
        for candidate in target.shrink(&input) {
            if Instant::now() > deadline {
                break 'shrinking;
            }
            if matches!(run_one(target, &candidate), Err((at, _)) if at == location) {
                input = candidate;
                continue 'shrinking;
            }
        }
        break;
    }
    input
}

fn save<T: Target>(target: &T, input: &T::Input, dir: &Path, name: &str) -> Option<PathBuf> {
    let result = std::fs::create_dir_all(dir).and_then(|()| target.save(input, &dir.join(name)));
    match result {
        Ok(path) => Some(path),
        Err(e) => {
            eprintln!("cannot save {name} in {}: {e}", dir.display());
            None
        }
    }
}
