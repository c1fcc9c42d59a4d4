//! End-to-end: the files a render writes are those its scene's Film asks for (`write_png`,
//! `write_tga`, `write_exr` and their channels and precision), named as LuxRender names them:
//! the Film's filename (or `-o`'s image) with each format's extension.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use crate::util::*;
use crate::workspace::workspace_root;

/// `scenes/exported/film-outputs.lxs`: LuxBlend's film with every file on.
fn film_outputs_scene() -> String {
    std::fs::read_to_string(workspace_root().join("scenes/exported/film-outputs.lxs")).unwrap()
}

/// `yat render SCENE ARGS` in `dir`, at 2 samples per pixel, no interim files.
fn render_in(dir: &Path, scene: &Path, args: &[&str]) -> std::process::Output {
    Command::new(YAT)
        .current_dir(dir)
        .arg("render")
        .arg(scene)
        .args([
            "--spp",
            "2",
            "--checkpoint-every",
            "0",
            "--preview-every",
            "0",
        ])
        .args(args)
        .output()
        .unwrap()
}

/// The names of the files in `dir`.
fn files_in(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

/// An EXR's channels: (name, half floats).
fn exr_channels(path: &Path) -> Vec<(String, bool)> {
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    meta.headers[0]
        .channels
        .list
        .iter()
        .map(|c| {
            let half = c.sample_type == exr::meta::attribute::SampleType::F16;
            (c.name.to_string(), half)
        })
        .collect()
}

fn names(list: &[&str]) -> BTreeSet<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// The scene's PNG, TGA and EXR, each as its Film says (a 16-bit RGBA PNG, an RGB TGA, a half
/// RGBA EXR), and no other file: under the Film's filename in the current folder, or beside
/// `-o`'s image; a Film without a PNG writes none even with `-o x.png`, `--exr` adds YAT's
/// linear full-float EXR where the Film writes none, and a Film writing nothing is refused.
#[test]
fn a_films_write_flags_choose_the_files_written() {
    let scene_dir = tempfile::tempdir().unwrap();
    let scene = scene_dir.path().join("film-outputs.lxs");
    std::fs::write(&scene, film_outputs_scene()).unwrap();

    let here = tempfile::tempdir().unwrap();
    assert_success(&render_in(here.path(), &scene, &[]));
    let base = "film-outputs.Scene.00001";
    let written = [".png", ".tga", ".exr"].map(|ext| format!("{base}{ext}"));
    assert_eq!(
        files_in(here.path()),
        names(&written.each_ref().map(|s| s.as_str()))
    );
    let png = image::open(here.path().join(&written[0])).unwrap();
    assert_eq!(png.color(), image::ColorType::Rgba16);
    let tga = std::fs::read(here.path().join(&written[1])).unwrap();
    assert_eq!((tga[2], tga[16], tga.len()), (2, 24, 18 + 96 * 64 * 3));
    let channels = exr_channels(&here.path().join(&written[2]));
    let half = |n: &str| (n.to_string(), true);
    assert_eq!(channels, [half("A"), half("B"), half("G"), half("R")]);

    let out = tempfile::tempdir().unwrap();
    let output = render_in(
        here.path(),
        &scene,
        &["-o", out.path().join("frame.png").to_str().unwrap()],
    );
    assert_success(&output);
    assert_eq!(
        files_in(out.path()),
        names(&["frame.png", "frame.tga", "frame.exr"])
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    for ext in ["png", "tga", "exr"] {
        assert!(stdout.contains(&format!("frame.{ext}")), "{stdout}");
    }

    // No PNG and no EXR in the Film: only the TGA, and --exr's EXR beside it.
    let text = film_outputs_scene()
        .replace(
            "\"bool write_png\" [\"true\"]",
            "\"bool write_png\" [\"false\"]",
        )
        .replace(
            "\"bool write_exr\" [\"true\"]",
            "\"bool write_exr\" [\"false\"]",
        )
        .replace("\"string write_exr_channels\" [\"RGBA\"]", "")
        .replace("\"bool write_exr_halftype\" [\"true\"]", "")
        .replace("\"bool write_exr_applyimaging\" [\"true\"]", "");
    std::fs::write(&scene, &text).unwrap();
    let out = tempfile::tempdir().unwrap();
    let x = out.path().join("x.png");
    assert_success(&render_in(
        here.path(),
        &scene,
        &["-o", x.to_str().unwrap()],
    ));
    assert_eq!(files_in(out.path()), names(&["x.tga"]));
    std::fs::remove_file(out.path().join("x.tga")).unwrap();
    assert_success(&render_in(
        here.path(),
        &scene,
        &["-o", x.to_str().unwrap(), "--exr"],
    ));
    assert_eq!(files_in(out.path()), names(&["x.tga", "x.exr"]));
    let full = |n: &str| (n.to_string(), false);
    assert_eq!(
        exr_channels(&out.path().join("x.exr")),
        [full("B"), full("G"), full("R")]
    );

    let none = text.replace(
        "\"bool write_tga\" [\"true\"]",
        "\"bool write_tga\" [\"false\"]",
    );
    std::fs::write(&scene, none).unwrap();
    let output = render_in(here.path(), &scene, &["-o", x.to_str().unwrap()]);
    assert!(!output.status.success());
    let err = stderr_of(&output);
    assert!(
        err.contains("writes no file") && err.contains("--exr"),
        "{err}"
    );
}

/// `--aovs` adds the AOVs' channels to the EXR, and the EXR itself where the Film writes none;
/// an unknown AOV is refused, naming it.
#[test]
fn aovs_go_into_the_exr() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("x.png");
    let output = render_in(
        dir.path(),
        &scene,
        &[
            "-o",
            out.to_str().unwrap(),
            "--resolution",
            "32x24",
            "--aovs",
            "depth,samples",
        ],
    );
    assert_success(&output);
    let channels: Vec<String> = exr_channels(&out.with_extension("exr"))
        .into_iter()
        .map(|(name, _)| name)
        .collect();
    assert_eq!(channels, ["B", "G", "R", "Z", "samples"]);
    let output = render_in(
        dir.path(),
        &scene,
        &["-o", out.to_str().unwrap(), "--aovs", "albedo,zbuf"],
    );
    assert!(!output.status.success());
    let err = stderr_of(&output);
    assert!(err.contains("unknown AOV \"zbuf\""), "{err}");
}
