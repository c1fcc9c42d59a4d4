//! The scene's halt conditions: a Film `halttime` stops a uniform render, which writes the image
//! of every sample merged, says exactly which samples those are and keeps the checkpoint, so
//! the same command with the limit lifted (`--time-limit 0`) goes on to the bytes of a render
//! never stopped.

use crate::util::*;

/// Up to 8192 samples per pixel on a small film (3 million samples): the scene's one-second
/// halttime lands long before the end.
const LONG: [&str; 4] = ["--spp", "8192", "--resolution", "24x16"];

#[test]
fn a_scenes_halttime_writes_the_samples_merged_and_the_same_command_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let text = std::fs::read_to_string(&scene).unwrap();
    let film = "Film \"fleximage\"";
    assert!(text.contains(film), "the test scene has a Film");
    std::fs::write(
        &scene,
        text.replacen(film, "Film \"fleximage\" \"float halttime\" [1]", 1),
    )
    .unwrap();
    let out = dir.path().join("halted.png");
    let checkpoint = out.with_extension("resume");
    let halted = render_command_with(
        &scene,
        &out,
        &LONG,
        &["--threads", "2", "--checkpoint-every", "1000"],
    )
    .output()
    .unwrap();
    assert_success(&halted);
    let stderr = stderr_of(&halted);
    let (_, said) = stderr
        .split_once("the scene's halttime (1 s) reached: writing the image of the samples merged: ")
        .unwrap_or_else(|| panic!("no halt reached: {stderr}"));
    let held = said.split(';').next().unwrap();
    assert!(
        held.starts_with("samples 0..") || held.starts_with("no sample of every pixel"),
        "which samples the image holds: {said}"
    );
    assert!(checkpoint.exists(), "the checkpoint is kept for the rest");
    let stopped = image_bytes(&out);

    // The same command, its limit lifted, goes on from every sample merged.
    let lifted = ["--threads", "2", "--time-limit", "0"];
    let resumed = render_command_with(&scene, &out, &LONG, &lifted)
        .output()
        .unwrap();
    assert_success(&resumed);
    assert!(
        stderr_of(&resumed).contains("resuming from"),
        "{}",
        stderr_of(&resumed)
    );
    assert!(
        !checkpoint.exists(),
        "a finished render removes its checkpoint"
    );

    let whole = dir.path().join("whole.png");
    let never_stopped = render_command_with(
        &scene,
        &whole,
        &LONG,
        &[
            "--threads",
            "2",
            "--time-limit",
            "0",
            "--checkpoint-every",
            "0",
        ],
    )
    .output()
    .unwrap();
    assert_success(&never_stopped);
    assert!(
        !stderr_of(&never_stopped).contains("reached"),
        "--time-limit 0 lifts the halttime"
    );
    let expected = image_bytes(&whole);
    let resumed_bytes = image_bytes(&out);
    assert!(
        resumed_bytes.1 == expected.1,
        "the resumed EXR differs from a render never stopped"
    );
    assert!(
        resumed_bytes.0 == expected.0,
        "the resumed PNG differs from a render never stopped"
    );
    assert!(
        stopped.1 != expected.1,
        "the halted image is the final one: no halt happened"
    );
}

/// The test scene with its Film's `extra` parameters.
fn scene_with_film(dir: &std::path::Path, extra: &str) -> std::path::PathBuf {
    let scene = write_scene(dir);
    let text = std::fs::read_to_string(&scene).unwrap();
    let film = "Film \"fleximage\"";
    assert!(text.contains(film), "the test scene has a Film");
    std::fs::write(&scene, text.replacen(film, &format!("{film} {extra}"), 1)).unwrap();
    scene
}

