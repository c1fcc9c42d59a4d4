//! The coordinator trusts no worker: a fake worker in this process (a tonic server on a real
//! loopback socket) misbehaves in one way per test, beside an honest `yat worker` process.
//! With the honest worker the image is bit-identical to the in-process render and the fake's
//! requests stay few; alone, the fake makes `yat render` fail with a clear error in bounded
//! time. Nothing the fake says reaches the terminal with an escape character.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use tonic::{Request, Response, Status, Streaming};
use yat_proto::hash::Sha256Stream;
use yat_proto::{pb, RenderNodeServer, PROTOCOL_VERSION};

use crate::util::*;

/// What the fake does wrong.
#[derive(Clone, Copy, Debug)]
enum Misbehaviour {
    /// Claims a million threads and never answers a unit.
    NeverAnswers,
    /// Advertises a message limit of one byte.
    TinyMessageLimit,
    /// Names another renderer build than the coordinator's.
    OtherBuild,
    /// Answers every unit with these RGB and weight sums in every pixel.
    Pixels { rgb: f32, weight: f32 },
    /// Answers with a sample buffer one pixel short.
    ShortBuffer,
    /// Answers with the next unit's index.
    OtherIndex,
    /// Reports one sample more than the unit has.
    WrongSampleCount,
    /// Answers every unit with INTERNAL at once.
    FailsAtOnce,
    /// Answers LoadScene with INTERNAL.
    LoadFails,
    /// Lists the first blob it is asked about as missing [`REPEATS`] times, then answers
    /// LoadScene with INTERNAL (one session is all it gets).
    RepeatsMissingBlob,
    /// Escape sequences in its host name, software name and error messages.
    Escapes,
    /// Refuses every unit as a draining worker does.
    Draining,
}

const ESCAPES: &str = "\x1b]0;pwn\x07\x1b[2J";

/// How often [`Misbehaviour::RepeatsMissingBlob`] lists its blob.
const REPEATS: usize = 2000;

/// The border of the bench scene's units' buffers: its blackmanharris filter is 2 pixels wide.
const BORDER: u32 = 2;

struct FakeState {
    misbehaviour: Mutex<Misbehaviour>,
    /// The image size of the scene loaded last.
    image: Mutex<(u32, u32)>,
    requests: AtomicU64,
    /// The blob its HasBlobs reply listed, and each PutBlob stream received: the hash its
    /// first chunk names and the SHA-256 of the bytes.
    listed: Mutex<Option<String>>,
    uploads: Mutex<Vec<(String, String)>>,
    units_in_flight: AtomicU64,
    max_units_in_flight: AtomicU64,
}

impl FakeState {
    fn misbehaviour(&self) -> Misbehaviour {
        *self.misbehaviour.lock().unwrap()
    }

    fn count(&self) {
        self.requests.fetch_add(1, Ordering::SeqCst);
    }
}

/// Counts a unit in flight while it lives.
struct InFlight<'a>(&'a FakeState);

impl<'a> InFlight<'a> {
    fn new(state: &'a FakeState) -> Self {
        let now = state.units_in_flight.fetch_add(1, Ordering::SeqCst) + 1;
        state.max_units_in_flight.fetch_max(now, Ordering::SeqCst);
        Self(state)
    }
}

impl Drop for InFlight<'_> {
    fn drop(&mut self) {
        self.0.units_in_flight.fetch_sub(1, Ordering::SeqCst);
    }
}

#[derive(Clone)]
struct FakeNode(Arc<FakeState>);

