//! The steps of a render on one worker: a loop that connects (again and again, with backoff),
//! shakes hands, uploads what the worker lacks, loads the scene, and then pulls units from the
//! shared schedule with a bounded number in flight. Whatever goes wrong, the units it held go
//! back to the queue. A worker asked to leave (its address gone from DNS: a pod deleted, a node
//! scaled away) takes no more units and finishes the ones it holds, which its drain allows.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;
use std::time::{Duration, Instant};

use prost::bytes::Bytes;
use prost::Message;
use tokio::sync::watch;
use tokio::task::JoinSet;
use yat_proto::convert::{result_from_wire, BYTES_PER_LAYER_SUM, BYTES_PER_PIXEL, BYTES_PER_SPLAT};
use yat_proto::{pb, PROTOCOL_VERSION};
use yat_tracer::film::MAX_SPLAT_PIXELS;
use yat_tracer::filter::MAX_BORDER;
use yat_tracer::render::layers::MAX_LAYER_SUMS;
use yat_tracer::render::unit::{FilmFrame, MAX_MASKED_SIDE};
use yat_tracer::render::{WorkUnit, TILE_SIZE};

use super::client::{WorkerClient, MIN_CHUNK_BYTES};
use super::node::Node;
use super::schedule::Schedule;
use super::session_context::{SessionContext, SessionEvent};
use super::session_error::SessionError;
use crate::sanitize::peer_text;

const MIN_BACKOFF: Duration = Duration::from_millis(250);
const MAX_BACKOFF: Duration = Duration::from_secs(5);
/// Units in flight per worker thread: one rendering, one queued behind it, so a worker never
/// idles for a round trip.
const UNITS_IN_FLIGHT_PER_THREAD: u32 = 2;
/// Units a session sends before the worker has returned one: one per thread it claims, at most
/// this many; each accepted result allows `UNITS_IN_FLIGHT_PER_THREAD` more, up to what its
/// threads take. A worker that claims many threads and never answers holds only these (and
/// the end game hands copies of them to the others), while an honest one has every thread busy
/// from its first unit on.
pub const MAX_UNITS_BEFORE_A_RESULT: usize = 64;
/// The most threads a worker's claim is believed (2048 units in flight).
pub const MAX_WORKER_THREADS: u32 = 1024;
/// Bad replies in a row (across sessions, until a result is accepted) after which a worker is
/// retired for this render.
pub const MAX_BAD_REPLIES_IN_A_ROW: u32 = 3;
/// Longest host or software name accepted from a worker: a longer one is a hostile worker's.
const MAX_NAME_BYTES: usize = 1024;
/// Characters of a worker's host or software name shown.
const MAX_NAME_CHARS: usize = 64;
/// Longest scene id accepted: it goes back with every unit (honest ones are 64 hex digits).
const MAX_SCENE_ID_BYTES: usize = 256;
/// Bytes of a unit's reply besides its pixels: index, counters, seconds, framing.
const REPLY_OVERHEAD_BYTES: u64 = 1024;

/// The smallest message limit a worker may advertise: two of the smallest blob chunk, and the
/// reply to the largest unit of any plan: a uniform unit's sums and the most layers' over its
/// tile and the widest filter's border with the most light splats a unit reports (4 MiB), or
/// an adaptive unit's (which has none) sums and layers per source plane and its half sums over
/// its (smaller) tile and that border.
pub fn min_message_bytes() -> u64 {
    let region = |tile: u32| u64::from(tile + 2 * MAX_BORDER).pow(2);
    let sums = BYTES_PER_PIXEL as u64;
    let layers = (MAX_LAYER_SUMS * BYTES_PER_LAYER_SUM) as u64;
    let splats = (MAX_SPLAT_PIXELS * BYTES_PER_SPLAT) as u64;
    let widest = FilmFrame {
        border: [MAX_BORDER; 2],
        ..FilmFrame::unbordered(u32::MAX, u32::MAX)
    };
    let planes = widest.source_planes() as u64;
    let adaptive = ((planes + 1) * sums + planes * layers) * region(MAX_MASKED_SIDE);
    let unit_reply = ((sums + layers) * region(TILE_SIZE) + splats).max(adaptive);
    (2 * MIN_CHUNK_BYTES as u64).max(unit_reply + REPLY_OVERHEAD_BYTES)
}

