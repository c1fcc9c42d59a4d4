//! Frames: `yat render a.lxs b.lxs ...` (or a glob, or `--frames LIST`) renders a sequence in
//! order on the same workers, each frame into its Film filename; workers keep the files they
//! were sent, so a frame sends only what changed; a sequence stopped by a failing frame goes on,
//! with the same command, at that frame, and every image is the bytes of the frame rendered
//! alone.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::util::*;

const SMALL: [&str; 4] = ["--spp", "16", "--resolution", "32x24"];

/// Frames 1..=count of the test scene (its materials, textures and sky shared, as an
/// exporter writes an animation): the camera moves a little each frame and every Film has its
/// own filename, `frame.000N`.
fn write_frames(dir: &Path, count: usize) -> Vec<PathBuf> {
    let scene = write_scene(dir);
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("[\"box\"]") && text.contains("LookAt 0 -0.9 1"));
    (1..=count)
        .map(|n| {
            let frame = text
                .replacen("[\"box\"]", &format!("[\"frame.{n:04}\"]"), 1)
                .replacen(
                    "LookAt 0 -0.9 1",
                    &format!("LookAt {:.2} -0.9 1", 0.05 * n as f64),
                    1,
                );
            let path = dir.join(format!("frame{n}.lxs"));
            std::fs::write(&path, frame).unwrap();
            path
        })
        .collect()
}

/// The frame rendered alone, in-process: the bytes every frame of a sequence must have.
fn alone(scene: &Path, dir: &Path) -> (Vec<u8>, Vec<u8>) {
    let out = dir.join(format!(
        "alone-{}.png",
        scene.file_stem().unwrap().to_string_lossy()
    ));
    assert_success(
        &render_command_with(scene, &out, &SMALL, &["--threads", "2"])
            .output()
            .unwrap(),
    );
    image_bytes(&out)
}

/// A sequence on two workers: every frame's image under its Film filename, the bytes of the
/// frame rendered alone in-process; the workers receive the shared files once and each later
/// frame's own file only.
#[test]
fn a_sequence_renders_each_frame_on_the_same_workers_sending_only_what_changed() {
    let dir = tempfile::tempdir().unwrap();
    let frames = write_frames(dir.path(), 3);
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let workers = [Worker::start(&[]), Worker::start(&[])];
    let list: Vec<&str> = workers.iter().map(|w| w.address.as_str()).collect();
    let mut command = Command::new(YAT);
    command
        .arg("render")
        .args(&frames)
        .arg("-o")
        .arg(&out)
        .arg("--exr")
        .args(SMALL)
        .args(["--workers", &list.join(",")])
        .env_remove("YAT_TOKEN");
    let output = command.output().unwrap();
    assert_success(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    for n in 1..=3 {
        assert!(stdout.contains(&format!("frame {n} of 3, ")), "{stdout}");
        let image = out.join(format!("frame.{n:04}.png"));
        assert!(
            image_bytes(&image) == alone(&frames[n - 1], dir.path()),
            "frame {n} differs from the frame rendered alone"
        );
    }
    assert!(
        !out.join("frame.0001.sequence").exists(),
        "a complete sequence leaves no journal"
    );
    // Every file of frame 1 went to each worker that rendered it, and then only frames 2 and 3.
    let shared: u64 = ["materials.lxo", "textures/checks.png", "textures/sky.png"]
        .iter()
        .map(|f| std::fs::metadata(dir.path().join(f)).unwrap().len())
        .sum();
    let own = |n: usize| std::fs::metadata(&frames[n]).unwrap().len();
    for worker in &workers {
        let received = worker.stats(None).blob_bytes_received;
        assert_eq!(
            received,
            shared + own(0) + own(1) + own(2),
            "worker {} received the shared files once",
            worker.address
        );
    }
}

/// A sequence whose second frame cannot render stops there, frame 1 written and journaled;
/// the same command, the frame mended, says frame 1 is rendered and goes on from frame 2. The
/// frames come from a list file.
#[test]
fn a_stopped_sequence_goes_on_at_the_frame_where_it_stopped() {
    let dir = tempfile::tempdir().unwrap();
    let frames = write_frames(dir.path(), 3);
    let list = dir.path().join("frames.txt");
    let names: Vec<String> = frames.iter().map(|f| f.display().to_string()).collect();
    std::fs::write(&list, names.join("\n")).unwrap();
    let good = std::fs::read_to_string(&frames[1]).unwrap();
    // An unterminated parameter list: a parse error at a line and column of frame2.lxs.
    let broken = good.replacen(
        "WorldBegin",
        "WorldBegin\nShape \"sphere\" \"float radius\" [",
        1,
    );
    assert_ne!(broken, good);
    std::fs::write(&frames[1], broken).unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let sequence = || {
        let mut command = Command::new(YAT);
        command
            .arg("render")
            .arg("--frames")
            .arg(&list)
            .arg("-o")
            .arg(&out)
            .arg("--exr")
            .args(SMALL)
            .args(["--threads", "2"]);
        command.output().unwrap()
    };
    let stopped = sequence();
    assert!(
        !stopped.status.success(),
        "{}{}",
        stderr_of(&stopped),
        String::from_utf8_lossy(&stopped.stdout)
    );
    let stderr = stderr_of(&stopped);
    assert!(
        stderr.contains("frame 2 of 3") && stderr.contains("frame2.lxs:"),
        "the failing frame and where its file is wrong are named: {stderr}"
    );
    assert!(out.join("frame.0001.png").exists());
    assert!(!out.join("frame.0002.png").exists());
    assert!(
        out.join("frame.0001.sequence").exists(),
        "the journal stays"
    );

    std::fs::write(&frames[1], good).unwrap();
    let first = std::fs::metadata(out.join("frame.0001.png"))
        .unwrap()
        .modified()
        .unwrap();
    let resumed = sequence();
    assert_success(&resumed);
    let stdout = String::from_utf8_lossy(&resumed.stdout);
    assert!(
        stdout.contains("frame 1 of 3, ") && stdout.contains("rendered already"),
        "{stdout}"
    );
    assert_eq!(
        std::fs::metadata(out.join("frame.0001.png"))
            .unwrap()
            .modified()
            .unwrap(),
        first,
        "frame 1 is not rendered again"
    );
    for n in 1..=3 {
        let image = out.join(format!("frame.{n:04}.png"));
        assert!(
            image_bytes(&image) == alone(&frames[n - 1], dir.path()),
            "frame {n} differs from the frame rendered alone"
        );
    }
    assert!(!out.join("frame.0001.sequence").exists());
}

/// Frames sharing a Film filename would overwrite each other's image: refused, naming both.
#[test]
fn frames_sharing_an_image_name_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let frames = write_frames(dir.path(), 2);
    let text = std::fs::read_to_string(&frames[1]).unwrap();
    std::fs::write(&frames[1], text.replace("frame.0002", "frame.0001")).unwrap();
    let mut command = Command::new(YAT);
    command.arg("render").args(&frames).args(SMALL);
    command.current_dir(dir.path());
    let refused = command.output().unwrap();
    assert!(!refused.status.success());
    let stderr = stderr_of(&refused);
    assert!(stderr.contains("an earlier frame's image"), "{stderr}");
}
