//! A render as one library call: [`render`] takes what to render ([`RenderRequest`]), who
//! renders it ([`Executor`]), who watches it ([`Observers`]) and the caller's [`Interrupt`], and
//! writes the image and returns its figures ([`RenderReport`]). `yat render` turns its flags
//! into these; the end-to-end tests and any other front end call it the same way.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context;
use yat_tracer::integrator::Transport;
use yat_tracer::render::adaptive::AdaptiveSettings;
use yat_tracer::render::convergence::ConvergenceHalt;
use yat_tracer::render::sampling::Sampling;
use yat_tracer::render::{RenderOverrides, RenderSettings};

use crate::checkpoint::{CheckpointFile, RenderIdentity};
use crate::exec::distributed::config::DistributedConfig;
use crate::exec::progress_log::ProgressLog;
use crate::exec::{distributed, in_process};
use crate::interim::{InterimOutputs, PreviewFile};
use crate::job::{check_output_path, film_output_path, Deadline, RenderJob};
use crate::manifest::SceneManifest;
use crate::render_report::RenderReport;
use crate::scene::ParsedScene;
use crate::shutdown::Interrupt;
use crate::status::StatusBoard;

/// What to render and where the image goes: the scene, the settings that decide its bytes, the
/// files written at the end.
pub struct RenderRequest {
    pub scene: ParsedScene,
    pub settings: RenderSettings,
    /// Every pixel spp samples, adaptive rounds, or rounds until the image stops changing
    /// (settings.spp then the most any pixel gets).
    pub sampling: Sampling,
    /// The image's path: the PNG's, when the Film writes one; the preview, the checkpoint and
    /// the TGA and EXR the Film asks for go beside it.
    pub output_png: PathBuf,
    /// `--exr`: also write an EXR (the linear radiance in full floats, unless the Film's
    /// `write_exr_*` say otherwise) where the Film writes none.
    pub exr: bool,
    /// Where to write the sample map of an adaptive render, at the end.
    pub sample_map: Option<PathBuf>,
    /// When the render stops (an adaptive one at a round boundary): the scene's `halttime`
    /// unless the caller sets another (`--time-limit`).
    pub deadline: Option<Deadline>,
    /// What the caller should tell the user before the render: a folder dropped from the
    /// Film's filename.
    pub warnings: Vec<String>,
}

impl RenderRequest {
    /// A render of `scene` with the settings `overrides` resolve from it, checked (and the
    /// film checked against the scene's memory budget), into `output_png`, or, when None, the
    /// PNG the scene's Film names in the current folder (with a warning in
    /// [`Self::warnings`] when the scene names a folder), stopping at the scene's `halttime`
    /// from now if it has one. With `adaptive` the render is adaptive; else it halts by
    /// convergence when the scene's `haltthreshold` or the overrides' say so. No EXR or sample
    /// map: set those fields after.
    pub fn new(
        scene: ParsedScene,
        overrides: &RenderOverrides,
        adaptive: Option<AdaptiveSettings>,
        output_png: Option<PathBuf>,
    ) -> anyhow::Result<Self> {
        let settings = RenderSettings::resolve(&scene.desc, overrides);
        let cannot_render = || format!("cannot render {}", scene.path.display());
        settings.check().with_context(cannot_render)?;
        let sampling = match (adaptive, ConvergenceHalt::resolve(&scene.desc, overrides)) {
            (Some(a), _) => Sampling::Adaptive(a),
            (None, Some(halt)) => {
                halt.check().with_context(cannot_render)?;
                Sampling::Converging(halt)
            }
            (None, None) => Sampling::Uniform,
        };
        if let Sampling::Adaptive(a) = &sampling {
            a.check().with_context(cannot_render)?;
            if settings.transport == Transport::Bidirectional {
                anyhow::bail!(
                    "{}: adaptive sampling (--noise-threshold) does not work with bidirectional                      path tracing yet: the light subpaths' splats land outside the blocks a                      round renders; render with a fixed --spp, or with --integrator path",
                    cannot_render()
                );
            }
        }
        scene.check_film(&settings, &sampling)?;
        let (output_png, warnings) = match output_png {
            Some(output) => (output, Vec::new()),
            None => {
                let (output, warning) = film_output_path(&scene.desc.film.filename)?;
                (output, warning.into_iter().collect())
            }
        };
        check_output_path(&output_png)?;
        let deadline = scene.desc.film.halttime.and_then(|seconds| {
            let after = Duration::try_from_secs_f32(seconds).ok()?;
            Deadline::after(after, format!("the scene's halttime ({seconds} s)"))
        });
        Ok(Self {
            scene,
            settings,
            sampling,
            output_png,
            exr: false,
            sample_map: None,
            deadline,
            warnings,
        })
    }
}

impl RenderRequest {
    /// What names this render (its checkpoint's identity): the scene's files by content, the
    /// settings and the sampling.
    pub fn identity(&self) -> anyhow::Result<RenderIdentity> {
        Ok(Self::identity_with(
            &SceneManifest::read(&self.scene)?,
            self,
        ))
    }

