//! `yat luxconsole` and the binary under the name `luxconsole`: LuxRender 1.x's command line
//! rendered by the real `yat`. YAT is deterministic (a sample's random numbers depend only on
//! the pixel, the sample index, the dimension and the seed, and the film's sums are exact), so
//! a scene rendered through luxconsole's command line must give the very pixels `yat render`
//! gives it with the same settings: every comparison here is byte for byte.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use yat::isa::{self, ISA_ENV, V3_NAME, V3_SUFFIX};

use crate::util::{assert_success, names_in, stderr_of, write_scene, yat_in, YAT};

/// The end-to-end tests' box (an Include'd materials file, PNG textures) at 48x36 and 16
/// samples per pixel from its Film, since luxconsole's command line sets neither.
fn small_scene(dir: &Path) -> PathBuf {
    let scene = write_scene(dir);
    let text = std::fs::read_to_string(&scene).unwrap();
    let film = r#"Film "fleximage" "integer xresolution" [128] "integer yresolution" [96]"#;
    assert!(text.contains(film), "the fixture's Film changed");
    let small = r#"Film "fleximage" "integer xresolution" [48] "integer yresolution" [36]
  "integer haltspp" [16]"#;
    std::fs::write(&scene, text.replace(film, small)).unwrap();
    scene
}

/// The image's 8-bit RGB pixels.
fn pixels(png: &Path) -> image::RgbImage {
    image::open(png)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", png.display()))
        .to_rgb8()
}

/// `yat render SCENE --threads 2 -o DIR/reference.png`: the pixels every luxconsole render of
/// the scene must have.
fn reference(dir: &Path, scene: &Path) -> image::RgbImage {
    let out = dir.join("reference.png");
    let output = Command::new(YAT)
        .arg("render")
        .arg(scene)
        .args(["--threads", "2", "-o"])
        .arg(&out)
        .env_remove("YAT_TOKEN")
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert_success(&output);
    let image = pixels(&out);
    assert_eq!(image.dimensions(), (48, 36));
    image
}

/// `exe` (yat, or yat under the name luxconsole) in the folder `cwd`, with these arguments.
fn command(exe: &Path, cwd: &Path, args: &[&str]) -> Command {
    let mut command = Command::new(exe);
    command
        .args(args)
        .current_dir(cwd)
        .env_remove("YAT_TOKEN")
        .env_remove("YAT_UNIT_DEADLINE")
        .stdin(Stdio::null());
    command
}

fn luxconsole(cwd: &Path, args: &[&str]) -> Output {
    let mut full = vec!["luxconsole"];
    full.extend_from_slice(args);
    command(Path::new(YAT), cwd, &full).output().unwrap()
}

