//! Helpers for the end-to-end tests: the seed scenes' folder, a small scene written to a
//! folder, `yat worker` processes on loopback ports, `yat render` runs, and renders by the
//! library in the test's own process (`yat::render::render`), for tests that need no
//! coordinator process.

use std::io::{BufRead, BufReader};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, Output, Stdio};
use std::thread::JoinHandle;
use std::time::Duration;

use yat::exec::distributed::config::DistributedConfig;
use yat::render::{Executor, Observers, RenderRequest};
use yat::render_report::RenderReport;
use yat::scene::{ParsedScene, Warnings};
use yat::shutdown::Interrupt;
use yat_tracer::render::adaptive::AdaptiveSettings;
use yat_tracer::render::RenderOverrides;

pub const YAT: &str = env!("CARGO_BIN_EXE_yat");

/// A box lit by an area light and, through its open side behind the camera, an environment
/// map (its light samples drawn for the side each matte surface faces), with a glossy sphere, a
/// rough metal ball (paths split where it shows the lamp), a flat mirror (whose lamp image the
/// path tracer samples), its materials in an Include'd file and a poster textured with a PNG
/// image map. Returns the main file.
pub fn write_scene(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir.join("textures")).unwrap();
    let checks = image::RgbImage::from_fn(8, 8, |x, y| {
        if (x + y) % 2 == 0 {
            image::Rgb([230, 200, 40])
        } else {
            image::Rgb([20, 60, 200])
        }
    });
    checks.save(dir.join("textures/checks.png")).unwrap();
    // A sky brighter overhead, with a small bright patch.
    let sky = image::RgbImage::from_fn(16, 8, |x, y| {
        let spot = if (x, y) == (3, 2) { 150 } else { 0 };
        let v = (200 - 20 * y) as u8;
        image::Rgb([v / 2 + spot, v / 2 + spot, v])
    });
    sky.save(dir.join("textures/sky.png")).unwrap();
    std::fs::write(
        dir.join("materials.lxo"),
        r#"Texture "checks" "color" "imagemap" "string filename" ["textures/checks.png"]
  "float gamma" [2.2]
MakeNamedMaterial "white" "string type" "matte" "color Kd" [0.7 0.7 0.7]
MakeNamedMaterial "red" "string type" "matte" "color Kd" [0.6 0.07 0.05]
MakeNamedMaterial "green" "string type" "matte" "color Kd" [0.12 0.45 0.09]
MakeNamedMaterial "poster" "string type" "matte" "texture Kd" "checks"
MakeNamedMaterial "shiny" "string type" "glossy" "color Kd" [0.2 0.3 0.6]
  "float uroughness" [0.05] "float vroughness" [0.05]
MakeNamedMaterial "lamp" "string type" "null"
MakeNamedMaterial "mirror" "string type" "mirror" "color Kr" [0.8 0.8 0.8]
MakeNamedMaterial "steel" "string type" "metal2" "color fresnel" [0.6 0.6 0.6]
  "float uroughness" [0.05] "float vroughness" [0.05]
"#,
    )
    .unwrap();
    let scene = dir.join("box.lxs");
    std::fs::write(
        &scene,
        r#"# A box open behind the camera with an area light and a sky, a glossy sphere, a metal ball, a mirror and a textured poster.
Film "fleximage" "integer xresolution" [128] "integer yresolution" [96]
  "string filename" ["box"]
PixelFilter "blackmanharris" "float xwidth" 2 "float ywidth" 2
SurfaceIntegrator "path" "integer maxdepth" [5]
LookAt 0 -0.9 1  0 0 1  0 0 1
Camera "perspective" "float fov" [70]
WorldBegin
Include "materials.lxo"
AttributeBegin
  NamedMaterial "white"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-1 -1 2  -1 1 2  1 1 2  1 -1 2]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-1 1 0  1 1 0  1 1 2  -1 1 2]
AttributeEnd
AttributeBegin
  NamedMaterial "red"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-1 -1 0  -1 1 0  -1 1 2  -1 -1 2]
AttributeEnd
AttributeBegin
  NamedMaterial "green"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [1 -1 0  1 -1 2  1 1 2  1 1 0]
AttributeEnd
AttributeBegin
  NamedMaterial "poster"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-0.5 0.99 0.6  0.5 0.99 0.6  0.5 0.99 1.4  -0.5 0.99 1.4]
    "float uv" [0 0  1 0  1 1  0 1]
