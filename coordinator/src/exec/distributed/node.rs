//! One worker as the coordinator sees it: a loop that connects (again and again, with backoff),
//! shakes hands, uploads what the worker lacks, loads the scene, and then pulls units from the
//! shared schedule with a bounded number in flight. Whatever goes wrong, the units it held go
//! back to the queue.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use prost::Message;
use tokio::sync::mpsc::UnboundedSender;
use tokio::task::JoinSet;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::{Channel, ClientTlsConfig, Endpoint};
use tonic::{Code, Request, Status};
use yat_proto::auth::AttachToken;
use yat_proto::convert::decode_pixels;
use yat_proto::{
    pb, RenderNodeClient, BLOB_CHUNK_BYTES, DEFAULT_MAX_MESSAGE_BYTES, PROTOCOL_VERSION,
};
use yat_tracer::film::SampleBuffer;
use yat_tracer::render::{UnitStats, WorkUnit};

use super::local::LocalWorker;
use super::schedule::{Schedule, UnitDeadline};
use crate::manifest::SceneManifest;

const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);
/// Deadline of the small calls (handshake, blob queries, stats).
const CALL_TIMEOUT: Duration = Duration::from_secs(10);
/// Deadline of a scene load: parsing and building a big mesh's BVH takes a while.
const LOAD_TIMEOUT: Duration = Duration::from_secs(600);
/// Upload deadline: a base plus this much time per MiB (a slow 1 MiB/s link still makes it).
const UPLOAD_TIMEOUT_BASE: Duration = Duration::from_secs(30);
const UPLOAD_TIMEOUT_PER_MIB: Duration = Duration::from_secs(1);
const MIN_BACKOFF: Duration = Duration::from_millis(250);
const MAX_BACKOFF: Duration = Duration::from_secs(5);
/// Units in flight per worker thread: one rendering, one queued behind it, so a worker never
/// idles for a round trip.
const UNITS_IN_FLIGHT_PER_THREAD: u32 = 2;

type Client = RenderNodeClient<InterceptedService<Channel, AttachToken>>;

/// How to reach one worker.
pub struct NodeConfig {
    pub address: String,
    pub token: Option<String>,
    pub tls: Option<ClientTlsConfig>,
    /// The process, for a worker this coordinator started.
    pub local: Option<Arc<LocalWorker>>,
}

impl NodeConfig {
    fn endpoint(&self) -> anyhow::Result<Endpoint> {
        let scheme = if self.tls.is_some() { "https" } else { "http" };
        let mut endpoint = Endpoint::from_shared(format!("{scheme}://{}", self.address))
            .map_err(|e| anyhow::anyhow!("bad worker address {:?}: {e}", self.address))?
            .connect_timeout(CONNECT_TIMEOUT)
            .tcp_nodelay(true)
            .http2_keep_alive_interval(Duration::from_secs(10))
            .keep_alive_timeout(Duration::from_secs(20))
            .keep_alive_while_idle(true);
        if let Some(tls) = &self.tls {
            endpoint = endpoint.tls_config(tls.clone())?;
        }
        Ok(endpoint)
    }

    /// Checks the address and token before anything starts.
    pub fn validate(&self) -> anyhow::Result<()> {
        self.endpoint()?;
        AttachToken::new(self.token.as_deref())?;
        Ok(())
    }
}

/// What a worker did in this render (the final summary and `--workers-json`).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct NodeReport {
    pub address: String,
    pub hostname: String,
    pub threads: u32,
    /// Units whose results were merged.
    pub units: u64,
    pub samples: u64,
    /// Sessions lost (connection errors, deadlines, bad replies) and units given back.
    pub failures: u64,
    pub units_requeued: u64,
    /// Scene-file bytes uploaded.
    pub blob_bytes_sent: u64,
    /// Every request's encoded bytes, blobs included.
    pub bytes_sent: u64,
    /// Every reply's encoded bytes.
    pub bytes_received: u64,
    /// Sample-buffer bytes and the pixels they cover, for bytes per pixel.
    pub result_bytes: u64,
    pub result_pixels: u64,
    #[serde(skip)]
    pub connected: bool,
    /// Why this worker will not be used again, if so.
    pub gone: Option<String>,
    pub last_error: Option<String>,
}

