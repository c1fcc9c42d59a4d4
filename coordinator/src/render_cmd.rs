//! `yat render`: in-process rendering and image output. OWNER: renderer (lead).

use std::path::PathBuf;

use yat_tracer::desc::SceneDesc;
use yat_tracer::film::Film;
use yat_tracer::render::{RenderSettings, UnitStats};

use crate::distributed::DistributedArgs;

#[derive(clap::Args)]
pub struct RenderArgs {
    /// The main .lxs file.
    pub scene: PathBuf,
    #[command(flatten)]
    pub distributed: DistributedArgs,
}

/// What a render needs, whoever renders it.
pub struct RenderJob {
    pub main_file: PathBuf,
    pub desc: SceneDesc,
    pub settings: RenderSettings,
    /// The PNG the render will write; previews go next to it.
    pub output_png: PathBuf,
    pub quiet: bool,
}

/// The merged result of a render.
pub struct RenderOutcome {
    pub film: Film,
    pub stats: UnitStats,
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    anyhow::bail!("render {} is not implemented yet", args.scene.display())
}