/// A worker as its handshake describes it, checked, clamped and safe to print.
#[derive(Debug)]
pub struct WorkerInfo {
    pub hostname: String,
    pub software: String,
    /// The threads it claims, at most [`MAX_WORKER_THREADS`].
    pub threads: u32,
    pub claimed_threads: u32,
    pub max_message_bytes: u64,
    pub max_blob_bytes: u64,
}

/// The worker's reply to the handshake, checked: the same protocol version and renderer build
/// as ours, at least one thread, names of a sane length, a message limit that fits a unit's
/// reply.
pub fn check_handshake(address: &str, reply: &pb::HandshakeReply) -> Result<WorkerInfo, String> {
    let longest = [&reply.hostname, &reply.software, &reply.renderer_build]
        .iter()
        .map(|name| name.len())
        .max()
        .unwrap_or(0);
    if longest > MAX_NAME_BYTES {
        return Err(format!(
            "worker {address} sends a host, software or build name of {longest} bytes (at most {MAX_NAME_BYTES})"
        ));
    }
    let software = peer_text(&reply.software, MAX_NAME_CHARS);
    if reply.protocol_version != PROTOCOL_VERSION {
        return Err(format!(
            "worker {address} ({software}) speaks protocol version {}, this coordinator version {}",
            reply.protocol_version, PROTOCOL_VERSION
        ));
    }
    if reply.renderer_build != yat_tracer::RENDERER_BUILD {
        // Another build may compute other bits: its units would break the promise that the
        // image is the same bytes however it is rendered.
        let theirs = match reply.renderer_build.as_str() {
            "" => "an unnamed renderer build (an older yat)".to_string(),
            build => format!("renderer build {}", peer_text(build, MAX_NAME_CHARS)),
        };
        return Err(format!(
            "worker {address} ({software}) runs {theirs}, this coordinator renderer build {}: \
             run the same yat on every machine of a render",
            yat_tracer::RENDERER_BUILD
        ));
    }
    if reply.threads == 0 {
        return Err(format!("worker {address} reports 0 threads"));
    }
    if reply.max_message_bytes < min_message_bytes() {
        return Err(format!(
            "worker {address} accepts messages of {} bytes, {} needed",
            reply.max_message_bytes,
            min_message_bytes()
        ));
    }
    Ok(WorkerInfo {
        hostname: peer_text(&reply.hostname, MAX_NAME_CHARS),
        software,
        threads: reply.threads.min(MAX_WORKER_THREADS),
        claimed_threads: reply.threads,
        max_message_bytes: reply.max_message_bytes,
        max_blob_bytes: reply.max_blob_bytes,
    })
}

/// Serves the render with one worker until the schedule is finished, the worker is gone for
/// good, or `leave` turns true (then the units in flight are finished first). The backoff
/// between sessions and the count of bad replies are reset only by an accepted result, so a
/// worker that fails fast is not retried fast, and one that never does better is retired.
pub async fn run_node(
    node: Arc<Node>,
    context: Arc<SessionContext>,
    mut leave: watch::Receiver<bool>,
) {
    let mut backoff = MIN_BACKOFF;
    let mut bad_in_a_row = 0;
    let mut changed = context.schedule.watch();
    while !context.schedule.is_finished() && !*leave.borrow() {
        if let Some(status) = node.local.as_ref().and_then(|l| l.exit_status()) {
            retire(
                &node,
                &context,
                format!("the local worker exited ({status})"),
            );
            return;
        }
        let mut accepted = 0;
        let outcome = session(&node, &context, &mut accepted, &mut leave).await;
        let was_rendering = std::mem::take(&mut node.report.lock().unwrap().connected);
        if accepted > 0 {
            backoff = MIN_BACKOFF;
            bad_in_a_row = 0;
        }
        match outcome {
            Ok(()) => {
                node.update(|r| r.finished = true);
                return;
            }
            Err(SessionError::Permanent(reason)) => {
                retire(&node, &context, reason);
                return;
            }
            Err(SessionError::Draining(what)) => {
                context.notice(format!(
                    "worker {} draining ({what}); its units go back to the queue",
                    node.address()
                ));
                node.update(|r| r.last_error = Some(format!("draining ({what})")));
            }
            Err(SessionError::BadReply(error)) => {
                bad_in_a_row += 1;
                node.update(|r| {
                    r.failures += 1;
                    r.last_error = Some(error.clone());
                });
                if bad_in_a_row >= MAX_BAD_REPLIES_IN_A_ROW {
                    let reason = format!(
                        "retired after {bad_in_a_row} bad replies in a row, the last: {error}"
                    );
                    retire(&node, &context, reason);
                    return;
                }
                context.notice(format!(
                    "worker {} answered badly ({error}); its units go back to the queue",
                    node.address()
                ));
            }
            Err(SessionError::Transient(error)) => {
                if was_rendering {
                    context.notice(format!(
                        "worker {} lost ({error}); its units go back to the queue",
                        node.address()
                    ));
                    node.update(|r| r.failures += 1);
                }
                node.update(|r| r.last_error = Some(error));
            }
        }
        tokio::select! {
            _ = tokio::time::sleep(backoff) => {}
            // Only the end cuts the wait short: a requeue (this worker's own units going back
            // included) must not, or a worker failing fast would be retried at once.
            _ = changed.wait_for(|_| context.schedule.is_finished()) => {}
            // Asked to leave (or the roster is gone): nothing is held between sessions.
            _ = leave.wait_for(|&leaving| leaving) => return,
        }
        backoff = (backoff * 2).min(MAX_BACKOFF);
    }
}

