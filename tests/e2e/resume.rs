//! End-to-end: a render stopped by a crash (SIGKILL), by Ctrl-C (SIGINT) or by the caller of the
//! library's render, in-process or on workers, resumes from its checkpoint to exactly the image
//! of a render never stopped.

use std::path::Path;
use std::process::{Child, Command};
use std::time::{Duration, Instant};

use yat::render::Observers;
use yat::shutdown::{Interrupt, Interrupted};

use crate::util::*;

/// Enough samples that each of the 32 units takes a noticeable time, so that a render can be
/// stopped half-way.
const LONG: [&str; 4] = ["--spp", "256", "--resolution", "128x96"];

fn long_render(scene: &Path, out: &Path, extra: &[&str]) -> Command {
    piped_render_command(scene, out, &LONG, extra)
}

/// Waits until `checkpoint` holds something other than `before` (a newer save), the render
/// still running.
fn wait_for_new_checkpoint(render: &mut Child, checkpoint: &Path, before: Option<&[u8]>) {
    wait_until(render, "saved a checkpoint", || {
        std::fs::read(checkpoint).is_ok_and(|bytes| Some(bytes.as_slice()) != before)
    });
}

/// Waits until `done` (the render has `what`), the render still running.
fn wait_until(render: &mut Child, what: &str, done: impl Fn() -> bool) {
    let started = Instant::now();
    while !done() {
        assert!(
            render.try_wait().unwrap().is_none(),
            "the render ended before it {what}"
        );
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "the render has not {what} in 60 s"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn a_killed_or_interrupted_render_resumes_to_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let fresh = dir.path().join("fresh.png");
    let output = long_render(
        &scene,
        &fresh,
        &["--threads", "2", "--checkpoint-every", "0"],
    )
    .output()
    .unwrap();
    assert_success(&output);
    assert!(!fresh.with_extension("resume").exists(), "checkpoints off");
    let expected = std::fs::read(fresh.with_extension("exr")).unwrap();

    let out = dir.path().join("stopped.png");
    let checkpoint = out.with_extension("resume");
    let every = ["--checkpoint-every", "0.05"];

    // 1. The coordinator of a distributed render dies without warning.
    let mut render = long_render(
        &scene,
        &out,
        &[&every[..], &["--local-workers", "1"]].concat(),
    )
    .spawn()
    .unwrap();
    wait_for_new_checkpoint(&mut render, &checkpoint, None);
    render.kill().unwrap();
    render.wait().unwrap();
    let after_crash = std::fs::read(&checkpoint).unwrap();

    // 2. An in-process render of the same scene picks it up, and is stopped by Ctrl-C.
    let mut render = long_render(
        &scene,
        &out,
        &[&every[..], &["--threads", "2", "--preview-every", "0.05"]].concat(),
    )
    .spawn()
    .unwrap();
    wait_for_new_checkpoint(&mut render, &checkpoint, Some(&after_crash));
    signal(render.id(), "INT");
    let interrupted = render.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&interrupted.stderr);
    assert_eq!(interrupted.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("resuming from"), "{stderr}");
    assert!(
        stderr.contains("interrupted") && stderr.contains("kept in"),
        "{stderr}"
    );
    assert!(!out.exists(), "no final image from a stopped render");
    let preview = image::open(out.with_extension("preview.png"))
        .expect("an in-process render writes previews")
        .to_rgb8();
    assert!(
        preview.pixels().any(|p| p.0 != [0, 0, 0]),
        "the preview shows the render so far"
    );
    let after_interrupt = std::fs::read(&checkpoint).unwrap();
    assert_ne!(after_interrupt, after_crash, "the second run added units");

    // 3. The same command again finishes the render: the image of a render never stopped.
    let finished = long_render(&scene, &out, &[&every[..], &["--threads", "2"]].concat())
        .output()
        .unwrap();
    assert_success(&finished);
    let stderr = String::from_utf8_lossy(&finished.stderr);
    let resumed_line = stderr
        .lines()
        .find(|l| l.starts_with("resuming from"))
        .unwrap_or_else(|| panic!("{stderr}"));
    let units_done: u32 = resumed_line
        .split(": ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{resumed_line}"));
    assert!((2..32).contains(&units_done), "{resumed_line}");
    assert_eq!(
        std::fs::read(out.with_extension("exr")).unwrap(),
        expected,
        "resumed image differs from the uninterrupted one"
    );
    assert!(!checkpoint.exists(), "the checkpoint is removed at the end");
    assert!(
        !out.with_extension("preview.png").exists(),
        "and so is the preview"
    );
}