#[tonic::async_trait]
impl yat_proto::RenderNode for FakeNode {
    async fn handshake(
        &self,
        _: Request<pb::HandshakeRequest>,
    ) -> Result<Response<pb::HandshakeReply>, Status> {
        self.0.count();
        let misbehaviour = self.0.misbehaviour();
        let (hostname, software) = match misbehaviour {
            Misbehaviour::Escapes => (format!("fake{ESCAPES}"), format!("{ESCAPES}fake 1")),
            _ => ("fake".to_string(), "fake 1".to_string()),
        };
        Ok(Response::new(pb::HandshakeReply {
            protocol_version: PROTOCOL_VERSION,
            threads: match misbehaviour {
                Misbehaviour::NeverAnswers => 1_000_000,
                _ => 4,
            },
            hostname,
            max_message_bytes: match misbehaviour {
                Misbehaviour::TinyMessageLimit => 1,
                _ => 8 << 20,
            },
            max_blob_bytes: 1 << 30,
            features: Vec::new(),
            software,
            renderer_build: match misbehaviour {
                Misbehaviour::OtherBuild => "0123456789abcdef".into(),
                _ => yat_tracer::RENDERER_BUILD.into(),
            },
        }))
    }

    async fn has_blobs(
        &self,
        request: Request<pb::HasBlobsRequest>,
    ) -> Result<Response<pb::HasBlobsReply>, Status> {
        self.0.count();
        let missing = match self.0.misbehaviour() {
            Misbehaviour::RepeatsMissingBlob => {
                let first = request.into_inner().sha256.into_iter().next();
                let first = first.unwrap_or_default();
                *self.0.listed.lock().unwrap() = Some(first.clone());
                vec![first; REPEATS]
            }
            // Claims every file, so the scene is never uploaded to it.
            _ => Vec::new(),
        };
        Ok(Response::new(pb::HasBlobsReply { missing }))
    }

    async fn put_blob(
        &self,
        request: Request<Streaming<pb::BlobChunk>>,
    ) -> Result<Response<pb::PutBlobReply>, Status> {
        self.0.count();
        let mut stream = request.into_inner();
        let mut named = String::new();
        let mut bytes = Sha256Stream::default();
        while let Some(chunk) = stream.message().await? {
            if named.is_empty() {
                named = chunk.sha256;
            }
            bytes.update(&chunk.data);
        }
        let upload = (named, bytes.finish_hex());
        self.0.uploads.lock().unwrap().push(upload);
        Ok(Response::new(pb::PutBlobReply::default()))
    }

    async fn load_scene(
        &self,
        request: Request<pb::LoadSceneRequest>,
    ) -> Result<Response<pb::LoadSceneReply>, Status> {
        self.0.count();
        let settings = request.into_inner().settings.unwrap_or_default();
        *self.0.image.lock().unwrap() = (settings.width, settings.height);
        if let Misbehaviour::LoadFails | Misbehaviour::RepeatsMissingBlob = self.0.misbehaviour() {
            return Err(Status::internal("out of luck"));
        }
        Ok(Response::new(pb::LoadSceneReply {
            scene_id: "fake-scene".into(),
            ..Default::default()
        }))
    }

