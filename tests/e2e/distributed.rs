//! Distributed rendering end to end: the real `yat` binary as coordinator and workers, real
//! sockets on loopback. Every image must be bit-identical to the in-process render, whatever
//! the workers do.

use std::path::Path;
use std::time::{Duration, Instant};

use crate::util::*;

/// The in-process render of the test scene: (PNG bytes, EXR bytes).
fn reference(dir: &Path, scene: &Path) -> (Vec<u8>, Vec<u8>) {
    let out = dir.join("in-process.png");
    assert_success(&render(scene, &out, &["--threads", "2", "--quiet"]));
    image_bytes(&out)
}

fn assert_same_image(out: &Path, expected: &(Vec<u8>, Vec<u8>)) {
    let (png, exr) = image_bytes(out);
    assert!(
        exr == expected.1,
        "{}: EXR differs from in-process",
        out.display()
    );
    assert!(
        png == expected.0,
        "{}: PNG differs from in-process",
        out.display()
    );
}

fn worker_entry<'a>(report: &'a serde_json::Value, address: &str) -> &'a serde_json::Value {
    report["workers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|w| w["address"] == address)
        .unwrap_or_else(|| panic!("{address} not in {report:#}"))
}

fn total_units(report: &serde_json::Value) -> u64 {
    report["workers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["units"].as_u64().unwrap())
        .sum()
}

/// Waits until the workers together have rendered `units` units.
fn wait_for_units(workers: &[&Worker], units: u64) {
    let started = Instant::now();
    while workers
        .iter()
        .map(|w| w.stats(None).units_done)
        .sum::<u64>()
        < units
    {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "render stalled"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn two_workers_and_local_workers_match_the_in_process_render() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference(dir.path(), &scene);
    let a = Worker::start(&[]);
    let b = Worker::start(&[]);
    let out = dir.path().join("two.png");
    let json = dir.path().join("two.json");
    let workers = format!("{},{}", a.address, b.address);
    let output = render(
        &scene,
        &out,
        &[
            "--workers",
            &workers,
            "--workers-json",
            json.to_str().unwrap(),
        ],
    );
    assert_success(&output);
    assert_same_image(&out, &expected);
    let report = workers_report(&json);
    assert_eq!(report["units"], 32);
    assert_eq!(
        total_units(&report),
        32,
        "each unit merged once: {report:#}"
    );
    // 16 bytes per pixel of each unit's tile and the 2-pixel border of the scene's
    // blackmanharris filter: 128x96 in 64-pixel tiles, regions of 66x66, 66x66, 66x34 and
    // 66x34 pixels, 13200 against the 12288 of the image.
    assert_eq!(
        report["result_bytes_per_unit_pixel"],
        16.0 * 13200.0 / 12288.0
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout.contains("samples/s") && stdout.contains(&a.address),
        "{stdout}"
    );

    let out = dir.path().join("local.png");
    assert_success(&render(&scene, &out, &["--local-workers", "2"]));
    assert_same_image(&out, &expected);
}

#[test]
fn a_killed_worker_costs_only_time() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference(dir.path(), &scene);
    let mut a = Worker::start(&["--throttle-ms", "100"]);
    let b = Worker::start(&["--throttle-ms", "100"]);
    let (a_address, workers) = (a.address.clone(), format!("{},{}", a.address, b.address));
    let out = dir.path().join("killed.png");
    let json = dir.path().join("killed.json");
    let mut coordinator = render_command(
        &scene,
        &out,
        &[
            "--workers",
            &workers,
            "--workers-json",
            json.to_str().unwrap(),
        ],
    )
    .args(["--preview-every", "0.1"])
    .spawn()
    .unwrap();
    wait_for_units(&[&a, &b], 12);
    assert!(
        out.with_extension("preview.png").exists(),
        "a preview is written during the render"
    );
    a.kill();
    assert!(coordinator.wait().unwrap().success());
    assert_same_image(&out, &expected);
    assert!(
        !out.with_extension("preview.png").exists(),
        "the preview is removed once the image is written"
    );
    let report = workers_report(&json);
    assert_eq!(total_units(&report), 32);
    let killed = worker_entry(&report, &a_address);
    assert!(killed["failures"].as_u64().unwrap() >= 1, "{report:#}");
    assert!(
        killed["units_requeued"].as_u64().unwrap() >= 1,
        "{report:#}"
    );
}

#[test]
fn a_frozen_worker_costs_only_time() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference(dir.path(), &scene);
    let a = Worker::start(&["--throttle-ms", "100"]);
    let b = Worker::start(&["--throttle-ms", "100"]);
    let workers = format!("{},{}", a.address, b.address);
    let out = dir.path().join("frozen.png");
    let json = dir.path().join("frozen.json");
    let mut coordinator = render_command(
        &scene,
        &out,
        &[
            "--workers",
            &workers,
            "--workers-json",
            json.to_str().unwrap(),
        ],
    )
    .env("YAT_UNIT_DEADLINE", "2")
    .spawn()
    .unwrap();
    wait_for_units(&[&a, &b], 8);
    b.signal("STOP");
    let status = coordinator.wait().unwrap();
    b.signal("CONT");
    assert!(status.success());
    assert_same_image(&out, &expected);
    let report = workers_report(&json);
    assert_eq!(total_units(&report), 32);
    let frozen = worker_entry(&report, &b.address);
    assert!(
        frozen["units_requeued"].as_u64().unwrap() >= 1,
        "{report:#}"
    );
}

