//! Distributed rendering end to end: real `yat worker` processes on loopback sockets, the
//! coordinator the library's render in this process (`yat render` where the test needs its
//! process: its output, its local workers). Every image must be bit-identical to the in-process
//! render, whatever the workers do.

use std::path::Path;
use std::time::{Duration, Instant};

use yat::exec::distributed::config::DistributedConfig;
use yat::render::{Executor, Observers};
use yat::shutdown::Interrupt;
use yat_proto::flags::ClientTlsFlags;
use yat_tracer::integrator::Transport;
use yat_tracer::render::RenderOverrides;

use crate::util::*;

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

fn total_units(report: &serde_json::Value) -> u64 {
    report["workers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["units"].as_u64().unwrap())
        .sum()
}

/// Two workers that pause `throttle_ms` before each unit, and the test scene in `dir`.
fn two_slow_workers(dir: &Path, throttle_ms: &str) -> (std::path::PathBuf, [Worker; 2]) {
    let throttle = ["--throttle-ms", throttle_ms];
    let scene = write_scene(dir);
    (scene, [Worker::start(&throttle), Worker::start(&throttle)])
}

/// `config` with its figures written to `json`.
fn reporting_to(json: &Path, config: DistributedConfig) -> Executor {
    Executor::from(DistributedConfig {
        workers_json: Some(json.into()),
        ..config
    })
}

/// The error text of a render that failed, as `yat render` prints it.
fn error_of(render: anyhow::Result<yat::render_report::RenderReport>) -> String {
    format!("{:?}", render.err().expect("the render fails"))
}

#[test]
fn two_workers_and_local_workers_match_the_in_process_render() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference_image(dir.path(), &scene);
    let a = Worker::start(&[]);
    let b = Worker::start(&[]);
    let out = dir.path().join("two.png");
    let json = dir.path().join("two.json");
    let on_both = workers_at(&[&a.address, &b.address]);
    render_here(request(&scene, &out), reporting_to(&json, on_both)).unwrap();
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

    // Local workers are `yat worker` processes of the coordinator's own binary.
    let out = dir.path().join("local.png");
    let output = render(&scene, &out, &["--local-workers", "2"]);
    assert_success(&output);
    assert_same_image(&out, &expected);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout.contains("samples/s") && stdout.contains("127.0.0.1:"),
        "the workers' figures are printed: {stdout}"
    );
}

#[test]
fn a_killed_worker_costs_only_time() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, [mut a, b]) = two_slow_workers(dir.path(), "100");
    let expected = reference_image(dir.path(), &scene);
    let a_address = a.address.clone();
    let out = dir.path().join("killed.png");
    let json = dir.path().join("killed.json");
    let observers = Observers {
        preview_every: Some(Duration::from_millis(100)),
        ..Observers::none()
    };
    let on_both = workers_at(&[&a.address, &b.address]);
    let coordinator = spawn_render(
        request(&scene, &out),
        reporting_to(&json, on_both),
        observers,
        Interrupt::default(),
    );
    wait_for_units(&[&a, &b], 12);
    assert!(
        out.with_extension("preview.png").exists(),
        "a preview is written during the render"
    );
    a.kill();
    coordinator.join().unwrap().unwrap();
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
    let (scene, [a, b]) = two_slow_workers(dir.path(), "100");
    let expected = reference_image(dir.path(), &scene);
    let out = dir.path().join("frozen.png");
    let json = dir.path().join("frozen.json");
    let config = DistributedConfig {
        unit_deadline: Some(Duration::from_secs(2)),
        ..workers_at(&[&a.address, &b.address])
    };
    let coordinator = spawn_render(
        request(&scene, &out),
        reporting_to(&json, config),
        Observers::none(),
        Interrupt::default(),
    );
    wait_for_units(&[&a, &b], 8);
    b.signal("STOP");
    let rendered = coordinator.join().unwrap();
    b.signal("CONT");
    rendered.unwrap();
    assert_same_image(&out, &expected);
    let report = workers_report(&json);
    assert_eq!(total_units(&report), 32);
    let frozen = worker_entry(&report, &b.address);
    assert!(
        frozen["units_requeued"].as_u64().unwrap() >= 1,
        "{report:#}"
    );
}

