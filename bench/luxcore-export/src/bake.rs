//! Texture mappings LuxCore lacks (planar, spherical, cylindrical) are baked into the vertex
//! uvs of the shapes whose material reads them; this finds the one mapping a material needs.

use std::collections::BTreeSet;

use yat_tracer::desc::{ConstOrTexture, Mapping2D, MaterialId, SceneDesc, TextureId, TextureKind};

use crate::error::ExportError;

/// Whether a 2D mapping is one LuxCore lacks and the export bakes into vertex uvs.
fn is_baked(mapping: &Mapping2D) -> bool {
    !matches!(mapping, Mapping2D::Uv { .. })
}

fn push_tex(t: &ConstOrTexture, out: &mut Vec<TextureId>) {
    if let ConstOrTexture::Texture(id) = t {
        out.push(*id);
    }
}

/// Textures a texture reads directly.
fn texture_inputs(kind: &TextureKind) -> Vec<TextureId> {
    let mut out = Vec::new();
    for t in kind.references() {
        push_tex(&t, &mut out);
    }
    out
}

/// The one non-uv mapping the material's textures use, if any: shapes with this material get
/// it baked into their uvs. A material that also reads uv-mapped textures, or two different
/// baked mappings, cannot be expressed.
pub fn material_bake(
    desc: &SceneDesc,
    material: MaterialId,
) -> Result<Option<Mapping2D>, ExportError> {
    let mut seen_mats = BTreeSet::new();
    let mut seen_tex = BTreeSet::new();
    let mut mat_stack = vec![material];
    let mut tex_stack = Vec::new();
    while let Some(m) = mat_stack.pop() {
        if !seen_mats.insert(m.0) {
            continue;
        }
        if let Some(md) = desc.materials.get(m.0 as usize) {
            tex_stack.extend(md.textures());
            mat_stack.extend(md.materials());
        }
    }
    let mut baked: Vec<&Mapping2D> = Vec::new();
    let mut uv_mapped = false;
    while let Some(t) = tex_stack.pop() {
        if !seen_tex.insert(t.0) {
            continue;
        }
        let Some(td) = desc.textures.get(t.0 as usize) else {
            continue;
        };
        tex_stack.extend(texture_inputs(&td.kind));
        match td.kind.mapping() {
            Some(m) if is_baked(m) && !baked.contains(&m) => baked.push(m),
            Some(m) if is_baked(m) => {}
            Some(_) => uv_mapped = true,
            None => {}
        }
    }
    match baked.as_slice() {
        [] => Ok(None),
        [m] if !uv_mapped => Ok(Some((*m).clone())),
        _ => Err(ExportError::Unsupported(format!(
            "material #{} combines texture mappings that cannot share one set of vertex uvs",
            material.0
        ))),
    }
}