#[test]
fn a_late_worker_receives_units() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference(dir.path(), &scene);
    let late_address = {
        let probe = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        probe.local_addr().unwrap().to_string()
    };
    let a = Worker::start(&["--throttle-ms", "250"]);
    let workers = format!("{},{late_address}", a.address);
    let out = dir.path().join("late.png");
    let json = dir.path().join("late.json");
    let mut coordinator = render_command(
        &scene,
        &out,
        &[
            "--workers",
            &workers,
            "--workers-json",
            json.to_str().unwrap(),
        ],
    )
    .spawn()
    .unwrap();
    wait_for_units(&[&a], 2);
    let late = Worker::start_on(&late_address, &["--throttle-ms", "250"]);
    assert!(coordinator.wait().unwrap().success());
    assert_same_image(&out, &expected);
    let report = workers_report(&json);
    assert_eq!(total_units(&report), 32);
    let late_units = worker_entry(&report, &late_address)["units"]
        .as_u64()
        .unwrap();
    assert!(late_units > 0, "{report:#}");
    assert_eq!(late.stats(None).units_done, late_units);
}

#[test]
fn a_wrong_or_missing_token_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let worker = Worker::start(&["--token", "correct horse"]);
    for token in [Some("battery staple"), None] {
        let mut args = vec!["--workers", worker.address.as_str(), "--timeout", "20"];
        if let Some(token) = token {
            args.extend(["--token", token]);
        }
        let output = render(&scene, &dir.path().join("refused.png"), &args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{stderr}");
        assert!(stderr.contains("authentication"), "{stderr}");
    }
    let out = dir.path().join("accepted.png");
    let workers = worker.address.as_str();
    let output = render(
        &scene,
        &out,
        &["--workers", workers, "--token", "correct horse"],
    );
    assert_success(&output);
}

#[test]
fn a_second_render_sends_no_scene_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let worker = Worker::start(&[]);
    let sent = |name: &str| {
        let json = dir.path().join(format!("{name}.json"));
        let output = render(
            &scene,
            &dir.path().join(format!("{name}.png")),
            &[
                "--workers",
                &worker.address,
                "--workers-json",
                json.to_str().unwrap(),
            ],
        );
        assert_success(&output);
        worker_entry(&workers_report(&json), &worker.address)["blob_bytes_sent"]
            .as_u64()
            .unwrap()
    };
    let files = scene_bytes(dir.path());
    assert_eq!(
        sent("first"),
        files,
        "the main file, the Include and the two PNGs"
    );
    assert_eq!(sent("second"), 0);
    let stats = worker.stats(None);
    assert_eq!(stats.blob_bytes_received, files);
    assert_eq!(stats.blobs_cached, 4);
    assert_eq!(
        stats.scenes_cached, 1,
        "the same scene and settings are built once"
    );
}