/// A loopback address nothing listens on (yet).
fn free_address() -> String {
    let probe = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    probe.local_addr().unwrap().to_string()
}

#[test]
fn a_late_worker_receives_units() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let expected = reference_image(dir.path(), &scene);
    let late_address = free_address();
    let a = Worker::start(&["--throttle-ms", "250"]);
    let out = dir.path().join("late.png");
    let json = dir.path().join("late.json");
    let coordinator = spawn_render(
        request(&scene, &out),
        reporting_to(&json, workers_at(&[&a.address, &late_address])),
        Observers::none(),
        Interrupt::default(),
    );
    wait_for_units(&[&a], 2);
    let late = Worker::start_on(&late_address, &["--throttle-ms", "250"]);
    coordinator.join().unwrap().unwrap();
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
    let with_token = |token: Option<&str>| DistributedConfig {
        token: token.map(String::from),
        ..workers_at(&[&worker.address])
    };
    for token in [Some("battery staple"), None] {
        let refused = DistributedConfig {
            timeout: Some(Duration::from_secs(20)),
            ..with_token(token)
        };
        let out = dir.path().join("refused.png");
        let error = error_of(render_here(request(&scene, &out), Executor::from(refused)));
        assert!(error.contains("authentication"), "{error}");
    }
    let out = dir.path().join("accepted.png");
    let accepted = with_token(Some("correct horse"));
    render_here(request(&scene, &out), Executor::from(accepted)).unwrap();
}

#[test]
fn a_second_render_sends_no_scene_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let worker = Worker::start(&[]);
    let sent = |name: &str| {
        let json = dir.path().join(format!("{name}.json"));
        let out = dir.path().join(format!("{name}.png"));
        let on_worker = reporting_to(&json, workers_at(&[&worker.address]));
        render_here(request(&scene, &out), on_worker).unwrap();
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
    let nobody = free_address();
    let started = Instant::now();
    let config = DistributedConfig {
        timeout: Some(Duration::from_millis(1500)),
        ..workers_at(&[&nobody])
    };
    let out = dir.path().join("never.png");
    let error = error_of(render_here(request(&scene, &out), Executor::from(config)));
    assert!(error.contains("no worker connected"), "{error}");
    assert!(error.contains(&nobody), "names the worker: {error}");
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
    let expected = reference_image(dir.path(), &scene);
    let [ca, cert, key] = write_tls_files(dir.path());
    let worker = Worker::start(&[
        "--tls-cert",
        cert.to_str().unwrap(),
        "--tls-key",
        key.to_str().unwrap(),
    ]);
    let out = dir.path().join("tls.png");
    let tls = ClientTlsFlags {
        tls_ca: Some(ca),
        tls_domain: Some("localhost".into()),
        ..ClientTlsFlags::default()
    };
    let trusting = DistributedConfig {
        tls: tls.config().unwrap(),
        tls_domain_given: true,
        ..workers_at(&[&worker.address])
    };
    render_here(request(&scene, &out), Executor::from(trusting)).unwrap();
    assert_same_image(&out, &expected);

    let plain = DistributedConfig {
        timeout: Some(Duration::from_secs(2)),
        ..workers_at(&[&worker.address])
    };
    let out = dir.path().join("plain.png");
    assert!(
        render_here(request(&scene, &out), Executor::from(plain)).is_err(),
        "a plaintext client is not served"
    );
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

/// A bidirectional render's light-tracing splats land anywhere on the film and travel with
/// their unit's result: the image is the in-process render's bytes on two workers, one of
/// them killed mid-render (its units requeued, their splats merged once), and it is not the
/// path tracer's image (the splats are there).
#[test]
fn a_bidirectional_render_is_the_same_bytes_on_workers_killed_or_not() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, [mut a, b]) = two_slow_workers(dir.path(), "100");
    let bidirectional = RenderOverrides {
        transport: Some(Transport::Bidirectional),
        ..SETTINGS_OVERRIDES
    };
    let reference = dir.path().join("bidirectional-in-process.png");
    render_here(
        request_with(&scene, &reference, &bidirectional, None),
        two_threads(),
    )
    .unwrap();
    let expected = image_bytes(&reference);
    let path_traced = dir.path().join("path.png");
    render_here(request(&scene, &path_traced), two_threads()).unwrap();
    assert!(
        image_bytes(&path_traced).1 != expected.1,
        "the bidirectional image is its own"
    );

    let out = dir.path().join("bidirectional.png");
    let json = dir.path().join("bidirectional.json");
    let coordinator = spawn_render(
        request_with(&scene, &out, &bidirectional, None),
        reporting_to(&json, workers_at(&[&a.address, &b.address])),
        Observers::none(),
        Interrupt::default(),
    );
    wait_for_units(&[&a, &b], 12);
    a.kill();
    coordinator.join().unwrap().unwrap();
    assert_same_image(&out, &expected);
    let report = workers_report(&json);
    assert!(
        report["result_bytes_per_unit_pixel"].as_f64().unwrap() > 16.0 * 13200.0 / 12288.0,
        "the results carry light splats: {report:#}"
    );
}

