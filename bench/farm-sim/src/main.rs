//! A render farm simulated on one machine: N fake workers (real tonic servers on loopback
//! sockets implementing `RenderNode`) that answer each unit after sleeping as long as a real
//! worker of their speed would render it, with an all-zero sample buffer of the right size; and
//! the real `yat render` as the coordinator, driving them over gRPC. It prints what a farm
//! costs the coordinator (CPU, bytes on the wire, units) and the idle tail: how many workers
//! still had work during the last 5% of the render.
//!
//! The fake workers claim every scene file is in their cache, so no scene bytes are uploaded,
//! as on a farm rendering a scene the second time.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use clap::Parser;
use tokio::sync::Semaphore;
use tonic::transport::server::TcpIncoming;
use tonic::transport::Server;
use tonic::{Request, Response, Status, Streaming};
use yat_proto::{pb, RenderNode, RenderNodeServer, DEFAULT_MAX_MESSAGE_BYTES, PROTOCOL_VERSION};
use yat_tracer::assets::FsSource;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::unit::{FilmFrame, WorkUnit};
use yat_tracer::render::{RenderOverrides, RenderSettings};

/// Core-microseconds per camera sample of captainfalcon.lxs (release build, depth 10:
/// bench/RESULTS.md, "core-us/sample").
const CAPTAIN_FALCON_SAMPLE_US: f64 = 2.12;
/// Bytes of one pixel in a unit's result: r, g, b, weight as f32.
const BYTES_PER_PIXEL: usize = 16;
/// Bytes of one layer sum of a pixel (alpha, an AOV, a light group's channel) as f32.
const BYTES_PER_LAYER_SUM: usize = 4;
/// The tail of the render whose busy workers are counted.
const TAIL_FRACTION: f64 = 0.05;

#[derive(Parser)]
#[command(about = "Simulate a render farm and measure the coordinator and the idle tail")]
struct Args {
    /// Fake workers to start.
    #[arg(long, default_value_t = 64)]
    workers: usize,
    /// Render threads each fake worker announces (and renders with).
    #[arg(long, default_value_t = 8)]
    threads: u32,
    /// Microseconds a thread takes per camera sample on an average worker.
    #[arg(long, default_value_t = CAPTAIN_FALCON_SAMPLE_US)]
    sample_us: f64,
    /// Workers' speeds spread evenly over 1 +- this fraction of the average.
    #[arg(long, default_value_t = 0.25)]
    spread: f64,
    /// Samples per pixel (the original's Captain Falcon render used 1000).
    #[arg(long, default_value_t = 1000)]
    spp: u32,
    /// The scene [default: $YAT_SEED_SCENES or the seed project's scenes, CaptainFalcon].
    #[arg(long)]
    scene: Option<PathBuf>,
    /// The `yat` binary acting as the coordinator [default: `yat` beside this program].
    #[arg(long)]
    yat: Option<PathBuf>,
}

/// When one unit was on one worker, and whether its result was sent (not cancelled).
#[derive(Clone, Copy)]
struct Busy {
    worker: usize,
    start: Instant,
    end: Instant,
    completed: bool,
}

/// A fake worker: `threads` units at a time, each taking its samples x `sample_time`, each
/// answered with the sums (all zero) a real worker's buffer of the render's film frame holds:
/// the unit's tile and the filter's border, and the layers the scene's film keeps.
struct FakeWorker {
    id: usize,
    frame: FilmFrame,
    threads: u32,
    sample_time: Duration,
    slots: Semaphore,
    log: Arc<Mutex<Vec<Busy>>>,
}

/// What a worker rendering `unit` (a tile inside `frame`'s film) for `took` sends back: all-zero
/// sums over the unit's region in `frame` (its tile and the filter's border) and its layers,
/// and the unit's samples.
fn fake_reply(frame: &FilmFrame, unit: &pb::WorkUnit, took: Duration) -> pb::RenderUnitReply {
    let tile = WorkUnit {
        index: unit.index,
        x0: unit.x0,
        y0: unit.y0,
        x1: unit.x1,
        y1: unit.y1,
        sample_start: unit.sample_start,
        sample_end: unit.sample_end,
        mask: None,
    };
    let region_pixels = frame.region(&tile).pixel_count();
    pb::RenderUnitReply {
        index: unit.index,
        pixels: vec![0; region_pixels * BYTES_PER_PIXEL].into(),
        stats: Some(pb::UnitStats {
            samples: tile.sample_count(),
            ..Default::default()
        }),
        render_seconds: took.as_secs_f64(),
        light_splats: Default::default(),
        layers: vec![0; region_pixels * frame.layers.len() * BYTES_PER_LAYER_SUM].into(),
    }
}