    async fn render_unit(
        &self,
        request: Request<pb::RenderUnitRequest>,
    ) -> Result<Response<pb::RenderUnitReply>, Status> {
        self.0.count();
        let _in_flight = InFlight::new(&self.0);
        let unit = request.into_inner().unit.unwrap_or_default();
        let tile =
            u64::from(unit.x1.saturating_sub(unit.x0)) * u64::from(unit.y1.saturating_sub(unit.y0));
        let samples = tile * u64::from(unit.sample_end.saturating_sub(unit.sample_start));
        // The buffer covers the tile and the filter's border, clipped to the image.
        let (width, height) = *self.0.image.lock().unwrap();
        let side = |lo: u32, hi: u32, end: u32| {
            u64::from(
                hi.saturating_add(BORDER)
                    .min(end)
                    .saturating_sub(lo.saturating_sub(BORDER)),
            )
        };
        let pixels = side(unit.x0, unit.x1, width) * side(unit.y0, unit.y1, height);
        let reply = |rgb: f32, weight: f32, pixels: u64| pb::RenderUnitReply {
            index: unit.index,
            pixels: (0..pixels)
                .flat_map(|_| [rgb, rgb, rgb, weight])
                .flat_map(f32::to_le_bytes)
                .collect::<Vec<u8>>()
                .into(),
            stats: Some(pb::UnitStats {
                samples,
                rays: samples,
                dropped: 0,
            }),
            render_seconds: 0.0,
            light_splats: Default::default(),
            layers: Default::default(),
        };
        let reply = match self.0.misbehaviour() {
            Misbehaviour::NeverAnswers => std::future::pending().await,
            Misbehaviour::Pixels { rgb, weight } => reply(rgb, weight, pixels),
            Misbehaviour::ShortBuffer => reply(0.5, 1.0, pixels - 1),
            Misbehaviour::OtherIndex => pb::RenderUnitReply {
                index: unit.index + 1,
                ..reply(0.5, 1.0, pixels)
            },
            Misbehaviour::WrongSampleCount => pb::RenderUnitReply {
                stats: Some(pb::UnitStats {
                    samples: samples + 1,
                    ..Default::default()
                }),
                ..reply(0.5, 1.0, pixels)
            },
            Misbehaviour::Escapes => return Err(Status::internal(format!("boom{ESCAPES}"))),
            Misbehaviour::Draining => {
                return Err(yat_proto::drain::draining_status("unit"));
            }
            Misbehaviour::FailsAtOnce
            | Misbehaviour::TinyMessageLimit
            | Misbehaviour::OtherBuild
            | Misbehaviour::LoadFails
            | Misbehaviour::RepeatsMissingBlob => return Err(Status::internal("no")),
        };
        Ok(Response::new(reply))
    }

    async fn stats(
        &self,
        _: Request<pb::StatsRequest>,
    ) -> Result<Response<pb::StatsReply>, Status> {
        self.0.count();
        Ok(Response::new(pb::StatsReply::default()))
    }
}

/// The fake worker, serving on a loopback port until dropped.
struct FakeWorker {
    address: String,
    state: Arc<FakeState>,
    _runtime: tokio::runtime::Runtime,
}

impl FakeWorker {
    fn start(misbehaviour: Misbehaviour) -> Self {
        let state = Arc::new(FakeState {
            misbehaviour: Mutex::new(misbehaviour),
            image: Mutex::new((0, 0)),
            requests: AtomicU64::new(0),
            listed: Mutex::new(None),
            uploads: Mutex::new(Vec::new()),
            units_in_flight: AtomicU64::new(0),
            max_units_in_flight: AtomicU64::new(0),
        });
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()
            .unwrap();
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let address = listener.local_addr().unwrap().to_string();
        listener.set_nonblocking(true).unwrap();
        let service = RenderNodeServer::new(FakeNode(state.clone()));
        runtime.spawn(async move {
            let listener = tokio::net::TcpListener::from_std(listener).unwrap();
            tonic::transport::Server::builder()
                .add_service(service)
                .serve_with_incoming(tonic::transport::server::TcpIncoming::from(listener))
                .await
                .unwrap();
        });
        Self {
            address,
            state,
            _runtime: runtime,
        }
    }

    /// Switches to `misbehaviour` and zeroes the counters.
    fn become_(&self, misbehaviour: Misbehaviour) {
        *self.state.misbehaviour.lock().unwrap() = misbehaviour;
        self.state.requests.store(0, Ordering::SeqCst);
        self.state.uploads.lock().unwrap().clear();
        self.state.max_units_in_flight.store(0, Ordering::SeqCst);
    }

    fn requests(&self) -> u64 {
        self.state.requests.load(Ordering::SeqCst)
    }
}

/// A scene, its in-process render, an honest worker and the fake.
struct Bench {
    dir: tempfile::TempDir,
    scene: PathBuf,
    expected: (Vec<u8>, Vec<u8>),
    honest: Worker,
    fake: FakeWorker,
}

/// The fake's requests in one render stay under this.
const MAX_FAKE_REQUESTS: u64 = 50;
/// Alone, the fake makes `yat render --timeout 5` fail within this.
const ALONE_FAILS_WITHIN: Duration = Duration::from_secs(20);