/// A film that writes alpha (`scenes/exported/film-outputs.lxs`: a 16-bit RGBA PNG, an RGB
/// TGA, a half RGBA EXR), with every AOV asked for, renders to the same bytes in-process and on
/// two workers, uniform, or adaptive with one worker killed mid-render; its alpha is 0 on the
/// sky and 1 on the floor, the EXR has the AOVs' channels, and each unit's reply carries 40
/// bytes of layers a pixel (alpha, albedo, normal, depth's two sums, samples) besides its 16
/// of sums.
#[test]
fn alpha_and_aovs_are_the_same_bytes_in_process_and_on_workers() {
    let overrides = RenderOverrides {
        spp: Some(16),
        aovs: yat_tracer::render::layers::Aovs::from_names("albedo,normal,depth,samples").unwrap(),
        ..SETTINGS_OVERRIDES
    };
    let bytes_per_pixel = same_files_in_process_and_on_workers(
        "film-outputs.lxs",
        &overrides,
        &["albedo.R", "N.Z", "Z", "samples"],
        |name, reference| {
            let png = image::open(reference).unwrap().to_rgba16();
            let alphas: std::collections::BTreeSet<u16> = png.pixels().map(|p| p.0[3]).collect();
            assert!(
                alphas.contains(&0) && alphas.contains(&65535),
                "{name}: transparent sky and opaque floor: {alphas:?}"
            );
            assert_eq!(png.get_pixel(48, 2).0[3], 0, "{name}: the sky");
            assert_eq!(png.get_pixel(48, 60).0[3], 65535, "{name}: the floor");
        },
    );
    assert_eq!(bytes_per_pixel, (16.0 + 40.0) * 12740.0 / 12288.0);
}

/// A scene with three light groups (`scenes/exported/lightgroups.lxs`) keeps each group's
/// light as a layer: the same PNG and EXR bytes in-process and on two workers, uniform, or
/// adaptive with one worker killed mid-render, and bidirectional (its light splats kept per
/// group too) with one killed; the EXR has a layer per group, and each unit's reply carries 36
/// bytes of layers a pixel (three groups' RGB sums) besides its 16 of sums.
#[test]
fn light_group_layers_are_the_same_bytes_in_process_and_on_workers() {
    let channels = [
        "lightgroup.daylight.R",
        "lightgroup.ceiling.G",
        "lightgroup.fill.B",
    ];
    let path = RenderOverrides {
        spp: Some(16),
        ..SETTINGS_OVERRIDES
    };
    let bytes_per_pixel =
        same_files_in_process_and_on_workers("lightgroups.lxs", &path, &channels, |_, _| {});
    assert_eq!(bytes_per_pixel, (16.0 + 36.0) * 12740.0 / 12288.0);
    let bidirectional = RenderOverrides {
        spp: Some(4),
        transport: Some(Transport::Bidirectional),
        ..SETTINGS_OVERRIDES
    };
    let bytes_per_pixel = same_files_in_process_and_on_workers(
        "lightgroups.lxs",
        &bidirectional,
        &channels,
        |_, _| {},
    );
    assert!(
        bytes_per_pixel > (16.0 + 36.0) * 12740.0 / 12288.0,
        "the results carry light splats: {bytes_per_pixel}"
    );
}

