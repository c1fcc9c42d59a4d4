//! Two things for the `yat` binary (`src/isa.rs` uses both):
//!
//! - `YAT_BUILD_ID`: a hash of the sources the binary is built from (every workspace crate it
//!   links, the lock file, the compiler's version). Two builds of one tree carry the same id
//!   whatever their flags, so a baseline `yat` hands over only to a sibling built from its own
//!   sources, never to a stale one left beside it.
//! - On a release build for x86-64 whose target is not x86-64-v3 already, the same binary
//!   compiled for x86-64-v3 (AVX2, FMA, BMI1/2, ...), installed beside the baseline one as
//!   `yat-x86-64-v3`: so the README's `cargo build --release` (or `cargo run --release`) gives
//!   what a CPU with those features runs fastest, the same image bytes (some 10% fewer
//!   instructions; bench/RESULTS.md, session 44). A nested cargo build in its own target
//!   directory: it doubles the release build's time. `YAT_BUILD_V3=0` skips it (the baseline
//!   binary then renders alone, as before); a failed nested build is a warning, not a failed
//!   build.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace directories whose files make the binary: the crates `yat` links.
const SOURCE_DIRS: &[&str] = &[
    "coordinator",
    "tracer",
    "proto",
    "worker",
    "bench/luxcore-export",
];

/// The environment variable that turns the x86-64-v3 sibling off (`0`), and that the nested
/// build is run with so it does not nest again.
const BUILD_V3_ENV: &str = "YAT_BUILD_V3";

fn main() {
    let manifest = PathBuf::from(env("CARGO_MANIFEST_DIR"));
    let workspace = manifest
        .parent()
        .expect("coordinator/ has a parent")
        .to_path_buf();
    let mut files = vec![workspace.join("Cargo.lock"), workspace.join("Cargo.toml")];
    for dir in SOURCE_DIRS {
        let dir = workspace.join(dir);
        println!("cargo:rerun-if-changed={}", dir.display());
        source_files(&dir, &mut files);
    }
    for file in &files[..2] {
        println!("cargo:rerun-if-changed={}", file.display());
    }
    println!("cargo:rerun-if-env-changed={BUILD_V3_ENV}");
    let id = build_id(&workspace, &mut files);
    println!("cargo:rustc-env=YAT_BUILD_ID={id}");

    if wants_v3_sibling() {
        build_v3_sibling(&workspace);
    }
}

fn env(name: &str) -> String {
    std::env::var(name).unwrap_or_default()
}

/// The files under `dir` that a build reads: everything but build output and hidden files.
fn source_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') || name == "target" {
            continue;
        }
        match entry.file_type() {
            Ok(t) if t.is_dir() => source_files(&path, out),
            Ok(t) if t.is_file() => out.push(path),
            _ => {}
        }
    }
}

/// A hash of the files' paths (relative to the workspace) and contents, in sorted order, and
/// of the compiler's version.
fn build_id(workspace: &Path, files: &mut [PathBuf]) -> String {
    files.sort();
    let mut hasher = DefaultHasher::new();
    for file in files.iter() {
        file.strip_prefix(workspace)
            .unwrap_or(file)
            .hash(&mut hasher);
        std::fs::read(file).unwrap_or_default().hash(&mut hasher);
    }
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    if let Ok(out) = Command::new(rustc).arg("-vV").output() {
        out.stdout.hash(&mut hasher);
    }
    format!("{:016x}", hasher.finish())
}

/// A release build for x86-64, not itself compiled for x86-64-v3, and not turned off.
fn wants_v3_sibling() -> bool {
    let features = env("CARGO_CFG_TARGET_FEATURE");
    let features: Vec<&str> = features.split(',').collect();
    let already_v3 = ["avx2", "fma", "bmi2"].iter().all(|f| features.contains(f));
    env("PROFILE") == "release"
        && env("CARGO_CFG_TARGET_ARCH") == "x86_64"
        && !already_v3
        && env(BUILD_V3_ENV) != "0"
}

/// Builds `yat` for x86-64-v3 in `<target>/x86-64-v3` and installs it beside the binary this
/// build makes, as `yat-x86-64-v3`.
fn build_v3_sibling(workspace: &Path) {
    // OUT_DIR is <profile dir>/build/yat-<hash>/out; the binary goes to <profile dir>.
    let out_dir = PathBuf::from(env("OUT_DIR"));
    let Some(profile_dir) = out_dir.ancestors().nth(3) else {
        println!(
            "cargo:warning=no x86-64-v3 build: unexpected OUT_DIR {}",
            out_dir.display()
        );
        return;
    };
    let nested_target = profile_dir.join("x86-64-v3");
    let triple = env("TARGET");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    // --target keeps the CPU flag off build scripts and proc macros; --offline: the outer
    // build has fetched every crate. The outer build's own flags (CARGO_ENCODED_RUSTFLAGS)
    // carry over, with the CPU added.
    let mut flags = env("CARGO_ENCODED_RUSTFLAGS");
    if !flags.is_empty() {
        flags.push('\x1f');
    }
    flags.push_str("-Ctarget-cpu=x86-64-v3");
    let status = Command::new(cargo)
        .current_dir(workspace)
        .args([
            "build",
            "--release",
            "--offline",
            "--locked",
            "-p",
            "yat",
            "--bin",
            "yat",
        ])
        .arg("--target")
        .arg(&triple)
        .arg("--target-dir")
        .arg(&nested_target)
        .env(BUILD_V3_ENV, "0")
        .env("CARGO_ENCODED_RUSTFLAGS", flags)
        .env_remove("RUSTFLAGS")
        .status();
    let built = nested_target.join(&triple).join("release").join("yat");
    let installed = profile_dir.join("yat-x86-64-v3");
    match status {
        Ok(s) if s.success() => {
            // Copied beside, then renamed over: a sibling still running keeps its file.
            let staged = profile_dir.join(".yat-x86-64-v3.new");
            let installed_ok =
                std::fs::copy(&built, &staged).and_then(|_| std::fs::rename(&staged, &installed));
            if let Err(e) = installed_ok {
                println!(
                    "cargo:warning=could not install the x86-64-v3 build as {}: {e}",
                    installed.display()
                );
            }
        }
        other => {
            // The baseline binary renders the same images without it.
            let _ = std::fs::remove_file(&installed);
            println!(
                "cargo:warning=the x86-64-v3 build of yat failed ({other:?}); the baseline \
                 build renders alone (set {BUILD_V3_ENV}=0 to skip it)"
            );
        }
    }
}
