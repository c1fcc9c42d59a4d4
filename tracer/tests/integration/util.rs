//! Fixtures shared by the tracer's tests: where the workspace and the seed project are.

use std::path::{Path, PathBuf};

pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The seed project's scene folder (`$YAT_SEED_SCENES`, else
/// `<workspace>/../shared/seed-project/scenes`), or None with a message saying the tests that
/// need it are skipped.
pub fn seed_scenes() -> Option<PathBuf> {
    let dir = match std::env::var_os("YAT_SEED_SCENES") {
        Some(d) => PathBuf::from(d),
        None => workspace_root().join("../shared/seed-project/scenes"),
    };
    if dir.is_dir() {
        Some(dir)
    } else {
        println!(
            "seed scenes not found at {} (set YAT_SEED_SCENES); skipping",
            dir.display()
        );
        None
    }
}
