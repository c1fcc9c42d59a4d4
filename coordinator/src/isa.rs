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
//! `cargo build --release` makes both (`coordinator/build.rs`). Each carries the hash of the
//! sources it was built from ([`BUILD_ID`]); the baseline names its own to the sibling, and a
//! sibling built from other sources (one left from an earlier build) hands the process back
//! to the baseline instead of rendering.
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

/// The hash of the sources this binary was built from (`coordinator/build.rs`).
pub const BUILD_ID: &str = env!("YAT_BUILD_ID");

/// The environment variable in which a baseline build names its [`BUILD_ID`] to the sibling
/// it hands over to.
pub const BUILD_ID_ENV: &str = "YAT_BUILD_ID";

/// What a starting `yat` does about its instruction set.
#[derive(Debug, PartialEq, Eq)]
pub enum IsaChoice {
    /// Run this binary.
    Stay,
    /// Replace the process with this x86-64-v3 build.
    HandOver(PathBuf),
    /// This x86-64-v3 build was handed over to by a baseline build of other sources: replace
    /// the process with that baseline build.
    HandBack(PathBuf),
    /// This binary needs x86-64-v3 and the CPU lacks it: running on would stop at the first
    /// instruction it lacks (SIGILL).
    Unsupported,
}

/// The decision, from plain facts: the running binary's path, whether it was compiled for
/// x86-64-v3, whether the CPU has x86-64-v3's features, [`ISA_ENV`]'s and [`BUILD_ID_ENV`]'s
/// values, and whether a path is an executable file.
pub fn choose(
    exe: &Path,
    built_for_v3: bool,
    cpu_has_v3: bool,
    env: (Option<&OsStr>, Option<&OsStr>),
    is_executable: impl Fn(&Path) -> bool,
) -> IsaChoice {
    let (isa_env, handed_id) = env;
    let handed_over = isa_env.is_some_and(|v| v == V3_NAME);
    if built_for_v3 {
        if !cpu_has_v3 {
            return IsaChoice::Unsupported;
        }
        if handed_over && handed_id.is_some_and(|id| id != BUILD_ID) {
            let baseline = exe
                .to_str()
                .and_then(|path| path.strip_suffix(V3_SUFFIX))
                .map(PathBuf::from);
            if let Some(baseline) = baseline.filter(|path| is_executable(path)) {
                return IsaChoice::HandBack(baseline);
            }
        }
        return IsaChoice::Stay;
    }
    if !cpu_has_v3 || handed_over || isa_env.is_some_and(|v| v == "baseline") {
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
    let Some((exe, choice)) = this_process() else {
        return Ok(());
    };
    match choice {
        IsaChoice::Stay => Ok(()),
        IsaChoice::Unsupported => Err(format!(
            "{} was built for x86-64-v3 (AVX2, FMA, BMI2) and this CPU lacks some of it: run \
             the baseline build ({} without the suffix)",
            exe.display(),
            V3_SUFFIX
        )),
        IsaChoice::HandOver(sibling) => {
            exec(&sibling, V3_NAME, None);
            Ok(())
        }
        IsaChoice::HandBack(baseline) => {
            tracing::warn!(
                "{} was built from other sources than {} (an earlier build left beside it); \
                 rendering with the baseline build (`cargo build --release` makes both anew)",
                exe.display(),
                baseline.display()
            );
            exec(&baseline, "baseline", None);
            Err(format!(
                "{} is a build of other sources and {} could not be run",
                exe.display(),
                baseline.display()
            ))
        }
    }
}

/// This process's binary and [`choose`]'s decision for it (None when the binary's path is
/// unknown: it stays).
pub fn this_process() -> Option<(PathBuf, IsaChoice)> {
    let exe = std::env::current_exe().ok()?;
    let isa_env = std::env::var_os(ISA_ENV);
    let handed_id = std::env::var_os(BUILD_ID_ENV);
    let choice = choose(
        &exe,
        built_for_v3(),
        cpu_has_v3(),
        (isa_env.as_deref(), handed_id.as_deref()),
        is_executable,
    );
    Some((exe, choice))
}

/// Replaces this process with `binary`, its arguments this process's (after `first`, when
/// given), [`ISA_ENV`] set to `isa` and [`BUILD_ID_ENV`] to this build's id; returns only if
/// that fails.
pub fn exec(binary: &Path, isa: &str, first: Option<&str>) {
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        let error = std::process::Command::new(binary)
            .args(first)
            .args(std::env::args_os().skip(1))
            .env(ISA_ENV, isa)
            .env(BUILD_ID_ENV, BUILD_ID)
            .exec();
        tracing::warn!(
            "could not run {} ({error}); rendering with this build",
            binary.display()
        );
    }
    #[cfg(not(unix))]
    let _ = (binary, isa, first);
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

    const BASELINE: &str = "/opt/yat/bin/yat";
    const SIBLING: &str = "/opt/yat/bin/yat-x86-64-v3";

    /// The choice of the binary at `exe` when `present` are the executables there.
    fn start_at(
        exe: &str,
        built_for_v3: bool,
        cpu_has_v3: bool,
        env: (Option<&str>, Option<&str>),
        present: &[&str],
    ) -> IsaChoice {
        choose(
            Path::new(exe),
            built_for_v3,
            cpu_has_v3,
            (env.0.map(OsStr::new), env.1.map(OsStr::new)),
            |p| present.iter().any(|q| p == Path::new(q)),
        )
    }

    fn start(built_for_v3: bool, cpu_has_v3: bool, env: Option<&str>, sibling: bool) -> IsaChoice {
        let exe = if built_for_v3 { SIBLING } else { BASELINE };
        let present: &[&str] = if sibling {
            &[BASELINE, SIBLING]
        } else {
            &[BASELINE]
        };
        start_at(exe, built_for_v3, cpu_has_v3, (env, None), present)
    }

    #[test]
    fn a_baseline_build_hands_over_only_to_a_sibling_the_cpu_can_run() {
        let sibling = PathBuf::from(SIBLING);
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

    /// A sibling handed over to by a baseline of other sources hands the process back to it;
    /// one of the same sources, or run by hand, or without the baseline beside it, renders.
    #[test]
    fn a_sibling_of_other_sources_hands_back_to_the_baseline() {
        let both = [BASELINE, SIBLING];
        let handed = |id| start_at(SIBLING, true, true, (Some(V3_NAME), Some(id)), &both);
        assert_eq!(handed(BUILD_ID), IsaChoice::Stay);
        assert_eq!(
            handed("0123456789abcdef"),
            IsaChoice::HandBack(PathBuf::from(BASELINE))
        );
        let by_hand = start_at(SIBLING, true, true, (None, Some("0123456789abcdef")), &both);
        assert_eq!(by_hand, IsaChoice::Stay);
        let alone = start_at(
            SIBLING,
            true,
            true,
            (Some(V3_NAME), Some("other")),
            &[SIBLING],
        );
        assert_eq!(alone, IsaChoice::Stay);
        assert_eq!(BUILD_ID.len(), 16, "{BUILD_ID}");
    }

    #[test]
    fn a_path_without_a_file_name_stays() {
        let start = choose(Path::new("/"), false, true, (None, None), |_| true);
        assert_eq!(start, IsaChoice::Stay);
    }
}
