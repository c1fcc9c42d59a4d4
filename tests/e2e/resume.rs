//! End-to-end: a render stopped by a crash (SIGKILL) or by Ctrl-C (SIGINT), in-process or on
//! workers, resumes from its checkpoint to exactly the image of a render never stopped.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::util::*;

/// Enough samples that each of the 32 units takes a noticeable time, so that a render can be
/// stopped half-way.
const LONG: [&str; 4] = ["--spp", "256", "--resolution", "128x96"];

fn long_render(scene: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut command = render_command_with(scene, out, &LONG, extra);
    command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    command
}

/// Waits until `checkpoint` holds something other than `before` (a newer save), the render
/// still running.
fn wait_for_new_checkpoint(render: &mut Child, checkpoint: &Path, before: Option<&[u8]>) {
    let started = Instant::now();
    loop {
        if let Ok(bytes) = std::fs::read(checkpoint) {
            if Some(bytes.as_slice()) != before {
                return;
            }
        }
        assert!(
            render.try_wait().unwrap().is_none(),
            "the render ended before it saved a checkpoint"
        );
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no checkpoint saved"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success(), "kill -{name} failed");
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
    signal(&render, "INT");
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
