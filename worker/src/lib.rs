//! The render node: a gRPC server that receives a scene and renders work units.
//! OWNER: distributed helper.

#[derive(clap::Args, Debug)]
pub struct WorkerArgs {}

pub fn run(_args: WorkerArgs) -> anyhow::Result<()> {
    anyhow::bail!("worker is not implemented yet")
}
