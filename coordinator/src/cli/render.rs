//! `yat render`: load the scene, turn the flags into a render request, an executor and its
//! observers, call [`crate::render::render`], then write and print what its report says; with
//! `--status-addr`, serve the status page meanwhile (and for `--status-linger` after), and
//! Ctrl-C and SIGTERM stop the render through its interrupt.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context;
use yat_tracer::integrator::Transport;
use yat_tracer::render::adaptive::{AdaptiveSettings, DEFAULT_MIN_SPP};
use yat_tracer::render::layers::Aovs;
use yat_tracer::render::settings::MAX_SIDE;
use yat_tracer::render::RenderOverrides;

use super::budget::BudgetArgs;
use super::distributed::DistributedArgs;
use super::latlong::LatLongArg;
use super::seconds::seconds;
use crate::exec::progress_log::{JsonTarget, ProgressLog, DEFAULT_PROGRESS_EVERY};
use crate::frames;
use crate::job::{film_output_path, Deadline};
use crate::render::{render, Executor, Observers, RenderRequest};
use crate::scene::{ParsedScene, Warnings};
use crate::shutdown::Interrupt;
use crate::status::server::StatusServer;
use crate::status::snapshot::{SceneInfo, SettingsInfo};
use crate::status::StatusBoard;

/// `--integrator`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum IntegratorArg {
    Path,
    Bidirectional,
    Directlighting,
}

impl From<IntegratorArg> for Transport {
    fn from(arg: IntegratorArg) -> Self {
        match arg {
            IntegratorArg::Path => Transport::Path,
            IntegratorArg::Bidirectional => Transport::Bidirectional,
            IntegratorArg::Directlighting => Transport::DirectLighting,
        }
    }
}

