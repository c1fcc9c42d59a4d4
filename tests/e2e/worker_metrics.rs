//! A worker's own `/metrics` (`yat worker --metrics-addr`): a real worker process scraped over
//! a real socket while strangers, a coordinator with the wrong token and two real renders
//! (`yat render --workers`) use it; the token rule; the rule beyond loopback; and the metrics
//! server stopping with the worker.

use std::io::BufReader;
use std::net::TcpStream;
use std::process::{Child, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant};

use yat_tracer::render::plan_units;

use crate::http::{http, metric, parse_prometheus};
use crate::util::*;

const TOKEN: &str = "metrics-test-token";

/// A `yat worker --metrics-addr 127.0.0.1:0` process; killed when dropped.
struct MetricsWorker {
    child: Child,
    /// host:port of the gRPC service.
    address: String,
    /// host:port of `/metrics`.
    metrics: String,
    _stdout: BufReader<ChildStdout>,
}

impl MetricsWorker {
    /// Starts `command` (a [`Worker::command`] with `--metrics-addr`) and reads the two
    /// addresses it prints: the gRPC one first, then the metrics one.
    fn spawn(mut command: Command) -> Self {
        let mut child = command.spawn().expect("start yat worker");
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let address = next_line_after(&mut stdout, "listening on ");
        let page = next_line_after(&mut stdout, "metrics on http://");
        let metrics = page
            .strip_suffix("/metrics")
            .unwrap_or_else(|| panic!("no /metrics after the address: {page:?}"))
            .to_string();
        Self {
            child,
            address,
            metrics,
            _stdout: stdout,
        }
    }

    fn get(&self, path: &str, token: Option<&str>) -> (u16, String) {
        get(&self.metrics, path, token)
    }

    /// The samples of `/metrics`, read with the token.
    fn scrape(&self) -> Vec<(String, f64)> {
        let (code, text) = self.get("/metrics", Some(TOKEN));
        assert_eq!(code, 200, "{text}");
        parse_prometheus(&text)
    }