AttributeEnd
AttributeBegin
  NamedMaterial "mirror"
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-0.99 -0.2 0.2  -0.99 0.6 0.2  -0.99 0.6 1.2  -0.99 -0.2 1.2]
AttributeEnd
AttributeBegin
  Translate 0.35 0.2 0.35
  NamedMaterial "shiny"
  Shape "sphere" "float radius" 0.35
AttributeEnd
AttributeBegin
  Translate -0.45 0.35 0.22
  NamedMaterial "steel"
  Shape "sphere" "float radius" 0.22
AttributeEnd
AttributeBegin
  NamedMaterial "lamp"
  AreaLightSource "area" "color L" [1 0.9 0.7] "float power" 40 "float efficacy" 17
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point P" [-0.3 -0.3 1.99  -0.3 0.3 1.99  0.3 0.3 1.99  0.3 -0.3 1.99]
AttributeEnd
AttributeBegin
  LightSource "infinite" "string mapname" ["textures/sky.png"] "float gamma" [2.2]
AttributeEnd
WorldEnd
"#,
    )
    .unwrap();
    scene
}

/// The scene's files and their total size, as a coordinator must upload them.
pub fn scene_bytes(dir: &Path) -> u64 {
    [
        "box.lxs",
        "materials.lxo",
        "textures/checks.png",
        "textures/sky.png",
    ]
    .iter()
    .map(|f| std::fs::metadata(dir.join(f)).unwrap().len())
    .sum()
}

/// Render settings every test uses: 4 tiles x 8 passes = 32 units.
pub const SETTINGS: [&str; 4] = ["--spp", "64", "--resolution", "128x96"];

/// [`SETTINGS`] as the library takes them (and `yat render` gives them, seed 0 included).
pub const SETTINGS_OVERRIDES: RenderOverrides = RenderOverrides {
    spp: Some(64),
    max_depth: None,
    seed: Some(0),
    resolution: Some((128, 96)),
    latlong: yat_tracer::desc::LatLongConvention::Seed,
    transport: None,
    halt_threshold: None,
    aovs: yat_tracer::render::layers::Aovs::NONE,
};

/// [`SETTINGS_OVERRIDES`] with `spp` samples per pixel.
pub fn settings_with_spp(spp: u32) -> RenderOverrides {
    RenderOverrides {
        spp: Some(spp),
        ..SETTINGS_OVERRIDES
    }
}

/// The request `yat render SCENE -o OUT --exr` makes with `overrides` (and `adaptive`).
pub fn request_with(
    scene: &Path,
    out: &Path,
    overrides: &RenderOverrides,
    adaptive: Option<AdaptiveSettings>,
) -> RenderRequest {
    let scene = ParsedScene::load(scene, Warnings::Keep).unwrap();
    let mut request = RenderRequest::new(scene, overrides, adaptive, Some(out.into())).unwrap();
    request.exr = true;
    request
}

/// [`request_with`] the test settings.
pub fn request(scene: &Path, out: &Path) -> RenderRequest {
    request_with(scene, out, &SETTINGS_OVERRIDES, None)
}

/// The workers at `addresses` (resolved once), with nothing else set.
pub fn workers_at(addresses: &[&str]) -> DistributedConfig {
    DistributedConfig {
        workers: addresses.iter().map(|a| a.to_string()).collect(),
        ..DistributedConfig::default()
    }
}

/// The in-process executor on two threads: the reference renders'.
pub fn two_threads() -> Executor {
    Executor::InProcess { threads: Some(2) }
}

/// Renders `request` on `executor` in this process, quiet and writing no interim file.
pub fn render_here(request: RenderRequest, executor: Executor) -> anyhow::Result<RenderReport> {
    yat::render::render(request, &executor, Observers::none(), Interrupt::default())
}

/// The in-process render of `scene` with the test settings, into `dir`/in-process.png: (PNG
/// bytes, EXR bytes), what every other render of it must match.
pub fn reference_image(dir: &Path, scene: &Path) -> (Vec<u8>, Vec<u8>) {
    let out = dir.join("in-process.png");
    render_here(request(scene, &out), two_threads()).unwrap();
    image_bytes(&out)
}

