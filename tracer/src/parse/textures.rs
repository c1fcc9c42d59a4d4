//! `Texture "name" "float"|"color"|"fresnel" "type" params`: texture descriptions, and the
//! resolution of texture-or-constant material parameters.

use glam::Vec3;

use super::builder::Builder;
use super::context::{ParseContext, TexBinding};
use super::params::ParamList;
use super::spectra::{blackbody_rgb, metal_preset};
use super::{ParseError, Pos};
use crate::desc::{Mapping2D, TextureDesc, TextureKind, Wrap};
use crate::param::{Fresnel, Tex};

impl Builder<'_> {
    pub(super) fn texture(
        &mut self,
        name: String,
        kind: &str,
        class: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<(), ParseError> {
        let is_color = match kind {
            "color" | "spectrum" => true,
            "float" => false,
            "fresnel" => {
                if let Some(f) = self.fresnel_texture(class, params, pos)? {
                    self.bind_texture(name, true, TexBinding::Fresnel(f));
                }
                return Ok(());
            }
            other => {
                return Err(ParseError::Invalid {
                    pos: pos.clone(),
                    message: format!(
                        "Texture \"{name}\": unknown texture kind \"{other}\" (expected \"float\", \"color\" or \"fresnel\")"
                    ),
                })
            }
        };
        // LuxRender also accepts the fresnel texture types under "color".
        if matches!(class, "fresnelcolor" | "fresnelname" | "preset") {
            if let Some(f) = self.fresnel_texture(class, params, pos)? {
                self.bind_texture(name, true, TexBinding::Fresnel(f));
            }
            return Ok(());
        }
        let tex = |b: &mut Self, n: &str, default: f32| -> Result<Tex, ParseError> {
            let v = if is_color {
                params.tex_color(n, Vec3::splat(default))?
            } else {
                params.tex_float(n, default)?
            };
            Ok(b.tex(v, is_color, Vec3::splat(default)))
        };
        let texture_kind = match class {
            "imagemap" => {
                let Some(filename) = params.string("filename")? else {
                    return Err(ParseError::Invalid {
                        pos: pos.clone(),
                        message: format!("Texture \"{name}\": imagemap needs \"string filename\""),
                    });
                };
                self.check_image(&filename, pos)?;
                let wrap = match params.string_or("wrap", "repeat")?.as_str() {
                    "repeat" => Wrap::Repeat,
                    "black" => Wrap::Black,
                    "white" => Wrap::White,
                    "clamp" => Wrap::Clamp,
                    other => {
                        self.warn(
                            pos,
                            format!("Texture \"{name}\": unknown wrap \"{other}\"; using repeat"),
                        );
                        Wrap::Repeat
                    }
                };
                if !is_color {
                    if let Some(channel) = params.string("channel")? {
                        if channel != "mean" {
                            self.warn(pos, format!("Texture \"{name}\": channel \"{channel}\" is not supported; using the mean"));
                        }
                    }
                }
                TextureKind::ImageMap {
                    gamma: params.float("gamma", 1.0)?,
                    gain: params.float("gain", 1.0)?,
                    wrap,
                    mapping: self.mapping(params, pos)?,
                    filename,
                }
            }
            "checkerboard" => {
                let dimension = params.int("dimension", 2)?;
                params.ignore("aamode");
                let tex1 = tex(self, "tex1", 1.0)?;
                let tex2 = tex(self, "tex2", 0.0)?;
                match dimension {
                    2 => TextureKind::Checkerboard2D {
                        tex1,
                        tex2,
                        mapping: self.mapping(params, pos)?,
                    },
                    3 => TextureKind::Checkerboard3D {
                        tex1,
                        tex2,
                        world_to_texture: self.ctm().inverse(),
                    },
                    d => {
                        let p = params.find("dimension").expect("read above");
                        return Err(params.error(p, format!("{d} is not 2 or 3")));
                    }
                }
            }
            "constant" => TextureKind::Constant(if is_color {
                params.color("value", Vec3::ONE)?
            } else {
                Vec3::splat(params.float("value", 1.0)?)
            }),
            "scale" => TextureKind::Scale {
                tex1: tex(self, "tex1", 1.0)?,
                tex2: tex(self, "tex2", 1.0)?,
            },
            "mix" => {
                let amount = params.tex_float("amount", 0.5)?;
                TextureKind::Mix {
                    tex1: tex(self, "tex1", 0.0)?,
                    tex2: tex(self, "tex2", 1.0)?,
                    amount: self.tex(amount, false, Vec3::splat(0.5)),
                }
            }
            "blackbody" => {
                TextureKind::Constant(blackbody_rgb(params.float("temperature", 6500.0)?))
            }
            other => {
                for p in &params.params {
                    params.ignore(&p.name);
                }
                self.warn(
                    pos,
                    format!("Texture \"{name}\": type \"{other}\" is not supported; the texture is left undefined"),
                );
                return Ok(());
            }
        };
        let id = self.add_texture(TextureDesc {
            name: name.clone(),
            is_color,
            kind: texture_kind,
        });
        self.bind_texture(name, is_color, TexBinding::Texture(id));
        Ok(())
    }

    /// fresnelcolor (a reflectance colour), fresnelname / preset (a named metal) and a
    /// constant index.
    fn fresnel_texture(
        &mut self,
        class: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<Option<Fresnel>, ParseError> {
        Ok(Some(match class {
            "fresnelcolor" => {
                let kr = params.tex_color("Kr", Vec3::splat(0.5))?;
                Fresnel::Reflectance(self.tex(kr, true, Vec3::splat(0.5)))
            }
            "fresnelname" | "preset" => {
                let name = match params.string("filename")? {
                    Some(f) => f,
                    None => params.string_or("name", "aluminium")?,
                };
                let (eta, k) = self.metal_by_name(&name, pos);
                Fresnel::Conductor { eta, k }
            }
            "constant" => Fresnel::Index(Tex::float(params.float("value", 1.5)?)),
            other => {
                for p in &params.params {
                    params.ignore(&p.name);
                }
                self.warn(pos, format!("fresnel texture type \"{other}\" is not supported; the texture is left undefined"));
                return Ok(None);
            }
        }))
    }

    /// A named metal preset, or aluminium with a warning (LuxRender's fallback for an unknown
    /// name or an .nk data file).
    pub(super) fn metal_by_name(&mut self, name: &str, pos: &Pos) -> (Vec3, Vec3) {
        if let Some(p) = metal_preset(name) {
            return p;
        }
        self.warn(
            pos,
            format!("metal \"{name}\" is not a built-in preset (.nk data files are not read); using aluminium"),
        );
        metal_preset("aluminium").expect("aluminium is a preset")
    }

    fn mapping(&mut self, params: &ParamList, pos: &Pos) -> Result<Mapping2D, ParseError> {
        let mapping = params.string_or("mapping", "uv")?;
        Ok(match mapping.as_str() {
            "spherical" | "cylindrical" => {
                let world_to_texture = self.ctm().inverse();
                let uscale = params.float("uscale", 1.0)?;
                let vscale = params.float("vscale", 1.0)?;
                let udelta = params.float("udelta", 0.0)?;
                let vdelta = params.float("vdelta", 0.0)?;
                if mapping == "spherical" {
                    Mapping2D::Spherical {
                        world_to_texture,
                        uscale,
                        vscale,
                        udelta,
                        vdelta,
                    }
                } else {
                    Mapping2D::Cylindrical {
                        world_to_texture,
                        uscale,
                        vscale,
                        udelta,
                        vdelta,
                    }
                }
            }
            "planar" => {
                // LuxRender's planar mapping has no scale; exporters write one anyway.
                params.ignore("uscale");
                params.ignore("vscale");
                Mapping2D::Planar {
                    world_to_texture: self.ctm().inverse(),
                    v1: params.vec3("v1", Vec3::X)?,
                    v2: params.vec3("v2", Vec3::Y)?,
                    udelta: params.float("udelta", 0.0)?,
                    vdelta: params.float("vdelta", 0.0)?,
                }
            }
            other => {
                if other != "uv" {
                    self.warn(
                        pos,
                        format!("unknown texture mapping \"{other}\"; using uv"),
                    );
                }
                Mapping2D::Uv {
                    uscale: params.float("uscale", 1.0)?,
                    vscale: params.float("vscale", 1.0)?,
                    udelta: params.float("udelta", 0.0)?,
                    vdelta: params.float("vdelta", 0.0)?,
                }
            }
        })
    }
}
