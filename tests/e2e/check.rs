//! `yat check` end to end: the real binary on a seed scene, on a scene whose Include is
//! missing, on a scene with known differences from LuxRender (each listed at its position and
//! counted), and on every complete scene of ours and of the seed project (no difference
//! besides the known gaps listed here).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::util::YAT;
use crate::workspace::{seed_scenes, workspace_root};

fn check(scene: &Path) -> (bool, String, String) {
    check_with(scene, &[])
}

fn check_with(scene: &Path, flags: &[&str]) -> (bool, String, String) {
    let out = Command::new(YAT)
        .arg("check")
        .args(flags)
        .arg(scene)
        .env_remove("RUST_BACKTRACE")
        .output()
        .expect("run yat");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn check_says_a_scene_with_point_light_caustics_renders_bidirectional() {
    let scene = workspace_root().join("scenes/caustics/caustics.lxs");
    let (ok, stdout, stderr) = check(&scene);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stdout
            .contains("integrator   bidirectional, max depth 8 (file asks for \"bidirectional\")"),
        "what will run: {stdout}"
    );
    assert!(
        stdout.contains(
            "bidirectional: the point light's caustics off \"mirror\" need light subpaths"
        ),
        "why, and what it costs: {stdout}"
    );
}

#[test]
fn check_summarises_a_seed_scene() {
    let Some(dir) = seed_scenes() else { return };
    let (ok, stdout, stderr) = check(&dir.join("CornellBox/cornell-box.lxs"));
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("resolution   960x540"), "{stdout}");
    assert!(stdout.contains("perspective fov 49.13"), "{stdout}");
    assert!(stdout.contains("8 (8 mesh), 32 triangles"), "{stdout}");
    assert!(stdout.contains("lights       1 area (shapes)"), "{stdout}");
    assert!(stdout.contains("parse time"), "{stdout}");
    assert!(
        stdout.contains("integrator   path, max depth 16 (file asks for \"bidirectional\")"),
        "what will run: {stdout}"
    );
    assert!(
        stdout.contains("--integrator bidirectional: eye depth 16, light depth 16"),
        "what the bidirectional integrator would render with: {stdout}"
    );
    assert!(
        stdout.contains("path tracing: no caustics of point, spot or distant lights here"),
        "why path tracing runs: {stdout}"
    );
    assert!(
        stdout.contains("notes (rendered as LuxRender would): 1\n  cornell-box.lxs:11:1: SurfaceIntegrator \"bidirectional\""),
        "the one note: {stdout}"
    );
    assert!(
        stdout.ends_with("\n0 statements or parameters not rendered as LuxRender would\n"),
        "{stdout}"
    );
}

/// The differences of a scene: four kinds, one of them on a thousand statements; two notes.
const REPEATS: usize = 1000;

fn scene_with_differences() -> String {
    let mut text = String::from(
        "Film \"fleximage\" \"integer xresolution\" [8] \"integer yresolution\" [8]\n\
         LookAt 0 -5 1  0 0 1  0 0 1\n\
         Camera \"realistic\"\n\
         WorldBegin\n\
         Material \"mirror\" \"float index\" [1.5] \"float film\" [200]\n\
         Texture \"t\" \"float\" \"frobnicate\"\n\
         LightSource \"laser\" \"color L\" [1 1 1]\n\
         NamedMaterial \"nosuch\"\n",
    );
    for _ in 0..REPEATS {
        text.push_str("Shape \"sphere\" \"float wobble\" [1]\n");
    }
    text.push_str("WorldEnd\n");
    text
}

