//! The build budget flags, the same on `yat render`, `yat check` and `yat worker`: what a scene
//! may cost to parse and build on this node. The memory figure's default is what this process
//! may still use ([`MemoryLimit::detect`], once, when the command line is read), and its help
//! says which limit that came from.

use std::sync::OnceLock;

use yat_tracer::budget::memory_limit::MemoryLimit;
use yat_tracer::budget::{self, BuildBudget};

const MIB: u64 = 1 << 20;

/// This process's memory limit, found once.
fn detected() -> &'static MemoryLimit {
    static DETECTED: OnceLock<MemoryLimit> = OnceLock::new();
    DETECTED.get_or_init(MemoryLimit::detect)
}

/// The `--max-memory-mib` default: what the build may hold under this process's limit.
fn default_memory_mib() -> u64 {
    detected().build_bytes() / MIB
}

fn memory_help() -> String {
    format!(
        "Most MiB the scene's build may hold at its peak, as estimated from its counts before \
         anything is allocated (primitives placed, with their share of the BVH; images, from \
         their headers; sky tables; and on `yat render`, the film). The default is {}",
        detected()
    )
}

#[derive(clap::Args, Clone, Debug)]
pub struct BudgetArgs {
    /// Most MiB of scene text parsed (a file counts once per Include of it; PLY files once).
    #[arg(long, value_name = "MIB", default_value_t = budget::DEFAULT_MAX_PARSED_BYTES / MIB)]
    pub max_scene_mib: u64,
    /// Most Include statements followed in one scene.
    #[arg(long, value_name = "N", default_value_t = budget::DEFAULT_MAX_INCLUDE_VISITS)]
    pub max_include_visits: u64,
    /// Most primitives (triangles, spheres, disks...) placed, counting every instance.
    #[arg(long, value_name = "N", default_value_t = budget::DEFAULT_MAX_PRIMITIVES)]
    pub max_primitives: u64,
    /// Most texels of the scene's image files (counted from their headers, before decoding).
    #[arg(long, value_name = "N", default_value_t = budget::DEFAULT_MAX_TEXELS)]
    pub max_texels: u64,
    #[arg(long, value_name = "MIB", default_value_t = default_memory_mib(), help = memory_help())]
    pub max_memory_mib: u64,
}

impl BudgetArgs {
    pub fn budget(&self) -> BuildBudget {
        BuildBudget {
            max_parsed_bytes: self.max_scene_mib.saturating_mul(MIB),
            max_include_visits: self.max_include_visits,
            max_primitives: self.max_primitives,
            max_texels: self.max_texels,
            max_memory_bytes: self.max_memory_mib.saturating_mul(MIB),
        }
    }
}
