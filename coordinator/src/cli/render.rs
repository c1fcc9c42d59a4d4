//! `yat render`: load the scene, make the render job from the flags, hand it to the in-process
//! executor or the distributed one, then write the image the scene's Film names and report;
//! with `--status-addr`, serve the status page meanwhile (and for `--status-linger` after).

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context;
use yat_tracer::render::adaptive::{AdaptiveSettings, DEFAULT_MIN_SPP};
use yat_tracer::render::settings::MAX_SIDE;
use yat_tracer::render::{RenderOverrides, RenderSettings};

use super::budget::BudgetArgs;
use super::distributed::DistributedArgs;
use super::latlong::LatLongArg;
use super::seconds::seconds;
use crate::checkpoint::{CheckpointFile, RenderIdentity};
use crate::exec::{distributed, in_process};
use crate::interim::{InterimOutputs, PreviewFile};
use crate::job::{check_output_path, film_output_path, RenderJob};
use crate::manifest::SceneManifest;
use crate::render_report::RenderReport;
use crate::scene::{ParsedScene, Warnings};
use crate::shutdown::Interrupt;
use crate::status::server::StatusServer;
use crate::status::snapshot::{SceneInfo, SettingsInfo};
use crate::status::StatusBoard;

#[derive(clap::Args)]
pub struct RenderArgs {
    /// The main .lxs file.
    pub scene: PathBuf,
    /// Output PNG (default: the Film's filename plus .png, in the current folder; a folder in
    /// the Film's filename is dropped). Its side files go beside it: X.preview.png, X.resume and
    /// X.exr, so an output named like one of those is refused.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write linear radiance as OpenEXR next to the PNG.
    #[arg(long)]
    pub exr: bool,
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
    /// With --noise-threshold: stop at the first round boundary after this many seconds (from
    /// the start of the command), writing the image of the last round completed, which is the
    /// same bytes as the render ending at that round; the checkpoint keeps every sample merged,
    /// so the same command (with a longer or no limit) goes on from there.
    #[arg(long, value_name = "SECONDS", requires = "noise_threshold")]
    pub time_limit: Option<f64>,
    /// With --noise-threshold: write a PNG of the samples each pixel got (grey, log scale).
    #[arg(long, value_name = "PNG", requires = "noise_threshold")]
    pub sample_map: Option<PathBuf>,
    /// Maximum path depth (default: the scene's integrator depth).
    #[arg(long)]
    pub maxdepth: Option<u32>,
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

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let scene = ParsedScene::load_within(
        &args.scene,
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
    };
    let settings = RenderSettings::resolve(&scene.desc, &overrides);
    settings
        .check()
        .with_context(|| format!("cannot render {}", args.scene.display()))?;
    let adaptive = args.noise_threshold.map(|threshold| AdaptiveSettings {
        threshold,
        min_spp: args.min_spp,
    });
    if let Some(a) = &adaptive {
        a.check()
            .with_context(|| format!("cannot render {}", args.scene.display()))?;
    }
    scene.check_film(&settings, adaptive.is_some())?;
    let output_png = match &args.output {
        Some(output) => output.clone(),
        None => {
            let (output, warning) = film_output_path(&scene.desc.film.filename)?;
            if let Some(warning) = warning {
                eprintln!("warning: {warning}");
            }
            output
        }
    };
    check_output_path(&output_png)?;
    let checkpoint_every = seconds("checkpoint-every", args.checkpoint_every)?;
    let preview_every = seconds("preview-every", args.preview_every)?;
    let status_linger = seconds("status-linger", args.status_linger)?;
    let deadline = args
        .time_limit
        .map(|t| seconds("time-limit", t).map(|limit| started + limit))
        .transpose()?;
    let workers = args.distributed.config()?;
    let status = Arc::new(StatusBoard::new(
        SceneInfo {
            path: args.scene.display().to_string(),
            name: scene.main_name.clone(),
        },
        SettingsInfo {
            width: settings.width,
            height: settings.height,
            spp: settings.spp,
            max_depth: settings.max_depth,
            seed: settings.seed,
            executor: if workers.is_some() {
                "distributed"
            } else {
                "in-process"
            }
            .into(),
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
    // The files by content: what workers receive, and what names the render for its checkpoint.
    let manifest = if workers.is_some() || !checkpoint_every.is_zero() {
        Some(SceneManifest::read(&scene)?)
    } else {
        None
    };
    let checkpoint = manifest
        .as_ref()
        .filter(|_| !checkpoint_every.is_zero())
        .map(|m| {
            let identity = RenderIdentity::of(&m.load_request(&settings), adaptive.as_ref());
            CheckpointFile::beside(&output_png, identity, checkpoint_every)
        });
    let interrupt = Interrupt::install()?;
    let job = RenderJob {
        scene,
        settings,
        adaptive,
        sample_map: args.sample_map.clone(),
        interim: InterimOutputs {
            preview: (!preview_every.is_zero())
                .then(|| PreviewFile::beside(&output_png, preview_every)),
            checkpoint,
            status: status.clone(),
        },
        output_png,
        exr: args.exr,
        quiet: args.quiet,
        interrupt,
        deadline,
    };

    let outcome = match (workers, manifest) {
        (Some(config), Some(manifest)) => distributed::render(&config, &job, manifest),
        (_, manifest) => {
            // The in-process render reads the files itself: their copies go before it starts.
            drop(manifest);
            in_process::render(&job, args.threads)
        }
    };
    let outcome = outcome.and_then(|outcome| {
        job.write_final(&outcome)?;
        Ok(outcome)
    });
    let outcome = match outcome {
        Ok(outcome) => {
            if server.is_some() {
                let image = outcome.film.to_display(&job.scene.desc.film);
                status.publish_image(image, Duration::ZERO);
            }
            status.finish(Some(job.output_png.display().to_string()), None);
            outcome
        }
        Err(e) => {
            status.finish(None, Some(format!("{e:#}")));
            linger(server, status_linger, &job.interrupt);
            return Err(e);
        }
    };
    let build_time = outcome.build.as_ref().map(|b| b.time).unwrap_or_default();
    let render_time = started.elapsed() - job.scene.parse_time - build_time;

    let report = RenderReport::new(&job, &outcome, render_time);
    if let Some(path) = &args.stats_json {
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if !args.quiet {
        println!("wrote {}", job.output_png.display());
        report.print();
    }
    linger(server, status_linger, &job.interrupt);
    Ok(())
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
