//! Adaptive sampling end to end: the rounds are decided from merged results only, so the image
//! is the same bytes in-process, on two workers, with a worker killed half way and after a stop
//! and resume; the sample map shows where the samples went.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use yat::render::{Executor, Observers};
use yat::shutdown::Interrupt;
use yat_tracer::render::adaptive::AdaptiveSettings;

use crate::util::*;

/// Up to 64 samples per pixel in five rounds (4, 4, 8, 16, 32 samples) of at most 4 units
/// (the --spp and --resolution of [`SETTINGS`]).
const ADAPTIVE: [&str; 8] = [
    "--spp",
    "64",
    "--resolution",
    "128x96",
    "--noise-threshold",
    "0.15",
    "--min-spp",
    "4",
];

fn adaptive_render(scene: &Path, out: &Path, extra: &[&str]) -> Command {
    piped_render_command(scene, out, &ADAPTIVE, extra)
}

fn assert_same(out: &Path, expected: &(Vec<u8>, Vec<u8>), what: &str) {
    let (png, exr) = image_bytes(out);
    assert!(exr == expected.1, "{what}: the EXR differs from in-process");
    assert!(png == expected.0, "{what}: the PNG differs from in-process");
}

#[test]
fn adaptive_images_are_the_same_bytes_wherever_and_however_rendered() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());

    // In-process, with the sample map.
    let reference = dir.path().join("in-process.png");
    let map = dir.path().join("map.png");
    let output = adaptive_render(
        &scene,
        &reference,
        &["--threads", "2", "--sample-map", map.to_str().unwrap()],
    )
    .output()
    .unwrap();
    assert_success(&output);
    let expected = image_bytes(&reference);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("sample map"), "{stdout}");

    // The map: the flat walls stop early, the lamp's edges and the glossy sphere go on.
    let map = image::open(&map).unwrap().to_luma8();
    assert_eq!(map.dimensions(), (128, 96));
    let values: Vec<u8> = map.pixels().map(|p| p.0[0]).collect();
    let (least, most) = (*values.iter().min().unwrap(), *values.iter().max().unwrap());
    assert_eq!(most, 255);
    assert!(least < most, "every pixel got the same samples");
    let white = values.iter().filter(|&&v| v == 255).count();
    assert!(
        white < values.len() * 9 / 10 && white > 0,
        "{white} of {} pixels at the most samples",
        values.len()
    );

    // Two local workers.
    let out = dir.path().join("local.png");
    let output = adaptive_render(&scene, &out, &["--local-workers", "2"])
        .output()
        .unwrap();
    assert_success(&output);
    assert_same(&out, &expected, "2 local workers");

    // Two workers, one killed half way: its units go to the other. The coordinator is the
    // library's render in this process.
    let mut a = Worker::start(&["--throttle-ms", "40"]);
    let b = Worker::start(&["--throttle-ms", "40"]);
    let out = dir.path().join("killed.png");
    let adaptive = AdaptiveSettings {
        threshold: 0.15,
        min_spp: 4,
    };
    let coordinator = spawn_render(
        request_with(&scene, &out, &SETTINGS_OVERRIDES, Some(adaptive)),
        Executor::from(workers_at(&[&a.address, &b.address])),
        Observers::none(),
        Interrupt::default(),
    );
    wait_for_units(&[&a, &b], 6);
    a.kill();
    coordinator.join().unwrap().unwrap();
    assert_same(&out, &expected, "a worker killed half way");

    // Stopped by Ctrl-C once a checkpoint is saved, then resumed in-process. The first part
    // runs on a throttled worker (250 ms a unit, a few dozen units), so the signal always
    // lands mid-render.
    let slow = Worker::start(&["--throttle-ms", "250"]);
    let out = dir.path().join("resumed.png");
    let checkpoint = out.with_extension("resume");
    let every = ["--checkpoint-every", "0.02"];
    let first = [&every[..], &["--workers", &slow.address]].concat();
    let mut render = adaptive_render(&scene, &out, &first).spawn().unwrap();
    let started = Instant::now();
    while !checkpoint.exists() {
        assert!(
            render.try_wait().unwrap().is_none(),
            "ended before a checkpoint"
        );
        assert!(started.elapsed() < Duration::from_secs(60), "no checkpoint");
        std::thread::sleep(Duration::from_millis(5));
    }
    // Into a later round, where the checkpoint holds decisions.
    std::thread::sleep(Duration::from_millis(300));
    signal(render.id(), "INT");
    let stopped = render.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&stopped.stderr);
    assert_eq!(stopped.status.code(), Some(130), "{stderr}");
    assert!(checkpoint.exists(), "{stderr}");
    let finished = adaptive_render(&scene, &out, &[&every[..], &["--threads", "1"]].concat())
        .output()
        .unwrap();
    assert_success(&finished);
    let stderr = String::from_utf8_lossy(&finished.stderr);
    assert!(stderr.contains("resuming from"), "{stderr}");
    assert_same(&out, &expected, "stopped and resumed");
}

