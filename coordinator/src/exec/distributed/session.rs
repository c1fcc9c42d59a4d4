//! The steps of a render on one worker: a loop that connects (again and again, with backoff),
//! shakes hands, uploads what the worker lacks, loads the scene, and then pulls units from the
//! shared schedule with a bounded number in flight. Whatever goes wrong, the units it held go
//! back to the queue.

use std::collections::HashMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use prost::Message;
use tokio::task::JoinSet;
use yat_proto::convert::decode_pixels;
use yat_proto::{pb, PROTOCOL_VERSION};
use yat_tracer::render::{UnitStats, WorkUnit};

use super::client::WorkerClient;
use super::node::Node;
use super::schedule::Schedule;
use super::session_error::SessionError;
use super::shared::{Event, Shared};

const MIN_BACKOFF: Duration = Duration::from_millis(250);
const MAX_BACKOFF: Duration = Duration::from_secs(5);
/// Units in flight per worker thread: one rendering, one queued behind it, so a worker never
/// idles for a round trip.
const UNITS_IN_FLIGHT_PER_THREAD: u32 = 2;

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

/// Serves the render with one worker until the schedule is finished or the worker is gone for
/// good.
pub async fn run_node(node: Arc<Node>, shared: Arc<Shared>) {
    let mut backoff = MIN_BACKOFF;
    let mut finished = shared.schedule.watch();
    while !shared.schedule.is_finished() {
        if let Some(status) = node.local.as_ref().and_then(|l| l.exit_status()) {
            let reason = format!("the local worker exited ({status})");
            shared.notice(format!("worker {}: {reason}", node.address()));
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
                shared.notice(format!("worker {} refused: {reason}", node.address()));
                node.update(|r| r.gone = Some(reason));
                return;
            }
            Err(SessionError::Transient(error)) => {
                if was_rendering {
                    shared.notice(format!(
                        "worker {} lost ({error}); its units go back to the queue",
                        node.address()
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
    check_handshake(address, &reply).map_err(SessionError::Permanent)?;
    node.update(|r| {
        r.hostname = reply.hostname.clone();
        r.threads = reply.threads;
    });

    upload_missing_blobs(&mut client, node, shared, &reply).await?;
    let load = shared.load_request.clone();
    let sent = load.encoded_len() as u64;
    let loaded = client.load_scene(load).await?;
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

/// Asks which blobs the worker lacks and uploads those.
async fn upload_missing_blobs(
    client: &mut WorkerClient,
    node: &Node,
    shared: &Shared,
    worker: &pb::HandshakeReply,
) -> Result<(), SessionError> {
    let blobs = &shared.manifest.blobs;
    let query = pb::HasBlobsRequest {
        sha256: blobs.keys().cloned().collect(),
    };
    node.update(|r| r.bytes_sent += query.encoded_len() as u64);
    for hash in client.missing_blobs(query).await? {
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
        let sent = client
            .put_blob(&hash, bytes, worker.max_message_bytes)
            .await?;
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

/// Pulls units while fewer than `limit` are in flight, until the render is finished.
async fn render_units(
    client: WorkerClient,
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
        while calls.len() < schedule.in_flight_limit(limit) {
            let Some(unit) = schedule.take(node.address()) else {
                break;
            };
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
                let outcome = outcome.inspect_err(|_| {
                    held.units.insert(unit.index, unit);
                    node.update(|r| r.failures += 1);
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
}
