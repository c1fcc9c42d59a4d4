//! LuxCore's SDL: one `key = value` line per property, values written as LuxCore reads them,
//! and the names the export gives textures and materials.

use std::fmt::{Display, Write as _};

use glam::{Mat4, Vec3};
use yat_tracer::desc::{ConstOrTexture, MaterialId, TextureId};

/// SDL text: one `key = value` line per property.
#[derive(Default)]
pub struct Props(String);

impl Props {
    pub fn set(&mut self, key: impl Display, value: impl Display) {
        // Writing to a String cannot fail.
        let _ = writeln!(self.0, "{key} = {value}");
    }

    pub fn into_text(self) -> String {
        self.0
    }
}

pub fn v3(v: Vec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

pub fn quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "/").replace('"', ""))
}

/// Matrix properties are the 16 entries column by column (glam's own order).
pub fn matrix(m: &Mat4) -> String {
    m.to_cols_array()
        .iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

pub fn tex_name(id: TextureId) -> String {
    format!("tex{}", id.0)
}

pub fn mat_name(id: MaterialId) -> String {
    format!("mat{}", id.0)
}

/// A material or texture parameter: a constant inline, a texture by name.
pub fn tex_value(t: &ConstOrTexture, color: bool) -> String {
    match t {
        ConstOrTexture::Const(c) if color => v3(*c),
        ConstOrTexture::Const(c) => c.x.to_string(),
        ConstOrTexture::Texture(id) => quoted(&tex_name(*id)),
    }
}
