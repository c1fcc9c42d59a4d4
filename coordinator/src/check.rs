//! `yat check`: parse a scene and print a summary. OWNER: parser helper.

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct CheckArgs {
    /// The main .lxs file.
    pub scene: PathBuf,
}

pub fn run(args: CheckArgs) -> anyhow::Result<()> {
    anyhow::bail!("check {} is not implemented yet", args.scene.display())
}
