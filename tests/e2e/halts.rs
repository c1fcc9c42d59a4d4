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