    fn identity_with(manifest: &SceneManifest, request: &RenderRequest) -> RenderIdentity {
        RenderIdentity::of(&manifest.load_request(&request.settings), &request.sampling)
    }
}

/// Who renders: this process's threads, or workers over gRPC.
pub enum Executor {
    /// On this many threads [default: the CPUs this process may use].
    InProcess { threads: Option<usize> },
    /// Boxed: a configuration is much larger than a thread count.
    Distributed(Box<DistributedConfig>),
}

impl From<DistributedConfig> for Executor {
    fn from(config: DistributedConfig) -> Self {
        Self::Distributed(Box::new(config))
    }
}

impl Executor {
    /// As the status page names it.
    pub fn name(&self) -> &'static str {
        match self {
            Self::InProcess { .. } => "in-process",
            Self::Distributed(_) => "distributed",
        }
    }
}

/// What watches a render as it goes, and what it writes meanwhile.
pub struct Observers {
    /// No progress bar and no notices on the terminal (the error a render returns is the
    /// caller's to print).
    pub quiet: bool,
    /// Rewrite `<output>.preview.png` this often; None writes no preview.
    pub preview_every: Option<Duration>,
    /// Save the render so far to `<output>.resume` this often (and when it stops short), so
    /// that the same request resumes it; None saves no checkpoint.
    pub checkpoint_every: Option<Duration>,
    /// The status page's board: progress, workers, events, the image when it is served.
    pub status: Arc<StatusBoard>,
    /// Progress lines where there is no terminal, and JSON progress.
    pub progress_log: ProgressLog,
}

impl Observers {
    /// Nothing on the terminal, no interim files, a board nobody serves.
    pub fn none() -> Self {
        Self {
            quiet: true,
            preview_every: None,
            checkpoint_every: None,
            status: StatusBoard::unserved(),
            progress_log: ProgressLog::default(),
        }
    }
}

/// Renders `request` on `executor`, resuming from its checkpoint when one of the same render is
/// beside the output, writing the interim outputs `observers` ask for, and stopping, its
/// checkpoint saved, once `interrupt` is set (the error is then
/// [`crate::shutdown::Interrupted`]). Writes the final image and removes the interim files; the
/// report says what the render cost. The status board is told how the render ended either way.
pub fn render(
    request: RenderRequest,
    executor: &Executor,
    observers: Observers,
    interrupt: Interrupt,
) -> anyhow::Result<RenderReport> {
    let status = observers.status.clone();
    let report = render_and_write(request, executor, observers, interrupt);
    if let Err(e) = &report {
        status.finish(None, Some(format!("{e:#}")));
    }
    report
}

/// [`render`] but for telling the board of a failure.
fn render_and_write(
    request: RenderRequest,
    executor: &Executor,
    observers: Observers,
    interrupt: Interrupt,
) -> anyhow::Result<RenderReport> {
    let started = Instant::now();
    if request
        .scene
        .desc
        .film
        .outputs
        .files(request.exr)
        .is_empty()
    {
        anyhow::bail!(
            "cannot render {}: its Film writes no file (write_png, write_tga and write_exr are \
             all false); set one of them, or add --exr",
            request.scene.path.display()
        );
    }
    let (distributed, threads) = match executor {
        Executor::Distributed(config) => (Some(config), None),
        Executor::InProcess { threads } => (None, *threads),
    };
    // The files by content: what workers receive, and what names the render for its checkpoint.
    let manifest = if distributed.is_some() || observers.checkpoint_every.is_some() {
        Some(SceneManifest::read(&request.scene)?)
    } else {
        None
    };
    let checkpoint = manifest
        .as_ref()
        .zip(observers.checkpoint_every)
        .map(|(m, every)| {
            let identity = RenderRequest::identity_with(m, &request);
            CheckpointFile::beside(&request.output_png, identity, every)
        });
    let status = observers.status;
    let job = RenderJob {
        interim: InterimOutputs {
            preview: observers
                .preview_every
                .map(|every| PreviewFile::beside(&request.output_png, every)),
            checkpoint,
            status: status.clone(),
        },
        scene: request.scene,
        settings: request.settings,
        sampling: request.sampling,
        sample_map: request.sample_map,
        output_png: request.output_png,
        exr: request.exr,
        quiet: observers.quiet,
        progress_log: observers.progress_log,
        interrupt,
        deadline: request.deadline,
    };

    let (outcome, workers) = match (distributed, manifest) {
        (Some(config), Some(manifest)) => {
            let (outcome, workers) = distributed::render(config, &job, manifest)?;
            (outcome, Some(workers))
        }
        (_, manifest) => {
            // The in-process render reads the files itself: their copies go before it starts.
            drop(manifest);
            (in_process::render(&job, threads)?, None)
        }
    };
    job.write_final(&outcome)?;
    if status.serving() {
        let image = outcome.film.to_display(&job.scene.desc.film);
        status.publish_image(image, Duration::ZERO);
    }
    status.finish(Some(job.output_png.display().to_string()), None);
    let build_time = outcome.build.as_ref().map(|b| b.time).unwrap_or_default();
    let mut report = RenderReport::new(&job, &outcome, started.elapsed() - build_time);
    report.workers = workers;
    Ok(report)
}
