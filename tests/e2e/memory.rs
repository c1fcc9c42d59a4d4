//! End-to-end: the build budget's memory figure under a real address-space limit (RLIMIT_AS).
//! Its default comes from the limit, so a scene the process cannot hold is refused with the
//! statement and the figure, never an allocation failure's abort: by `yat render` in-process,
//! and by a worker, which refuses that LoadScene and goes on rendering other scenes.

use std::os::unix::process::ExitStatusExt;
use std::process::Output;
use std::time::{Duration, Instant};

use crate::hostile::{self, Files};
use crate::util::*;

/// The address space of the processes under test: room for the small scenes, not for the
/// hostile ones.
const ADDRESS_SPACE: u64 = 1 << 30;

/// Generous for a debug build on a loaded machine; each refusal takes well under a second.
const QUICKLY: Duration = Duration::from_secs(30);

/// 5 million triangles (under the primitive limit), gigabytes once built; and an 8192 x 8192
/// PNG (under the texel limit) of a few hundred kilobytes that takes a gigabyte to decode.
/// With the position of the statement that goes over.
fn hostile_scenes() -> [(&'static str, Files, &'static str); 2] {
    [
        ("instances", hostile::instanced_strips(10_000), "main.lxs:"),
        (
            "image",
            hostile::image_texture(hostile::uniform_png(8192, 8192)),
            "main.lxs:6:",
        ),
    ]
}

/// Asserts that `output` is a clean refusal at the memory budget: exit status 1 (no signal),
/// the statement's position, the figure and the flag.
fn assert_refused(name: &str, output: &Output, at: &str) {
    let err = stderr_of(output);
    assert_eq!(output.status.signal(), None, "{name}: killed: {err}");
    assert_eq!(output.status.code(), Some(1), "{name}: {err}");
    assert!(
        err.contains(at) && err.contains("--max-memory-mib") && err.contains("MiB reached"),
        "{name}: {err}"
    );
}

/// `yat render` in-process refuses each hostile scene under the address-space limit, by the
/// default its budget takes from it.
#[test]
fn an_in_process_render_refuses_what_its_address_space_cannot_hold() {
    for (name, files, at) in hostile_scenes() {
        let dir = tempfile::tempdir().unwrap();
        let scene = write_files(dir.path(), &files);
        let out = dir.path().join("out.png");
        let output =
            run_in_address_space(render_command(&scene, &out, &[]), ADDRESS_SPACE, QUICKLY);
        assert_refused(name, &output, at);
        assert!(!out.exists());
    }
}

/// A worker under the address-space limit refuses each hostile scene's LoadScene with the
/// statement and the figure (the render through it fails with that reason), stays up, and
/// then renders a legitimate scene for a coordinator.
#[test]
fn a_worker_refuses_what_its_address_space_cannot_hold_and_keeps_serving() {
    let mut worker = Worker::start_in_address_space(ADDRESS_SPACE, &[]);
    let address = worker.address.clone();
    let through_worker = ["--workers", &address, "--timeout", "20"];
    for (name, files, at) in hostile_scenes() {
        let dir = tempfile::tempdir().unwrap();
        let scene = write_files(dir.path(), &files);
        let out = dir.path().join("out.png");
        let started = Instant::now();
        let output = render_command(&scene, &out, &through_worker)
            .output()
            .unwrap();
        assert!(started.elapsed() < QUICKLY, "took {:?}", started.elapsed());
        assert_refused(name, &output, at);
        assert!(
            worker.wait_for_exit(Duration::ZERO).is_none(),
            "{name}: the worker died"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let out = dir.path().join("out.png");
    assert_success(
        &render_command(&scene, &out, &through_worker)
            .output()
            .unwrap(),
    );
    assert!(out.exists());
}