#[test]
fn check_lists_and_counts_every_difference_at_its_position() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("diff.lxs");
    std::fs::write(&scene, scene_with_differences()).unwrap();
    let (ok, stdout, stderr) = check(&scene);
    assert!(
        ok,
        "without --strict a scene that parses succeeds: {stdout}\n{stderr}"
    );
    let total = 3 + REPEATS;
    for line in [
        format!("not rendered as LuxRender would: {total}"),
        "  diff.lxs:3:1: Camera \"realistic\" is not supported; rendering with a perspective camera"
            .into(),
        "  diff.lxs:6:1: Texture \"t\": type \"frobnicate\" is not supported".into(),
        "  diff.lxs:7:1: unknown LightSource \"laser\" skipped".into(),
        "  diff.lxs:9:16: Shape \"sphere\": unknown parameter \"float wobble\" ignored".into(),
        // The first ten occurrences with positions, then the count of the rest.
        "  diff.lxs:18:16: the same".into(),
        format!("  ... and {} more", REPEATS - 10),
        "notes (rendered as LuxRender would): 2".into(),
        "  diff.lxs:5:19: Material \"mirror\": \"float index\" is ignored, as LuxRender ignores it"
            .into(),
        "  diff.lxs:8:1: NamedMaterial: no material named \"nosuch\"".into(),
        format!("{total} statements or parameters not rendered as LuxRender would"),
    ] {
        assert!(
            stdout.lines().any(|l| l.starts_with(&line)),
            "missing {line:?} in\n{stdout}"
        );
    }
    assert!(!stdout.contains("diff.lxs:19:16"), "{stdout}");
    assert!(stdout.ends_with(&format!(
        "\n{total} statements or parameters not rendered as LuxRender would\n"
    )));

    let (ok, stdout, stderr) = check_with(&scene, &["--strict"]);
    assert!(!ok, "--strict fails on differences: {stdout}");
    assert!(
        stderr.contains(&format!("--strict: {total} statements")),
        "{stderr}"
    );
}

/// Differences known and not yet closed, by scene (a path under `scenes/` or the seed
/// project's folder) and how many; every other complete scene must have none.
const KNOWN_GAPS: &[(&str, u64, &str)] = &[(
    "textures/procedural.lxs",
    9,
    "blender_* noise bases do not use Blender's random tables",
)];

/// The scene files under `dir` that are complete scenes (fragments meant to be included have
/// no WorldBegin).
fn complete_scenes(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "lxs")
                && std::fs::read_to_string(&path).is_ok_and(|t| t.contains("WorldBegin"))
            {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn complete_scenes_have_no_difference_but_the_known_gaps() {
    let mut dirs = vec![workspace_root().join("scenes")];
    dirs.extend(seed_scenes());
    let mut checked = 0;
    let mut failures = Vec::new();
    for dir in dirs {
        for scene in complete_scenes(&dir) {
            let relative = scene
                .strip_prefix(&dir)
                .unwrap()
                .to_string_lossy()
                .into_owned();
            let expected = KNOWN_GAPS
                .iter()
                .find(|(path, _, _)| *path == relative)
                .map_or(0, |&(_, n, _)| n);
            let (ok, stdout, stderr) = check(&scene);
            // Some seed scenes lack their geometry files: not complete, not checkable.
            if !ok && stderr.contains("file not found") {
                println!("skipped (a file is missing): {}", scene.display());
                continue;
            }
            let want =
                format!("\n{expected} statements or parameters not rendered as LuxRender would\n");
            if !ok || !stdout.ends_with(&want) {
                failures.push(format!(
                    "{}: expected {expected}\n{stdout}{stderr}",
                    scene.display()
                ));
            }
            checked += 1;
        }
    }
    assert!(checked >= 14, "only {checked} complete scenes found");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn check_fails_naming_a_missing_include() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("broken.lxs");
    std::fs::write(
        &scene,
        "Camera \"perspective\"\nWorldBegin\nInclude \"geometry/missing.lxo\"\nWorldEnd\n",
    )
    .unwrap();
    let (ok, stdout, stderr) = check(&scene);
    assert!(!ok, "{stdout}");
    assert!(stderr.contains("broken.lxs:3:1"), "{stderr}");
    assert!(stderr.contains("\"geometry/missing.lxo\""), "{stderr}");
    assert!(
        stderr.contains(
            &dir.path()
                .join("geometry/missing.lxo")
                .display()
                .to_string()
        ),
        "{stderr}"
    );
}

#[test]
fn check_fails_on_a_syntax_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("bad.lxs");
    std::fs::write(
        &scene,
        "Film \"fleximage\" \"integer xresolution\" [64\nWorldBegin\n",
    )
    .unwrap();
    let (ok, _, stderr) = check(&scene);
    assert!(!ok);
    assert!(stderr.contains("bad.lxs:2:1: syntax error"), "{stderr}");
}
