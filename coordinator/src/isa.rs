//! One `yat` for any x86-64, the speed of one compiled for the CPU it runs on.
//!
//! The release binary is built for baseline x86-64 (SSE2) so that it runs anywhere; only the
//! traversal picks AVX2 or AVX-512 at run time. A second build of the same source for
//! x86-64-v3 (AVX2, FMA, BMI1/2, ...; `deploy/build-pgo.sh` makes both) placed beside it as
//! `yat-x86-64-v3` runs some 12% fewer instructions on the seed scenes. At start, a baseline
//! `yat` on a CPU with those features hands its process over (exec, same arguments) to that
//! sibling when it is there.
//!
//! The images are the same bytes either way, so workers of both kinds can share a render:
//! Rust never contracts a multiply and an add into a fused one on its own, and libm picks its
//! kernels by the CPU at run time whichever build calls it, so only instruction selection
//! differs (`deploy/build-pgo.sh` renders the seed scenes with both and compares the EXRs).
//!
//! `YAT_ISA=baseline` keeps the baseline build running (to compare the two).

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

/// What the sibling's file name adds to this binary's.
pub const V3_SUFFIX: &str = "-x86-64-v3";

/// The environment variable that names the build to run: `baseline` keeps this binary; the
/// hand-over sets it to `x86-64-v3` (a guard against handing over again).
pub const ISA_ENV: &str = "YAT_ISA";

/// [`ISA_ENV`]'s value in the process handed over to.
pub const V3_NAME: &str = "x86-64-v3";

/// What a starting `yat` does about its instruction set.
#[derive(Debug, PartialEq, Eq)]
pub enum IsaChoice {
    /// Run this binary.
    Stay,
    /// Replace the process with this x86-64-v3 build.
    HandOver(PathBuf),
    /// This binary needs x86-64-v3 and the CPU lacks it: running on would stop at the first
    /// instruction it lacks (SIGILL).
    Unsupported,
}

/// The decision, from plain facts: the running binary's path, whether it was compiled for
/// x86-64-v3, whether the CPU has x86-64-v3's features, [`ISA_ENV`]'s value, and whether a
/// path is an executable file.
pub fn choose(
    exe: &Path,
    built_for_v3: bool,
    cpu_has_v3: bool,
    isa_env: Option<&OsStr>,
    is_executable: impl Fn(&Path) -> bool,
) -> IsaChoice {
    if built_for_v3 {
        return if cpu_has_v3 {
            IsaChoice::Stay
        } else {
            IsaChoice::Unsupported
        };
    }
    if !cpu_has_v3 || isa_env.is_some_and(|v| v == "baseline" || v == V3_NAME) {
        return IsaChoice::Stay;
    }
    let Some(name) = exe.file_name() else {
        return IsaChoice::Stay;
    };
    let mut sibling_name = name.to_os_string();
    sibling_name.push(V3_SUFFIX);
    let sibling = exe.with_file_name(sibling_name);
    if is_executable(&sibling) {
        IsaChoice::HandOver(sibling)
    } else {
        IsaChoice::Stay
    }
}

/// Applies [`choose`] to this process. Returns to run this binary (also when the hand-over
/// fails: a warning, and the baseline build renders the same image); does not return when
/// the sibling takes over; an error when this binary cannot run on this CPU.
pub fn start() -> Result<(), String> {
    let Ok(exe) = std::env::current_exe() else {
        return Ok(());
    };
    let isa_env = std::env::var_os(ISA_ENV);
    match choose(
        &exe,
        built_for_v3(),
        cpu_has_v3(),
        isa_env.as_deref(),
        is_executable,
    ) {
        IsaChoice::Stay => Ok(()),
        IsaChoice::Unsupported => Err(format!(
            "{} was built for x86-64-v3 (AVX2, FMA, BMI2) and this CPU lacks some of it: run \
             the baseline build ({} without the suffix)",
            exe.display(),
            V3_SUFFIX
        )),
        IsaChoice::HandOver(sibling) => {
            hand_over(&sibling);
            Ok(())
        }
    }
}

/// Replaces this process with `sibling`, same arguments, [`ISA_ENV`] set; returns only if
/// that fails.
fn hand_over(sibling: &Path) {
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        let error = std::process::Command::new(sibling)
            .args(std::env::args_os().skip(1))
            .env(ISA_ENV, V3_NAME)
            .exec();
        tracing::warn!(
            "could not run {} ({error}); rendering with this baseline build",
            sibling.display()
        );
    }
    #[cfg(not(unix))]
    let _ = sibling;
}

/// This binary's build: `x86-64-v3`, or `baseline` (any CPU of its architecture).
pub fn build_name() -> &'static str {
    if built_for_v3() {
        V3_NAME
    } else {
        "baseline"
    }
}

/// Whether this binary was compiled for x86-64-v3 (the features it may use unchecked).
pub fn built_for_v3() -> bool {
    cfg!(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma",
        target_feature = "bmi2"
    ))
}

/// Whether the CPU (and the OS, for the AVX registers) has every x86-64-v3 feature.
pub fn cpu_has_v3() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("bmi1")
            && std::arch::is_x86_feature_detected!("bmi2")
            && std::arch::is_x86_feature_detected!("f16c")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("lzcnt")
            && std::arch::is_x86_feature_detected!("movbe")
            && std::arch::is_x86_feature_detected!("popcnt")
            && std::arch::is_x86_feature_detected!("sse4.2")
            && std::arch::is_x86_feature_detected!("ssse3")
            && std::arch::is_x86_feature_detected!("cmpxchg16b")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// A regular file with an execute bit (what `exec` would run).
pub fn is_executable(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    }
    #[cfg(not(unix))]
    {
        path.is_file()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn start(built_for_v3: bool, cpu_has_v3: bool, env: Option<&str>, sibling: bool) -> IsaChoice {
        choose(
            Path::new("/opt/yat/bin/yat"),
            built_for_v3,
            cpu_has_v3,
            env.map(OsStr::new),
            |p| sibling && p == Path::new("/opt/yat/bin/yat-x86-64-v3"),
        )
    }

    #[test]
    fn a_baseline_build_hands_over_only_to_a_sibling_the_cpu_can_run() {
        let sibling = PathBuf::from("/opt/yat/bin/yat-x86-64-v3");
        assert_eq!(
            start(false, true, None, true),
            IsaChoice::HandOver(sibling.clone())
        );
        assert_eq!(
            start(false, true, Some("auto"), true),
            IsaChoice::HandOver(sibling)
        );
        assert_eq!(start(false, false, None, true), IsaChoice::Stay);
        assert_eq!(start(false, true, None, false), IsaChoice::Stay);
        assert_eq!(start(false, true, Some("baseline"), true), IsaChoice::Stay);
        // Handed over already (a baseline binary under the sibling's name): no second exec.
        assert_eq!(start(false, true, Some(V3_NAME), true), IsaChoice::Stay);
    }

    #[test]
    fn a_v3_build_runs_only_where_the_cpu_has_v3() {
        assert_eq!(start(true, true, None, false), IsaChoice::Stay);
        assert_eq!(start(true, true, Some("baseline"), true), IsaChoice::Stay);
        assert_eq!(start(true, false, None, true), IsaChoice::Unsupported);
    }

    #[test]
    fn a_path_without_a_file_name_stays() {
        let start = choose(Path::new("/"), false, true, None, |_| true);
        assert_eq!(start, IsaChoice::Stay);
    }
}
