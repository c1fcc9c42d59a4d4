//! Names this build of the renderer: `YAT_RENDERER_BUILD`, a hash of the crate's sources and
//! manifest and of the workspace's manifest and locked dependency versions. Two builds with the
//! same name render the same bits (the determinism rules in docs/architecture.md make the build
//! profile and the CPU irrelevant); a coordinator refuses workers whose build differs from its
//! own.

use std::fs;
use std::path::{Path, PathBuf};

/// FNV-1a, 64 bits: enough to tell builds apart, and no build dependency.
fn fnv1a(hash: &mut u64, bytes: &[u8]) {
    for &b in bytes {
        *hash ^= u64::from(b);
        *hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else {
            out.push(path);
        }
    }
}

fn main() {
    let crate_dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let mut files = Vec::new();
    sources(&crate_dir.join("src"), &mut files);
    files.push(crate_dir.join("Cargo.toml"));
    // The workspace's manifest and lock file: the features and versions of glam, libm, obvhs,
    // image, ... compiled in.
    for workspace_file in ["Cargo.toml", "Cargo.lock"] {
        let path = crate_dir.join("..").join(workspace_file);
        if path.is_file() {
            files.push(path);
        }
    }
    files.sort();
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    for file in &files {
        let name = file.strip_prefix(&crate_dir).unwrap_or(file);
        fnv1a(&mut hash, name.to_string_lossy().as_bytes());
        fnv1a(&mut hash, &[0]);
        fnv1a(&mut hash, &fs::read(file).unwrap_or_default());
        fnv1a(&mut hash, &[0]);
    }
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.toml");
    println!("cargo:rerun-if-changed=../Cargo.toml");
    println!("cargo:rerun-if-changed=../Cargo.lock");
    println!("cargo:rustc-env=YAT_RENDERER_BUILD={hash:016x}");
}
