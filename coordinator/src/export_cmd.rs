//! `yat export-luxcore`: write a scene as LuxCoreRender SDL with world-space PLY meshes, so
//! LuxCore renders the scene exactly as YAT parsed it (the benchmark's side by side).

use std::path::PathBuf;

use anyhow::Context;
use yat_luxcore::{export, ExportOptions};
use yat_tracer::assets::FsSource;
use yat_tracer::parse::parse_scene;

use crate::render_cmd::LatLongArg;

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
    let main = args
        .scene
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("\"{}\" is not a scene file path", args.scene.display()))?;
    let source = FsSource::for_main_file(&args.scene);
    let desc = parse_scene(main, &source)
        .with_context(|| format!("cannot load scene {}", args.scene.display()))?;
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