/// A bidirectional render killed once its checkpoint holds units resumes to the bytes of one
/// never stopped: the checkpoint keeps the light splats' sums and the light subpaths they are
/// over as it keeps the camera samples' sums.
#[test]
fn a_killed_bidirectional_render_resumes_to_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let bidirectional = ["--integrator", "bidirectional", "--threads", "2"];
    let fresh = dir.path().join("fresh.png");
    let output = long_render(
        &scene,
        &fresh,
        &[&bidirectional[..], &["--checkpoint-every", "0"]].concat(),
    )
    .output()
    .unwrap();
    assert_success(&output);
    let expected = std::fs::read(fresh.with_extension("exr")).unwrap();

    let out = dir.path().join("stopped.png");
    let checkpoint = out.with_extension("resume");
    let every = ["--checkpoint-every", "0.05"];
    let mut render = long_render(&scene, &out, &[&bidirectional[..], &every[..]].concat())
        .spawn()
        .unwrap();
    wait_for_new_checkpoint(&mut render, &checkpoint, None);
    render.kill().unwrap();
    render.wait().unwrap();

    let finished = long_render(&scene, &out, &[&bidirectional[..], &every[..]].concat())
        .output()
        .unwrap();
    assert_success(&finished);
    let stderr = String::from_utf8_lossy(&finished.stderr);
    assert!(stderr.contains("resuming from"), "{stderr}");
    assert_eq!(
        std::fs::read(out.with_extension("exr")).unwrap(),
        expected,
        "resumed bidirectional image differs from the uninterrupted one"
    );
}

/// With checkpoints off, SIGTERM stops a render as with them on, and says what that costs: exit
/// status 130, the signal named, the merged samples lost to the next run and the preview that
/// shows them; no checkpoint, no final image.
#[test]
fn sigterm_with_checkpoints_off_says_the_merged_samples_are_lost() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("off.png");
    let preview = out.with_extension("preview.png");
    let mut render = long_render(
        &scene,
        &out,
        &[
            "--threads",
            "2",
            "--checkpoint-every",
            "0",
            "--preview-every",
            "0.05",
        ],
    )
    .spawn()
    .unwrap();
    // An in-process render writes its preview after merging a unit.
    wait_until(&mut render, "merged a unit", || preview.exists());
    signal(render.id(), "TERM");
    let stopped = render.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&stopped.stderr);
    assert_eq!(stopped.status.code(), Some(130), "{stderr}");
    let line = stderr
        .lines()
        .find(|l| l.contains("interrupted by SIGTERM; "))
        .unwrap_or_else(|| panic!("no word of the signal:\n{stderr}"));
    let shown_in = format!(
        " samples) are lost: the same command starts over; {} shows them",
        preview.display()
    );
    let (percent, samples) = line
        .split_once("interrupted by SIGTERM; checkpoints are off (--checkpoint-every 0), so the ")
        .and_then(|(_, rest)| rest.strip_suffix(&shown_in))
        .and_then(|rest| rest.split_once("% of the samples merged ("))
        .and_then(|(percent, samples)| {
            Some((percent.parse::<f64>().ok()?, samples.parse::<u64>().ok()?))
        })
        .unwrap_or_else(|| panic!("{line}"));
    // 256 spp over 128 x 96 pixels, in 8 passes over 64x64 and 64x32 tiles: units of 131072 or
    // 65536 samples; at least one of them merged, not all.
    let (total, smallest) = (256 * 128 * 96, 32 * 64 * 32);
    assert!(
        samples >= smallest && samples < total && samples % smallest == 0,
        "{line}"
    );
    let share = 100.0 * samples as f64 / total as f64;
    assert!((percent - share).abs() < 0.06, "{line}");
    assert!(!out.exists(), "no final image from a stopped render");
    assert!(!out.with_extension("resume").exists(), "checkpoints off");
    let shown = image::open(&preview).unwrap().to_rgb8();
    assert!(
        shown.pixels().any(|p| p.0 != [0, 0, 0]),
        "the preview shows them"
    );
}