impl Bench {
    fn new(misbehaviour: Misbehaviour) -> Self {
        let dir = tempfile::tempdir().unwrap();
        let scene = write_scene(dir.path());
        let out = dir.path().join("in-process.png");
        assert_success(&render(&scene, &out, &["--threads", "2", "--quiet"]));
        Self {
            expected: image_bytes(&out),
            scene,
            honest: Worker::start(&[]),
            fake: FakeWorker::start(misbehaviour),
            dir,
        }
    }

    /// `yat render` on `workers`, with a fixed unit deadline in seconds unless None.
    fn run(
        &self,
        name: &str,
        workers: &str,
        extra: &[&str],
        deadline: Option<&str>,
    ) -> (Output, PathBuf) {
        let out = self.dir.path().join(format!("{name}.png"));
        let json = self.dir.path().join(format!("{name}.json"));
        let mut command = render_command(&self.scene, &out, extra);
        command
            .args(["--workers", workers, "--workers-json"])
            .arg(&json);
        if let Some(seconds) = deadline {
            command.env("YAT_UNIT_DEADLINE", seconds);
        }
        let output = command.output().unwrap();
        assert_no_escapes(&output, &json);
        (output, out)
    }

    /// Renders with the honest worker and the fake: the in-process image, few requests to the
    /// fake. Returns the fake's entry of the workers report and the coordinator's stderr.
    fn with_honest(&self, misbehaviour: Misbehaviour) -> (serde_json::Value, String) {
        self.fake.become_(misbehaviour);
        let name = format!("{misbehaviour:?}").replace(|c: char| !c.is_alphanumeric(), "_");
        let workers = format!("{},{}", self.fake.address, self.honest.address);
        let (output, out) = self.run(&name, &workers, &[], Some("4"));
        assert_success(&output);
        assert!(
            image_bytes(&out) == self.expected,
            "{misbehaviour:?}: the image differs from the in-process render"
        );
        let requests = self.fake.requests();
        assert!(
            requests < MAX_FAKE_REQUESTS,
            "{misbehaviour:?}: {requests} requests to the fake"
        );
        let report = workers_report(&out.with_extension("json"));
        let fake = worker_entry(&report, &self.fake.address).clone();
        assert_eq!(fake["units"], 0, "{misbehaviour:?}: {report:#}");
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        (fake, stderr)
    }

    /// Renders with the fake alone and `--timeout 5`: fails within [`ALONE_FAILS_WITHIN`],
    /// naming the fake and saying `why`. Returns stderr.
    fn alone(&self, misbehaviour: Misbehaviour, deadline: Option<&str>, why: &str) -> String {
        self.fake.become_(misbehaviour);
        let started = Instant::now();
        let (output, _) = self.run("alone", &self.fake.address, &["--timeout", "5"], deadline);
        let took = started.elapsed();
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        assert!(!output.status.success(), "{misbehaviour:?}: {stderr}");
        assert!(took < ALONE_FAILS_WITHIN, "{misbehaviour:?}: {took:?}");
        assert!(
            stderr.contains(&self.fake.address) && stderr.contains(why),
            "{misbehaviour:?}: expected {why:?} and the address in\n{stderr}"
        );
        assert!(self.fake.requests() < MAX_FAKE_REQUESTS);
        stderr
    }
}

/// No escape or bell character from the fake on the terminal or in the report.
fn assert_no_escapes(output: &Output, json: &Path) {
    let report = std::fs::read(json).unwrap_or_default();
    for (what, bytes) in [
        ("stdout", &output.stdout),
        ("stderr", &output.stderr),
        ("--workers-json", &report),
    ] {
        assert!(
            !bytes.iter().any(|&b| b == 0x1b || b == 0x07),
            "{what} carries a control character:\n{}",
            String::from_utf8_lossy(bytes)
        );
    }
    assert!(
        !String::from_utf8_lossy(&report).contains("\\u001b"),
        "the report carries an escaped ESC"
    );
}

