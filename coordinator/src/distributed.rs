//! Rendering over gRPC workers. OWNER: distributed helper.

use crate::render_cmd::{RenderJob, RenderOutcome};

/// Command-line options of a distributed render (flattened into `yat render`).
#[derive(clap::Args, Debug, Default)]
pub struct DistributedArgs {}

impl DistributedArgs {
    /// True when the render should go to workers instead of in-process.
    pub fn is_active(&self) -> bool {
        false
    }
}

pub fn render(_args: &DistributedArgs, _job: &RenderJob) -> anyhow::Result<RenderOutcome> {
    anyhow::bail!("distributed rendering is not implemented yet")
}