/// Records a unit's busy interval when the call ends, completed or dropped by the client.
struct BusyGuard<'a> {
    worker: &'a FakeWorker,
    start: Instant,
    completed: bool,
}

impl Drop for BusyGuard<'_> {
    fn drop(&mut self) {
        self.worker.log.lock().unwrap().push(Busy {
            worker: self.worker.id,
            start: self.start,
            end: Instant::now(),
            completed: self.completed,
        });
    }
}

#[tonic::async_trait]
impl RenderNode for FakeWorker {
    async fn handshake(
        &self,
        _request: Request<pb::HandshakeRequest>,
    ) -> Result<Response<pb::HandshakeReply>, Status> {
        Ok(Response::new(pb::HandshakeReply {
            protocol_version: PROTOCOL_VERSION,
            threads: self.threads,
            hostname: format!("fake-{}", self.id),
            max_message_bytes: DEFAULT_MAX_MESSAGE_BYTES as u64,
            max_blob_bytes: 1 << 31,
            features: Vec::new(),
            software: "yat-farm-sim".into(),
            // The coordinator's own build, which it requires of its workers.
            renderer_build: yat_tracer::RENDERER_BUILD.into(),
        }))
    }

    async fn has_blobs(
        &self,
        _request: Request<pb::HasBlobsRequest>,
    ) -> Result<Response<pb::HasBlobsReply>, Status> {
        Ok(Response::new(pb::HasBlobsReply::default()))
    }

    async fn put_blob(
        &self,
        _request: Request<Streaming<pb::BlobChunk>>,
    ) -> Result<Response<pb::PutBlobReply>, Status> {
        Err(Status::unimplemented("the farm has every file cached"))
    }

    async fn load_scene(
        &self,
        _request: Request<pb::LoadSceneRequest>,
    ) -> Result<Response<pb::LoadSceneReply>, Status> {
        Ok(Response::new(pb::LoadSceneReply {
            scene_id: "farm-sim".into(),
            ..Default::default()
        }))
    }

    async fn render_unit(
        &self,
        request: Request<pb::RenderUnitRequest>,
    ) -> Result<Response<pb::RenderUnitReply>, Status> {
        let unit = request
            .into_inner()
            .unit
            .ok_or_else(|| Status::invalid_argument("no unit"))?;
        let pixels =
            u64::from(unit.x1.saturating_sub(unit.x0)) * u64::from(unit.y1.saturating_sub(unit.y0));
        let samples = pixels * u64::from(unit.sample_end.saturating_sub(unit.sample_start));
        if pixels > 1 << 18 || unit.x1 > self.frame.width || unit.y1 > self.frame.height {
            return Err(Status::invalid_argument("unit too large"));
        }
        let _thread = self
            .slots
            .acquire()
            .await
            .map_err(|_| Status::unavailable("closed"))?;
        let mut busy = BusyGuard {
            worker: self,
            start: Instant::now(),
            completed: false,
        };
        let took = self.sample_time.mul_f64(samples as f64);
        tokio::time::sleep(took).await;
        busy.completed = true;
        Ok(Response::new(fake_reply(&self.frame, &unit, took)))
    }

    async fn stats(
        &self,
        _request: Request<pb::StatsRequest>,
    ) -> Result<Response<pb::StatsReply>, Status> {
        Ok(Response::new(pb::StatsReply::default()))
    }
}

/// How much longer than average worker `id` takes per sample: spread evenly over
/// 1 +- `--spread`, the first worker the fastest.
fn speed_factor(args: &Args, id: usize) -> f64 {
    let position = if args.workers > 1 {
        id as f64 / (args.workers - 1) as f64
    } else {
        0.5
    };
    1.0 + args.spread * (2.0 * position - 1.0)
}

/// Starts the fake workers on loopback ports; returns their addresses.
async fn start_farm(
    args: &Args,
    frame: FilmFrame,
    log: &Arc<Mutex<Vec<Busy>>>,
) -> anyhow::Result<Vec<String>> {
    let mut addresses = Vec::new();
    for id in 0..args.workers {
        let worker = FakeWorker {
            id,
            frame,
            threads: args.threads,
            sample_time: Duration::from_secs_f64(args.sample_us * 1e-6 * speed_factor(args, id)),
            slots: Semaphore::new(args.threads as usize),
            log: log.clone(),
        };
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await?;
        addresses.push(listener.local_addr()?.to_string());
        let service = RenderNodeServer::new(worker)
            .max_decoding_message_size(DEFAULT_MAX_MESSAGE_BYTES)
            .max_encoding_message_size(DEFAULT_MAX_MESSAGE_BYTES);
        let incoming = TcpIncoming::from(listener).with_nodelay(Some(true));
        tokio::spawn(
            Server::builder()
                .add_service(service)
                .serve_with_incoming(incoming),
        );
    }
    Ok(addresses)
}

