//! `yat export-luxcore`: write a scene as LuxCoreRender SDL with world-space PLY meshes, so
//! LuxCore renders the scene exactly as YAT parsed it (the benchmark's side by side).

use std::path::PathBuf;

use anyhow::Context;
use yat_luxcore::{export, ExportOptions};

use super::latlong::LatLongArg;
use crate::scene::{ParsedScene, Warnings};

#[derive(clap::Args)]
pub struct ExportArgs {
    /// The main .lxs file.
    pub scene: PathBuf,
    /// Folder to write scene.scn, render.cfg and meshes/ into (created if missing).
    pub out_dir: PathBuf,
    /// LatLong convention YAT renders with; LuxCore's map is turned to match.
    #[arg(long, value_enum, default_value = "seed")]
    pub latlong: LatLongArg,
    /// Segments around tessellated spheres, disks and cylinders.
    #[arg(long, default_value_t = 256)]
    pub segments: u32,
}

pub fn run(args: ExportArgs) -> anyhow::Result<()> {
    let desc = ParsedScene::load(&args.scene, Warnings::Keep)?.desc;
    let scene_dir = std::path::absolute(&args.scene)?
        .parent()
        .map(PathBuf::from)
        .unwrap_or_default();
    let opts = ExportOptions {
        latlong: args.latlong.into(),
        segments: args.segments,
    };
    let lux = export(&desc, &scene_dir, &opts)
        .with_context(|| format!("cannot export {}", args.scene.display()))?;
    lux.write_to(&args.out_dir)
        .with_context(|| format!("cannot write {}", args.out_dir.display()))?;
    for note in &lux.notes {
        eprintln!("note: {note}");
    }
    println!(
        "wrote {} ({} meshes)",
        args.out_dir.join("scene.scn").display(),
        lux.meshes.len()
    );
    Ok(())
}