#[test]
fn an_adaptive_render_of_one_round_matches_the_uniform_render() {
    // With --min-spp equal to --spp an adaptive render is one round of every pixel's samples:
    // the uniform render's image, up to the f32 rounding of the other unit cut.
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let settings = settings_with_spp(16);
    let uniform = dir.path().join("uniform.png");
    render_here(
        request_with(&scene, &uniform, &settings, None),
        two_threads(),
    )
    .unwrap();
    let adaptive = dir.path().join("adaptive.png");
    let one_round = AdaptiveSettings {
        threshold: 0.5,
        min_spp: 16,
    };
    let request = request_with(&scene, &adaptive, &settings, Some(one_round));
    render_here(request, two_threads()).unwrap();
    // min-spp = spp: one round, every pixel 16 samples, the same samples as the uniform
    // render; only the unit cut differs (one unit per tile instead of 2 passes), which changes
    // the f32 sums' rounding at most.
    let a = image::open(uniform.with_extension("exr"))
        .unwrap()
        .to_rgb32f();
    let b = image::open(adaptive.with_extension("exr"))
        .unwrap()
        .to_rgb32f();
    let worst = a
        .pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| (p.0[c] - q.0[c]).abs() / p.0[c].abs().max(1e-3)))
        .fold(0f32, f32::max);
    assert!(worst < 1e-4, "relative difference {worst}");
}

/// The round `--time-limit` stopped at, from the render's stderr.
fn round_written(output: &std::process::Output) -> u32 {
    assert_success(output);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let (_, rest) = stderr
        .split_once("--time-limit reached: writing the image of round ")
        .unwrap_or_else(|| panic!("no time limit reached: {stderr}"));
    rest.split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn a_time_limit_writes_the_last_round_and_the_same_command_goes_on() {
    // A threshold no block reaches and up to 8192 samples per pixel in 12 rounds: the limit
    // lands after round 0 (1,536 samples) and long before the last (3 million samples).
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let settings = [
        "--spp",
        "8192",
        "--resolution",
        "24x16",
        "--noise-threshold",
        "0.00001",
        "--min-spp",
        "4",
    ];
    let out = dir.path().join("limited.png");
    let map = dir.path().join("map.png");
    let checkpoint = out.with_extension("resume");
    let limited = render_command_with(
        &scene,
        &out,
        &settings,
        &[
            "--threads",
            "2",
            "--time-limit",
            "1",
            "--checkpoint-every",
            "1000",
            "--sample-map",
            map.to_str().unwrap(),
        ],
    )
    .output()
    .unwrap();
    let round = round_written(&limited);
    assert!(round < 11, "round {round} is the last: no limit reached");
    assert!(checkpoint.exists(), "the checkpoint is kept for the rest");
    // The map is the round's: the most samples any pixel has are the round's end, 4 x 2^k.
    assert!(map.exists());
    let stdout = String::from_utf8_lossy(&limited.stdout);
    assert!(
        stdout.contains(&format!("to {} (white)", 4u32 << round)),
        "round {round}: {stdout}"
    );
    let stopped = image_bytes(&out);

    // The same command without the limit goes on from every sample merged, to the image of a
    // render never stopped.
    let resumed = render_command_with(&scene, &out, &settings, &["--threads", "1"])
        .output()
        .unwrap();
    assert_success(&resumed);
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert!(stderr.contains("resuming from"), "{stderr}");
    assert!(
        !checkpoint.exists(),
        "a finished render removes its checkpoint"
    );
    let whole = dir.path().join("whole.png");
    let output = render_command_with(
        &scene,
        &whole,
        &settings,
        &["--threads", "2", "--checkpoint-every", "0", "--quiet"],
    )
    .output()
    .unwrap();
    assert_success(&output);
    let expected = image_bytes(&whole);
    assert_same(&out, &expected, "a time-limited render resumed");
    assert!(
        stopped.1 != expected.1,
        "round {round}'s image is the final one"
    );
}

/// Adaptive sampling is refused for a bidirectional render, saying why (its light splats land
/// outside the blocks a round renders) and what to do instead.
#[test]
fn an_adaptive_bidirectional_render_is_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let overrides = yat_tracer::render::RenderOverrides {
        transport: Some(yat_tracer::integrator::Transport::Bidirectional),
        ..SETTINGS_OVERRIDES
    };
    let adaptive = AdaptiveSettings {
        threshold: 0.1,
        min_spp: 4,
    };
    let parsed = yat::scene::ParsedScene::load(&scene, yat::scene::Warnings::Keep).unwrap();
    let refused = yat::render::RenderRequest::new(
        parsed,
        &overrides,
        Some(adaptive),
        Some(dir.path().join("out.png")),
    );
    let message = format!("{:#}", refused.err().expect("refused"));
    assert!(
        message.contains("bidirectional") && message.contains("--integrator path"),
        "{message}"
    );
}