#[test]
fn with_no_worker_the_render_stops_after_its_timeout() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let nobody = {
        let probe = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        probe.local_addr().unwrap().to_string()
    };
    let started = Instant::now();
    let output = render(
        &scene,
        &dir.path().join("never.png"),
        &["--workers", &nobody, "--timeout", "1.5"],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(stderr.contains("no worker connected"), "{stderr}");
    assert!(stderr.contains(&nobody), "names the worker: {stderr}");
    let took = started.elapsed();
    assert!(
        took >= Duration::from_millis(1500) && took < Duration::from_secs(10),
        "{took:?}"
    );
}

/// A CA and a worker certificate for "localhost" signed by it, as PEM files in `dir`:
/// (ca.pem, worker.pem, worker.key).
fn write_tls_files(dir: &Path) -> [std::path::PathBuf; 3] {
    use rcgen::{BasicConstraints, CertificateParams, CertifiedIssuer, IsCa, KeyPair};
    let mut ca_params = CertificateParams::new(Vec::new()).unwrap();
    ca_params.is_ca = IsCa::Ca(BasicConstraints::Unconstrained);
    let ca = CertifiedIssuer::self_signed(ca_params, KeyPair::generate().unwrap()).unwrap();
    let key = KeyPair::generate().unwrap();
    let cert = CertificateParams::new(vec!["localhost".to_string()])
        .unwrap()
        .signed_by(&key, &ca)
        .unwrap();
    let paths = ["ca.pem", "worker.pem", "worker.key"].map(|f| dir.join(f));
    std::fs::write(&paths[0], ca.pem()).unwrap();
    std::fs::write(&paths[1], cert.pem()).unwrap();
    std::fs::write(&paths[2], key.serialize_pem()).unwrap();
    paths
}

#[test]
fn tls_workers_render_for_a_coordinator_that_trusts_their_ca() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference(dir.path(), &scene);
    let [ca, cert, key] = write_tls_files(dir.path());
    let worker = Worker::start(&[
        "--tls-cert",
        cert.to_str().unwrap(),
        "--tls-key",
        key.to_str().unwrap(),
    ]);
    let out = dir.path().join("tls.png");
    let tls = [
        "--workers",
        &worker.address,
        "--tls-ca",
        ca.to_str().unwrap(),
        "--tls-domain",
        "localhost",
    ];
    assert_success(&render(&scene, &out, &tls));
    assert_same_image(&out, &expected);

    let plain = render(
        &scene,
        &dir.path().join("plain.png"),
        &["--workers", &worker.address, "--timeout", "2"],
    );
    assert!(!plain.status.success(), "a plaintext client is not served");
}

/// The processes whose parent is `pid`.
fn children(pid: u32) -> Vec<u32> {
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return Vec::new();
    };
    tasks
        .flatten()
        .filter_map(|t| std::fs::read_to_string(t.path().join("children")).ok())
        .flat_map(|s| {
            s.split_whitespace()
                .filter_map(|p| p.parse().ok())
                .collect::<Vec<u32>>()
        })
        .collect()
}

/// True while `pid` exists and is not a zombie.
fn is_running(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .map(|stat| {
            let state = stat.rsplit(')').next().unwrap_or("").trim_start();
            !state.starts_with('Z') && !state.starts_with('X')
        })
        .unwrap_or(false)
}

#[test]
fn local_workers_do_not_outlive_a_killed_coordinator() {
    if !Path::new("/proc/self/task").exists() {
        println!("no /proc: skipping");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    // Long enough to be killed mid-way: thousands of samples per pixel.
    let mut coordinator = std::process::Command::new(YAT)
        .arg("render")
        .arg(&scene)
        .arg("-o")
        .arg(dir.path().join("long.png"))
        .args(["--local-workers", "2", "--spp", "8192", "--quiet"])
        .spawn()
        .unwrap();
    let started = Instant::now();
    let workers = loop {
        let workers = children(coordinator.id());
        if workers.len() == 2 {
            break workers;
        }
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "no local workers"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    std::thread::sleep(Duration::from_millis(300));
    assert!(workers.iter().all(|&w| is_running(w)));
    coordinator.kill().unwrap();
    coordinator.wait().unwrap();
    let killed = Instant::now();
    while workers.iter().any(|&w| is_running(w)) {
        assert!(
            killed.elapsed() < Duration::from_secs(10),
            "local workers outlived their coordinator"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}
