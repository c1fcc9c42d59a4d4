//! Textures (`scene.textures.tex<N>`): each YAT texture as the LuxCore texture of the same
//! meaning, with its 2D mapping as LuxCore's uvmapping2d (baked mappings read the vertex uvs).

use std::path::Path;

use glam::Vec2;
use yat_tracer::desc::{Mapping2D, SceneDesc, TextureId, TextureKind, Wrap};
use yat_tracer::texture::{
    Checkerboard, Checkerboard2D, Checkerboard3D, Constant, ImageMap, Mix, Scale,
};

use crate::error::ExportError;
use crate::procedural::{write_mapping3d, write_procedural};
use crate::props::{quoted, tex_name, tex_value, v3, Props};

/// LuxCore's uvmapping2d is YAT's uv mapping (scale, then offset), and both read image row
/// t x height counted from the top, so the parameters carry over unchanged.
fn write_mapping(p: &mut Props, prefix: &str, mapping: &Mapping2D) {
    p.set(format!("{prefix}.mapping.type"), quoted("uvmapping2d"));
    let (scale, delta) = match *mapping {
        Mapping2D::Uv {
            uscale,
            vscale,
            udelta,
            vdelta,
        } => (Vec2::new(uscale, vscale), Vec2::new(udelta, vdelta)),
        // Baked: the vertex uvs already hold the texture coordinates.
        _ => (Vec2::ONE, Vec2::ZERO),
    };
    p.set(
        format!("{prefix}.mapping.uvscale"),
        format!("{} {}", scale.x, scale.y),
    );
    p.set(
        format!("{prefix}.mapping.uvdelta"),
        format!("{} {}", delta.x, delta.y),
    );
}

pub fn write_textures(
    desc: &SceneDesc,
    scene_dir: &Path,
    p: &mut Props,
    notes: &mut Vec<String>,
) -> Result<(), ExportError> {
    for (i, t) in desc.textures.iter().enumerate() {
        let prefix = format!("scene.textures.{}", tex_name(TextureId(i as u32)));
        let color = t.is_color;
        match &t.kind {
            TextureKind::ImageMap(ImageMap {
                filename,
                gamma,
                gain,
                wrap,
                mapping,
            }) => {
                p.set(format!("{prefix}.type"), quoted("imagemap"));
                let path = scene_dir.join(filename);
                p.set(format!("{prefix}.file"), quoted(&path.to_string_lossy()));
                p.set(format!("{prefix}.gamma"), gamma);
                p.set(format!("{prefix}.gain"), gain);
                let wrap = match wrap {
                    Wrap::Repeat => "repeat",
                    Wrap::Black => "black",
                    Wrap::White => "white",
                    Wrap::Clamp => "clamp",
                };
                p.set(format!("{prefix}.wrap"), quoted(wrap));
                if !color {
                    p.set(format!("{prefix}.channel"), quoted("mean"));
                }
                write_mapping(p, &prefix, mapping);
            }
            TextureKind::Checkerboard(Checkerboard::D2(Checkerboard2D {
                tex1,
                tex2,
                mapping,
            })) => {
                p.set(format!("{prefix}.type"), quoted("checkerboard2d"));
                p.set(format!("{prefix}.texture1"), tex_value(tex1, color));
                p.set(format!("{prefix}.texture2"), tex_value(tex2, color));
                write_mapping(p, &prefix, mapping);
            }
            TextureKind::Checkerboard(Checkerboard::D3(Checkerboard3D {
                tex1,
                tex2,
                mapping,
            })) => {
                p.set(format!("{prefix}.type"), quoted("checkerboard3d"));
                p.set(format!("{prefix}.texture1"), tex_value(tex1, color));
                p.set(format!("{prefix}.texture2"), tex_value(tex2, color));
                write_mapping3d(p, &prefix, mapping);
            }
            TextureKind::Constant(Constant { value }) => {
                p.set(format!("{prefix}.type"), quoted("constfloat3"));
                p.set(format!("{prefix}.value"), v3(*value));
            }
            TextureKind::Scale(Scale { tex1, tex2 }) => {
                p.set(format!("{prefix}.type"), quoted("scale"));
                p.set(format!("{prefix}.texture1"), tex_value(tex1, color));
                p.set(format!("{prefix}.texture2"), tex_value(tex2, color));
            }
            TextureKind::Mix(Mix { tex1, tex2, amount }) => {
                p.set(format!("{prefix}.type"), quoted("mix"));
                p.set(format!("{prefix}.texture1"), tex_value(tex1, color));
                p.set(format!("{prefix}.texture2"), tex_value(tex2, color));
                p.set(format!("{prefix}.amount"), tex_value(amount, false));
            }
            other if write_procedural(p, &prefix, other, color, scene_dir, notes) => {}
            other => {
                return Err(ExportError::Unsupported(format!(
                    "texture \"{}\": no LuxCore equivalent for type \"{}\"",
                    t.name,
                    other.name()
                )))
            }
        }
    }
    Ok(())
}