pub struct Node {
    pub config: NodeConfig,
    pub report: Mutex<NodeReport>,
}

impl Node {
    pub fn new(config: NodeConfig) -> Self {
        let report = NodeReport {
            address: config.address.clone(),
            ..NodeReport::default()
        };
        Self {
            config,
            report: Mutex::new(report),
        }
    }

    fn update(&self, f: impl FnOnce(&mut NodeReport)) {
        f(&mut self.report.lock().unwrap());
    }
}

/// What node loops tell the render loop.
pub enum Event {
    /// A unit's result, the first one for that unit.
    Result {
        buffer: SampleBuffer,
        stats: UnitStats,
    },
    /// A message for the terminal.
    Notice(String),
    /// The render cannot succeed (e.g. the scene does not build).
    Fatal(anyhow::Error),
}

/// What every node loop shares.
pub struct Shared {
    pub schedule: Schedule,
    pub deadline: UnitDeadline,
    pub manifest: SceneManifest,
    pub load_request: pb::LoadSceneRequest,
    pub events: UnboundedSender<Event>,
}

impl Shared {
    fn notice(&self, message: String) {
        let _ = self.events.send(Event::Notice(message));
    }
}

/// How a session with a worker ended badly.
enum SessionError {
    /// Worth trying again later (connection lost, deadline, worker restarted).
    Transient(String),
    /// This worker cannot serve this render (token, protocol version, limits).
    Permanent(String),
    /// Nobody can serve this render.
    Fatal(anyhow::Error),
}

fn transient(what: &str, status: Status) -> SessionError {
    match status.code() {
        Code::Unauthenticated => SessionError::Permanent(format!(
            "authentication failed (unauthenticated): {}",
            status.message()
        )),
        _ => SessionError::Transient(format!("{what}: {}", describe_status(&status))),
    }
}

fn describe_status(status: &Status) -> String {
    let text = format!("{:?}: {}", status.code(), status.message());
    match std::error::Error::source(status) {
        Some(cause) => format!("{text}: {}", error_chain(cause)),
        None => text,
    }
}

/// The worker's reply to the handshake, checked: the same protocol version as ours.
pub fn check_handshake(address: &str, reply: &pb::HandshakeReply) -> Result<(), String> {
    if reply.protocol_version != PROTOCOL_VERSION {
        return Err(format!(
            "worker {address} ({}) speaks protocol version {}, this coordinator version {}",
            reply.software, reply.protocol_version, PROTOCOL_VERSION
        ));
    }
    if reply.threads == 0 {
        return Err(format!("worker {address} reports 0 threads"));
    }
    Ok(())
}

async fn with_deadline<T>(
    deadline: Duration,
    call: impl std::future::Future<Output = Result<tonic::Response<T>, Status>>,
) -> Result<T, Status> {
    match tokio::time::timeout(deadline, call).await {
        Ok(reply) => reply.map(tonic::Response::into_inner),
        Err(_) => Err(Status::deadline_exceeded(format!(
            "no answer within {:.1} s",
            deadline.as_secs_f64()
        ))),
    }
}

fn request<T>(message: T, deadline: Duration) -> Request<T> {
    let mut request = Request::new(message);
    request.set_timeout(deadline);
    request
}