/// The share of `window` during which each worker had at least one unit, averaged over the
/// `workers`.
fn busy_share(log: &[Busy], workers: usize, window: (Instant, Instant)) -> f64 {
    let length = window.1.duration_since(window.0).as_secs_f64();
    if length <= 0.0 {
        return 0.0;
    }
    let mut total = 0.0;
    for worker in 0..workers {
        let mut intervals: Vec<(Instant, Instant)> = log
            .iter()
            .filter(|b| b.worker == worker)
            .map(|b| (b.start.max(window.0), b.end.min(window.1)))
            .filter(|(s, e)| s < e)
            .collect();
        intervals.sort();
        let mut covered = 0.0;
        let mut reach = window.0;
        for (start, end) in intervals {
            let start = start.max(reach);
            if end > start {
                covered += end.duration_since(start).as_secs_f64();
                reach = end;
            }
        }
        total += covered / length;
    }
    total / workers as f64
}

fn default_scene() -> PathBuf {
    let root = std::env::var_os("YAT_SEED_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/work/shared/seed-project/scenes"));
    root.join("CaptainFalcon/captainfalcon.lxs")
}

fn default_yat() -> anyhow::Result<PathBuf> {
    let me = std::env::current_exe()?;
    Ok(me.with_file_name("yat"))
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    if args.workers == 0 || args.threads == 0 {
        bail!("--workers and --threads must be at least 1");
    }
    let sample_us_ok = args.sample_us > 0.0 && args.sample_us < 1e6;
    if !sample_us_ok || !(0.0..1.0).contains(&args.spread) {
        bail!("--sample-us must be in (0, 1e6) and --spread in [0, 1)");
    }
    let scene = args.scene.clone().unwrap_or_else(default_scene);
    let yat = match &args.yat {
        Some(path) => path.clone(),
        None => default_yat()?,
    };
    if !yat.exists() {
        bail!(
            "{} not found: build it (cargo build -p yat) or pass --yat",
            yat.display()
        );
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    let log = Arc::new(Mutex::new(Vec::new()));
    // The film frame every node derives from the scene and the settings: what a unit's buffer
    // covers (the coordinator checks it exactly).
    let name = scene
        .file_name()
        .and_then(|n| n.to_str())
        .context("the scene's file name")?;
    let desc = parse_scene(name, &FsSource::for_main_file(&scene))
        .map_err(|e| anyhow::anyhow!("{}: {e}", scene.display()))?;
    let overrides = RenderOverrides {
        spp: Some(args.spp),
        ..Default::default()
    };
    let frame = RenderSettings::resolve(&desc, &overrides).film_frame(&desc);
    let addresses = runtime.block_on(start_farm(&args, frame, &log))?;

    let dir = std::env::temp_dir().join(format!("yat-farm-sim-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let json = dir.join("workers.json");
    let status = Command::new(&yat)
        .arg("render")
        .arg(&scene)
        .arg("-o")
        .arg(dir.join("farm.png"))
        .args(["--spp", &args.spp.to_string(), "--quiet"])
        .args(["--checkpoint-every", "0", "--preview-every", "0"])
        .arg("--workers")
        .arg(addresses.join(","))
        .arg("--workers-json")
        .arg(&json)
        .env_remove("YAT_TOKEN")
        .env_remove("YAT_UNIT_DEADLINE")
        .status()
        .with_context(|| format!("cannot run {}", yat.display()))?;
    if !status.success() {
        bail!("the coordinator failed: {status}");
    }
    // Lets the servers see the coordinator's connections close, ending the calls cut short.
    std::thread::sleep(Duration::from_millis(200));
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json)?)?;
    let log = log.lock().unwrap().clone();
    print_figures(&args, &scene, &report, &log)?;
    drop(runtime);
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}

fn print_figures(
    args: &Args,
    scene: &Path,
    report: &serde_json::Value,
    log: &[Busy],
) -> anyhow::Result<()> {
    let number = |key: &str| report[key].as_f64().with_context(|| format!("no {key}"));
    let workers = report["workers"].as_array().context("no workers")?;
    let sum = |key: &str| -> f64 { workers.iter().filter_map(|w| w[key].as_f64()).sum() };
    let wall = number("wall_seconds")?;
    let cpu = number("coordinator_cpu_seconds")?;
    let samples = number("samples")?;
    let first = log
        .iter()
        .map(|b| b.start)
        .min()
        .context("no unit rendered")?;
    let last = log
        .iter()
        .filter(|b| b.completed)
        .map(|b| b.end)
        .max()
        .context("no unit completed")?;
    let span = last.duration_since(first);
    let tail_start = last - span.mul_f64(TAIL_FRACTION);
    // Samples per second the whole farm renders: each thread at its worker's speed.
    let farm_rate: f64 = (0..args.workers)
        .map(|id| f64::from(args.threads) / (args.sample_us * 1e-6 * speed_factor(args, id)))
        .sum();
    let ideal = samples / farm_rate;
    let pixels = workers
        .iter()
        .filter_map(|w| w["result_pixels"].as_f64())
        .sum::<f64>();
    let wasted = log.iter().filter(|b| !b.completed).count();
    println!(
        "farm: {} workers x {} threads, {:.2} us/sample +-{:.0}%, {} at {} spp",
        args.workers,
        args.threads,
        args.sample_us,
        args.spread * 100.0,
        scene.display(),
        args.spp
    );
    println!(
        "units: {} ({} copies in the end game, {} calls cut short)",
        report["units"], report["units_copied"], wasted
    );
    println!(
        "coordinator: {cpu:.2} s CPU over {wall:.2} s wall = {:.1}% of a core",
        100.0 * cpu / wall
    );
    println!(
        "wire: {:.1} result bytes per unit pixel, {:.2} bytes per unit pixel both ways",
        number("result_bytes_per_unit_pixel")?,
        (sum("bytes_sent") + sum("bytes_received")) / pixels.max(1.0)
    );
    println!(
        "render span: {:.2} s (ideal {:.2} s: {:.1}% efficient)",
        span.as_secs_f64(),
        ideal,
        100.0 * ideal / span.as_secs_f64()
    );
    println!(
        "idle tail: workers busy {:.1}% of the last {:.0}% ({:.2} s)",
        100.0 * busy_share(log, args.workers, (tail_start, last)),
        TAIL_FRACTION * 100.0,
        (last - tail_start).as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use yat_tracer::assets::MemorySource;
    use yat_tracer::filter::PixelFilter;

    /// The fake workers' replies pass the coordinator's checks of a real worker's (a scene
    /// whose filter reaches a neighbour and whose film keeps alpha), at the film's edge and
    /// inside it: the simulation measures a farm the coordinator accepts.
    #[test]
    fn fake_replies_pass_the_coordinators_checks() {
        let text =
            "Film \"fleximage\" \"integer xresolution\" [100] \"integer yresolution\" [70]\n\
                    \x20 \"string write_png_channels\" [\"RGBA\"]\n\
                    PixelFilter \"mitchell\" \"float xwidth\" [2] \"float ywidth\" [2]\n\
                    WorldBegin\nWorldEnd\n";
        let mut source = MemorySource::new();
        source.insert("main.lxs", text.as_bytes().into());
        let desc = parse_scene("main.lxs", &source).unwrap();
        let overrides = RenderOverrides {
            spp: Some(16),
            ..Default::default()
        };
        let settings = RenderSettings::resolve(&desc, &overrides);
        let frame = settings.film_frame(&desc);
        assert!(frame.border[0] > 0 && frame.layers.alpha, "{frame:?}");
        let weights = PixelFilter::new(&desc.filter).weight_bounds();
        for (x0, y0, x1, y1) in [(0, 0, 64, 64), (64, 64, 100, 70)] {
            let unit = pb::WorkUnit {
                index: 3,
                x0,
                y0,
                x1,
                y1,
                sample_start: 8,
                sample_end: 16,
                ..Default::default()
            };
            let reply = fake_reply(&frame, &unit, Duration::from_millis(1));
            let tile = yat_proto::convert::unit_from_wire(&unit, &settings).unwrap();
            let checked = yat_proto::convert::result_from_wire(tile, &frame, &weights, &reply);
            assert!(checked.is_ok(), "{x0},{y0}: {checked:?}");
        }
    }

    #[test]
    fn busy_share_counts_each_workers_covered_time_once() {
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        let busy = |worker, start, end| Busy {
            worker,
            start: at(start),
            end: at(end),
            completed: true,
        };
        let log = [
            // Worker 0: overlapping units covering the whole window and beyond.
            busy(0, 0, 700),
            busy(0, 500, 1200),
            // Worker 1: half of the window.
            busy(1, 900, 1400),
            // Worker 2: nothing in the window.
            busy(2, 0, 400),
        ];
        let share = busy_share(&log, 3, (at(600), at(1000)));
        assert!((share - (1.0 + 0.25 + 0.0) / 3.0).abs() < 1e-9, "{share}");
        assert_eq!(busy_share(&log, 3, (at(5), at(5))), 0.0);
    }
}