/// This worker will not be used again in this render, for `reason`.
fn retire(node: &Node, context: &SessionContext, reason: String) {
    context.notice(format!("worker {} refused: {reason}", node.address()));
    node.update(|r| r.gone = Some(reason));
}

/// One session; `accepted` counts the results it accepted.
async fn session(
    node: &Node,
    context: &SessionContext,
    accepted: &mut usize,
    leave: &mut watch::Receiver<bool>,
) -> Result<(), SessionError> {
    let address = node.address();
    let mut client = WorkerClient::connect(&node.config).await?;

    let hello = pb::HandshakeRequest {
        protocol_version: PROTOCOL_VERSION,
        client: format!(
            "yat {} on {}",
            env!("CARGO_PKG_VERSION"),
            gethostname::gethostname().to_string_lossy()
        ),
    };
    let reply = client.handshake(hello).await?;
    let worker = check_handshake(address, &reply).map_err(SessionError::Permanent)?;
    node.update(|r| {
        r.hostname = worker.hostname.clone();
        r.threads = worker.threads;
    });

    upload_missing_blobs(&mut client, node, context, &worker).await?;
    let load = context.load_request.clone();
    let sent = load.encoded_len() as u64;
    let loaded = client.load_scene(load).await?;
    if loaded.scene_id.is_empty() || loaded.scene_id.len() > MAX_SCENE_ID_BYTES {
        return Err(SessionError::Permanent(format!(
            "a scene id of {} bytes (1 to {MAX_SCENE_ID_BYTES} expected)",
            loaded.scene_id.len()
        )));
    }
    node.update(|r| {
        r.bytes_sent += sent;
        r.bytes_received += loaded.encoded_len() as u64;
        r.connected = true;
    });
    context.notice(format!(
        "worker {address} ({}, {}, {} threads{}) ready{}",
        worker.hostname,
        worker.software,
        worker.threads,
        if worker.claimed_threads > worker.threads {
            format!(" of {} claimed", worker.claimed_threads)
        } else {
            String::new()
        },
        if loaded.build_seconds > 0.0 {
            format!(", scene built in {:.2} s", loaded.build_seconds)
        } else {
            String::new()
        }
    ));
    let in_flight = (worker.threads * UNITS_IN_FLIGHT_PER_THREAD) as usize;
    let first_in_flight = (worker.threads as usize).min(MAX_UNITS_BEFORE_A_RESULT);
    let units = UnitLoop {
        node,
        context,
        scene_id: &loaded.scene_id,
        first_in_flight,
        max_in_flight: in_flight,
    };
    units.run(client, accepted, leave).await
}