#[derive(clap::Args)]
pub struct RenderArgs {
    /// The main .lxs file. Several (or a glob pattern, or --frames) render one after another
    /// as the frames of a sequence, on the same workers (which keep the files they were sent),
    /// each into its Film filename plus .png; the same command, stopped, goes on at the frame
    /// and the sample where it stopped.
    #[arg(required_unless_present = "frames", num_args = 1..)]
    pub scenes: Vec<PathBuf>,
    /// A file listing the frames' scene files, one a line, rendered after any given as
    /// arguments ("-": standard input).
    #[arg(long, value_name = "FILE")]
    pub frames: Option<PathBuf>,
    /// Render only this task's frames of the sequence (from 0): a job array's task or an
    /// indexed job's pod, each taking --frames-per-task frames in order.
    #[arg(long, value_name = "N")]
    pub frames_task: Option<usize>,
    /// Frames of the sequence each --frames-task renders.
    #[arg(long, value_name = "N", default_value_t = 1, requires = "frames_task")]
    pub frames_per_task: usize,
    /// Output PNG (default: the Film's filename plus .png, in the current folder; a folder in
    /// the Film's filename is dropped). The Film's write_png, write_tga and write_exr choose
    /// which files are written: the PNG here, the TGA and EXR beside it as X.tga and X.exr, and
    /// the side files X.preview.png and X.resume, so an output named like one of those is
    /// refused. With several frames, or a path ending in "/", the folder the frames' images go
    /// to (made if missing).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write an EXR beside the image where the Film writes none: the linear radiance in
    /// 32-bit floats (in the Film's write_exr_channels).
    #[arg(long)]
    pub exr: bool,
    /// AOVs to add to the EXR as extra channels (and the EXR, as --exr, where the Film writes
    /// none), a comma-separated list of: albedo (albedo.R/G/B: the first surface's
    /// reflectance), normal (N.X/Y/Z: its shading normal), depth (Z: its distance from the
    /// camera), samples (the camera samples each pixel got). The same bytes in-process and on
    /// workers.
    #[arg(long, value_name = "LIST", value_parser = parse_aovs)]
    pub aovs: Option<Aovs>,
    /// Samples per pixel (default: the Film's haltspp, else 64); with --noise-threshold, the
    /// most any pixel gets.
    #[arg(long)]
    pub spp: Option<u32>,
    /// Adaptive sampling: render in rounds, each doubling the samples of the 4x4-pixel blocks
    /// that still need them for the image's error to reach E (root-mean-square error over mean
    /// brightness, e.g. 0.02) at the least cost, until none does or --spp is reached. The
    /// image is the same bytes however and wherever it is rendered.
    #[arg(long, value_name = "E")]
    pub noise_threshold: Option<f32>,
    /// With --noise-threshold: the samples every pixel gets in the first round (even).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MIN_SPP, requires = "noise_threshold")]
    pub min_spp: u32,
    /// Stop after this many seconds (from the start of the command; 0: no limit), in place of
    /// the scene's Film "halttime". A uniform render writes the image of every sample merged
    /// and says exactly which those are; with --noise-threshold, the render stops at the first
    /// round boundary after the limit and writes the image of the last round completed (the
    /// same bytes as the render ending at that round). Either way the checkpoint keeps every
    /// sample merged, so the same command (with a longer or no limit) goes on from there.
    #[arg(long, value_name = "SECONDS")]
    pub time_limit: Option<f64>,
    /// Halt once at most this share of the pixels (0 to 1) changed visibly since the last test,
    /// tested every Film "convergencestep" samples (32) on the merged image, in place of the
    /// scene's Film "haltthreshold" (a negative share lifts it). The render ends at the same
    /// round however and wherever it is rendered; --spp (or haltspp) is then the most a pixel
    /// gets, 16777216 without either.
    #[arg(long, value_name = "SHARE", allow_negative_numbers = true)]
    pub halt_threshold: Option<f32>,
    /// With --noise-threshold: write a PNG of the samples each pixel got (grey, log scale).
    #[arg(long, value_name = "PNG", requires = "noise_threshold")]
    pub sample_map: Option<PathBuf>,
    /// Maximum path depth (default: the scene's integrator depth; a bidirectional render's
    /// camera subpath depth; a direct-lighting render's vertices that take light, its
    /// specular maxdepth plus one).
    #[arg(long)]
    pub maxdepth: Option<u32>,
    /// The light transport: path tracing (what scenes render with by default), bidirectional
    /// path tracing (with the scene's eyedepth and lightdepth; the default of a
    /// SurfaceIntegrator "bidirectional" whose scene has caustics of point, spot or distant
    /// lights) or direct lighting (LuxRender's: the default of a SurfaceIntegrator
    /// "directlighting"). `yat check` says which runs and why.
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorArg>,
    /// Render threads for an in-process render [default: the CPUs this process may use].
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
    /// No progress bar, no progress lines and no summary.
    #[arg(short, long)]
    pub quiet: bool,
    /// Where standard error is not a terminal (a farm's log), a progress line this often
    /// (percent, samples/s, ETA, units, workers, requeued units), as --progress-json's objects.
    #[arg(long, value_name = "SECONDS", default_value_t = DEFAULT_PROGRESS_EVERY.as_secs_f64())]
    pub progress_every: f64,
    /// Progress as one JSON object a line (state, units and samples done and in all, samples/s,
    /// ETA, requeued units, round, workers connected), every --progress-every and once at the
    /// end, to this file, or to standard error with "-".
    #[arg(long, value_name = "PATH|-")]
    pub progress_json: Option<PathBuf>,
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
    /// Serve a live status page (the image, progress, workers, events; JSON at /api/status,
    /// Prometheus text at /metrics) on this address, e.g. 127.0.0.1:8080 or 0.0.0.0:8080 (port
    /// 0: any free port; the address is printed). A token (--token, --token-file, YAT_TOKEN)
    /// protects it. See docs/status.md.
    #[arg(long, value_name = "IP:PORT")]
    pub status_addr: Option<SocketAddr>,
    /// Keep serving the status page this long after the render ends (its final image and
    /// summary), then exit.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 0.0,
        requires = "status_addr"
    )]
    pub status_linger: f64,
    #[command(flatten)]
    pub budget: BudgetArgs,
    #[command(flatten)]
    pub distributed: DistributedArgs,
}

