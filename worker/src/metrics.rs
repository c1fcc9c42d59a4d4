//! The worker's own figures, and their Prometheus text (`yat worker --metrics-addr`,
//! `metrics_server.rs`; every family is described in docs/status.md, "A worker's
//! `/metrics`").
//!
//! Counters are atomics bumped where the event happens, once per unit, upload, request,
//! refusal or connection, never per sample: rendering pays one relaxed add per figure per
//! unit. Gauges that the node's state already holds (busy render threads, queued units,
//! cache sizes, upload bytes held) are read from it when a scrape asks, into [`NodeGauges`].
//!
//! The families are `yat_node_*` (the render node's own view), apart from the coordinator's
//! `yat_worker_*` ones, which are its view of each worker during one render.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use yat_tracer::parse::ParseError;
use yat_tracer::render::BuildError;

use crate::error::NodeError;
use crate::prometheus_text::{labels, Exposition, MetricType};

/// Why the worker refused a connection or a request: the `reason` label of
/// `yat_node_refusals_total`. Each is a limit or a check the worker applies (docs/security.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// A connection from an address already holding `--max-unauthenticated-per-address`
    /// unauthenticated ones, closed at once.
    AddressFull,
    /// An unauthenticated connection closed to make room at `--max-unauthenticated`.
    UnauthenticatedEvicted,
    /// A connection with no authenticated request within `--handshake-seconds`.
    HandshakeTimeout,
    /// A request without a token, to a worker that requires one.
    TokenMissing,
    /// A request with another token.
    TokenWrong,
    /// A handshake of another protocol version.
    ProtocolVersion,
    /// Work offered during a drain, and units handed back by it.
    Draining,
    /// A unit beyond `--max-queued-units`.
    QueueFull,
    /// A blob over `--max-blob-mib`.
    BlobTooLarge,
    /// An upload that would pass `--upload-budget-mib`.
    UploadBudget,
    /// An upload without a chunk for `--blob-idle-seconds`.
    BlobStalled,
    /// A blob larger than the whole `--cache-dir-mib`.
    CacheFull,
    /// A blob whose bytes do not match its declared size or hash.
    BlobInvalid,
    /// A message that describes no valid render, unit or file (settings over their limits
    /// included).
    InvalidRequest,
    /// A scene naming a blob the worker does not hold.
    BlobMissing,
    /// A scene that does not parse or build.
    SceneInvalid,
    /// A scene over the build budget (`--max-primitives`, `--max-memory-mib`, ...).
    SceneBudget,
    /// A unit of a scene the worker does not hold (never loaded, or evicted).
    SceneNotLoaded,
}

impl Refusal {
    pub const ALL: [Refusal; 18] = [
        Refusal::AddressFull,
        Refusal::UnauthenticatedEvicted,
        Refusal::HandshakeTimeout,
        Refusal::TokenMissing,
        Refusal::TokenWrong,
        Refusal::ProtocolVersion,
        Refusal::Draining,
        Refusal::QueueFull,
        Refusal::BlobTooLarge,
        Refusal::UploadBudget,
        Refusal::BlobStalled,
        Refusal::CacheFull,
        Refusal::BlobInvalid,
        Refusal::InvalidRequest,
        Refusal::BlobMissing,
        Refusal::SceneInvalid,
        Refusal::SceneBudget,
        Refusal::SceneNotLoaded,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Refusal::AddressFull => "address_full",
            Refusal::UnauthenticatedEvicted => "unauthenticated_evicted",
            Refusal::HandshakeTimeout => "handshake_timeout",
            Refusal::TokenMissing => "token_missing",
            Refusal::TokenWrong => "token_wrong",
            Refusal::ProtocolVersion => "protocol_version",
            Refusal::Draining => "draining",
            Refusal::QueueFull => "queue_full",
            Refusal::BlobTooLarge => "blob_too_large",
            Refusal::UploadBudget => "upload_budget",
            Refusal::BlobStalled => "blob_stalled",
            Refusal::CacheFull => "cache_full",
            Refusal::BlobInvalid => "blob_invalid",
            Refusal::InvalidRequest => "invalid_request",
            Refusal::BlobMissing => "blob_missing",
            Refusal::SceneInvalid => "scene_invalid",
            Refusal::SceneBudget => "scene_budget",
            Refusal::SceneNotLoaded => "scene_not_loaded",
        }
    }

    /// Its place in [`Refusal::ALL`] and in the counters.
    fn index(self) -> usize {
        self as usize
    }
}