#[test]
fn a_worker_that_claims_a_million_threads_and_never_answers() {
    let bench = Bench::new(Misbehaviour::NeverAnswers);
    let (fake, _) = bench.with_honest(Misbehaviour::NeverAnswers);
    assert_eq!(fake["threads"], 1024, "the claim is clamped: {fake:#}");
    let held = bench.fake.state.max_units_in_flight.load(Ordering::SeqCst);
    // One unit per claimed thread before a first result, at most MAX_UNITS_BEFORE_A_RESULT
    // (64): not the 2 x 1024 its clamped claim would allow.
    assert!(
        (1..=64).contains(&held),
        "a worker that never returned a unit holds at most 64: {held}"
    );
    // The adaptive deadline is 30 s: --timeout, not the deadline, ends the render.
    bench.alone(Misbehaviour::NeverAnswers, None, "no unit merged for 5.0 s");
}

#[test]
fn a_worker_with_a_one_byte_message_limit_is_refused() {
    let bench = Bench::new(Misbehaviour::TinyMessageLimit);
    let (fake, _) = bench.with_honest(Misbehaviour::TinyMessageLimit);
    assert_eq!(bench.fake.requests(), 1, "refused at the handshake");
    assert!(fake["gone"]
        .as_str()
        .unwrap()
        .contains("accepts messages of 1 bytes"));
    bench.alone(
        Misbehaviour::TinyMessageLimit,
        Some("4"),
        "no worker can render this scene",
    );
}

/// A worker of another renderer build could render other bits: refused at the handshake, so the
/// image stays the in-process one.
#[test]
fn a_worker_of_another_renderer_build_is_refused() {
    let bench = Bench::new(Misbehaviour::OtherBuild);
    let (fake, _) = bench.with_honest(Misbehaviour::OtherBuild);
    assert_eq!(bench.fake.requests(), 1, "refused at the handshake");
    let gone = fake["gone"].as_str().unwrap();
    assert!(
        gone.contains("renderer build 0123456789abcdef")
            && gone.contains(yat_tracer::RENDERER_BUILD),
        "{gone}"
    );
    bench.alone(
        Misbehaviour::OtherBuild,
        Some("4"),
        "no worker can render this scene",
    );
}

/// Values no render gives: not finite, beyond the film's range, and the plausible ones the
/// bench scene's blackmanharris filter rules out: a negative weight sum (it weighs no sample
/// negatively), and a weight sum of 1 in every pixel (the region's edge, two pixels from the
/// tile, gets at most 8 samples x 0.022, the filter at 1.5 pixels, from each tile pixel within
/// reach).
#[test]
fn non_finite_negative_or_huge_sums_are_refused() {
    let bench = Bench::new(Misbehaviour::FailsAtOnce);
    for (rgb, weight, why) in [
        (f32::NAN, 1.0, "is not finite"),
        (0.5, f32::INFINITY, "is not finite"),
        (0.5, -1e6, "negative weight sum"),
        (f32::MAX, 1.0, "exceeds what the film holds"),
        (-1e30, 1.0, "exceeds what the film holds"),
        (0.5, -0.5, "negative weight sum"),
        (
            0.5,
            1.0,
            "exceeds the weight sum the unit's samples can give the pixel",
        ),
    ] {
        let (fake, stderr) = bench.with_honest(Misbehaviour::Pixels { rgb, weight });
        assert!(fake["failures"].as_u64().unwrap() >= 1, "{fake:#}");
        assert!(
            stderr.contains(why),
            "({rgb}, {weight}): {why:?} not in\n{stderr}"
        );
    }
    let stderr = bench.alone(
        Misbehaviour::Pixels {
            rgb: f32::NAN,
            weight: 1.0,
        },
        Some("4"),
        "retired after 3 bad replies in a row",
    );
    assert!(stderr.contains("is not finite"), "{stderr}");
}