#[test]
fn a_checkpoint_of_another_render_is_not_used() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("other.png");
    let checkpoint = out.with_extension("resume");
    let mut render = long_render(&scene, &out, &["--checkpoint-every", "0.05", "--seed", "1"])
        .spawn()
        .unwrap();
    wait_for_new_checkpoint(&mut render, &checkpoint, None);
    render.kill().unwrap();
    render.wait().unwrap();

    let reference = dir.path().join("reference.png");
    assert_success(
        &long_render(&scene, &reference, &[])
            .args(["--checkpoint-every", "0"])
            .output()
            .unwrap(),
    );
    // Same output path, another seed: the checkpoint is someone else's.
    let output = long_render(&scene, &out, &["--checkpoint-every", "0.05"])
        .output()
        .unwrap();
    assert_success(&output);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("not resuming from") && stderr.contains("another render"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read(out.with_extension("exr")).unwrap(),
        std::fs::read(reference.with_extension("exr")).unwrap()
    );
}

/// The library's render stopped by its caller (the interrupt it was given) saves its
/// checkpoint, and the same request resumes from it to the image of a render never stopped.
#[test]
fn a_render_its_caller_interrupts_resumes_to_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let long = settings_with_spp(256);
    let fresh = dir.path().join("fresh.png");
    render_here(request_with(&scene, &fresh, &long, None), two_threads()).unwrap();

    let out = dir.path().join("stopped.png");
    let checkpoint = out.with_extension("resume");
    let checkpointing = || Observers {
        checkpoint_every: Some(Duration::from_millis(50)),
        ..Observers::none()
    };
    let interrupt = Interrupt::default();
    let render = spawn_render(
        request_with(&scene, &out, &long, None),
        two_threads(),
        checkpointing(),
        interrupt.clone(),
    );
    let started = Instant::now();
    while !checkpoint.exists() {
        assert!(
            !render.is_finished(),
            "the render ended before a checkpoint"
        );
        assert!(started.elapsed() < Duration::from_secs(60), "no checkpoint");
        std::thread::sleep(Duration::from_millis(10));
    }
    interrupt.cancel();
    let error = render.join().unwrap().err().expect("the render stops");
    let stopped = error
        .downcast_ref::<Interrupted>()
        .unwrap_or_else(|| panic!("{error:?}"));
    assert_eq!(stopped.cause, "its caller");
    assert!(stopped.kept.contains("kept in"), "{}", stopped.kept);
    assert!(!out.exists(), "no final image from a stopped render");

    let report = yat::render::render(
        request_with(&scene, &out, &long, None),
        &two_threads(),
        checkpointing(),
        Interrupt::default(),
    )
    .unwrap();
    assert!(
        report.samples < 256 * 128 * 96,
        "rendered only what the checkpoint lacked: {} samples",
        report.samples
    );
    assert_eq!(
        std::fs::read(out.with_extension("exr")).unwrap(),
        std::fs::read(fresh.with_extension("exr")).unwrap(),
        "resumed image differs from the uninterrupted one"
    );
    assert!(!checkpoint.exists(), "the checkpoint is removed at the end");
}