/// Asks which blobs the worker lacks and uploads those.
async fn upload_missing_blobs(
    client: &mut WorkerClient,
    node: &Node,
    context: &SessionContext,
    worker: &WorkerInfo,
) -> Result<(), SessionError> {
    let blobs = &context.manifest.blobs;
    let query = pb::HasBlobsRequest {
        sha256: blobs.keys().cloned().collect(),
    };
    node.update(|r| r.bytes_sent += query.encoded_len() as u64);
    let missing = client.missing_blobs(query).await?;
    for (hash, bytes) in blobs_to_upload(blobs, &missing).map_err(SessionError::BadReply)? {
        if bytes.len() as u64 > worker.max_blob_bytes {
            return Err(SessionError::Permanent(format!(
                "a scene file of {} bytes exceeds the worker's limit of {} (--max-blob-mib)",
                bytes.len(),
                worker.max_blob_bytes
            )));
        }
        let sent = client
            .put_blob(hash, bytes, worker.max_message_bytes)
            .await?;
        node.update(|r| {
            r.bytes_sent += sent;
            r.blob_bytes_sent += bytes.len() as u64;
        });
    }
    Ok(())
}

/// The blobs of `blobs` a worker's reply lists as missing, each once (in the order first
/// listed): a session uploads each of the scene's files at most once, however often a reply
/// repeats it. A hash that is not one of ours makes the reply a bad one, said in the error.
fn blobs_to_upload<'a>(
    blobs: &'a HashMap<String, Bytes>,
    missing: &[String],
) -> Result<Vec<(&'a str, &'a Bytes)>, String> {
    let mut listed = HashSet::new();
    let mut upload = Vec::new();
    for hash in missing {
        let (hash, bytes) = blobs.get_key_value(hash).ok_or_else(|| {
            format!(
                "the worker asked for blob {}, which is not ours",
                peer_text(hash, MAX_NAME_CHARS)
            )
        })?;
        if listed.insert(hash) {
            upload.push((hash.as_str(), bytes));
        }
    }
    Ok(upload)
}

/// Units this session holds; whatever is still held when it ends goes back to the queue. Known
/// by the whole unit: an adaptive render's rounds reuse indices.
struct HeldUnits<'a> {
    schedule: &'a Schedule,
    units: HashSet<WorkUnit>,
    node: &'a Node,
}

impl Drop for HeldUnits<'_> {
    fn drop(&mut self) {
        let requeued = self.units.len() as u64;
        for unit in &self.units {
            self.schedule.requeue(unit);
        }
        if requeued > 0 {
            self.node.update(|r| r.units_requeued += requeued);
        }
    }
}

type UnitOutcome = (
    WorkUnit,
    Result<(pb::RenderUnitReply, Duration), SessionError>,
);

async fn render_one(
    mut client: WorkerClient,
    request: pb::RenderUnitRequest,
    unit: WorkUnit,
    deadline: Duration,
) -> UnitOutcome {
    let started = Instant::now();
    let reply = client.render_unit(request, deadline).await;
    (unit, reply.map(|r| (r, started.elapsed())))
}

/// A session's unit loop: the worker, the render, the scene id it loaded and the most units
/// it may hold.
struct UnitLoop<'a> {
    node: &'a Node,
    context: &'a SessionContext,
    scene_id: &'a str,
    first_in_flight: usize,
    max_in_flight: usize,
}

