//! The narrow interface between the parser's graphics state and the readers of each family of
//! descriptions (materials, textures, lights, shapes, options): diagnostics, name lookup,
//! referenced files and the current transform. Readers take `&mut dyn ParseContext`, so a new
//! kind of material or light never needs to know how the builder keeps its state.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};

use super::error::ParseError;
use super::params::{ConstOrTextureName, ParamList, ParamType, Values};
use crate::assets::AssetKind;
use crate::diag::{Severity, SourcePos};
use crate::mesh::TriangleMesh;
use crate::refs::{ConstOrTexture, Fresnel, MaterialId, TextureId};
use crate::spectra::metal_preset;

/// What a texture name is bound to in the current attribute scope. Fresnel textures are not
/// evaluated per hit: metal materials fold them into their description.
#[derive(Clone, Debug)]
pub enum BoundTexture {
    Texture(TextureId),
    Fresnel(Fresnel),
}

/// What an image file is read for: each use decodes it its own way.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ImageUse {
    /// An image texture's texels at this gamma (decoded once per file and gamma).
    Texture { gamma: f32 },
    /// An infinite light's map, with its sampling tables (decoded for each light).
    Environment,
}

pub trait ParseContext {
    /// Records a warning of kind `key`: the first occurrence of a kind with its message, later
    /// ones as positions of it (so `yat check` lists and counts every occurrence while a render
    /// prints each kind once).
    fn diagnose(&mut self, severity: Severity, key: String, pos: &SourcePos, message: String);

    /// Something not rendered as LuxRender would; occurrences with the same message are one
    /// kind.
    fn warn(&mut self, pos: &SourcePos, message: String) {
        self.diagnose(
            Severity::Differs,
            format!("message|{message}"),
            pos,
            message,
        );
    }

    /// Something not rendered as LuxRender would, of kind `key`: its message is the first
    /// occurrence's, later ones are listed as positions.
    fn warn_once(&mut self, key: String, pos: &SourcePos, message: String) {
        self.diagnose(Severity::Differs, key, pos, message);
    }

    /// A difference from LuxRender's image that is documented and accepted, of kind `key`:
    /// listed apart from the differences, and not counted as one.
    fn accepted_once(&mut self, key: String, pos: &SourcePos, message: String) {
        self.diagnose(Severity::Accepted, key, pos, message);
    }

    /// Something about the file that leaves the image as LuxRender would render it (the same
    /// fallback, a parameter it ignores too); occurrences with the same message are one kind.
    fn note(&mut self, pos: &SourcePos, message: String) {
        self.diagnose(Severity::Note, format!("note|{message}"), pos, message);
    }

    /// A note of kind `key`.
    fn note_once(&mut self, key: String, pos: &SourcePos, message: String) {
        self.diagnose(Severity::Note, key, pos, message);
    }

    /// The current transformation matrix (object, light or texture space to world).
    fn ctm(&self) -> Mat4;

    /// The texture named `name` in scope, preferring one of the requested kind (a float
    /// texture used as a colour is splatted).
    fn find_texture(&self, name: &str, want_color: bool) -> Option<BoundTexture>;

    /// Whether texture `id` was declared "color" (else "float").
    fn texture_is_color(&self, id: TextureId) -> bool;

    /// The value of a texture-or-constant that is the same at every point (a constant, a
    /// blackbody, scale or mix of such), None if it varies over a surface.
    fn uniform_texture(&self, tex: ConstOrTexture) -> Option<Vec3>;

    /// A new texture: texture `id` times the constant `factor`.
    fn scaled_texture(&mut self, id: TextureId, factor: f32) -> TextureId;

    /// The material made with `MakeNamedMaterial name`, or the default with a warning.
    fn named_material(&mut self, name: &str, pos: &SourcePos) -> MaterialId;

    /// LuxRender's default material (a shape with none, a dangling name).
    fn default_material(&mut self) -> MaterialId;

    /// Reads a referenced file and records it as one of the scene's assets.
    fn read_asset(
        &mut self,
        path: &str,
        kind: AssetKind,
        pos: &SourcePos,
    ) -> Result<Arc<[u8]>, ParseError>;

    /// Checks that an image file exists and its header decodes, records it as an asset, and
    /// counts what decoding it for `purpose` will take against the build budget.
    fn check_image(
        &mut self,
        path: &str,
        purpose: ImageUse,
        pos: &SourcePos,
    ) -> Result<(), ParseError>;