/// What a failed request was: a refusal, the worker's own failure, or work its caller gave up
/// (nobody reads that answer, and nothing is counted).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Failure {
    Refused(Refusal),
    Internal,
    Abandoned,
}

fn failure_of(error: &NodeError) -> Failure {
    use Failure::{Abandoned, Internal, Refused};
    use NodeError::*;
    match error {
        ProtocolVersion { .. } => Refused(Refusal::ProtocolVersion),
        Wire(_) | MalformedHash { .. } | EmptyBlobStream | UnnamedBlob => {
            Refused(Refusal::InvalidRequest)
        }
        UploadBudget { .. } => Refused(Refusal::UploadBudget),
        BlobStalled { .. } => Refused(Refusal::BlobStalled),
        BlobTooLarge { .. } => Refused(Refusal::BlobTooLarge),
        BlobTooLong { .. } | BlobTooShort { .. } | BlobHashMismatch { .. } => {
            Refused(Refusal::BlobInvalid)
        }
        BlobMissing { .. } => Refused(Refusal::BlobMissing),
        CacheFull { .. } => Refused(Refusal::CacheFull),
        SceneParse { source, .. } => match **source {
            ParseError::OverBudget { .. } => Refused(Refusal::SceneBudget),
            ParseError::Cancelled { .. } => Abandoned,
            _ => Refused(Refusal::SceneInvalid),
        },
        SceneBuild { source, .. } => match source {
            BuildError::OverBudget(_) => Refused(Refusal::SceneBudget),
            BuildError::Cancelled(_) => Abandoned,
            _ => Refused(Refusal::SceneInvalid),
        },
        SceneNotLoaded(_) => Refused(Refusal::SceneNotLoaded),
        QueueFull { .. } => Refused(Refusal::QueueFull),
        Draining(_) => Refused(Refusal::Draining),
        UnitCancelled(_) => Abandoned,
        BlobCache(_) | UnitPanicked(_) | RenderThreadVanished | BlobTask(_) | BuildTask(_) => {
            Internal
        }
    }
}

/// The worker's counters since it started, and its connection gauges.
#[derive(Debug, Default)]
pub struct Metrics {
    units: AtomicU64,
    samples: AtomicU64,
    render_nanos: AtomicU64,
    result_bytes: AtomicU64,
    uploads: AtomicU64,
    upload_bytes: AtomicU64,
    blob_hits: AtomicU64,
    blob_misses: AtomicU64,
    scene_hits: AtomicU64,
    scene_misses: AtomicU64,
    connections_accepted: AtomicU64,
    connections_open: AtomicU64,
    connections_authenticated: AtomicU64,
    refusals: [AtomicU64; Refusal::ALL.len()],
    internal_errors: AtomicU64,
}

/// The counters the Stats RPC reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StatsCounters {
    pub units: u64,
    pub samples: u64,
    pub upload_bytes: u64,
    pub result_bytes: u64,
}

/// What the node's state holds when a scrape asks.
#[derive(Clone, Copy, Debug, Default)]
pub struct NodeGauges {
    pub threads: u32,
    /// Units on a render thread.
    pub busy_threads: u64,
    /// Units waiting for a render thread.
    pub queued_units: u64,
    pub memory_cache_bytes: u64,
    /// `None` without a cache folder.
    pub disk_cache_bytes: Option<u64>,
    pub blobs_cached: u64,
    pub scenes_cached: u64,
    /// Bytes unfinished uploads hold.
    pub upload_bytes_held: u64,
    pub draining: bool,
    pub uptime: Duration,
}

