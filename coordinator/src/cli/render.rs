//! `yat render`: parse, build, render in-process on all cores (or hand the job to workers),
//! then write the image the scene's Film names.

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use yat_tracer::desc::SceneDesc;
use yat_tracer::film::Film;
use yat_tracer::render::{
    plan_units, RenderOverrides, RenderScene, RenderSettings, UnitStats, WorkUnit,
};

use super::latlong::LatLongArg;
use crate::checkpoint::{Checkpoint, CheckpointFile, RenderIdentity};
use crate::exec::distributed::DistributedArgs;
use crate::interim::{InterimClock, InterimOutputs, PreviewFile};
use crate::manifest::SceneManifest;
use crate::scene::{ParsedScene, Warnings};
use crate::shutdown::{Interrupt, Interrupted};

#[derive(clap::Args)]
pub struct RenderArgs {
    /// The main .lxs file.
    pub scene: PathBuf,
    /// Output PNG (default: the Film's filename plus .png, in the current folder).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write linear radiance as OpenEXR next to the PNG.
    #[arg(long)]
    pub exr: bool,
    /// Samples per pixel (default: the Film's haltspp, else 64).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Maximum path depth (default: the scene's integrator depth).
    #[arg(long)]
    pub maxdepth: Option<u32>,
    /// Render threads for an in-process render (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of the sampler: the same seed gives the same image.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Image size WxH, overriding the Film (the camera's screen window is kept).
    #[arg(long, value_parser = parse_resolution)]
    pub resolution: Option<(u32, u32)>,
    /// LatLong environment-map convention.
    #[arg(long, value_enum, default_value = "seed")]
    pub latlong: LatLongArg,
    /// No progress bar and no summary.
    #[arg(short, long)]
    pub quiet: bool,
    /// Write the render's figures (times, samples/s, rays/s, memory) as JSON to this file.
    #[arg(long)]
    pub stats_json: Option<PathBuf>,
    /// Save the render so far to `<output>.resume` this often (and on Ctrl-C), so that running
    /// the same command again resumes it; 0 disables checkpoints.
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
    pub checkpoint_every: f64,
    /// Rewrite `<output>.preview.png` this often during the render; 0 disables.
    #[arg(long, value_name = "SECONDS", default_value_t = 10.0)]
    pub preview_every: f64,
    #[command(flatten)]
    pub distributed: DistributedArgs,
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, got {s:?}"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=65_536).contains(&n))
            .ok_or_else(|| format!("bad size {v:?} in {s:?} (1 to 65536)"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// What a render needs, whoever renders it.
pub struct RenderJob {
    pub main_file: PathBuf,
    pub desc: SceneDesc,
    pub settings: RenderSettings,
    /// The PNG the render will write; previews and the checkpoint go next to it.
    pub output_png: PathBuf,
    pub quiet: bool,
    /// The preview and the checkpoint, written as the render goes.
    pub interim: InterimOutputs,
    /// Set by Ctrl-C or SIGTERM when checkpoints are on: the render stops, saved.
    pub interrupt: Interrupt,
}

impl RenderJob {
    /// The render to start from: the checkpoint a previous run of this render left, or nothing.
    pub fn resume(&self, units: &[WorkUnit]) -> Checkpoint {
        match &self.interim.checkpoint {
            Some(file) => file.resume(&self.settings, units, self.quiet),
            None => Checkpoint::new(&self.settings, units.len()),
        }
    }

    /// The error of a render that stopped short, after saving what it merged and saying how to
    /// resume it.
    pub fn stopped(
        &self,
        checkpoint: &Checkpoint,
        units: &[WorkUnit],
        why: anyhow::Error,
    ) -> anyhow::Error {
        let kept = match &self.interim.checkpoint {
            Some(file) if checkpoint.done_count() > 0 => Some(match file.save(checkpoint) {
                Ok(()) => format!(
                    "{:.1}% of the samples are kept in {}; the same command resumes the render",
                    100.0 * checkpoint.done_samples(units) as f64
                        / units.iter().map(WorkUnit::sample_count).sum::<u64>().max(1) as f64,
                    file.path().display()
                ),
                Err(e) => format!("{e:#}"),
            }),
            _ => None,
        };
        match (self.interrupt.is_set(), kept) {
            (true, kept) => Interrupted {
                kept: kept.unwrap_or_else(|| "nothing had been rendered yet".into()),
            }
            .into(),
            (false, Some(kept)) => anyhow::anyhow!("{why:#}\n{kept}"),
            (false, None) => why,
        }
    }
}

/// A duration option given in seconds.
pub fn seconds(name: &str, value: f64) -> anyhow::Result<Duration> {
    Duration::try_from_secs_f64(value)
        .with_context(|| format!("--{name} must be a non-negative number of seconds"))
}

/// The merged result of a render.
pub struct RenderOutcome {
    pub film: Film,
    pub stats: UnitStats,
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let scene = ParsedScene::load(
        &args.scene,
        if args.quiet {
            Warnings::Keep
        } else {
            Warnings::Print
        },
    )?;
    let parse_time = scene.parse_time;
    let desc = &scene.desc;
    let overrides = RenderOverrides {
        spp: args.spp,
        max_depth: args.maxdepth,
        seed: Some(args.seed),
        resolution: args.resolution,
        latlong: args.latlong.into(),
    };
    let settings = RenderSettings::resolve(desc, &overrides);
    let output_png = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.png", desc.film.filename)));
    let checkpoint_every = seconds("checkpoint-every", args.checkpoint_every)?;
    let preview_every = seconds("preview-every", args.preview_every)?;
    // The files by content: what workers receive, and what names the render for its checkpoint.
    let manifest = if args.distributed.is_active() || !checkpoint_every.is_zero() {
        Some(SceneManifest::read(&scene)?)
    } else {
        None
    };
    let checkpoint = manifest
        .as_ref()
        .filter(|_| !checkpoint_every.is_zero())
        .map(|m| {
            let identity = RenderIdentity::of(&m.load_request(&settings));
            CheckpointFile::beside(&output_png, identity, checkpoint_every)
        });
    let interrupt = if checkpoint.is_some() {
        Interrupt::install()?
    } else {
        Interrupt::default()
    };
    let ParsedScene {
        path: main_file,
        source,
        desc,
        ..
    } = scene;
    let job = RenderJob {
        main_file,
        desc,
        settings,
        interim: InterimOutputs {
            preview: (!preview_every.is_zero())
                .then(|| PreviewFile::beside(&output_png, preview_every)),
            checkpoint,
        },
        output_png,
        quiet: args.quiet,
        interrupt,
    };

    let (outcome, build_time, triangles) = match manifest {
        Some(manifest) if args.distributed.is_active() => (
            crate::exec::distributed::render(&args.distributed, &job, manifest)?,
            None,
            None,
        ),
        _ => {
            drop(manifest);
            let build_start = Instant::now();
            let scene = RenderScene::build(&job.desc, &source, &job.settings)
                .with_context(|| format!("cannot build {}", args.scene.display()))?;
            let build_time = build_start.elapsed();
            let triangles = scene.triangle_count();
            (
                render_in_process(&scene, args.threads, &job)?,
                Some(build_time),
                Some(triangles),
            )
        }
    };
    let render_time = started.elapsed() - parse_time - build_time.unwrap_or_default();

    write_outputs(&job, &outcome.film, args.exr)?;
    job.interim.remove();
    let render_secs = render_time.as_secs_f64().max(1e-9);
    let report = RenderReport {
        scene: job.main_file.display().to_string(),
        width: job.settings.width,
        height: job.settings.height,
        spp: job.settings.spp,
        max_depth: job.settings.max_depth,
        triangles,
        parse_seconds: parse_time.as_secs_f64(),
        build_seconds: build_time.map(|b| b.as_secs_f64()),
        render_seconds: render_secs,
        samples: outcome.stats.samples,
        rays: outcome.stats.rays,
        dropped_samples: outcome.stats.dropped,
        samples_per_second: outcome.stats.samples as f64 / render_secs,
        rays_per_second: outcome.stats.rays as f64 / render_secs,
        peak_memory_bytes: peak_memory_bytes(),
    };
    if let Some(path) = &args.stats_json {
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if !args.quiet {
        println!("wrote {}", job.output_png.display());
        report.print();
    }
    Ok(())
}

/// The render so far, as the in-process render threads share it.
struct InProcessState {
    checkpoint: Checkpoint,
    stats: UnitStats,
    clock: InterimClock,
}

/// Renders every unit of the plan not yet in the job's checkpoint on a rayon pool, merging as
/// units finish and writing the preview and checkpoint as often as the job asks.
pub fn render_in_process(
    scene: &RenderScene,
    threads: Option<usize>,
    job: &RenderJob,
) -> anyhow::Result<RenderOutcome> {
    let units = plan_units(scene.settings());
    let start = job.resume(&units);
    let todo: Vec<WorkUnit> = units
        .iter()
        .filter(|u| !start.is_done(u))
        .copied()
        .collect();
    let progress = progress_bar(
        units.iter().map(WorkUnit::sample_count).sum(),
        start.done_samples(&units),
        job.quiet,
    );
    let state = Mutex::new(InProcessState {
        checkpoint: start,
        stats: UnitStats::default(),
        clock: InterimClock::default(),
    });
    // One thread writes at a time; one finding another writing leaves it to that one.
    let writing = Mutex::new(());
    let poisoned = || anyhow::anyhow!("a render thread panicked");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("cannot start the render threads")?;
    let result = pool.install(|| {
        todo.par_iter().try_for_each(|unit| {
            if job.interrupt.is_set() {
                anyhow::bail!("interrupted");
            }
            let (buffer, unit_stats) = scene.render_unit(unit);
            let staged = {
                let mut state = state.lock().map_err(|_| poisoned())?;
                state.checkpoint.add(&buffer)?;
                state.stats += unit_stats;
                let guard = writing.try_lock().ok();
                let due = match guard {
                    Some(_) => job.interim.due(&mut state.clock),
                    None => Default::default(),
                };
                due.any().then(|| {
                    let staged = job.interim.stage(due, &state.checkpoint, &job.desc.film);
                    (guard, staged)
                })
            };
            progress.inc(unit_stats.samples);
            // Encoding and syncing happen with the render's lock released.
            if let Some((_guard, staged)) = staged {
                for e in staged.finish() {
                    progress.println(format!("{e:#}"));
                }
            }
            anyhow::Ok(())
        })
    });
    progress.finish_and_clear();
    let state = state.into_inner().map_err(|_| poisoned())?;
    if let Err(why) = result {
        return Err(job.stopped(&state.checkpoint, &units, why));
    }
    Ok(RenderOutcome {
        film: state.checkpoint.into_film(),
        stats: state.stats,
    })
}

/// A progress bar over samples (hidden when quiet), starting at those a checkpoint holds; its
/// message, if any, follows the ETA.
pub fn progress_bar(total_samples: u64, done_samples: u64, quiet: bool) -> ProgressBar {
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

/// Writes the PNG (and the linear EXR when asked) exactly the same way for every render path.
pub fn write_outputs(job: &RenderJob, film: &Film, exr: bool) -> anyhow::Result<()> {
    film.write_png(&job.output_png, &job.desc.film)
        .with_context(|| format!("cannot write {}", job.output_png.display()))?;
    if exr {
        let path = job.output_png.with_extension("exr");
        film.write_exr(&path)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// The figures of one render, printed at the end and written by `--stats-json`.
#[derive(serde::Serialize)]
pub struct RenderReport {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub triangles: Option<usize>,
    pub parse_seconds: f64,
    pub build_seconds: Option<f64>,
    pub render_seconds: f64,
    pub samples: u64,
    pub rays: u64,
    pub dropped_samples: u64,
    pub samples_per_second: f64,
    pub rays_per_second: f64,
    pub peak_memory_bytes: Option<u64>,
}

impl RenderReport {
    fn print(&self) {
        println!(
            "{}x{} at {} spp, depth {}{}",
            self.width,
            self.height,
            self.spp,
            self.max_depth,
            self.triangles
                .map_or(String::new(), |t| format!(", {t} triangles"))
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