impl UnitLoop<'_> {
    /// Pulls units while fewer than allowed are in flight (`first_in_flight`, more with
    /// each accepted result, at most `max_in_flight`), until the render is finished, or until
    /// `leave` turns true or the worker starts draining, and the units in flight are in;
    /// `accepted` counts the results accepted.
    async fn run(
        self,
        client: WorkerClient,
        accepted: &mut usize,
        leave: &mut watch::Receiver<bool>,
    ) -> Result<(), SessionError> {
        let UnitLoop {
            node,
            context,
            scene_id,
            first_in_flight,
            max_in_flight,
        } = self;
        let schedule = &context.schedule;
        let mut changed = schedule.watch();
        let mut held = HeldUnits {
            schedule,
            units: HashSet::new(),
            node,
        };
        // Dropped (aborting the calls) before `held` gives their units back.
        let mut calls = JoinSet::new();
        // Set by the first call a draining worker refused: the units it is still rendering
        // come back as results, so the session takes no more and ends when they are in.
        let mut draining: Option<String> = None;
        loop {
            if schedule.is_finished() {
                return Ok(());
            }
            // A roster that dropped its sender will never say: as good as asked to leave.
            let leaving = *leave.borrow() || leave.has_changed().is_err() || draining.is_some();
            let limit = max_in_flight.min(
                first_in_flight.saturating_add(UNITS_IN_FLIGHT_PER_THREAD as usize * *accepted),
            );
            while !leaving && calls.len() < schedule.in_flight_limit(limit) {
                let Some(unit) = schedule.take(node.address()) else {
                    break;
                };
                held.units.insert(unit);
                let request = pb::RenderUnitRequest {
                    scene_id: scene_id.to_string(),
                    unit: Some((&unit).into()),
                };
                node.update(|r| r.bytes_sent += request.encoded_len() as u64);
                calls.spawn(render_one(
                    client.clone(),
                    request,
                    unit,
                    context.deadline.current(),
                ));
            }
            if calls.is_empty() {
                if let Some(what) = draining {
                    return Err(SessionError::Draining(what));
                }
                if leaving {
                    return Ok(());
                }
                // Nothing to take: wait for a requeued unit, the end, or the request to leave.
                tokio::select! {
                    _ = changed.changed() => {}
                    _ = leave.changed() => {}
                }
                continue;
            }
            tokio::select! {
                joined = calls.join_next() => {
                    let (unit, outcome) = joined
                        .expect("calls is not empty")
                        .map_err(|e| SessionError::Transient(format!("unit task: {e}")))?;
                    let outcome = match outcome {
                        // Refused without being worked on: back to the queue at once.
                        Err(SessionError::Draining(what)) => {
                            held.units.remove(&unit);
                            schedule.requeue(&unit);
                            node.update(|r| r.units_requeued += 1);
                            draining.get_or_insert(what);
                            continue;
                        }
                        outcome => outcome?,
                    };
                    // Kept in `held` until accepted: an error returns it to the queue.
                    accept(node, context, unit, outcome)?;
                    held.units.remove(&unit);
                    *accepted += 1;
                }
                _ = changed.changed() => {}
                _ = leave.changed(), if !leaving => {}
            }
        }
    }
}