fn add(counter: &AtomicU64, n: u64) {
    counter.fetch_add(n, Ordering::Relaxed);
}

fn read(counter: &AtomicU64) -> u64 {
    counter.load(Ordering::Relaxed)
}

impl Metrics {
    /// A unit rendered and answered: its samples, its result's bytes, its render thread's time.
    pub fn unit_rendered(&self, samples: u64, result_bytes: u64, render_time: Duration) {
        add(&self.units, 1);
        add(&self.samples, samples);
        add(&self.result_bytes, result_bytes);
        let nanos = u64::try_from(render_time.as_nanos()).unwrap_or(u64::MAX);
        add(&self.render_nanos, nanos);
    }

    /// A blob received whole, verified and stored.
    pub fn blob_stored(&self, bytes: u64) {
        add(&self.uploads, 1);
        add(&self.upload_bytes, bytes);
    }

    /// A coordinator asked which blobs the worker holds: `held` it had, `missing` it must send.
    pub fn blobs_asked(&self, held: u64, missing: u64) {
        add(&self.blob_hits, held);
        add(&self.blob_misses, missing);
    }

    /// A scene loaded: built now (a miss) or found built (a hit).
    pub fn scene_loaded(&self, built: bool) {
        let counter = if built {
            &self.scene_misses
        } else {
            &self.scene_hits
        };
        add(counter, 1);
    }

    pub fn connection_accepted(&self) {
        add(&self.connections_accepted, 1);
    }

    /// A connection counted open until the guard drops.
    pub fn open_connection(self: &Arc<Self>) -> OpenConnection {
        add(&self.connections_open, 1);
        OpenConnection {
            metrics: self.clone(),
            authenticated: false,
        }
    }

    pub fn refused(&self, reason: Refusal) {
        add(&self.refusals[reason.index()], 1);
    }

    /// A request failed with `error`: counted as its refusal, or as an internal error.
    pub fn failed(&self, error: &NodeError) {
        match failure_of(error) {
            Failure::Refused(reason) => self.refused(reason),
            Failure::Internal => add(&self.internal_errors, 1),
            Failure::Abandoned => {}
        }
    }

    pub fn stats_counters(&self) -> StatsCounters {
        StatsCounters {
            units: read(&self.units),
            samples: read(&self.samples),
            upload_bytes: read(&self.upload_bytes),
            result_bytes: read(&self.result_bytes),
        }
    }

