//! `yat render`: in-process rendering and image output. OWNER: renderer (lead).

use std::path::PathBuf;

use crate::distributed::DistributedArgs;

#[derive(clap::Args)]
pub struct RenderArgs {
    /// The main .lxs file.
    pub scene: PathBuf,
    #[command(flatten)]
    pub distributed: DistributedArgs,
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    anyhow::bail!("render {} is not implemented yet", args.scene.display())
}
