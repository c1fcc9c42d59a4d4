//! A hostile client on loopback against a real worker (served in-process on a real socket):
//! every attack is bounded, the worker stays up, its resident memory stays under a stated
//! bound, and an honest token holder is still served. The tests run one at a time, since they
//! measure the process's memory.

use std::time::Duration;

use tokio::io::AsyncReadExt;
use tonic::Code;
use yat_proto::hash::sha256_hex;
use yat_proto::pb;
use yat_worker::{NetworkLimits, WorkerConfig, MIB};

mod support;
use support::*;

/// The tests measure the whole process: one at a time.
static ONE_AT_A_TIME: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());

const TOKEN: &str = "honest";

/// The process's resident memory, from /proc/self/status.
fn resident_bytes() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap();
    let kib: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kib * 1024
}

fn hostile_config() -> WorkerConfig {
    WorkerConfig {
        token: Some(TOKEN.into()),
        ..WorkerConfig::default()
    }
}

/// An honest token holder loads the scene and renders a unit within `limit`.
async fn honest_unit_renders(worker: &Served, limit: Duration) {
    let started = tokio::time::Instant::now();
    let mut client = worker.client(Some(TOKEN));
    let scene = load_scene(&mut client, 2).await;
    let reply = client.render_unit(unit(&scene, 7, 0..2)).await.unwrap();
    assert_eq!(reply.into_inner().pixels.len(), 16 * 16 * 16);
    let took = started.elapsed();
    assert!(took < limit, "an honest unit took {took:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unfinished_and_oversized_uploads_stay_within_the_upload_budget() {
    let _one = ONE_AT_A_TIME.lock().await;
    const BUDGET: u64 = 32 * MIB;
    let worker = Served::start(WorkerConfig {
        upload_budget_bytes: BUDGET,
        network: NetworkLimits {
            blob_idle: Duration::from_secs(2),
            ..NetworkLimits::default()
        },
        ..hostile_config()
    })
    .await;
    let before = resident_bytes();
    let mut client = worker.client(Some(TOKEN));

    // A declared 2^60 bytes is refused before anything is allocated.
    let huge = chunks(&sha256_hex(b"x"), 1 << 60, &[b"x"]);
    let refused = client.put_blob(tokio_stream::iter(huge)).await.unwrap_err();
    assert_eq!(refused.code(), Code::ResourceExhausted, "{refused:?}");

    // 100 uploads of 8 MiB each (declared 32 MiB) in 64 KiB chunks that then stall: 800 MiB
    // offered. The chunks go one at a time, so the client's side buffers little.
    let chunk = prost::bytes::Bytes::from(vec![7u8; 64 << 10]);
    let mut uploads = Vec::new();
    let (stall, stalled) = tokio::sync::watch::channel(());
    for i in 0..100u32 {
        let (send, chunks) = tokio::sync::mpsc::channel(1);
        let (chunk, mut stalled) = (chunk.clone(), stalled.clone());
        tokio::spawn(async move {
            for part in 0..128 {
                let first = part == 0;
                let message = pb::BlobChunk {
                    sha256: if first {
                        sha256_hex(&i.to_le_bytes())
                    } else {
                        String::new()
                    },
                    size: if first { BUDGET } else { 0 },
                    data: chunk.clone(),
                };
                if send.send(message).await.is_err() {
                    return;
                }
            }
            let _ = stalled.changed().await;
        });
        let mut c = client.clone();
        let stream = tokio_stream::wrappers::ReceiverStream::new(chunks);
        uploads.push(tokio::spawn(async move { c.put_blob(stream).await }));
    }
    let mut peak = 0;
    let mut codes = Vec::new();
    let started = tokio::time::Instant::now();
    for upload in uploads {
        while !upload.is_finished() {
            peak = peak.max(resident_bytes());
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        codes.push(upload.await.unwrap().unwrap_err().code());
    }
    let waited = started.elapsed();
    drop(stall);
    let exhausted = codes
        .iter()
        .filter(|c| **c == Code::ResourceExhausted)
        .count();
    let stalled = codes
        .iter()
        .filter(|c| **c == Code::DeadlineExceeded)
        .count();
    let growth = peak.saturating_sub(before);
    eprintln!(
        "uploads: {exhausted} over budget, {stalled} stalled, all failed within {waited:?}, \
         resident memory +{} MiB",
        growth / MIB
    );
    assert_eq!(exhausted + stalled, 100, "{codes:?}");
    assert!(
        exhausted >= 100 - 4,
        "at most 4 uploads of 8 MiB fit 32 MiB: {exhausted}"
    );
    assert!(
        waited < Duration::from_secs(10),
        "stalled uploads end after 2 s idle"
    );
    // The budget's 32 MiB, plus what the transport buffers for 100 streams (800 MiB were sent).
    assert!(
        growth < 160 * MIB,
        "resident memory grew {} MiB",
        growth / MIB
    );
    honest_unit_renders(&worker, Duration::from_secs(10)).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn idle_connections_and_streams_are_closed_and_an_honest_client_gets_in() {
    let _one = ONE_AT_A_TIME.lock().await;
    let worker = Served::start(WorkerConfig {
        network: NetworkLimits {
            max_connections: 64,
            connection_idle: Duration::from_secs(1),
            blob_idle: Duration::from_secs(1),
            ..NetworkLimits::default()
        },
        ..hostile_config()
    })
    .await;
    let before = resident_bytes();
    // 300 sockets opened by a stranger and left silent: more than the 64 connections served
    // at once.
    let mut idle = Vec::new();
    for _ in 0..300 {
        idle.push(connect_from_elsewhere(worker.address).await.unwrap());
    }
    // 200 uploads that never send their first chunk, on one HTTP/2 connection.
    let mut client = worker.client(Some(TOKEN));
    let mut silent = Vec::new();
    let mut held = Vec::new();
    for _ in 0..200 {
        let (send, chunks) = tokio::sync::mpsc::channel::<pb::BlobChunk>(1);
        held.push(send);
        let mut c = client.clone();
        let stream = tokio_stream::wrappers::ReceiverStream::new(chunks);
        silent.push(tokio::spawn(async move { c.put_blob(stream).await }));
    }
    let started = tokio::time::Instant::now();
    honest_unit_renders(&worker, Duration::from_secs(15)).await;
    let honest = started.elapsed();
    for upload in silent {
        let status = upload.await.unwrap().unwrap_err();
        assert_eq!(status.code(), Code::DeadlineExceeded, "{status:?}");
    }
    let streams_closed = started.elapsed();
    let mut closed = 0;
    for mut socket in idle {
        // The worker's HTTP/2 settings come first, then the end of the stream.
        let mut sent = Vec::new();
        let read = tokio::time::timeout(Duration::from_secs(15), socket.read_to_end(&mut sent));
        if read.await.is_ok() {
            closed += 1;
        }
    }
    let all_closed = started.elapsed();
    let growth = resident_bytes().saturating_sub(before);
    eprintln!(
        "idle: honest unit after {honest:?}, 200 silent uploads failed by {streams_closed:?}, \
         {closed}/300 silent sockets closed by {all_closed:?}, resident memory +{} MiB",
        growth / MIB
    );
    assert_eq!(closed, 300);
    assert!(all_closed < Duration::from_secs(30), "{all_closed:?}");
    assert!(
        growth < 100 * MIB,
        "resident memory grew {} MiB",
        growth / MIB
    );
    let stats = client
        .stats(pb::StatsRequest {})
        .await
        .unwrap()
        .into_inner();
    assert_eq!(stats.blob_bytes_received, SCENE.len() as u64);
    drop(held);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_flood_of_huge_units_is_capped_and_abandoned_units_stop() {
    let _one = ONE_AT_A_TIME.lock().await;
    let worker = Served::start(WorkerConfig {
        threads: 2,
        max_queued_units: 24,
        // The token holder below opens 50 connections at the same instant.
        network: NetworkLimits {
            max_unauthenticated_per_address: 64,
            ..NetworkLimits::default()
        },
        ..hostile_config()
    })
    .await;
    let mut client = worker.client(Some(TOKEN));
    let settings = |spp, max_depth| pb::LoadSceneRequest {
        main: Some(pb::SceneFile {
            path: "sphere.lxs".into(),
            sha256: sha256_hex(SCENE),
        }),
        assets: vec![],
        settings: Some(pb::RenderSettings {
            width: 16,
            height: 16,
            spp,
            max_depth,
            ..Default::default()
        }),
    };
    // A scene uploaded and loaded with a huge but legal sample count: 2^20 per pixel.
    let heavy_spp = 1 << 20;
    let heavy = load_scene(&mut client, heavy_spp).await;
    for (spp, depth) in [(u32::MAX, 4), (4, u32::MAX), (0, 4)] {
        let status = client.load_scene(settings(spp, depth)).await.unwrap_err();
        assert_eq!(
            status.code(),
            Code::InvalidArgument,
            "spp {spp} depth {depth}"
        );
    }
    let outside = client.render_unit(unit(&heavy, 0, 0..heavy_spp + 1)).await;
    assert_eq!(outside.unwrap_err().code(), Code::InvalidArgument);

    // 500 units of 2^28 samples each, from 50 connections at once.
    let before = resident_bytes();
    let mut flood = Vec::new();
    for i in 0..500u32 {
        let mut c = if i % 10 == 0 {
            worker.client(Some(TOKEN))
        } else {
            client.clone()
        };
        let request = unit(&heavy, i, 0..heavy_spp);
        flood.push(tokio::spawn(async move { c.render_unit(request).await }));
    }
    let limit = Duration::from_secs(20);
    let mut exhausted = 0;
    let started = tokio::time::Instant::now();
    for call in &mut flood {
        if started.elapsed() > limit {
            break;
        }
        let done = tokio::time::timeout(Duration::from_millis(200), &mut *call).await;
        if let Ok(reply) = done {
            let status = reply.unwrap().unwrap_err();
            assert_eq!(status.code(), Code::ResourceExhausted, "{status:?}");
            exhausted += 1;
        }
    }
    let in_flight = units_in_flight(&mut client).await;
    eprintln!("flood: {exhausted} of 500 refused, {in_flight} in flight");
    assert_eq!(in_flight, 2 + 24, "2 rendering and 24 waiting");
    assert_eq!(exhausted, 500 - 26);

    // The callers vanish: every unit stops, waiting or rendering.
    for call in flood {
        call.abort();
    }
    let stopped = wait_until(Duration::from_secs(3), async || {
        units_in_flight(&mut client).await == 0
    })
    .await;
    let growth = resident_bytes().saturating_sub(before);
    eprintln!(
        "abandoned units stopped within {stopped:?}; resident memory +{} MiB",
        growth / MIB
    );
    assert!(stopped < Duration::from_millis(1500), "{stopped:?}");
    assert!(
        growth < 100 * MIB,
        "resident memory grew {} MiB",
        growth / MIB
    );
    honest_unit_renders(&worker, Duration::from_secs(10)).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn strangers_and_failing_loads_do_not_disturb_running_units() {
    let _one = ONE_AT_A_TIME.lock().await;
    let worker = Served::start(hostile_config()).await;
    let mut client = worker.client(Some(TOKEN));

    let mut stranger = worker.client(None);
    let mut impostor = worker.client(Some("guess"));
    for _ in 0..200 {
        let stats = stranger.stats(pb::StatsRequest {}).await.unwrap_err();
        assert_eq!(stats.code(), Code::Unauthenticated);
        let load = impostor.load_scene(pb::LoadSceneRequest::default()).await;
        assert_eq!(load.unwrap_err().code(), Code::Unauthenticated);
    }

    // A long unit renders while strangers' loads fail and other scenes fill the cache.
    let running = load_scene(&mut client, 1 << 16).await;
    let long_unit = tokio::spawn({
        let mut c = client.clone();
        let request = unit(&running, 0, 0..1 << 16);
        async move { c.render_unit(request).await }
    });
    wait_until(Duration::from_secs(5), async || {
        units_in_flight(&mut client).await == 1
    })
    .await;
    let broken: &'static [u8] = b"Film \"fleximage\" \"integer xresolution\" [64\nWorldBegin\n";
    let hash = sha256_hex(broken);
    let upload = chunks(&hash, broken.len() as u64, &[broken]);
    client.put_blob(tokio_stream::iter(upload)).await.unwrap();
    for _ in 0..20 {
        let request = pb::LoadSceneRequest {
            main: Some(pb::SceneFile {
                path: "broken.lxs".into(),
                sha256: hash.clone(),
            }),
            assets: vec![],
            settings: Some(pb::RenderSettings {
                width: 16,
                height: 16,
                spp: 1,
                max_depth: 1,
                ..Default::default()
            }),
        };
        let status = client.load_scene(request).await.unwrap_err();
        assert_eq!(status.code(), Code::InvalidArgument);
    }
    // Five other scenes, one more than the cache holds: the one rendering must stay.
    for spp in 1..=5 {
        load_scene(&mut client, spp).await;
    }
    let quick = client.render_unit(unit(&running, 1, 0..1)).await;
    assert!(quick.is_ok(), "the rendering scene was evicted: {quick:?}");
    long_unit.abort();
    wait_until(Duration::from_secs(3), async || {
        units_in_flight(&mut client).await == 0
    })
    .await;
    honest_unit_renders(&worker, Duration::from_secs(10)).await;
}
