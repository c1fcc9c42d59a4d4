//! End-to-end: what `yat` reads and writes on disk is confined and bounded. Hostile scenes are
//! refused at the build budget in-process and on a worker; an output named like a side file is
//! refused; a scene cannot choose the output folder; a symlink or a FIFO planted at the
//! checkpoint is neither followed nor read; settings beyond the limits name the limit.

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::hostile;
use crate::util::*;

/// The address space a `yat` refusing a hostile scene runs in: a build without budget would
/// need tens of gigabytes (and fail with an allocation error, not the budget's message).
const ADDRESS_SPACE: u64 = 2 << 30;

/// Generous for a debug build on a loaded machine; each refusal takes well under a second.
const QUICKLY: Duration = Duration::from_secs(20);

/// Each bomb: `yat render` refuses it, naming the limit's flag and the file:line where it was
/// reached, quickly and within 2 GiB of address space.
#[test]
fn hostile_scenes_are_refused_at_the_build_budget() {
    // The bomb's memory estimate goes over first under this address space (see memory.rs):
    // with the memory figure raised, the primitive limit is what stops it.
    let unbounded_memory = ["--max-memory-mib", "100000000"];
    let cases = [
        (hostile::include_fan_out(), "--max-include-visits", "level"),
        (
            hostile::instancing_bomb(),
            "--max-primitives",
            "level3.lxo:",
        ),
        (hostile::huge_image(), "--max-texels", "main.lxs:6:"),
    ];
    for (files, flag, at) in cases {
        let dir = tempfile::tempdir().unwrap();
        let scene = write_files(dir.path(), &files);
        let out = dir.path().join("out.png");
        let output = run_in_address_space(
            render_command(&scene, &out, &unbounded_memory),
            ADDRESS_SPACE,
            QUICKLY,
        );
        let err = stderr_of(&output);
        assert!(!output.status.success(), "{flag}: rendered");
        assert_eq!(output.status.code(), Some(1), "{flag}: {err}");
        assert!(
            err.contains(flag) && err.contains(at) && err.contains("limit"),
            "{flag}: {err}"
        );
        assert!(!out.exists());
    }
}

/// A limit set low on the command line is the one enforced, on `yat check` as on `yat render`.
#[test]
fn budget_flags_set_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let check = |extra: &[&str]| {
        Command::new(YAT)
            .arg("check")
            .arg(&scene)
            .args(extra)
            .output()
            .unwrap()
    };
    assert_success(&check(&[]));
    for (flag, low) in [
        ("--max-primitives", "3"),
        ("--max-texels", "10"),
        ("--max-include-visits", "0"),
        ("--max-scene-mib", "0"),
        ("--max-memory-mib", "0"),
    ] {
        let output = check(&[flag, low]);
        assert!(!output.status.success(), "{flag} {low}");
        assert!(
            stderr_of(&output).contains(flag),
            "{flag}: {}",
            stderr_of(&output)
        );
    }
}

/// A worker with a lower budget than the coordinator refuses the scene, and the render fails
/// with the worker's reason.
#[test]
fn a_worker_enforces_its_own_budget() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let worker = Worker::start(&["--max-primitives", "3"]);
    let out = dir.path().join("out.png");
    let output = render_command(
        &scene,
        &out,
        &["--workers", &worker.address, "--timeout", "20"],
    )
    .output()
    .unwrap();
    let err = stderr_of(&output);
    assert!(!output.status.success(), "{err}");
    assert!(err.contains("--max-primitives"), "{err}");
    assert!(!out.exists());
}

#[test]
fn an_output_named_like_a_side_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let before = std::fs::read_dir(dir.path()).unwrap().count();
    for name in ["x.resume", "x.preview.png", "x.tga", "x.exr"] {
        let output = render(&scene, &dir.path().join(name), &[]);
        let err = stderr_of(&output);
        assert!(!output.status.success(), "{name}: rendered");
        assert!(
            err.contains("choose a name ending in .png"),
            "{name}: {err}"
        );
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        before,
        "nothing written"
    );
}