/// Serves the render with one worker until the schedule is finished or the worker is gone for
/// good.
pub async fn run_node(node: Arc<Node>, shared: Arc<Shared>) {
    let mut backoff = MIN_BACKOFF;
    let mut finished = shared.schedule.watch();
    while !shared.schedule.is_finished() {
        if let Some(status) = node.config.local.as_ref().and_then(|l| l.exit_status()) {
            let reason = format!("the local worker exited ({status})");
            shared.notice(format!("worker {}: {reason}", node.config.address));
            node.update(|r| r.gone = Some(reason));
            return;
        }
        let outcome = session(&node, &shared).await;
        let was_rendering = std::mem::take(&mut node.report.lock().unwrap().connected);
        match outcome {
            Ok(()) => return,
            Err(SessionError::Fatal(e)) => {
                let _ = shared.events.send(Event::Fatal(e));
                return;
            }
            Err(SessionError::Permanent(reason)) => {
                shared.notice(format!("worker {} refused: {reason}", node.config.address));
                node.update(|r| r.gone = Some(reason));
                return;
            }
            Err(SessionError::Transient(error)) => {
                if was_rendering {
                    shared.notice(format!(
                        "worker {} lost ({error}); its units go back to the queue",
                        node.config.address
                    ));
                    backoff = MIN_BACKOFF;
                }
                node.update(|r| r.last_error = Some(error));
            }
        }
        tokio::select! {
            _ = tokio::time::sleep(backoff) => {}
            _ = finished.changed() => {}
        }
        backoff = (backoff * 2).min(MAX_BACKOFF);
    }
}

async fn session(node: &Node, shared: &Shared) -> Result<(), SessionError> {
    let address = &node.config.address;
    let channel = node
        .config
        .endpoint()
        .map_err(|e| SessionError::Permanent(format!("{e:#}")))?
        .connect()
        .await
        .map_err(|e| SessionError::Transient(format!("cannot connect: {}", error_chain(&e))))?;
    let token = AttachToken::new(node.config.token.as_deref())
        .map_err(|e| SessionError::Permanent(e.to_string()))?;
    let mut client = RenderNodeClient::with_interceptor(channel, token)
        .max_decoding_message_size(DEFAULT_MAX_MESSAGE_BYTES)
        .max_encoding_message_size(DEFAULT_MAX_MESSAGE_BYTES);

    let hello = pb::HandshakeRequest {
        protocol_version: PROTOCOL_VERSION,
        client: format!(
            "yat {} on {}",
            env!("CARGO_PKG_VERSION"),
            gethostname::gethostname().to_string_lossy()
        ),
    };
    let reply = with_deadline(CALL_TIMEOUT, client.handshake(request(hello, CALL_TIMEOUT)))
        .await
        .map_err(|status| match status.code() {
            Code::FailedPrecondition => SessionError::Permanent(status.message().to_string()),
            _ => transient("handshake", status),
        })?;
    check_handshake(address, &reply).map_err(SessionError::Permanent)?;
    node.update(|r| {
        r.hostname = reply.hostname.clone();
        r.threads = reply.threads;
    });

    upload_missing_blobs(&mut client, node, shared, &reply).await?;
    let load = shared.load_request.clone();
    let sent = load.encoded_len() as u64;
    let loaded = with_deadline(LOAD_TIMEOUT, client.load_scene(request(load, LOAD_TIMEOUT)))
        .await
        .map_err(|status| match status.code() {
            Code::InvalidArgument => SessionError::Fatal(anyhow::anyhow!(
                "worker {address} cannot load the scene: {}",
                status.message()
            )),
            _ => transient("scene load", status),
        })?;
    node.update(|r| {
        r.bytes_sent += sent;
        r.bytes_received += loaded.encoded_len() as u64;
        r.connected = true;
    });
    shared.notice(format!(
        "worker {address} ({}, {} threads) ready{}",
        reply.hostname,
        reply.threads,
        if loaded.build_seconds > 0.0 {
            format!(", scene built in {:.2} s", loaded.build_seconds)
        } else {
            String::new()
        }
    ));
    let in_flight = reply.threads.saturating_mul(UNITS_IN_FLIGHT_PER_THREAD);
    render_units(client, node, shared, &loaded.scene_id, in_flight as usize).await
}

