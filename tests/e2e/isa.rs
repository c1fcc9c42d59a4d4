//! The hand-over to an x86-64-v3 build beside the binary (`yat::isa`), with real processes:
//! a copy of `yat` next to a stand-in `yat-x86-64-v3` script that prints what it was given.

use std::path::Path;
use std::process::Command;

use yat::isa::{self, ISA_ENV, V3_NAME, V3_SUFFIX};

use crate::util::yat_in;

/// `yat check` of a file that does not exist, run as `exe`: its stdout and stderr.
fn check_missing(exe: &Path, isa_env: Option<&str>) -> (String, String) {
    let mut command = Command::new(exe);
    command.args(["check", "/nonexistent/scene.lxs"]);
    command.env_remove(ISA_ENV);
    if let Some(value) = isa_env {
        command.env(ISA_ENV, value);
    }
    let out = command.output().unwrap();
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_baseline_yat_hands_over_to_the_v3_build_beside_it_where_the_cpu_has_v3() {
    let dir = tempfile::tempdir().unwrap();
    let exe = yat_in(dir.path());
    let stand_in = dir.path().join(format!("yat{V3_SUFFIX}"));
    std::fs::write(&stand_in, "#!/bin/sh\necho \"v3 build: $YAT_ISA $*\"\n").unwrap();

    // Not executable yet: the baseline build runs (and names the missing scene).
    let (_, stderr) = check_missing(&exe, None);
    assert!(stderr.contains("/nonexistent/scene.lxs"), "{stderr}");

    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&stand_in, std::fs::Permissions::from_mode(0o755)).unwrap();
    let (stdout, stderr) = check_missing(&exe, None);
    if isa::cpu_has_v3() && !isa::built_for_v3() {
        assert_eq!(
            stdout.trim(),
            format!("v3 build: {V3_NAME} check /nonexistent/scene.lxs")
        );
    } else {
        eprintln!("this CPU or build does not hand over: checking that it stays");
        assert!(stderr.contains("/nonexistent/scene.lxs"), "{stderr}");
    }
    // YAT_ISA=baseline keeps the baseline build.
    let (stdout, stderr) = check_missing(&exe, Some("baseline"));
    assert!(stdout.is_empty(), "{stdout}");
    assert!(stderr.contains("/nonexistent/scene.lxs"), "{stderr}");
}