fn parse_aovs(s: &str) -> Result<Aovs, String> {
    Aovs::from_names(s)
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, got {s:?}"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=MAX_SIDE).contains(&n))
            .ok_or_else(|| format!("bad size {v:?} in {s:?} (1 to {MAX_SIDE})"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// Renders as the flags ask; returns the PNG written if the Film writes one, the last frame's
/// of a sequence (`yat luxconsole -b` reads it back).
pub fn run(args: RenderArgs) -> anyhow::Result<Option<PathBuf>> {
    let slice = args.frames_task.map(|task| frames::FrameSlice {
        task,
        per_task: args.frames_per_task,
    });
    let scenes = frames::scene_files(&args.scenes, args.frames.as_deref(), slice)?;
    let executor = match args.distributed.config()? {
        Some(config) => config.into(),
        None => Executor::InProcess {
            threads: args.threads,
        },
    };
    let interrupt = Interrupt::install()?;
    // One scene into a file is a plain render; into a folder (a job array's task of one
    // frame), a sequence of one frame.
    let into_folder = args.output.as_deref().is_some_and(frames::is_folder);
    if let ([scene], false) = (&scenes[..], into_folder) {
        let request = frame_request(&args, scene, |_| Ok(args.output.clone()))?;
        return render_frame(&args, request, &executor, &interrupt, true);
    }
    let mut outputs = frames::FrameOutputs::new(args.output.as_deref())?;
    let mut journal = None;
    let mut last = None;
    let count = scenes.len();
    for (i, scene) in scenes.iter().enumerate() {
        let which = || format!("frame {} of {count}, {}", i + 1, scene.display());
        let request = frame_request(&args, scene, |scene| {
            let (film_output, _) = film_output_path(&scene.desc.film.filename)?;
            outputs.place(&scene.path, &film_output).map(Some)
        })
        .with_context(which)?;
        let image = request.output_png.clone();
        let journal = match &mut journal {
            Some(journal) => journal,
            None => journal.insert(frames::FrameJournal::beside(&image)?),
        };
        let identity = request.identity()?;
        if journal.is_done(&identity, &image) {
            if !args.quiet {
                println!("{}: rendered already ({})", which(), image.display());
            }
            last = Some(image);
            continue;
        }
        if !args.quiet {
            println!("{}", which());
        }
        last = render_frame(&args, request, &executor, &interrupt, i + 1 == count).with_context(
            || {
                format!(
                    "{}; the same command goes on from there (frames rendered are in {})",
                    which(),
                    journal.path().display()
                )
            },
        )?;
        journal.record(&identity, &image)?;
    }
    if let Some(journal) = journal {
        journal.remove();
    }
    Ok(last)
}

/// The request of one frame (or of the one scene): its scene loaded, the flags applied, its
/// image the one `output` chooses for the scene (None: its Film's), its time limit from now.
fn frame_request(
    args: &RenderArgs,
    scene_path: &Path,
    output: impl FnOnce(&ParsedScene) -> anyhow::Result<Option<PathBuf>>,
) -> anyhow::Result<RenderRequest> {
    let started = Instant::now();
    let scene = ParsedScene::load_within(
        scene_path,
        if args.quiet {
            Warnings::Keep
        } else {
            Warnings::Print
        },
        args.budget.budget(),
    )?;
    let overrides = RenderOverrides {
        spp: args.spp,
        max_depth: args.maxdepth,
        seed: Some(args.seed),
        resolution: args.resolution,
        latlong: args.latlong.into(),
        transport: args.integrator.map(Into::into),
        halt_threshold: args.halt_threshold,
        aovs: args.aovs.unwrap_or_default(),
    };
    let adaptive = args.noise_threshold.map(|threshold| AdaptiveSettings {
        threshold,
        min_spp: args.min_spp,
    });
    let output = output(&scene)?;
    let mut request = RenderRequest::new(scene, &overrides, adaptive, output)?;
    if let Some(limit) = args.time_limit {
        let limit = seconds("time-limit", limit)?;
        let left = limit.saturating_sub(started.elapsed());
        request.deadline = Deadline::after(left.max(Duration::from_nanos(1)), "--time-limit")
            .filter(|_| !limit.is_zero());
    }
    request.exr = args.exr || args.aovs.is_some_and(|a| !a.is_empty());
    request.sample_map = args.sample_map.clone();
    Ok(request)
}

/// Renders one frame's request on `executor`, serving its status page as the flags ask
/// (lingering after the `last` frame), and prints its summary; returns the PNG written.
fn render_frame(
    args: &RenderArgs,
    request: RenderRequest,
    executor: &Executor,
    interrupt: &Interrupt,
    last: bool,
) -> anyhow::Result<Option<PathBuf>> {
    for warning in &request.warnings {
        eprintln!("warning: {warning}");
    }
    let every = |name, value| seconds(name, value).map(|every| (!every.is_zero()).then_some(every));
    let checkpoint_every = every("checkpoint-every", args.checkpoint_every)?;
    let preview_every = every("preview-every", args.preview_every)?;
    let status_linger = if last {
        seconds("status-linger", args.status_linger)?
    } else {
        Duration::ZERO
    };
    let settings = &request.settings;
    let status = Arc::new(StatusBoard::new(
        SceneInfo {
            path: request.scene.path.display().to_string(),
            name: request.scene.main_name.clone(),
        },
        SettingsInfo {
            width: settings.width,
            height: settings.height,
            spp: settings.spp,
            max_depth: settings.max_depth,
            seed: settings.seed,
            executor: executor.name().into(),
            threads: None,
        },
        args.status_addr.is_some(),
    ));
    let server = match args.status_addr {
        Some(address) => {
            let token = args.distributed.token.resolve()?;
            let server = StatusServer::start(address, status.clone(), token.as_deref())?;
            println!("status page on http://{}/", server.address());
            Some(server)
        }
        None => None,
    };
    let progress_log = ProgressLog {
        every: seconds("progress-every", args.progress_every)?,
        json: args.progress_json.clone().map(|path| {
            if path.as_os_str() == "-" {
                JsonTarget::Stderr
            } else {
                JsonTarget::File(path)
            }
        }),
    };
    let observers = Observers {
        quiet: args.quiet,
        preview_every,
        checkpoint_every,
        progress_log,
        status,
    };
    let files = crate::job::output_files(
        &request.output_png,
        &request.scene.desc.film.outputs.files(request.exr),
    );
    let report = match render(request, executor, observers, interrupt.clone()) {
        Ok(report) => report,
        Err(e) => {
            linger(server, status_linger, interrupt);
            return Err(e);
        }
    };
    if let Some(path) = &args.stats_json {
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if !args.quiet {
        if let Some(workers) = &report.workers {
            workers.print();
        }
        for (_, path) in &files {
            println!("wrote {}", path.display());
        }
        report.print();
    }
    linger(server, status_linger, interrupt);
    Ok(files.into_iter().find_map(|(file, path)| {
        matches!(file, yat_tracer::film::OutputFile::Png { .. }).then_some(path)
    }))
}

/// Keeps the status page up for `--status-linger` after the render (or until Ctrl-C), then
/// stops it.
fn linger(server: Option<StatusServer>, linger: Duration, interrupt: &Interrupt) {
    let Some(server) = server else {
        return;
    };
    if linger.is_zero() {
        return;
    }
    eprintln!(
        "status page on http://{}/ for {:.0} s more (Ctrl-C ends it)",
        server.address(),
        linger.as_secs_f64()
    );
    let until = Instant::now() + linger;
    while Instant::now() < until && !interrupt.is_set() {
        std::thread::sleep(LINGER_POLL.min(until.saturating_duration_since(Instant::now())));
    }
}

/// How often a lingering status page looks for Ctrl-C.
const LINGER_POLL: Duration = Duration::from_millis(100);