/// The summary's "N spp (converged: ...)" of a render halted by convergence: (N, the line).
fn converged_at(output: &std::process::Output) -> (u32, String) {
    let stdout = String::from_utf8_lossy(&output.stdout).to_string();
    let line = stdout
        .lines()
        .find(|l| l.contains(" spp ("))
        .unwrap_or_else(|| panic!("no convergence in the summary: {stdout}"))
        .to_string();
    let spp = line
        .split(" spp (")
        .next()
        .and_then(|head| head.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no spp in {line}"));
    (spp, line)
}

const CONVERGING: [&str; 2] = ["--resolution", "32x24"];

/// Renders `scene` into `out` with `--time-limit` 1, 2, 4, ... seconds until a run stops at its
/// limit with something merged (on a busy machine the first limits may come before any unit
/// is), which it says, keeping its checkpoint. Panics if a run ends before its limit.
fn stop_by_time(scene: &std::path::Path, out: &std::path::Path, settings: &[&str], extra: &[&str]) {
    for limit in ["1", "2", "4", "8", "16"] {
        let every = ["--time-limit", limit, "--checkpoint-every", "1000"];
        let output = render_command_with(scene, out, settings, &[extra, &every[..]].concat())
            .output()
            .unwrap();
        let stderr = stderr_of(&output);
        if stderr.contains("reached before any unit was complete") {
            continue;
        }
        assert_success(&output);
        assert!(
            stderr.contains("--time-limit reached: writing the image of the samples merged: "),
            "the render ended before its {limit} s limit: {stderr}"
        );
        assert!(
            out.with_extension("resume").exists(),
            "the checkpoint is kept"
        );
        return;
    }
    panic!("no unit of {} was complete after 16 s", scene.display());
}

/// A scene's `haltthreshold` ends the render at the first round (of `convergencestep`
/// samples) whose image differs visibly from the last round's in at most that share of the
/// pixels, long before its haltspp; the round, and so the image, is the same in-process and on
/// two workers; `--halt-threshold -1` lifts it.
#[test]
fn a_scenes_haltthreshold_ends_the_render_at_the_same_round_anywhere() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_with_film(
        dir.path(),
        "\"float haltthreshold\" [0.05] \"float convergencestep\" [16] \"integer haltspp\" [4096]",
    );
    let here = dir.path().join("here.png");
    let in_process = render_command_with(&scene, &here, &CONVERGING, &["--threads", "2"])
        .output()
        .unwrap();
    assert_success(&in_process);
    let (spp, line) = converged_at(&in_process);
    assert!(line.contains("(converged: "), "{line}");
    assert!(
        (32..4096).contains(&spp) && spp % 16 == 0,
        "ends at a round boundary after the first test, before haltspp: {line}"
    );
    let share: f64 = line
        .split(", ")
        .find_map(|part| part.strip_suffix("%"))
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no share in {line}"));
    assert!(share <= 5.0, "{line}");

    let there = dir.path().join("there.png");
    let distributed = render_command_with(&scene, &there, &CONVERGING, &["--local-workers", "2"])
        .output()
        .unwrap();
    assert_success(&distributed);
    assert_eq!(
        converged_at(&distributed).0,
        spp,
        "the same round on workers"
    );
    assert!(
        image_bytes(&here) == image_bytes(&there),
        "a render halted by convergence is the same bytes in-process and on workers"
    );

    let lifted = dir.path().join("lifted.png");
    let output = render_command_with(
        &scene,
        &lifted,
        &CONVERGING,
        &["--threads", "2", "--halt-threshold", "-1", "--spp", "48"],
    )
    .output()
    .unwrap();
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout.contains("32x24 at 48 spp,"),
        "without the halt the render takes every sample: {stdout}"
    );
}

/// A render halted by convergence and stopped by a time limit keeps its round, its last test's
/// image and every sample merged in its checkpoint: the same command with the limit lifted
/// ends at the round, and with the bytes, of a render never stopped.
#[test]
fn a_converging_render_stopped_by_time_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    // A threshold of 0 ends on the first round after which no pixel changed visibly.
    let scene = scene_with_film(
        dir.path(),
        "\"float haltthreshold\" [0] \"float convergencestep\" [8]",
    );
    let long = ["--resolution", "160x120", "--spp", "1024"];
    let out = dir.path().join("halted.png");
    stop_by_time(&scene, &out, &long, &["--threads", "2"]);
    let (resumed, never_stopped) = resume_beside_a_render_never_stopped(&scene, &out, &long);
    let (spp, line) = converged_at(&resumed);
    assert_eq!(
        converged_at(&never_stopped).0,
        spp,
        "the same round: {line}"
    );
}

/// A distributed render stops at its time limit as an in-process one does: the image of every
/// sample merged, which it names, and the checkpoint kept; the same scene resumed in-process
/// goes on to the bytes of a render never stopped.
#[test]
fn a_distributed_render_stopped_by_time_resumes_in_process_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    // 6 million samples in 32 units of 0.2 million.
    let long = ["--spp", "512", "--resolution", "128x96"];
    let out = dir.path().join("halted.png");
    stop_by_time(&scene, &out, &long, &["--local-workers", "2"]);
    resume_beside_a_render_never_stopped(&scene, &out, &long);
}

/// Resumes the render stopped into `out` in-process, renders the same never stopped beside it
/// and checks the two are the same bytes; returns both runs' output.
fn resume_beside_a_render_never_stopped(
    scene: &std::path::Path,
    out: &std::path::Path,
    settings: &[&str],
) -> (std::process::Output, std::process::Output) {
    let resumed = render_command_with(scene, out, settings, &["--threads", "2"])
        .output()
        .unwrap();
    assert_success(&resumed);
    assert!(
        stderr_of(&resumed).contains("resuming from"),
        "{}",
        stderr_of(&resumed)
    );
    let whole = out.with_file_name("never-stopped.png");
    let never_stopped = render_command_with(
        scene,
        &whole,
        settings,
        &["--threads", "2", "--checkpoint-every", "0"],
    )
    .output()
    .unwrap();
    assert_success(&never_stopped);
    assert!(
        image_bytes(out) == image_bytes(&whole),
        "the resumed render differs from one never stopped"
    );
    (resumed, never_stopped)
}
