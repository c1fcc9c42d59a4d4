//! Rendering over gRPC workers. OWNER: distributed helper.

/// Command-line options of a distributed render (flattened into `yat render`).
#[derive(clap::Args, Debug, Default)]
pub struct DistributedArgs {}

impl DistributedArgs {
    /// True when the render should go to workers instead of in-process.
    pub fn is_active(&self) -> bool {
        false
    }
}
