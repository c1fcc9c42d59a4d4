//! The in-process executor: builds the scene here and renders every unit of the plan not yet in
//! the job's checkpoint on a rayon pool, merging as units finish and writing the preview and the
//! checkpoint as often as the job asks; an adaptive render does so round after round, each
//! decided from the film merged by the last.

use std::sync::Mutex;
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;
use yat_tracer::render::{UnitStats, WorkUnit};

use super::progress::Progress;
use crate::checkpoint::Checkpoint;
use crate::interim::InterimClock;
use crate::job::{RenderJob, RenderOutcome, SceneBuild, TimeLimitReached};

/// The render so far, as the render threads share it.
struct InProcessState {
    checkpoint: Checkpoint,
    stats: UnitStats,
    clock: InterimClock,
}

/// Renders `job` on `threads` threads (default: the CPUs this process may use).
pub fn render(job: &RenderJob, threads: Option<usize>) -> anyhow::Result<RenderOutcome> {
    let threads = crate::cpus::threads_or_usable_cpus(threads, "in-process render");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the render threads")?;
    let build_start = Instant::now();
    // In the render's threads: the build's pilot (`render::branching`) runs on them too.
    let scene = pool.install(|| job.scene.build(&job.settings))?;
    let build = SceneBuild {
        time: build_start.elapsed(),
        triangles: scene.triangle_count(),
        first_vertex_branches: scene.first_vertex_branches(),
    };

    let settings = &job.settings;
    let start = job.resume();
    let progress = Progress::start(job, &start);
    let status = &job.interim.status;
    let state = Mutex::new(InProcessState {
        checkpoint: start,
        stats: UnitStats::default(),
        clock: InterimClock::default(),
    });
    // One thread writes at a time; one finding another writing leaves it to that one.
    let writing = Mutex::new(());
    let poisoned = || anyhow::anyhow!("a render thread panicked");
    status.set_threads(threads);
    // Round after round (a uniform render has one): the units not yet merged, then the next
    // round decided from the merged film.
    let mut completed = None;
    let result = pool.install(|| loop {
        let todo: Vec<WorkUnit> = {
            let state = state.lock().map_err(|_| poisoned())?;
            let checkpoint = &state.checkpoint;
            let units = checkpoint.units(settings);
            let todo: Vec<WorkUnit> = units
                .into_iter()
                .filter(|u| !checkpoint.is_done(u))
                .collect();
            if let Some(round) = checkpoint.rounds().index() {
                progress.set_status(format!("| round {round}"));
            }
            todo
        };
        todo.par_iter().try_for_each(|unit| {
            if job.interrupt.is_set() {
                anyhow::bail!("interrupted");
            }
            if job.out_of_time() {
                return Err(TimeLimitReached.into());
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
                    let staged = job
                        .interim
                        .stage(due, &state.checkpoint, &job.scene.desc.film);
                    (guard, staged)
                })
            };
            progress.unit_merged(unit_stats.samples);
            // Encoding and syncing happen with the render's lock released.
            if let Some((_guard, staged)) = staged {
                for e in staged.finish() {
                    progress.say(&format!("{e:#}"));
                }
            }
            anyhow::Ok(())
        })?;
        let mut done = state.lock().map_err(|_| poisoned())?;
        if let Some(round) = job.keep_round(&done.checkpoint) {
            completed = Some(round);
        }
        if job.out_of_time() {
            break Err(TimeLimitReached.into());
        }
        // The next round's decision reads the whole film, as the last unit's thread does.
        if !done.checkpoint.advance(settings, &job.scene.desc.film) {
            break anyhow::Ok(());
        }
        progress.round(job, &done.checkpoint);
    });
    progress.finish();
    let state = state.into_inner().map_err(|_| poisoned())?;
    match result {
        Err(why) if why.is::<TimeLimitReached>() => {
            job.timed_out(&state.checkpoint, completed, state.stats, Some(build))
        }
        Err(why) => Err(job.stopped(&state.checkpoint, why)),
        Ok(()) => Ok(RenderOutcome {
            round: state.checkpoint.adaptive_round().cloned(),
            ended: state.checkpoint.ended(),
            film: state.checkpoint.into_film(),
            stats: state.stats,
            build: Some(build),
            complete: true,
        }),
    }
}