/// Checks a reply and hands its buffer to the render loop if it is the unit's first result.
fn accept(
    node: &Node,
    context: &SessionContext,
    unit: WorkUnit,
    (reply, took): (pb::RenderUnitReply, Duration),
) -> Result<(), SessionError> {
    let received = reply.encoded_len() as u64;
    let (buffer, stats) = result_from_wire(unit, &context.frame, &context.weights, &reply)
        .map_err(|e| SessionError::BadReply(e.to_string()))?;
    context.deadline.observe(took);
    let first = context.schedule.complete(&unit);
    node.update(|r| {
        r.bytes_received += received;
        if first {
            r.units += 1;
            r.samples += stats.samples;
            r.result_bytes +=
                (reply.pixels.len() + reply.layers.len() + reply.light_splats.len()) as u64;
            r.result_pixels += unit.pixel_count() as u64;
        }
    });
    if first {
        let _ = context.events.send(SessionEvent::Result {
            buffer: Box::new(buffer),
            stats,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn honest() -> pb::HandshakeReply {
        pb::HandshakeReply {
            protocol_version: PROTOCOL_VERSION,
            threads: 2,
            hostname: "node-1".into(),
            software: "yat 9.9".into(),
            renderer_build: yat_tracer::RENDERER_BUILD.into(),
            max_message_bytes: 8 << 20,
            max_blob_bytes: 1 << 30,
            features: Vec::new(),
        }
    }

    #[test]
    fn another_protocol_version_is_refused_naming_both() {
        let mut reply = honest();
        assert!(check_handshake("h:1", &reply).is_ok());
        reply.protocol_version = PROTOCOL_VERSION + 1;
        let message = check_handshake("h:1", &reply).unwrap_err();
        assert!(message.contains(&format!("version {}", PROTOCOL_VERSION + 1)));
        assert!(message.contains(&format!("version {PROTOCOL_VERSION}")));
    }

    /// A worker of another renderer build may render other bits: refused, naming both builds;
    /// an older worker, which names none, is told apart; a build name is printed safe.
    #[test]
    fn another_renderer_build_is_refused_naming_both() {
        let ours = yat_tracer::RENDERER_BUILD;
        assert_eq!(ours.len(), 16, "{ours}");
        let other = pb::HandshakeReply {
            renderer_build: "0123456789abcdef".into(),
            ..honest()
        };
        let message = check_handshake("h:1", &other).unwrap_err();
        assert!(
            message.contains("renderer build 0123456789abcdef"),
            "{message}"
        );
        assert!(
            message.contains(&format!("coordinator renderer build {ours}")),
            "{message}"
        );
        let older = pb::HandshakeReply {
            renderer_build: String::new(),
            ..honest()
        };
        let message = check_handshake("h:1", &older).unwrap_err();
        assert!(message.contains("an older yat"), "{message}");
        let hostile = pb::HandshakeReply {
            renderer_build: "\x1b[2J".into(),
            ..honest()
        };
        let message = check_handshake("h:1", &hostile).unwrap_err();
        assert!(!message.contains('\x1b'), "{message:?}");
    }

    #[test]
    fn a_workers_claims_are_clamped_or_refused() {
        let many = pb::HandshakeReply {
            threads: 1_000_000,
            ..honest()
        };
        let info = check_handshake("h:1", &many).unwrap();
        assert_eq!(
            (info.threads, info.claimed_threads),
            (MAX_WORKER_THREADS, 1_000_000)
        );
        for bad in [
            pb::HandshakeReply {
                threads: 0,
                ..honest()
            },
            pb::HandshakeReply {
                max_message_bytes: 1,
                ..honest()
            },
            pb::HandshakeReply {
                max_message_bytes: 64 << 10,
                ..honest()
            },
            pb::HandshakeReply {
                hostname: "h".repeat(MAX_NAME_BYTES + 1),
                ..honest()
            },
            pb::HandshakeReply {
                software: "s".repeat(1 << 20),
                ..honest()
            },
            pb::HandshakeReply {
                renderer_build: "b".repeat(MAX_NAME_BYTES + 1),
                ..honest()
            },
        ] {
            assert!(check_handshake("h:1", &bad).is_err(), "{bad:?}");
        }
        // The smallest limit that holds a 64x64 tile's reply and two 64 KiB chunks passes.
        let tight = pb::HandshakeReply {
            max_message_bytes: min_message_bytes(),
            ..honest()
        };
        assert!(check_handshake("h:1", &tight).is_ok());
        assert!(min_message_bytes() >= 16 * 64 * 64 && min_message_bytes() >= 128 << 10);
        // Every node's own limit holds the largest reply (docs/security.md's figure), light
        // group layers included.
        assert_eq!(min_message_bytes(), 7_410_688);
        assert!(min_message_bytes() <= yat_proto::DEFAULT_MAX_MESSAGE_BYTES as u64);
    }

    /// A reply that lists a blob again and again gets it once; one that lists a blob that is
    /// not the scene's is a bad reply, naming it safely.
    #[test]
    fn each_missing_blob_is_uploaded_once() {
        let blobs: HashMap<String, Bytes> = [("a", "A"), ("b", "BB"), ("c", "CCC")]
            .into_iter()
            .map(|(hash, bytes)| (hash.to_string(), Bytes::from(bytes)))
            .collect();
        let hashes = |upload: Vec<(&str, &Bytes)>| -> Vec<String> {
            upload
                .into_iter()
                .map(|(hash, bytes)| {
                    assert_eq!(bytes, &blobs[hash]);
                    hash.to_string()
                })
                .collect()
        };
        let listed = |hashes: &[&str]| hashes.iter().map(|h| h.to_string()).collect::<Vec<_>>();
        let repeated = vec!["b".to_string(); 2000];
        assert_eq!(hashes(blobs_to_upload(&blobs, &repeated).unwrap()), ["b"]);
        let mixed = listed(&["c", "a", "c", "a", "c"]);
        assert_eq!(hashes(blobs_to_upload(&blobs, &mixed).unwrap()), ["c", "a"]);
        assert!(blobs_to_upload(&blobs, &[]).unwrap().is_empty());
        let foreign = listed(&["a", "\x1b[2Jz"]);
        let message = blobs_to_upload(&blobs, &foreign).unwrap_err();
        assert!(
            message.contains("[2Jz") && !message.contains('\x1b'),
            "{message:?}"
        );
    }

    #[test]
    fn a_workers_names_are_made_safe_and_short() {
        let hostile = pb::HandshakeReply {
            hostname: format!("\x1b]0;pwn\x07{}", "n".repeat(500)),
            software: "\x1b[2Jyat".into(),
            ..honest()
        };
        let info = check_handshake("h:1", &hostile).unwrap();
        for name in [&info.hostname, &info.software] {
            assert!(!name.chars().any(char::is_control), "{name:?}");
            assert!(name.chars().count() <= MAX_NAME_CHARS);
        }
        assert!(info.software.ends_with("[2Jyat"));
    }
}