/// Renders `scenes/exported/<scene>` (whose Film writes a PNG and an EXR, perhaps a TGA) with
/// `overrides` in-process and on two workers, uniform, then (one worker killed mid-render)
/// adaptive, or again uniform for a bidirectional render (which takes no adaptive sampling),
/// and asserts every file is the same bytes both ways and the EXR has `channels`;
/// `check(name, png)` looks at each in-process PNG. Returns the bytes a unit's reply carries
/// per image pixel in the uniform render, 128x96 in 64-pixel tiles: with the 1-pixel border of
/// the scenes' mitchell of half-width 1.5, regions of 65x65, 65x65, 65x33 and 65x33 pixels,
/// 12740 for the 12288 of the image, 16 bytes of sums each and the layers'.
fn same_files_in_process_and_on_workers(
    scene: &str,
    overrides: &RenderOverrides,
    channels: &[&str],
    check: impl Fn(&str, &Path),
) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let scene = crate::workspace::workspace_root()
        .join("scenes/exported")
        .join(scene);
    let adaptive = yat_tracer::render::adaptive::AdaptiveSettings {
        threshold: 0.05,
        min_spp: 4,
    };
    let throttle = ["--throttle-ms", "50"];
    let mut bytes_per_pixel = None;
    let bidirectional = overrides.transport == Some(Transport::Bidirectional);
    let second = if bidirectional {
        ("killed", None)
    } else {
        ("adaptive", Some(adaptive))
    };
    for (name, adaptive) in [("uniform", None), second] {
        let reference = dir.path().join(format!("{name}-in-process.png"));
        render_here(
            request_with(&scene, &reference, overrides, adaptive),
            two_threads(),
        )
        .unwrap();
        let expected = film_files(&reference);
        check(name, &reference);
        let exr = exr::meta::MetaData::read_from_file(reference.with_extension("exr"), false);
        let found: Vec<String> = exr.unwrap().headers[0]
            .channels
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        for channel in channels {
            assert!(found.iter().any(|c| c == channel), "{name}: {found:?}");
        }

        let (mut a, b) = (Worker::start(&throttle), Worker::start(&throttle));
        let out = dir.path().join(format!("{name}-workers.png"));
        let json = dir.path().join(format!("{name}.json"));
        let coordinator = spawn_render(
            request_with(&scene, &out, overrides, adaptive),
            reporting_to(&json, workers_at(&[&a.address, &b.address])),
            Observers::none(),
            Interrupt::default(),
        );
        if name != "uniform" {
            wait_for_units(&[&a, &b], 2);
            a.kill();
        }
        coordinator.join().unwrap().unwrap();
        let got = film_files(&out);
        assert_eq!(got.len(), expected.len(), "{name}: the files written");
        for ((ext, got), (_, expected)) in got.iter().zip(&expected) {
            assert!(got == expected, "{name}: the {ext} differs from in-process");
        }
        if name == "uniform" {
            let report = workers_report(&json);
            let per_pixel = report["result_bytes_per_unit_pixel"].as_f64().unwrap();
            bytes_per_pixel = Some(per_pixel);
        }
    }
    bytes_per_pixel.expect("the uniform render's report")
}

/// The PNG, TGA and EXR of `out` that the render wrote, with their extensions.
fn film_files(out: &Path) -> Vec<(&'static str, Vec<u8>)> {
    ["png", "tga", "exr"]
        .into_iter()
        .filter_map(|ext| Some((ext, std::fs::read(out.with_extension(ext)).ok()?)))
        .collect()
}
