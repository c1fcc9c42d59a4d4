//! Writes a parsed scene as a LuxCoreRender scene: SDL properties (`scene.scn`, `render.cfg`)
//! and world-space binary PLY meshes. LuxCore then renders the geometry, camera, materials and
//! lights exactly as YAT parsed them, which its own `.lxs` importer does not (it drops spheres
//! and planar mappings, refuses metal2's `color fresnel`, and loses named materials and the
//! camera). The benchmark's side-by-side comparison renders these exports.
//!
//! What LuxCore cannot express is either converted with a note (spheres, disks and cylinders
//! are tessellated; planar, spherical and cylindrical mappings are baked into vertex uvs;
//! infinite planes become large quads) or refused with [`ExportError::Unsupported`] (the
//! course's fisheye camera).
//!
//! It reads only the scene description ([`yat_tracer::desc`]) and the tracer's mesh helpers.
//! One file per part of the output: `props` (the SDL text and the names of things), `camera`
//! (camera and `render.cfg`), `textures`, `materials`, `bake` (mappings baked into vertex
//! uvs), `shapes` (meshes and objects), `ply` (the PLY files), `lights`, `volumes` (clear and
//! homogeneous volumes, the camera's, a shape's interior and exterior); `options` and `error`
//! are the leaves they share.

mod bake;
mod camera;
mod daylight;
mod error;
mod lights;
mod materials;
mod materials_extra;
mod options;
mod ply;
mod procedural;
mod props;
mod shapes;
mod textures;
mod volumes;

use std::path::Path;

use yat_tracer::desc::{FilterKind, MaterialId, SceneDesc};

pub use error::ExportError;
pub use options::ExportOptions;

/// A LuxCore scene in memory: paths in `scene` and `config` are relative to the folder the
/// files are written to (LuxCore resolves them from its working directory), image paths are
/// absolute.
#[derive(Debug)]
pub struct LuxCoreScene {
    /// `scene.scn`: camera, textures, materials, shapes, objects, lights.
    pub scene: String,
    /// `render.cfg`: film size, pixel filter and `scene.file`; the caller adds the engine,
    /// sampler, depth and halt conditions.
    pub config: String,
    /// (relative path, binary PLY bytes).
    pub meshes: Vec<(String, Vec<u8>)>,
    /// Approximations made, one line each.
    pub notes: Vec<String>,
}

impl LuxCoreScene {
    pub fn write_to(&self, dir: &Path) -> std::io::Result<()> {
        std::fs::create_dir_all(dir.join("meshes"))?;
        std::fs::write(dir.join("scene.scn"), &self.scene)?;
        std::fs::write(dir.join("render.cfg"), &self.config)?;
        for (path, bytes) in &self.meshes {
            std::fs::write(dir.join(path), bytes)?;
        }
        Ok(())
    }
}

/// Converts a parsed scene. `scene_dir` is the main file's folder (image paths are relative
/// to it).
pub fn export(
    desc: &SceneDesc,
    scene_dir: &Path,
    opts: &ExportOptions,
) -> Result<LuxCoreScene, ExportError> {
    let mut notes = Vec::new();
    if matches!(
        desc.filter.kind,
        FilterKind::Triangle | FilterKind::Sinc { .. }
    ) {
        notes.push("pixel filter: LuxCore has no triangle or sinc filter; Blackman-Harris".into());
    }
    let mut p = props::Props::default();
    camera::write_camera(desc, &mut p)?;
    volumes::write_volumes(desc, &mut p);
    textures::write_textures(desc, scene_dir, &mut p, &mut notes)?;
    for (i, m) in desc.materials.iter().enumerate() {
        materials::write_material(&mut p, &props::mat_name(MaterialId(i as u32)), m, None);
    }
    let meshes = shapes::write_shapes(desc, opts, &mut p, &mut notes)?;
    for (i, light) in desc.lights.iter().enumerate() {
        lights::write_light(&mut p, i, light, scene_dir, opts, &mut notes);
        // Light groups are LuxCore's light ids (0, the first group, its default).
        let group = desc
            .film
            .light_groups
            .of_sources
            .get(i)
            .copied()
            .unwrap_or(0);
        if group > 0 {
            p.set(format!("scene.lights.light{i}.id"), group);
        }
    }
    Ok(LuxCoreScene {
        scene: p.into_text(),
        config: camera::write_config(desc),
        meshes,
        notes,
    })
}

#[cfg(test)]
mod tests;
