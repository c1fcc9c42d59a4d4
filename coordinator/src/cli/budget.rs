//! The build budget flags, the same on `yat render`, `yat check` and `yat worker`: what a scene
//! may cost to parse and build on this node.

use yat_tracer::budget::{self, BuildBudget};

const MIB: u64 = 1 << 20;

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
}

impl BudgetArgs {
    pub fn budget(&self) -> BuildBudget {
        BuildBudget {
            max_parsed_bytes: self.max_scene_mib.saturating_mul(MIB),
            max_include_visits: self.max_include_visits,
            max_primitives: self.max_primitives,
            max_texels: self.max_texels,
        }
    }
}