fn folder(root: &Path, name: &str) -> PathBuf {
    let dir = root.join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn path_str(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn luxconsole_s_command_line_renders_yat_render_s_image_beside_the_scene() {
    let root = tempfile::tempdir().unwrap();
    let scenes = folder(root.path(), "scene");
    let elsewhere = folder(root.path(), "elsewhere");
    let scene = small_scene(&scenes);
    let expected = reference(root.path(), &scene);

    let output = luxconsole(&elsewhere, &["-t", "2", "-o", "OUT.png", path_str(&scene)]);
    assert_success(&output);
    // A relative -o is in the scene's folder, where luxconsole (which changes into it) writes.
    assert!(!elsewhere.join("OUT.png").exists());
    assert_eq!(pixels(&scenes.join("OUT.png")), expected);

    // LuxRender's -o is a base name: its extension gives way to the PNG's.
    let output = luxconsole(&elsewhere, &["-t", "2", "-o", "base.exr", path_str(&scene)]);
    assert_success(&output);
    assert_eq!(pixels(&scenes.join("base.png")), expected);
}

#[test]
fn the_scene_on_standard_input_renders_against_the_current_folder() {
    let root = tempfile::tempdir().unwrap();
    let scenes = folder(root.path(), "scene");
    let scene = small_scene(&scenes);
    let expected = reference(root.path(), &scene);

    // Its Include and its textures are relative: they resolve in the current folder.
    let mut child = command(
        Path::new(YAT),
        &scenes,
        &["luxconsole", "-t", "2", "-o", "stdin.png", "-"],
    )
    .stdin(Stdio::piped())
    .stdout(Stdio::piped())
    .stderr(Stdio::piped())
    .spawn()
    .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(&std::fs::read(&scene).unwrap())
        .unwrap();
    let output = child.wait_with_output().unwrap();
    assert_success(&output);
    assert_eq!(pixels(&scenes.join("stdin.png")), expected);
    // The staged copy is gone.
    let left = names_in(&scenes, |name| name.starts_with(".yat-stdin-"));
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn the_binary_under_the_name_luxconsole_reads_luxconsole_s_command_line() {
    let root = tempfile::tempdir().unwrap();
    let scenes = folder(root.path(), "scene");
    let bin = folder(root.path(), "bin");
    let scene = small_scene(&scenes);
    let expected = reference(root.path(), &scene);
    let named = bin.join("luxconsole");
    std::os::unix::fs::symlink(YAT, &named).unwrap();

    let output = command(
        &named,
        root.path(),
        &["-t", "2", "-o", "named.png", path_str(&scene)],
    )
    .output()
    .unwrap();
    assert_success(&output);
    assert_eq!(pixels(&scenes.join("named.png")), expected);

    // Its help is luxconsole's options, not yat's subcommands.
    let help = command(&named, root.path(), &["--help"]).output().unwrap();
    assert_success(&help);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("--useserver") && !help.contains("export-luxcore"),
        "{help}"
    );
}

#[test]
fn bindump_writes_the_pixels_alone_on_standard_output() {
    let root = tempfile::tempdir().unwrap();
    let scenes = folder(root.path(), "scene");
    let scene = small_scene(&scenes);
    let expected = reference(root.path(), &scene);

    let output = luxconsole(
        root.path(),
        &["-b", "-t", "2", "-o", "dump.png", path_str(&scene)],
    );
    assert_success(&output);
    // LuxBlend's pipe reads width x height x 3 bytes, rows top to bottom.
    assert_eq!(output.stdout.len(), 48 * 36 * 3);
    assert!(
        output.stdout == expected.as_raw()[..],
        "the dump is not the image's pixels"
    );
    // What yat render prints on standard output went to standard error.
    assert!(
        stderr_of(&output).contains("wrote dump.png"),
        "{}",
        stderr_of(&output)
    );
}

#[test]
fn a_queue_renders_each_scene_to_its_film_s_name_in_its_folder() {
    let root = tempfile::tempdir().unwrap();
    let first = folder(root.path(), "first");
    let second = folder(root.path(), "second");
    let elsewhere = folder(root.path(), "elsewhere");
    let scene = small_scene(&first);
    small_scene(&second);
    let expected = reference(root.path(), &scene);
    std::fs::write(elsewhere.join("queue.txt"), "../second/box.lxs\n").unwrap();

    let output = luxconsole(
        &elsewhere,
        &[
            "-t",
            "2",
            "-i",
            "180",
            "../first/box.lxs",
            "-L",
            "queue.txt",
        ],
    );
    assert_success(&output);
    for dir in [&first, &second] {
        assert_eq!(pixels(&dir.join("box.png")), expected, "{}", dir.display());
    }
    assert!(!elsewhere.join("box.png").exists());
    // The option YAT ignores is named.
    let stderr = stderr_of(&output);
    assert!(
        stderr.contains("luxconsole option --serverinterval (-i) is ignored by YAT"),
        "{stderr}"
    );
}

#[test]
fn unknown_and_unsupported_options_are_named_and_nothing_renders() {
    let root = tempfile::tempdir().unwrap();
    let scene = small_scene(root.path());
    for (args, named) in [
        (
            &["--frobnicate", "-t", "2"][..],
            "unknown luxconsole option: --frobnicate",
        ),
        (
            &["-s"][..],
            "luxconsole option --server (-s) is not supported by YAT",
        ),
        (
            &["-R", "box.flm"][..],
            "luxconsole option --overrideresume (-R) is not supported by YAT",
        ),
    ] {
        let mut full = args.to_vec();
        full.push(path_str(&scene));
        let output = luxconsole(root.path(), &full);
        assert!(!output.status.success(), "{args:?} succeeded");
        let stderr = stderr_of(&output);
        assert!(stderr.contains(named), "{args:?}: {stderr}");
        assert!(!root.path().join("box.png").exists(), "{args:?} rendered");
    }
}

#[test]
fn under_the_name_luxconsole_the_v3_build_is_handed_the_subcommand() {
    let dir = tempfile::tempdir().unwrap();
    // The name luxconsole is a symbolic link to it, which the running binary resolves to `yat`.
    let exe = yat_in(dir.path());
    let named = dir.path().join("luxconsole");
    std::os::unix::fs::symlink(&exe, &named).unwrap();
    let stand_in = dir.path().join(format!("yat{V3_SUFFIX}"));
    std::fs::write(&stand_in, "#!/bin/sh\necho \"v3 build: $YAT_ISA $*\"\n").unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&stand_in, std::fs::Permissions::from_mode(0o755)).unwrap();

    let output = command(&named, dir.path(), &["-t", "2", "/nonexistent/scene.lxs"])
        .env_remove(ISA_ENV)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    if isa::cpu_has_v3() && !isa::built_for_v3() {
        assert_eq!(
            stdout.trim(),
            format!("v3 build: {V3_NAME} luxconsole -t 2 /nonexistent/scene.lxs")
        );
    } else {
        eprintln!("this CPU or build does not hand over: checking that it stays");
        assert!(!output.status.success());
        let stderr = stderr_of(&output);
        assert!(stderr.contains("/nonexistent/scene.lxs"), "{stderr}");
    }
}