/// A scene whose Film filename names another folder writes only to the current folder, with
/// a warning; one that names no file is refused.
#[test]
fn a_film_filename_cannot_leave_the_current_folder() {
    let root = tempfile::tempdir().unwrap();
    let work = root.path().join("a/b/work");
    std::fs::create_dir_all(&work).unwrap();
    let elsewhere = root.path().join("elsewhere");
    let cases = [
        "../../escape".to_string(),
        format!("{}", elsewhere.display()),
    ];
    // `yat render scene.lxs -q` in `work`, scene.lxs holding `text`.
    let render_in_work = |text: String| {
        std::fs::write(work.join("scene.lxs"), text).unwrap();
        Command::new(YAT)
            .current_dir(&work)
            .args(["render", "scene.lxs", "-q"])
            .output()
            .unwrap()
    };
    for filename in &cases {
        let output = render_in_work(hostile::scene("Shape \"sphere\"").replace(
            "\"string filename\" [\"hostile\"]",
            &format!("\"string filename\" [\"{filename}\"]"),
        ));
        assert_success(&output);
        let err = stderr_of(&output);
        let name = Path::new(filename).file_name().unwrap().to_str().unwrap();
        assert!(
            err.contains("current folder") && err.contains(&format!("{name}.png")),
            "{err}"
        );
        assert!(work.join(format!("{name}.png")).is_file());
    }
    assert!(!root.path().join("a/escape.png").exists());
    assert!(!elsewhere.with_extension("png").exists());

    let output = render_in_work(hostile::scene("").replace("[\"hostile\"]", "[\"..\"]"));
    assert!(!output.status.success());
    assert!(
        stderr_of(&output).contains("names no file"),
        "{}",
        stderr_of(&output)
    );
}

/// Waits for `child` at most `limit`; kills it and fails the test past that.
fn wait_at_most(mut child: Child, limit: Duration) -> Output {
    if wait_for_exit(&mut child, limit).is_none() {
        let _ = child.kill();
        panic!("still running after {limit:?}");
    }
    child.wait_with_output().unwrap()
}

/// A symlink planted at the checkpoint and at the preview: the render does not read through
/// them, replaces the links themselves when it saves, and the files they point to are intact.
#[test]
fn planted_symlinks_at_the_side_files_are_not_followed() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("out.png");
    let precious = dir.path().join("precious.txt");
    std::fs::write(&precious, b"do not touch").unwrap();
    let checkpoint = out.with_extension("resume");
    let preview = out.with_extension("preview.png");
    std::os::unix::fs::symlink(&precious, &checkpoint).unwrap();
    std::os::unix::fs::symlink(&precious, &preview).unwrap();
    let mut render = render_command_with(
        &scene,
        &out,
        &["--spp", "256", "--resolution", "128x96"],
        &["--checkpoint-every", "0.05", "--preview-every", "0.05"],
    );
    let child = render
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Both links are replaced by regular files while the render runs.
    let started = Instant::now();
    let is_file = |p: &Path| std::fs::symlink_metadata(p).is_ok_and(|m| m.is_file());
    while !(is_file(&checkpoint) && is_file(&preview)) {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no checkpoint or preview saved"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let output = wait_at_most(child, Duration::from_secs(120));
    assert_success(&output);
    assert!(
        stderr_of(&output).contains("not a regular file"),
        "{}",
        stderr_of(&output)
    );
    assert_eq!(std::fs::read(&precious).unwrap(), b"do not touch");
    let leftovers = names_in(dir.path(), |n| n.ends_with(".tmp"));
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// A FIFO at the checkpoint's name: the render neither blocks opening it nor reads it.
#[test]
fn a_fifo_at_the_checkpoint_does_not_hang_the_render() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("out.png");
    let fifo = out.with_extension("resume");
    let status = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(status.success());
    let child = render_command(&scene, &out, &[])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let output = wait_at_most(child, Duration::from_secs(60));
    assert_success(&output);
    assert!(
        stderr_of(&output).contains("not a regular file"),
        "{}",
        stderr_of(&output)
    );
    assert!(out.is_file());
}

/// Settings beyond the limits are refused with the limit named, before anything is allocated.
#[test]
fn settings_beyond_the_limits_name_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("out.png");
    let cases = [
        (
            ["--spp", "4294967295", "--resolution", "8x8"],
            "at most 16777216",
        ),
        (
            ["--spp", "1", "--resolution", "65536x65536"],
            "268435456 pixels in all",
        ),
    ];
    for (settings, limit) in cases {
        let command = render_command_with(&scene, &out, &settings, &[]);
        let output = run_in_address_space(command, ADDRESS_SPACE, QUICKLY);
        assert!(!output.status.success(), "{settings:?}");
        assert!(stderr_of(&output).contains(limit), "{}", stderr_of(&output));
    }
}
