//! A worker under an orchestrator (Kubernetes, Slurm): SIGTERM mid-render drains it without
//! costing the render anything but time, and `--threads` defaults to the CPUs it was given.

use std::io::{BufReader, Read};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use yat::exec::distributed::config::DistributedConfig;
use yat::render::{Executor, Observers};
use yat::shutdown::Interrupt;

use crate::lit_sphere::LIT_SPHERE;
use crate::util::*;

#[test]
fn a_worker_terminated_mid_render_drains_and_exits_0() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference_image(dir.path(), &scene);

    let mut a = Worker::start(&["--throttle-ms", "150"]);
    // b is the slower: a's units are its own, not end-game copies of b's, when it is signalled.
    let b = Worker::start(&["--throttle-ms", "300"]);
    let out = dir.path().join("drained.png");
    let json = dir.path().join("workers.json");
    let started = Instant::now();
    // No unit deadline: a unit lost in the drain would cost the default 30 s.
    let coordinator = spawn_render(
        request(&scene, &out),
        Executor::from(DistributedConfig {
            workers_json: Some(json.clone()),
            ..workers_at(&[&a.address, &b.address])
        }),
        Observers::none(),
        Interrupt::default(),
    );
    let polling = Instant::now();
    // Signalled once a has returned a unit and is on another (its 2 threads pause 150 ms per
    // unit, so one in flight is on a thread, not queued).
    let before = loop {
        let stats = a.stats(None);
        if stats.units_done >= 1 && stats.units_in_flight >= 1 {
            break stats;
        }
        assert!(polling.elapsed() < Duration::from_secs(30), "worker a idle");
        std::thread::sleep(Duration::from_millis(5));
    };
    a.signal("TERM");
    let signalled = Instant::now();
    let status = a
        .wait_for_exit(Duration::from_secs(20 + 5))
        .expect("the drained worker exits within --drain-seconds + 5 s");
    assert!(status.success(), "{status}");
    let drain = signalled.elapsed();
    coordinator.join().unwrap().unwrap();
    let elapsed = started.elapsed();
    let (png, exr) = image_bytes(&out);
    assert!(exr == expected.1, "EXR differs from in-process");
    assert!(png == expected.0, "PNG differs from in-process");
    assert!(
        elapsed < Duration::from_secs(25),
        "no unit waited for the 30 s deadline: {elapsed:?}"
    );
    // The units a's threads were on (each pauses 150 ms first) were finished and merged, not
    // thrown away with the session when a's queue was handed back.
    let report = workers_report(&json);
    let merged_by_a = worker_entry(&report, &a.address)["units"].as_u64().unwrap();
    assert!(
        merged_by_a > before.units_done,
        "a had {} unit(s) in flight and {} done at SIGTERM, and {merged_by_a} merged: {report:#}",
        before.units_in_flight,
        before.units_done
    );
    eprintln!(
        "drain: {} unit(s) in flight at SIGTERM, {} more merged, exit after {drain:?}, render \
         {elapsed:?}",
        before.units_in_flight,
        merged_by_a - before.units_done
    );
}

#[test]
fn threads_default_to_the_cpus_the_worker_may_use() {
    if Command::new("taskset").arg("--version").output().is_err() {
        eprintln!("skipped: `taskset` is not installed (util-linux)");
        return;
    }
    let mut child = Command::new("taskset")
        .args(["-c", "0", YAT, "worker", "--listen", "127.0.0.1:0"])
        .env_remove("YAT_TOKEN")
        .env("YAT_LOG", "info")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let address = next_line_after(&mut stdout, "listening on ");
    let threads = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap()
        .block_on(async move {
            let mut client = yat_proto::RenderNodeClient::connect(format!("http://{address}"))
                .await
                .unwrap();
            let hello = yat_proto::pb::HandshakeRequest {
                protocol_version: yat_proto::PROTOCOL_VERSION,
                client: "e2e".into(),
            };
            client.handshake(hello).await.unwrap().into_inner().threads
        });
    // Terminated, not killed: the worker's log lines are written by a thread of their own,
    // which a SIGKILL may stop before it has written the start line; SIGTERM drains (nothing
    // to drain here) and exits, flushing them.
    signal(child.id(), "TERM");
    let exited = wait_for_exit(&mut child, Duration::from_secs(30));
    assert!(exited.is_some(), "the worker exits on SIGTERM");
    let mut log = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut log)
        .unwrap();
    assert_eq!(threads, 1, "taskset -c 0 leaves one CPU");
    assert!(
        log.contains("1 thread(s), the CPUs this process may use"),
        "{log}"
    );
}

/// Uploads [`LIT_SPHERE`] to the worker at `address`, loads it and asks for one unit, on
/// `runtime`; the call stays pending until the worker answers or goes.
fn send_one_unit(runtime: &tokio::runtime::Runtime, address: &str) {
    use yat_proto::pb;
    let address = format!("http://{address}");
    runtime.spawn(async move {
        let mut client = yat_proto::RenderNodeClient::connect(address).await.unwrap();
        let sha256 = yat_proto::hash::sha256_hex(LIT_SPHERE);
        let chunk = pb::BlobChunk {
            sha256: sha256.clone(),
            size: LIT_SPHERE.len() as u64,
            data: LIT_SPHERE.to_vec().into(),
        };
        client.put_blob(tokio_stream::iter([chunk])).await.unwrap();
        let load = pb::LoadSceneRequest {
            main: Some(pb::SceneFile {
                path: "sphere.lxs".into(),
                sha256,
            }),
            assets: vec![],
            settings: Some(pb::RenderSettings {
                width: 16,
                height: 16,
                spp: 1,
                max_depth: 2,
                ..Default::default()
            }),
        };
        let scene_id = client.load_scene(load).await.unwrap().into_inner().scene_id;
        let unit = pb::WorkUnit {
            index: 0,
            x0: 0,
            y0: 0,
            x1: 16,
            y1: 16,
            sample_start: 0,
            sample_end: 1,
            block_mask: None,
        };
        let request = pb::RenderUnitRequest {
            scene_id,
            unit: Some(unit),
        };
        let _ = client.render_unit(request).await;
    });
}

#[test]
fn a_second_signal_stops_a_draining_worker_at_once() {
    let mut worker = Worker::start(&["--throttle-ms", "10000"]);
    let runtime = tokio::runtime::Runtime::new().unwrap();
    send_one_unit(&runtime, &worker.address);
    let polling = Instant::now();
    while worker.stats(None).units_in_flight < 1 {
        assert!(
            polling.elapsed() < Duration::from_secs(30),
            "no unit arrived"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    worker.signal("TERM");
    assert!(
        worker.wait_for_exit(Duration::from_millis(500)).is_none(),
        "the first signal drains: a unit is still rendering"
    );
    worker.signal("TERM");
    let status = worker
        .wait_for_exit(Duration::from_secs(3))
        .expect("the second signal stops the worker at once");
    assert_eq!(status.code(), Some(130), "{status}");
}
