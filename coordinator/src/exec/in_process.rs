//! The in-process executor: builds the scene here and renders every unit of the plan not yet in
//! the job's checkpoint on a rayon pool, merging as units finish and writing the preview and the
//! checkpoint as often as the job asks.

use std::sync::Mutex;
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;
use yat_tracer::render::{plan_units, UnitStats, WorkUnit};

use super::progress::Progress;
use crate::checkpoint::Checkpoint;
use crate::interim::InterimClock;
use crate::job::{RenderJob, RenderOutcome, SceneBuild};

/// The render so far, as the render threads share it.
struct InProcessState {
    checkpoint: Checkpoint,
    stats: UnitStats,
    clock: InterimClock,
}

/// Renders `job` on `threads` threads (default: the CPUs this process may use).
pub fn render(job: &RenderJob, threads: Option<usize>) -> anyhow::Result<RenderOutcome> {
    let build_start = Instant::now();
    let scene = job.scene.build(&job.settings)?;
    let build = SceneBuild {
        time: build_start.elapsed(),
        triangles: scene.triangle_count(),
    };

    let units = plan_units(scene.settings());
    let start = job.resume(&units);
    let todo: Vec<WorkUnit> = units
        .iter()
        .filter(|u| !start.is_done(u))
        .copied()
        .collect();
    let total_samples = units.iter().map(WorkUnit::sample_count).sum();
    let progress = Progress::new(total_samples, start.done_samples(&units), job.quiet);
    let status = &job.interim.status;
    status.plan(
        units.len(),
        start.done_count(),
        total_samples,
        start.done_samples(&units),
    );
    let state = Mutex::new(InProcessState {
        checkpoint: start,
        stats: UnitStats::default(),
        clock: InterimClock::default(),
    });
    // One thread writes at a time; one finding another writing leaves it to that one.
    let writing = Mutex::new(());
    let poisoned = || anyhow::anyhow!("a render thread panicked");
    let threads = crate::cpus::threads_or_usable_cpus(threads, "in-process render");
    status.set_threads(threads);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
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
                    let staged = job
                        .interim
                        .stage(due, &state.checkpoint, &job.scene.desc.film);
                    (guard, staged)
                })
            };
            progress.add_samples(unit_stats.samples);
            status.unit_merged(unit_stats.samples);
            // Encoding and syncing happen with the render's lock released.
            if let Some((_guard, staged)) = staged {
                for e in staged.finish() {
                    progress.say(&format!("{e:#}"));
                }
            }
            anyhow::Ok(())
        })
    });
    progress.finish();
    let state = state.into_inner().map_err(|_| poisoned())?;
    if let Err(why) = result {
        return Err(job.stopped(&state.checkpoint, &units, why));
    }
    Ok(RenderOutcome {
        film: state.checkpoint.into_film(),
        stats: state.stats,
        build: Some(build),
    })
}