    /// The exposition of these counters and `node`'s gauges.
    pub fn render(&self, node: &NodeGauges) -> String {
        use MetricType::{Counter, Gauge};
        let mut out = Exposition::new();
        out.family(
            "yat_node_build_info",
            Gauge,
            "1, labelled with the yat version and the renderer build coordinators compare.",
            [(
                labels(&[
                    ("version", env!("CARGO_PKG_VERSION")),
                    ("renderer_build", yat_tracer::RENDERER_BUILD),
                ]),
                1,
            )],
        );
        out.single(
            "yat_node_uptime_seconds",
            Gauge,
            "Seconds since the worker started.",
            node.uptime.as_secs_f64(),
        );
        // Counters and gauges of one sample each: name, type, help, value.
        let figures = [
            (
                "yat_node_draining",
                Gauge,
                "1 once the worker drains (after SIGTERM): new work is refused.",
                u64::from(node.draining),
            ),
            (
                "yat_node_render_threads",
                Gauge,
                "Units the worker renders at once (--threads).",
                u64::from(node.threads),
            ),
            (
                "yat_node_render_threads_busy",
                Gauge,
                "Render threads working on a unit now.",
                node.busy_threads,
            ),
            (
                "yat_node_units_queued",
                Gauge,
                "Units waiting for a render thread.",
                node.queued_units,
            ),
            (
                "yat_node_units_total",
                Counter,
                "Work units rendered and answered.",
                read(&self.units),
            ),
            (
                "yat_node_samples_total",
                Counter,
                "Camera samples of the units rendered and answered.",
                read(&self.samples),
            ),
            (
                "yat_node_result_bytes_total",
                Counter,
                "Bytes of the units' results (sample sums and light splats) answered.",
                read(&self.result_bytes),
            ),
            (
                "yat_node_uploads_total",
                Counter,
                "Blobs (scene files) received whole, verified and stored.",
                read(&self.uploads),
            ),
            (
                "yat_node_upload_bytes_total",
                Counter,
                "Bytes of the blobs received whole, verified and stored.",
                read(&self.upload_bytes),
            ),
            (
                "yat_node_upload_bytes_held",
                Gauge,
                "Bytes unfinished uploads hold (at most --upload-budget-mib).",
                node.upload_bytes_held,
            ),
            (
                "yat_node_blobs_cached",
                Gauge,
                "Distinct blobs held in memory or in the cache folder.",
                node.blobs_cached,
            ),
            (
                "yat_node_blob_cache_hits_total",
                Counter,
                "Blobs a coordinator asked about that the worker held (nothing to upload).",
                read(&self.blob_hits),
            ),
            (
                "yat_node_blob_cache_misses_total",
                Counter,
                "Blobs a coordinator asked about that the worker did not hold (to upload).",
                read(&self.blob_misses),
            ),
            (
                "yat_node_scenes_cached",
                Gauge,
                "Scenes built and held.",
                node.scenes_cached,
            ),
            (
                "yat_node_scene_cache_hits_total",
                Counter,
                "Scene loads that found the scene built.",
                read(&self.scene_hits),
            ),
            (
                "yat_node_scene_cache_misses_total",
                Counter,
                "Scene loads that built the scene.",
                read(&self.scene_misses),
            ),
            (
                "yat_node_connections",
                Gauge,
                "Connections open (authenticated or not).",
                read(&self.connections_open),
            ),
            (
                "yat_node_connections_authenticated",
                Gauge,
                "Connections open on which a request passed the token check: coordinators.",
                read(&self.connections_authenticated),
            ),
            (
                "yat_node_connections_accepted_total",
                Counter,
                "Connections accepted, including those refused at once.",
                read(&self.connections_accepted),
            ),
        ];
        for (name, kind, help, value) in figures {
            out.single(name, kind, help, value);
        }
        let mut cache_bytes = vec![(labels(&[("tier", "memory")]), node.memory_cache_bytes)];
        if let Some(disk) = node.disk_cache_bytes {
            cache_bytes.push((labels(&[("tier", "disk")]), disk));
        }
        out.family(
            "yat_node_blob_cache_bytes",
            Gauge,
            "Bytes of blobs held, in memory and (with --cache-dir) in the cache folder.",
            cache_bytes,
        );
        out.single(
            "yat_node_render_seconds_total",
            Counter,
            "Render threads' seconds spent on the units answered.",
            read(&self.render_nanos) as f64 / 1e9,
        );
        out.family(
            "yat_node_refusals_total",
            Counter,
            "Connections and requests refused, by reason (docs/status.md lists them).",
            Refusal::ALL.map(|reason| {
                (
                    labels(&[("reason", reason.name())]),
                    read(&self.refusals[reason.index()]),
                )
            }),
        );
        out.single(
            "yat_node_internal_errors_total",
            Counter,
            "Requests the worker failed itself (a unit that panicked, a cache folder error).",
            read(&self.internal_errors),
        );
        out.finish()
    }
}

/// An open connection, counted in `yat_node_connections` (and, once authenticated, in
/// `yat_node_connections_authenticated`) until it drops.
#[derive(Debug)]
pub struct OpenConnection {
    metrics: Arc<Metrics>,
    authenticated: bool,
}

impl OpenConnection {
    /// A request on it passed the token check; only the first call counts.
    pub fn authenticated(&mut self) {
        if !std::mem::replace(&mut self.authenticated, true) {
            add(&self.metrics.connections_authenticated, 1);
        }
    }
}