/// [`yat::render::render`] on a thread of its own, as a coordinator beside the test.
pub fn spawn_render(
    request: RenderRequest,
    executor: Executor,
    observers: Observers,
    interrupt: Interrupt,
) -> JoinHandle<anyhow::Result<RenderReport>> {
    std::thread::spawn(move || yat::render::render(request, &executor, observers, interrupt))
}

/// A `yat worker` process on a loopback port; killed when dropped.
pub struct Worker {
    pub address: String,
    child: Child,
    _stdout: BufReader<ChildStdout>,
}

impl Worker {
    /// Starts a worker with one render thread and these extra arguments.
    pub fn start(extra: &[&str]) -> Self {
        Self::start_on("127.0.0.1:0", extra)
    }

    pub fn start_on(listen: &str, extra: &[&str]) -> Self {
        Self::spawn(Self::command(listen, extra))
    }

    /// [`Worker::start`] in an address space of `bytes` (RLIMIT_AS).
    pub fn start_in_address_space(bytes: u64, extra: &[&str]) -> Self {
        let mut command = Self::command("127.0.0.1:0", extra);
        limit_address_space(&mut command, bytes);
        Self::spawn(command)
    }

    /// `yat worker` on `listen` with one render thread and these extra arguments, its standard
    /// output piped (the parent reads the address from it) and its standard error inherited,
    /// logging warnings.
    pub fn command(listen: &str, extra: &[&str]) -> Command {
        let mut command = Command::new(YAT);
        command
            .args(["worker", "--listen", listen, "--threads", "1"])
            .args(extra)
            .env_remove("YAT_TOKEN")
            // Warnings only: a worker's start and sessions would fill the test log.
            .env("YAT_LOG", "warn")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit());
        command
    }

    /// Starts `command` (see [`Worker::command`]) and reads the address it listens on.
    pub fn spawn(mut command: Command) -> Self {
        let mut child = command.spawn().expect("start yat worker");
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let address = next_line_after(&mut stdout, "listening on ");
        Self {
            address,
            child,
            _stdout: stdout,
        }
    }

    /// The worker's standard error, when its command piped it.
    pub fn take_stderr(&mut self) -> Option<std::process::ChildStderr> {
        self.child.stderr.take()
    }

    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// SIGKILL.
    pub fn kill(&mut self) {
        self.child.kill().unwrap();
        self.child.wait().unwrap();
    }

    /// The exit status, once the process ends within `limit`.
    pub fn wait_for_exit(
        &mut self,
        limit: std::time::Duration,
    ) -> Option<std::process::ExitStatus> {
        wait_for_exit(&mut self.child, limit)
    }

    /// Sends a signal (STOP, CONT, TERM).
    pub fn signal(&self, name: &str) {
        signal(self.pid(), name);
    }

    /// The worker's counters, over its Stats RPC.
    pub fn stats(&self, token: Option<&str>) -> yat_proto::pb::StatsReply {
        let address = format!("http://{}", self.address);
        let token = yat_proto::auth::AttachToken::new(token).unwrap();
        tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap()
            .block_on(async move {
                let channel = tonic::transport::Endpoint::from_shared(address)
                    .unwrap()
                    .connect()
                    .await
                    .unwrap();
                yat_proto::RenderNodeClient::with_interceptor(channel, token)
                    .stats(yat_proto::pb::StatsRequest {})
                    .await
                    .unwrap()
                    .into_inner()
            })
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        let _ = Command::new("kill")
            .args(["-CONT", &self.pid().to_string()])
            .stderr(Stdio::null())
            .status();
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The next line of `output`, trimmed, without `prefix`; panics on a line without it.
pub fn next_line_after(output: &mut impl BufRead, prefix: &str) -> String {
    let mut line = String::new();
    output.read_line(&mut line).unwrap();
    line.trim()
        .strip_prefix(prefix)
        .unwrap_or_else(|| panic!("expected a line starting {prefix:?}, got {line:?}"))
        .to_string()
}

/// `child`'s exit status, once it ends within `limit` (polled: its pipes stay the caller's).
pub fn wait_for_exit(
    child: &mut std::process::Child,
    limit: std::time::Duration,
) -> Option<std::process::ExitStatus> {
    let started = std::time::Instant::now();
    while started.elapsed() < limit {
        if let Some(status) = child.try_wait().unwrap() {
            return Some(status);
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    None
}

/// Sends process `pid` a signal (INT, TERM, STOP, CONT) with the `kill` command.
pub fn signal(pid: u32, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &pid.to_string()])
        .status()
        .unwrap();
    assert!(status.success(), "kill -{name} failed");
}

/// Runs `command`'s process in an address space of `bytes` (RLIMIT_AS): an allocation beyond
/// it fails, and Rust's allocation-failure handler aborts the process.
pub fn limit_address_space(command: &mut Command, bytes: u64) {
    // SAFETY: setrlimit is async-signal-safe; nothing else runs between fork and exec.
    unsafe {
        command.pre_exec(move || {
            let limit = libc::rlimit {
                rlim_cur: bytes,
                rlim_max: bytes,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
}

/// Writes a scene's files into `dir`; the main file is the first. Returns its path.
pub fn write_files(dir: &Path, files: &crate::hostile::Files) -> PathBuf {
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    dir.join(&files[0].0)
}

pub fn stderr_of(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Runs `command` in an address space of `bytes`, failing the test if it takes `within` or
/// longer.
pub fn run_in_address_space(mut command: Command, bytes: u64, within: Duration) -> Output {
    limit_address_space(&mut command, bytes);
    let started = std::time::Instant::now();
    let output = command.output().expect("run yat");
    assert!(started.elapsed() < within, "took {:?}", started.elapsed());
    output
}

/// `yat render SCENE -o OUT --exr` with the test settings and `extra` arguments.
pub fn render_command(scene: &Path, out: &Path, extra: &[&str]) -> Command {
    render_command_with(scene, out, &SETTINGS, extra)
}

/// `yat render SCENE -o OUT --exr` with `settings` (spp, resolution...) and `extra` arguments,
/// free of the caller's token and unit deadline.
pub fn render_command_with(scene: &Path, out: &Path, settings: &[&str], extra: &[&str]) -> Command {
    let mut command = Command::new(YAT);
    command
        .arg("render")
        .arg(scene)
        .arg("-o")
        .arg(out)
        .arg("--exr")
        .args(settings)
        .args(extra)
        .env_remove("YAT_TOKEN")
        .env_remove("YAT_UNIT_DEADLINE");
    command
}

/// [`render_command_with`], its input closed and its output piped (to read or to wait on).
pub fn piped_render_command(
    scene: &Path,
    out: &Path,
    settings: &[&str],
    extra: &[&str],
) -> Command {
    let mut command = render_command_with(scene, out, settings, extra);
    command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    command
}

pub fn render(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    render_command(scene, out, extra)
        .output()
        .expect("run yat render")
}

/// Panics with the command's output unless it succeeded.
pub fn assert_success(output: &Output) {
    assert!(
        output.status.success(),
        "yat failed ({})\nstdout:\n{}\nstderr:\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The PNG and EXR bytes of a render written to `out`.
pub fn image_bytes(out: &Path) -> (Vec<u8>, Vec<u8>) {
    (
        std::fs::read(out).unwrap(),
        std::fs::read(out.with_extension("exr")).unwrap(),
    )
}

/// Waits until the workers together have rendered `units` units.
pub fn wait_for_units(workers: &[&Worker], units: u64) {
    let started = std::time::Instant::now();
    while workers
        .iter()
        .map(|w| w.stats(None).units_done)
        .sum::<u64>()
        < units
    {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "render stalled"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The entry of the worker at `address` in the `workers` array of `report` (the
/// `--workers-json` report or the status page's JSON).
pub fn worker_entry<'a>(report: &'a serde_json::Value, address: &str) -> &'a serde_json::Value {
    report["workers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|w| w["address"] == address)
        .unwrap_or_else(|| panic!("no worker {address} in {report:#}"))
}

/// The `--workers-json` report.
pub fn workers_report(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `yat` as a file of its own in `dir` (a hard link where the filesystem allows, the binary
/// being large, else a copy): a binary that looks beside itself for the x86-64-v3 build finds
/// `dir`, where a symbolic link would resolve to the build folder.
pub fn yat_in(dir: &Path) -> PathBuf {
    let exe = dir.join("yat");
    if std::fs::hard_link(YAT, &exe).is_err() {
        std::fs::copy(YAT, &exe).unwrap();
    }
    exe
}

/// The names of the files in `dir` that `keep` accepts (files a test expects gone).
pub fn names_in(dir: &Path, keep: impl Fn(&str) -> bool) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| keep(name))
        .collect()
}