/// Asks which blobs the worker lacks and streams those in chunks.
async fn upload_missing_blobs(
    client: &mut Client,
    node: &Node,
    shared: &Shared,
    worker: &pb::HandshakeReply,
) -> Result<(), SessionError> {
    let blobs = &shared.manifest.blobs;
    let query = pb::HasBlobsRequest {
        sha256: blobs.keys().cloned().collect(),
    };
    node.update(|r| r.bytes_sent += query.encoded_len() as u64);
    let missing = with_deadline(CALL_TIMEOUT, client.has_blobs(request(query, CALL_TIMEOUT)))
        .await
        .map_err(|s| transient("blob query", s))?
        .missing;
    let chunk_bytes = BLOB_CHUNK_BYTES
        .min(worker.max_message_bytes as usize / 2)
        .max(1);
    for hash in missing {
        let bytes = blobs.get(&hash).ok_or_else(|| {
            SessionError::Transient(format!(
                "the worker asked for blob {hash}, which is not ours"
            ))
        })?;
        if bytes.len() as u64 > worker.max_blob_bytes {
            return Err(SessionError::Permanent(format!(
                "a scene file of {} bytes exceeds the worker's limit of {} (--max-blob-mib)",
                bytes.len(),
                worker.max_blob_bytes
            )));
        }
        let chunks: Vec<pb::BlobChunk> = (0..bytes.len().div_ceil(chunk_bytes).max(1))
            .map(|i| {
                let range = i * chunk_bytes..((i + 1) * chunk_bytes).min(bytes.len());
                pb::BlobChunk {
                    sha256: if i == 0 { hash.clone() } else { String::new() },
                    size: if i == 0 { bytes.len() as u64 } else { 0 },
                    data: bytes.slice(range),
                }
            })
            .collect();
        let sent: u64 = chunks.iter().map(|c| c.encoded_len() as u64).sum();
        let deadline = UPLOAD_TIMEOUT_BASE
            + UPLOAD_TIMEOUT_PER_MIB * (bytes.len() >> 20).try_into().unwrap_or(u32::MAX);
        with_deadline(
            deadline,
            client.put_blob(request(tokio_stream::iter(chunks), deadline)),
        )
        .await
        .map_err(|status| match status.code() {
            Code::ResourceExhausted => SessionError::Permanent(status.message().to_string()),
            _ => transient("upload", status),
        })?;
        node.update(|r| {
            r.bytes_sent += sent;
            r.blob_bytes_sent += bytes.len() as u64;
        });
    }
    Ok(())
}

/// Units this session holds; whatever is still held when it ends goes back to the queue.
struct HeldUnits<'a> {
    schedule: &'a Schedule,
    units: HashMap<u32, WorkUnit>,
    node: &'a Node,
}

impl Drop for HeldUnits<'_> {
    fn drop(&mut self) {
        let requeued = self.units.len() as u64;
        for unit in self.units.values() {
            self.schedule.requeue(unit);
        }
        if requeued > 0 {
            self.node.update(|r| r.units_requeued += requeued);
        }
    }
}

type UnitOutcome = (WorkUnit, Result<(pb::RenderUnitReply, Duration), Status>);

async fn render_one(
    mut client: Client,
    message: pb::RenderUnitRequest,
    unit: WorkUnit,
    deadline: Duration,
) -> UnitOutcome {
    let started = Instant::now();
    let reply = with_deadline(deadline, client.render_unit(request(message, deadline))).await;
    (unit, reply.map(|r| (r, started.elapsed())))
}

