//! `yat check` end to end: the real binary on a seed scene and on a scene whose Include is
//! missing.

use std::path::Path;
use std::process::Command;

use crate::util::YAT;
use crate::workspace::seed_scenes;

fn check(scene: &Path) -> (bool, String, String) {
    let out = Command::new(YAT)
        .arg("check")
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
        stdout.contains("bidirectional"),
        "the one meaningful warning: {stdout}"
    );
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