impl Drop for OpenConnection {
    fn drop(&mut self) {
        self.metrics
            .connections_open
            .fetch_sub(1, Ordering::Relaxed);
        if self.authenticated {
            self.metrics
                .connections_authenticated
                .fetch_sub(1, Ordering::Relaxed);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The value of the sample `series` (name and labels) in `text`.
    fn value(text: &str, series: &str) -> f64 {
        let prefix = format!("{series} ");
        let line = text
            .lines()
            .find(|l| l.starts_with(&prefix))
            .unwrap_or_else(|| panic!("no {series} in\n{text}"));
        line[prefix.len()..].parse().unwrap()
    }

    #[test]
    fn counters_after_events() {
        let metrics = Arc::new(Metrics::default());
        for _ in 0..3 {
            metrics.unit_rendered(64 * 64 * 8, 1000, Duration::from_millis(250));
        }
        metrics.blob_stored(100);
        metrics.blob_stored(23);
        metrics.blobs_asked(1, 2);
        metrics.blobs_asked(3, 0);
        metrics.scene_loaded(true);
        metrics.scene_loaded(false);
        metrics.scene_loaded(false);
        metrics.connection_accepted();
        metrics.connection_accepted();
        let mut coordinator = metrics.open_connection();
        coordinator.authenticated();
        coordinator.authenticated();
        let stranger = metrics.open_connection();
        let gauges = NodeGauges {
            threads: 4,
            busy_threads: 3,
            queued_units: 2,
            memory_cache_bytes: 4096,
            disk_cache_bytes: Some(8192),
            blobs_cached: 5,
            scenes_cached: 1,
            upload_bytes_held: 77,
            draining: true,
            uptime: Duration::from_secs(9),
        };
        let text = metrics.render(&gauges);
        for (series, expected) in [
            ("yat_node_units_total", 3.0),
            ("yat_node_samples_total", 3.0 * 64.0 * 64.0 * 8.0),
            ("yat_node_result_bytes_total", 3000.0),
            ("yat_node_render_seconds_total", 0.75),
            ("yat_node_uploads_total", 2.0),
            ("yat_node_upload_bytes_total", 123.0),
            ("yat_node_blob_cache_hits_total", 4.0),
            ("yat_node_blob_cache_misses_total", 2.0),
            ("yat_node_scene_cache_hits_total", 2.0),
            ("yat_node_scene_cache_misses_total", 1.0),
            ("yat_node_connections_accepted_total", 2.0),
            ("yat_node_connections", 2.0),
            ("yat_node_connections_authenticated", 1.0),
            ("yat_node_render_threads", 4.0),
            ("yat_node_render_threads_busy", 3.0),
            ("yat_node_units_queued", 2.0),
            ("yat_node_blob_cache_bytes{tier=\"memory\"}", 4096.0),
            ("yat_node_blob_cache_bytes{tier=\"disk\"}", 8192.0),
            ("yat_node_blobs_cached", 5.0),
            ("yat_node_scenes_cached", 1.0),
            ("yat_node_upload_bytes_held", 77.0),
            ("yat_node_draining", 1.0),
            ("yat_node_uptime_seconds", 9.0),
            ("yat_node_internal_errors_total", 0.0),
        ] {
            assert_eq!(value(&text, series), expected, "{series}");
        }
        assert!(text.contains("# TYPE yat_node_units_total counter\n"));
        assert!(text.contains("# TYPE yat_node_connections gauge\n"));
        assert!(text.contains(&format!(
            "yat_node_build_info{{version=\"{}\",renderer_build=\"{}\"}} 1\n",
            env!("CARGO_PKG_VERSION"),
            yat_tracer::RENDERER_BUILD
        )));
        // Connections closing take themselves off the gauges.
        drop(coordinator);
        drop(stranger);
        let text = metrics.render(&NodeGauges::default());
        assert_eq!(value(&text, "yat_node_connections"), 0.0);
        assert_eq!(value(&text, "yat_node_connections_authenticated"), 0.0);
        assert!(
            !text.contains("tier=\"disk\""),
            "no disk tier without a cache folder"
        );
        // Every line is a comment or `name{labels} value` with a number.
        for line in text.lines().filter(|l| !l.starts_with('#')) {
            let (series, number) = line.rsplit_once(' ').unwrap();
            assert!(series.starts_with("yat_node_"), "{line}");
            assert!(number.parse::<f64>().is_ok(), "{line}");
        }
    }

    #[test]
    fn refusals_are_counted_under_their_reason_and_every_reason_is_shown() {
        let metrics = Metrics::default();
        metrics.refused(Refusal::TokenWrong);
        metrics.refused(Refusal::TokenWrong);
        metrics.refused(Refusal::AddressFull);
        metrics.failed(&NodeError::QueueFull { max: 4 });
        metrics.failed(&NodeError::Draining("unit 3".into()));
        metrics.failed(&NodeError::BlobTooLarge {
            hash: "h".into(),
            size: 9,
            max: 1,
        });
        metrics.failed(&NodeError::ProtocolVersion {
            client: "c".into(),
            version: 1,
        });
        metrics.failed(&NodeError::SceneNotLoaded("s".into()));
        // The worker's own failures are not refusals; a unit nobody waits for is not counted.
        metrics.failed(&NodeError::UnitPanicked(1));
        metrics.failed(&NodeError::RenderThreadVanished);
        metrics.failed(&NodeError::UnitCancelled(2));
        let text = metrics.render(&NodeGauges::default());
        let refused = |reason: &str| {
            value(
                &text,
                &format!("yat_node_refusals_total{{reason=\"{reason}\"}}"),
            )
        };
        assert_eq!(refused("token_wrong"), 2.0);
        assert_eq!(refused("address_full"), 1.0);
        assert_eq!(refused("queue_full"), 1.0);
        assert_eq!(refused("draining"), 1.0);
        assert_eq!(refused("blob_too_large"), 1.0);
        assert_eq!(refused("protocol_version"), 1.0);
        assert_eq!(refused("scene_not_loaded"), 1.0);
        assert_eq!(refused("token_missing"), 0.0);
        assert_eq!(value(&text, "yat_node_internal_errors_total"), 2.0);
        let shown = text
            .lines()
            .filter(|l| l.starts_with("yat_node_refusals_total{"))
            .count();
        assert_eq!(shown, Refusal::ALL.len(), "every reason, zeros included");
        let total: f64 = Refusal::ALL.iter().map(|r| refused(r.name())).sum();
        assert_eq!(total, 8.0);
    }

    #[test]
    fn reasons_are_listed_once_in_order_with_distinct_names() {
        for (i, reason) in Refusal::ALL.iter().enumerate() {
            assert_eq!(reason.index(), i, "{reason:?}");
            assert!(reason
                .name()
                .chars()
                .all(|c| c.is_ascii_lowercase() || c == '_'));
        }
        let names: std::collections::BTreeSet<_> = Refusal::ALL.iter().map(|r| r.name()).collect();
        assert_eq!(names.len(), Refusal::ALL.len());
    }

    #[test]
    fn scene_errors_over_the_budget_are_told_apart() {
        use yat_tracer::budget::{Cancelled, Limit, OverBudget};
        let over = OverBudget {
            limit: Limit::Primitives,
            reached: 4,
            max: 3,
        };
        let built = |source| NodeError::SceneBuild {
            path: "a.lxs".into(),
            source,
        };
        assert_eq!(
            failure_of(&built(BuildError::OverBudget(over.clone()))),
            Failure::Refused(Refusal::SceneBudget)
        );
        assert_eq!(
            failure_of(&built(BuildError::Cancelled(Cancelled))),
            Failure::Abandoned
        );
        let parsed = |source| NodeError::SceneParse {
            path: "a.lxs".into(),
            source: Box::new(source),
        };
        let pos = yat_tracer::diag::SourcePos::new("a.lxs", 1, 1);
        assert_eq!(
            failure_of(&parsed(ParseError::OverBudget {
                pos: pos.clone(),
                exceeded: over,
            })),
            Failure::Refused(Refusal::SceneBudget)
        );
        assert_eq!(
            failure_of(&parsed(ParseError::Syntax {
                pos,
                message: "x".into(),
            })),
            Failure::Refused(Refusal::SceneInvalid)
        );
    }
}