/// Pulls units while fewer than `limit` are in flight, until the render is finished.
async fn render_units(
    client: Client,
    node: &Node,
    shared: &Shared,
    scene_id: &str,
    limit: usize,
) -> Result<(), SessionError> {
    let schedule = &shared.schedule;
    let mut changed = schedule.watch();
    let mut held = HeldUnits {
        schedule,
        units: HashMap::new(),
        node,
    };
    // Dropped (aborting the calls) before `held` gives their units back.
    let mut calls = JoinSet::new();
    loop {
        if schedule.is_finished() {
            return Ok(());
        }
        while calls.len() < limit {
            let Some(unit) = schedule.take() else { break };
            held.units.insert(unit.index, unit);
            let request = pb::RenderUnitRequest {
                scene_id: scene_id.to_string(),
                unit: Some((&unit).into()),
            };
            node.update(|r| r.bytes_sent += request.encoded_len() as u64);
            calls.spawn(render_one(
                client.clone(),
                request,
                unit,
                shared.deadline.current(),
            ));
        }
        if calls.is_empty() {
            // Nothing to take: wait for a requeued unit or the end.
            let _ = changed.changed().await;
            continue;
        }
        tokio::select! {
            joined = calls.join_next() => {
                let (unit, outcome) = joined
                    .expect("calls is not empty")
                    .map_err(|e| SessionError::Transient(format!("unit task: {e}")))?;
                held.units.remove(&unit.index);
                let outcome = outcome.map_err(|status| {
                    held.units.insert(unit.index, unit);
                    node.update(|r| r.failures += 1);
                    transient(&format!("unit {}", unit.index), status)
                })?;
                accept(node, shared, unit, outcome).inspect_err(|_| {
                    held.units.insert(unit.index, unit);
                    node.update(|r| r.failures += 1);
                })?;
            }
            _ = changed.changed() => {}
        }
    }
}

/// Checks a reply and hands its buffer to the render loop if it is the unit's first result.
fn accept(
    node: &Node,
    shared: &Shared,
    unit: WorkUnit,
    (reply, took): (pb::RenderUnitReply, Duration),
) -> Result<(), SessionError> {
    let received = reply.encoded_len() as u64;
    if reply.index != unit.index {
        return Err(SessionError::Transient(format!(
            "asked for unit {}, got unit {}",
            unit.index, reply.index
        )));
    }
    let buffer =
        decode_pixels(unit, &reply.pixels).map_err(|e| SessionError::Transient(e.to_string()))?;
    shared.deadline.observe(took);
    let stats = UnitStats::from(reply.stats.unwrap_or_default());
    let first = shared.schedule.complete(&unit);
    node.update(|r| {
        r.bytes_received += received;
        if first {
            r.units += 1;
            r.samples += stats.samples;
            r.result_bytes += reply.pixels.len() as u64;
            r.result_pixels += unit.pixel_count() as u64;
        }
    });
    if first {
        let _ = shared.events.send(Event::Result { buffer, stats });
    }
    Ok(())
}

/// An error and its causes on one line (tonic's transport errors hide the useful part in
/// their sources).
pub fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        let cause_text = cause.to_string();
        // Layers often repeat their cause's words ("transport error: transport error").
        if !text.ends_with(&cause_text) {
            text.push_str(": ");
            text.push_str(&cause_text);
        }
        source = cause.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn another_protocol_version_is_refused_naming_both() {
        let mut reply = pb::HandshakeReply {
            protocol_version: PROTOCOL_VERSION,
            threads: 2,
            software: "yat 9.9".into(),
            ..Default::default()
        };
        assert!(check_handshake("h:1", &reply).is_ok());
        reply.protocol_version = PROTOCOL_VERSION + 1;
        let message = check_handshake("h:1", &reply).unwrap_err();
        assert!(message.contains(&format!("version {}", PROTOCOL_VERSION + 1)));
        assert!(message.contains(&format!("version {PROTOCOL_VERSION}")));
    }

    #[test]
    fn an_authentication_failure_is_permanent_and_says_so() {
        let refused = transient("handshake", Status::unauthenticated("wrong token"));
        assert!(matches!(refused, SessionError::Permanent(m) if m.contains("authentication")));
        let lost = transient("unit 3", Status::unavailable("connection reset"));
        assert!(matches!(lost, SessionError::Transient(m) if m.contains("unit 3")));
    }
}
