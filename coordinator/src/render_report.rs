//! The figures of one render: printed at its end and written by `--stats-json`.

use std::time::Duration;

use yat_tracer::render::sampling::{RoundsEnd, Sampling};

use crate::exec::distributed::report::DistributedReport;
use crate::job::{RenderJob, RenderOutcome};

#[derive(serde::Serialize)]
pub struct RenderReport {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub triangles: Option<usize>,
    /// The continuations camera paths took at their first broad vertex (in-process renders;
    /// `yat_tracer::render::branching`).
    pub first_vertex_branches: Option<usize>,
    pub parse_seconds: f64,
    pub build_seconds: Option<f64>,
    pub render_seconds: f64,
    pub samples: u64,
    pub rays: u64,
    pub dropped_samples: u64,
    pub samples_per_second: f64,
    pub rays_per_second: f64,
    pub peak_memory_bytes: Option<u64>,
    /// Rounds of an adaptive render (its spp is then the most a pixel got).
    pub adaptive_rounds: Option<u32>,
    /// How a render halted by convergence ended (its spp is then the most it could take).
    pub convergence: Option<ConvergenceEnd>,
    /// The build of the coordinator's process ([`crate::isa::build_name`]), which renders an
    /// in-process render.
    pub instruction_set: &'static str,
    /// A distributed render's figures of the workers and the coordinator (`--workers-json`
    /// writes them, the stats JSON leaves them out).
    #[serde(skip)]
    pub workers: Option<DistributedReport>,
}

/// The end of a render halted by convergence: the samples every pixel got, and how many pixels
/// changed visibly in its last test.
#[derive(serde::Serialize)]
pub struct ConvergenceEnd {
    pub spp: u32,
    pub converged: bool,
    pub unconverged_pixels: Option<u64>,
    pub pixels: u64,
    pub threshold: f32,
}

impl ConvergenceEnd {
    fn of(outcome: &RenderOutcome, sampling: &Sampling) -> Option<Self> {
        let Sampling::Converging(halt) = sampling else {
            return None;
        };
        let (spp, converged, unconverged, pixels) = match outcome.ended? {
            RoundsEnd::Converged {
                spp,
                unconverged,
                pixels,
            } => (spp, true, Some(unconverged), pixels),
            RoundsEnd::SamplesSpent {
                spp,
                unconverged,
                pixels,
            } => (spp, false, unconverged, pixels),
            RoundsEnd::Planned => return None,
        };
        Some(Self {
            spp,
            converged,
            unconverged_pixels: unconverged,
            pixels,
            threshold: halt.threshold,
        })
    }

    /// "96 spp (converged: 12 of 1536 pixels, 0.78%, changed visibly in the last test, at
    /// most 2%)".
    fn describe(&self) -> String {
        let changed = match self.unconverged_pixels {
            Some(n) => format!(
                "{n} of {} pixels, {:.2}%, changed visibly in the last test",
                self.pixels,
                100.0 * n as f64 / self.pixels.max(1) as f64
            ),
            None => "no test yet".to_string(),
        };
        let how = if self.converged {
            "converged"
        } else {
            "samples spent before converging"
        };
        format!(
            "{} spp ({how}: {changed}, halting at {}% or fewer)",
            self.spp,
            self.threshold * 100.0
        )
    }
}

impl RenderReport {
    /// The figures of `job`, rendered into `outcome` in `render_time` (parse and build apart).
    pub fn new(job: &RenderJob, outcome: &RenderOutcome, render_time: Duration) -> Self {
        let render_secs = render_time.as_secs_f64().max(1e-9);
        let stats = &outcome.stats;
        Self {
            scene: job.scene.path.display().to_string(),
            width: job.settings.width,
            height: job.settings.height,
            spp: job.settings.spp,
            max_depth: job.settings.max_depth,
            triangles: outcome.build.as_ref().map(|b| b.triangles),
            first_vertex_branches: outcome.build.as_ref().map(|b| b.first_vertex_branches),
            parse_seconds: job.scene.parse_time.as_secs_f64(),
            build_seconds: outcome.build.as_ref().map(|b| b.time.as_secs_f64()),
            render_seconds: render_secs,
            samples: stats.samples,
            rays: stats.rays,
            dropped_samples: stats.dropped,
            samples_per_second: stats.samples as f64 / render_secs,
            rays_per_second: stats.rays as f64 / render_secs,
            peak_memory_bytes: peak_memory_bytes(),
            adaptive_rounds: outcome.round.as_ref().map(|r| r.index + 1),
            convergence: ConvergenceEnd::of(outcome, &job.sampling),
            instruction_set: crate::isa::build_name(),
            workers: None,
        }
    }

    pub fn print(&self) {
        let pixels = u64::from(self.width) * u64::from(self.height);
        println!(
            "{}x{} at {}, depth {}{}{}",
            self.width,
            self.height,
            match (self.adaptive_rounds, &self.convergence) {
                (Some(rounds), _) => format!(
                    "{:.1} spp on average (adaptive: {rounds} rounds, at most {})",
                    self.samples as f64 / pixels.max(1) as f64,
                    self.spp
                ),
                (None, Some(end)) => end.describe(),
                (None, None) => format!("{} spp", self.spp),
            },
            self.max_depth,
            self.triangles
                .map_or(String::new(), |t| format!(", {t} triangles")),
            self.first_vertex_branches
                .filter(|&b| b > 1)
                .map_or(String::new(), |b| format!(
                    ", {b} continuations from each camera path's first bounce"
                ))
        );
        println!(
            "parse {:.3} s{}, render {:.3} s",
            self.parse_seconds,
            self.build_seconds
                .map_or(String::new(), |b| format!(", build {b:.3} s")),
            self.render_seconds
        );
        println!(
            "{:.3} M samples/s, {:.3} M rays/s{}{}",
            self.samples_per_second / 1e6,
            self.rays_per_second / 1e6,
            self.peak_memory_bytes
                .map_or(String::new(), |m| format!(", peak memory {} MB", m >> 20)),
            if self.dropped_samples > 0 {
                format!(", {} NaN/Inf samples dropped", self.dropped_samples)
            } else {
                String::new()
            }
        );
    }
}

/// The process's peak resident set size, where the OS reports it (Linux).
fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
