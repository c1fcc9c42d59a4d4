//! A render job: the scene, the settings that decide the image, and the outputs (the final
//! image, the interim preview and checkpoint); and what rendering it yields, whoever renders it.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;
use yat_tracer::film::Film;
use yat_tracer::render::{RenderSettings, UnitStats, WorkUnit};

use crate::checkpoint::Checkpoint;
use crate::interim::InterimOutputs;
use crate::scene::ParsedScene;
use crate::shutdown::{Interrupt, Interrupted};

/// What a render needs, whoever renders it.
pub struct RenderJob {
    pub scene: ParsedScene,
    pub settings: RenderSettings,
    /// The PNG the render will write; previews and the checkpoint go next to it.
    pub output_png: PathBuf,
    /// Also write linear radiance as OpenEXR next to the PNG.
    pub exr: bool,
    pub quiet: bool,
    /// The preview and the checkpoint, written as the render goes.
    pub interim: InterimOutputs,
    /// Set by Ctrl-C or SIGTERM when checkpoints are on: the render stops, saved.
    pub interrupt: Interrupt,
}

/// The merged result of a render.
pub struct RenderOutcome {
    pub film: Film,
    pub stats: UnitStats,
    /// Building the scene in this process, if it was (workers build their own).
    pub build: Option<SceneBuild>,
}

/// What building the scene cost.
pub struct SceneBuild {
    pub time: Duration,
    pub triangles: usize,
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

    /// Writes the final image, the PNG (and the linear EXR when asked) exactly the same way for
    /// every executor, then removes the interim outputs it replaces.
    pub fn write_final(&self, film: &Film) -> anyhow::Result<()> {
        film.write_png(&self.output_png, &self.scene.desc.film)
            .with_context(|| format!("cannot write {}", self.output_png.display()))?;
        if self.exr {
            let path = self.output_png.with_extension("exr");
            film.write_exr(&path)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        self.interim.remove();
        Ok(())
    }
}