    /// The triangle mesh of a PLY file, read, validated and recorded as an asset on first use
    /// and shared by every later shape that names the same file.
    fn ply_mesh(&mut self, path: &str, pos: &SourcePos) -> Result<Arc<TriangleMesh>, ParseError>;

    /// Fails (naming the limit and `pos`) unless `count` more primitives fit the build budget:
    /// what a shape that multiplies its input (subdivision) checks before making them.
    fn check_primitives(&self, count: u64, pos: &SourcePos) -> Result<(), ParseError>;

    /// The float texture `tex` (a colour texture gives the mean of its channels) at
    /// object-space points of the current object with their (u, v): what a displacement map
    /// reads while the shape is built. Fails if an image the textures read does not decode.
    fn eval_float_texture(
        &mut self,
        tex: ConstOrTexture,
        points: &[(Vec3, Vec2)],
        pos: &SourcePos,
    ) -> Result<Vec<f32>, ParseError>;

    /// Reports (once per statement type and parameter) what the table of LuxRender's
    /// parameters says of the statement's ([`super::luxrender_params::verdict`]): parameters
    /// nothing read, and those read by LuxRender that change nothing in its image.
    fn warn_unused(&mut self, params: &ParamList);

    /// Resolves a texture-or-constant parameter; an undefined texture name (or a fresnel
    /// texture where a colour or float is wanted) is a warning and falls back to `default`.
    fn tex(&mut self, v: ConstOrTextureName, want_color: bool, default: Vec3) -> ConstOrTexture {
        match v {
            ConstOrTextureName::Const(c) => ConstOrTexture::Const(c),
            ConstOrTextureName::Named { name, pos } => match self.find_texture(&name, want_color) {
                Some(BoundTexture::Texture(id)) => ConstOrTexture::Texture(id),
                Some(BoundTexture::Fresnel(_)) => {
                    self.warn(&pos, format!("texture \"{name}\" is a fresnel texture, usable only as metal2's fresnel; using the default"));
                    ConstOrTexture::Const(default)
                }
                // LuxRender's fallback too: a constant of the parameter's default.
                None => {
                    self.note(
                        &pos,
                        format!("no texture named \"{name}\"; using the default"),
                    );
                    ConstOrTexture::Const(default)
                }
            },
        }
    }

    /// A named metal preset's complex index (eta, k), or aluminium with a warning (LuxRender's
    /// fallback for an unknown name). Used by the `fresnelname` texture and the `metal`
    /// material (which reads `.nk` data files itself).
    fn metal_by_name(&mut self, name: &str, pos: &SourcePos) -> (Vec3, Vec3) {
        if let Some(p) = metal_preset(name) {
            return p;
        }
        self.note(
            pos,
            format!("metal \"{name}\" is not a built-in preset or an .nk file; using aluminium"),
        );
        metal_preset("aluminium").expect("aluminium is a preset")
    }

    /// A colour parameter (constant or texture); constants are clamped to [0, 1] when `clamp`.
    fn color_param(
        &mut self,
        params: &ParamList,
        name: &str,
        default: f32,
        clamp: bool,
    ) -> Result<ConstOrTexture, ParseError> {
        let v = params.tex_color(name, Vec3::splat(default))?;
        Ok(match self.tex(v, true, Vec3::splat(default)) {
            ConstOrTexture::Const(c) if clamp => {
                ConstOrTexture::Const(c.clamp(Vec3::ZERO, Vec3::ONE))
            }
            t => t,
        })
    }

    /// A float parameter (constant or texture).
    fn float_param(
        &mut self,
        params: &ParamList,
        name: &str,
        default: f32,
    ) -> Result<ConstOrTexture, ParseError> {
        let v = params.tex_float(name, default)?;
        Ok(self.tex(v, false, Vec3::splat(default)))
    }

    /// A parameter this renderer does not model: silent at its default, a warning (once per
    /// statement and parameter) otherwise.
    fn unsupported_unless(&mut self, params: &ParamList, name: &str, default: f32) {
        let Some(p) = params.find(name) else {
            return;
        };
        let is_default = matches!(&p.values, Values::Numbers(v) if v.len() == 1 && v[0] as f32 == default)
            && matches!(p.ty, ParamType::Float | ParamType::Integer);
        if !is_default {
            let key = format!("unsupported|{}|{name}", params.statement);
            let message = format!(
                "{}: \"{}\" is not supported and is ignored",
                params.statement,
                p.decl()
            );
            let pos = p.pos.clone();
            self.warn_once(key, &pos, message);
        }
    }
}