    /// Scrapes until `done` holds of the samples (at most 60 s) and returns them.
    fn scrape_until(
        &self,
        what: &str,
        done: impl Fn(&[(String, f64)]) -> bool,
    ) -> Vec<(String, f64)> {
        let started = Instant::now();
        loop {
            let samples = self.scrape();
            if done(&samples) {
                return samples;
            }
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "waited 60 s for {what}: {samples:?}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for MetricsWorker {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A GET of `path` at `address`, with the bearer `token` if any: the status code and the body.
fn get(address: &str, path: &str, token: Option<&str>) -> (u16, String) {
    let authorization = token.map(|t| format!("Bearer {t}"));
    let headers: Vec<(&str, &str)> = authorization
        .as_deref()
        .map(|a| ("Authorization", a))
        .into_iter()
        .collect();
    let response = http(address, "GET", path, &headers);
    (response.code, response.text())
}

fn refused(samples: &[(String, f64)], reason: &str) -> f64 {
    metric(
        samples,
        &format!("yat_node_refusals_total{{reason=\"{reason}\"}}"),
    )
}

/// A gRPC connection of a token holder, held open until dropped.
struct Coordinator {
    _client: yat_proto::RenderNodeClient<
        tonic::service::interceptor::InterceptedService<
            tonic::transport::Channel,
            yat_proto::auth::AttachToken,
        >,
    >,
    _runtime: tokio::runtime::Runtime,
}

impl Coordinator {
    /// Connects to `address` and makes one call (Stats) that passes the token check.
    fn connect(address: &str) -> Self {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        let token = yat_proto::auth::AttachToken::new(Some(TOKEN)).unwrap();
        let endpoint = format!("http://{address}");
        let client = runtime.block_on(async move {
            let channel = tonic::transport::Endpoint::from_shared(endpoint)
                .unwrap()
                .connect()
                .await
                .unwrap();
            let mut client = yat_proto::RenderNodeClient::with_interceptor(channel, token);
            client.stats(yat_proto::pb::StatsRequest {}).await.unwrap();
            client
        });
        Self {
            _client: client,
            _runtime: runtime,
        }
    }
}

#[test]
fn a_worker_counts_what_it_rendered_refused_and_served() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let mut command = Worker::command(
        "127.0.0.1:0",
        &[
            "--metrics-addr",
            "127.0.0.1:0",
            "--max-unauthenticated-per-address",
            "2",
            "--handshake-seconds",
            "1",
        ],
    );
    command.env("YAT_TOKEN", TOKEN);
    let worker = MetricsWorker::spawn(command);

    // The worker has a token: /metrics wants it, and says nothing without it.
    for token in [None, Some("wrong")] {
        let (code, body) = worker.get("/metrics", token);
        assert_eq!(code, 401, "{token:?}: {body}");
        assert!(!body.contains("yat_node"), "{body}");
    }
    assert_eq!(worker.get("/", Some(TOKEN)).0, 404);
    assert_eq!(worker.get("/api/status", Some(TOKEN)).0, 404);
    let fresh = worker.scrape();
    assert_eq!(metric(&fresh, "yat_node_units_total"), 0.0);
    assert_eq!(metric(&fresh, "yat_node_render_threads"), 1.0);
    assert_eq!(metric(&fresh, "yat_node_draining"), 0.0);

    // Strangers: three silent sockets from one address allowed two unauthenticated ones. The
    // third is closed at once, the other two at the handshake deadline.
    let silent: Vec<_> = (0..3)
        .map(|_| TcpStream::connect(&worker.address).unwrap())
        .collect();
    let strangers = worker.scrape_until("the strangers refused", |s| {
        refused(s, "address_full") >= 1.0 && refused(s, "handshake_timeout") >= 2.0
    });
    assert_eq!(refused(&strangers, "address_full"), 1.0);
    assert_eq!(refused(&strangers, "handshake_timeout"), 2.0);
    assert_eq!(
        metric(&strangers, "yat_node_connections_accepted_total"),
        3.0
    );
    drop(silent);

    // A coordinator with the wrong token is refused, and the render fails.
    let wrong = render_command(
        &scene,
        &dir.path().join("wrong.png"),
        &["--workers", &worker.address, "--quiet"],
    )
    .env("YAT_TOKEN", "not-the-token")
    .output()
    .unwrap();
    assert!(!wrong.status.success(), "{}", stderr_of(&wrong));
    let after_wrong = worker.scrape();
    assert!(
        refused(&after_wrong, "token_wrong") >= 1.0,
        "{after_wrong:?}"
    );
    assert_eq!(refused(&after_wrong, "token_missing"), 0.0);
    assert_eq!(metric(&after_wrong, "yat_node_units_total"), 0.0);

    // A real render: every unit of the plan rendered here once, every sample counted.
    let out = dir.path().join("box.png");
    let render = |out: &std::path::Path| {
        let output = render_command(&scene, out, &["--workers", &worker.address, "--quiet"])
            .env("YAT_TOKEN", TOKEN)
            .output()
            .unwrap();
        assert_success(&output);
    };
    render(&out);
    let settings = request(&scene, &out).settings;
    let plan = plan_units(&settings);
    let planned_samples: u64 = plan.iter().map(|u| u.sample_count()).sum();
    assert_eq!(
        planned_samples,
        128 * 96 * 64,
        "the plan covers every sample once"
    );
    let files = scene_bytes(dir.path()) as f64;
    let first = worker.scrape();
    assert_eq!(metric(&first, "yat_node_units_total"), plan.len() as f64);
    assert_eq!(
        metric(&first, "yat_node_samples_total"),
        planned_samples as f64
    );
    assert!(metric(&first, "yat_node_result_bytes_total") > 0.0);
    assert!(metric(&first, "yat_node_render_seconds_total") > 0.0);
    assert_eq!(
        metric(&first, "yat_node_uploads_total"),
        4.0,
        "the scene's 4 files"
    );
    assert_eq!(metric(&first, "yat_node_upload_bytes_total"), files);
    assert_eq!(metric(&first, "yat_node_blob_cache_misses_total"), 4.0);
    assert_eq!(metric(&first, "yat_node_blob_cache_hits_total"), 0.0);
    assert_eq!(metric(&first, "yat_node_blobs_cached"), 4.0);
    assert_eq!(
        metric(&first, "yat_node_blob_cache_bytes{tier=\"memory\"}"),
        files
    );
    assert_eq!(metric(&first, "yat_node_scene_cache_misses_total"), 1.0);
    assert_eq!(metric(&first, "yat_node_scenes_cached"), 1.0);
    assert_eq!(metric(&first, "yat_node_render_threads_busy"), 0.0);
    assert_eq!(metric(&first, "yat_node_units_queued"), 0.0);
    assert_eq!(metric(&first, "yat_node_upload_bytes_held"), 0.0);
    assert_eq!(metric(&first, "yat_node_internal_errors_total"), 0.0);

    // The same scene again: nothing uploaded, the scene found built.
    render(&dir.path().join("again.png"));
    let second = worker.scrape();
    assert_eq!(
        metric(&second, "yat_node_units_total"),
        2.0 * plan.len() as f64
    );
    assert_eq!(
        metric(&second, "yat_node_samples_total"),
        2.0 * planned_samples as f64
    );
    assert_eq!(metric(&second, "yat_node_uploads_total"), 4.0);
    assert_eq!(metric(&second, "yat_node_blob_cache_hits_total"), 4.0);
    assert_eq!(metric(&second, "yat_node_scene_cache_hits_total"), 1.0);
    assert_eq!(metric(&second, "yat_node_scene_cache_misses_total"), 1.0);

    // The connection gauges: none once the coordinators have gone, one authenticated while a
    // token holder's connection is open, none again once it closes.
    let gone = |s: &[(String, f64)]| metric(s, "yat_node_connections") == 0.0;
    let idle = worker.scrape_until("the coordinators' connections closed", gone);
    assert_eq!(metric(&idle, "yat_node_connections_authenticated"), 0.0);
    let coordinator = Coordinator::connect(&worker.address);
    worker.scrape_until("one coordinator connected", |s| {
        metric(s, "yat_node_connections") == 1.0
            && metric(s, "yat_node_connections_authenticated") == 1.0
    });
    drop(coordinator);
    let closed = worker.scrape_until("the coordinator's connection closed", gone);
    assert_eq!(metric(&closed, "yat_node_connections_authenticated"), 0.0);
    // Nothing the honest renders did was refused.
    assert_eq!(
        refused(&closed, "token_wrong"),
        refused(&after_wrong, "token_wrong")
    );
    assert_eq!(refused(&closed, "address_full"), 1.0);
}

#[test]
fn metrics_beyond_loopback_need_a_token_and_stop_with_the_worker() {
    // No token, metrics on every address: refused at start, naming the way out.
    let exposed = Worker::command("127.0.0.1:0", &["--metrics-addr", "0.0.0.0:0"])
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(!exposed.status.success());
    let stderr = stderr_of(&exposed);
    assert!(
        stderr.contains("refusing to serve metrics") && stderr.contains("--insecure"),
        "{stderr}"
    );
    assert!(
        !String::from_utf8_lossy(&exposed.stdout).contains("listening on"),
        "refused before it listens"
    );

    // With --insecure it serves them to anyone; without a token, so does a loopback address.
    let mut worker = MetricsWorker::spawn(Worker::command(
        "127.0.0.1:0",
        &["--metrics-addr", "0.0.0.0:0", "--insecure"],
    ));
    let port = worker.metrics.rsplit_once(':').unwrap().1.to_string();
    let local = format!("127.0.0.1:{port}");
    let (code, body) = get(&local, "/metrics", None);
    assert_eq!(code, 200, "{body}");
    assert_eq!(
        metric(&parse_prometheus(&body), "yat_node_connections"),
        0.0
    );
    let open = MetricsWorker::spawn(Worker::command(
        "127.0.0.1:0",
        &["--metrics-addr", "127.0.0.1:0"],
    ));
    assert_eq!(open.get("/metrics", None).0, 200);

    // SIGTERM: the worker drains and exits 0, and its metrics port is closed with it.
    signal(worker.child.id(), "TERM");
    let exit = wait_for_exit(&mut worker.child, Duration::from_secs(60)).expect("the worker exits");
    assert!(exit.success(), "{exit}");
    assert!(
        TcpStream::connect(&local).is_err(),
        "the metrics port is closed"
    );
}