#[test]
fn wrong_sizes_indices_and_counters_are_refused() {
    let bench = Bench::new(Misbehaviour::FailsAtOnce);
    for misbehaviour in [
        Misbehaviour::ShortBuffer,
        Misbehaviour::OtherIndex,
        Misbehaviour::WrongSampleCount,
    ] {
        bench.with_honest(misbehaviour);
    }
    let stderr = bench.alone(
        Misbehaviour::OtherIndex,
        Some("4"),
        "retired after 3 bad replies in a row",
    );
    assert!(stderr.contains("asked for unit"), "{stderr}");
}

#[test]
fn a_worker_that_fails_every_unit_at_once_is_retired() {
    let bench = Bench::new(Misbehaviour::FailsAtOnce);
    bench.with_honest(Misbehaviour::FailsAtOnce);
    bench.alone(
        Misbehaviour::FailsAtOnce,
        Some("4"),
        "retired after 3 bad replies in a row",
    );
    assert!(
        bench.fake.requests() <= 3 * (3 + 4),
        "three sessions of handshake, blob query, load and a unit per claimed thread (4): {}",
        bench.fake.requests()
    );
}

#[test]
fn a_worker_that_cannot_load_the_scene_is_retired() {
    let bench = Bench::new(Misbehaviour::LoadFails);
    let (fake, _) = bench.with_honest(Misbehaviour::LoadFails);
    assert!(
        fake["gone"]
            .as_str()
            .unwrap()
            .contains("cannot load the scene"),
        "{fake:#}"
    );
    assert_eq!(bench.fake.requests(), 3, "handshake, blob query, load");
    bench.alone(Misbehaviour::LoadFails, Some("4"), "cannot load the scene");
}

#[test]
fn escape_sequences_from_a_worker_never_reach_the_terminal() {
    let bench = Bench::new(Misbehaviour::Escapes);
    let (fake, stderr) = bench.with_honest(Misbehaviour::Escapes);
    // The text is there, its control characters replaced (assert_no_escapes checked them).
    assert!(stderr.contains("]0;pwn"), "{stderr}");
    assert!(
        fake["hostname"]
            .as_str()
            .unwrap()
            .starts_with("fake\u{fffd}]0;pwn"),
        "{fake:#}"
    );
    bench.alone(
        Misbehaviour::Escapes,
        Some("4"),
        "retired after 3 bad replies in a row",
    );
}

#[test]
fn a_draining_worker_costs_no_failure_and_is_tried_again() {
    let bench = Bench::new(Misbehaviour::Draining);
    let (fake, stderr) = bench.with_honest(Misbehaviour::Draining);
    assert!(
        stderr.contains(&format!("worker {} draining", bench.fake.address)),
        "{stderr}"
    );
    assert_eq!(fake["failures"], 0, "{fake:#}");
    assert!(fake["gone"].is_null(), "a drain is not a fault: {fake:#}");
    let stderr = bench.alone(
        Misbehaviour::Draining,
        Some("4"),
        "no unit merged for 5.0 s",
    );
    assert!(
        stderr.matches("draining").count() >= 2,
        "tried again after the drain: {stderr}"
    );
}

/// A worker that lists one of the scene's files as missing 2000 times receives it once, whole:
/// one PutBlob stream naming that file and carrying its bytes. It then fails to load the scene,
/// so that one session is the render's only upload to it.
#[test]
fn a_blob_listed_again_and_again_is_uploaded_once() {
    let bench = Bench::new(Misbehaviour::RepeatsMissingBlob);
    bench.with_honest(Misbehaviour::RepeatsMissingBlob);
    let listed = bench.fake.state.listed.lock().unwrap().clone().unwrap();
    let uploads = bench.fake.state.uploads.lock().unwrap().clone();
    assert_eq!(
        uploads,
        [(listed.clone(), listed)],
        "one upload of the listed blob"
    );
    assert_eq!(
        bench.fake.requests(),
        4,
        "handshake, blob query, one upload, load"
    );
}
