//! `Material "type"` and `MakeNamedMaterial "name" "string type"`: material descriptions with
//! LuxRender's defaults.

use glam::Vec3;

use super::builder::Builder;
use super::context::{ParseContext, TexBinding};
use super::params::{ParamList, ParamType, TexValue};
use super::{ParseError, Pos};
use crate::desc::MaterialDesc;
use crate::param::{Fresnel, MaterialId, Tex};

impl Builder<'_> {
    /// Describes a material, stores it and returns its id. Warns about parameters it did not
    /// read.
    pub(super) fn material(
        &mut self,
        ty: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<MaterialId, ParseError> {
        params.ignore("type");
        let desc = self.material_desc(ty, params, pos)?;
        self.warn_unused(params);
        Ok(self.add_material(desc))
    }

    fn material_desc(
        &mut self,
        ty: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<MaterialDesc, ParseError> {
        Ok(match ty {
            "matte" => MaterialDesc::Matte {
                kd: self.color_param(params, "Kd", 0.9, true)?,
                sigma: self.float_param(params, "sigma", 0.0)?,
            },
            "glossy" | "glossy2" => {
                let kd = self.color_param(params, "Kd", 1.0, true)?;
                let ks = self.color_param(params, "Ks", 1.0, false)?;
                let ka = self.color_param(params, "Ka", 0.0, true)?;
                let index = self.float_param(params, "index", 0.0)?;
                let ks = match index {
                    Tex::Const(i) if i.x > 0.0 => {
                        let f = ((i.x - 1.0) / (i.x + 1.0)).powi(2);
                        match ks {
                            Tex::Const(c) => Tex::Const(c * f),
                            Tex::Texture(id) => Tex::Texture(self.scaled_texture(id, f)),
                        }
                    }
                    Tex::Const(_) => ks,
                    Tex::Texture(_) => {
                        self.warn(
                            pos,
                            format!(
                                "{}: a textured \"index\" is not supported; Ks is used as given",
                                params.statement
                            ),
                        );
                        ks
                    }
                };
                let ks = match ks {
                    Tex::Const(c) => Tex::Const(c.clamp(Vec3::ZERO, Vec3::ONE)),
                    t => t,
                };
                self.unsupported_unless(params, "sigma", 0.0);
                MaterialDesc::Glossy {
                    kd,
                    ks,
                    ka,
                    depth: self.float_param(params, "d", 0.0)?,
                    uroughness: self.float_param(params, "uroughness", 0.1)?,
                    vroughness: self.float_param(params, "vroughness", 0.1)?,
                    multibounce: params.bool("multibounce", false)?,
                }
            }
            "mirror" => {
                self.unsupported_unless(params, "film", 0.0);
                MaterialDesc::Mirror {
                    kr: self.color_param(params, "Kr", 1.0, false)?,
                }
            }
            "glass" | "roughglass" | "glass2" => {
                let rough = if ty == "roughglass" { 0.001 } else { 0.0 };
                self.unsupported_unless(params, "film", 0.0);
                self.unsupported_unless(params, "cauchyb", 0.0);
                if ty == "glass2" {
                    self.warn_once("glass2".into(), pos, "glass2 takes its index from volumes, which are not rendered; using index 1.5".into());
                    params.ignore("dispersion");
                }
                MaterialDesc::Glass {
                    kr: self.color_param(params, "Kr", 1.0, false)?,
                    kt: self.color_param(params, "Kt", 1.0, false)?,
                    index: if ty == "glass2" {
                        Tex::float(1.5)
                    } else {
                        self.float_param(params, "index", 1.5)?
                    },
                    architectural: params.bool("architectural", false)?,
                    uroughness: if rough > 0.0 {
                        self.float_param(params, "uroughness", rough)?
                    } else {
                        Tex::float(0.0)
                    },
                    vroughness: if rough > 0.0 {
                        self.float_param(params, "vroughness", rough)?
                    } else {
                        Tex::float(0.0)
                    },
                }
            }
            "metal" => {
                let name = match params.string("filename")? {
                    Some(f) => f,
                    None => params.string_or("name", "aluminium")?,
                };
                let (eta, k) = self.metal_by_name(&name, pos);
                MaterialDesc::Metal {
                    fresnel: Fresnel::Conductor { eta, k },
                    uroughness: self.float_param(params, "uroughness", 0.1)?,
                    vroughness: self.float_param(params, "vroughness", 0.1)?,
                }
            }
            "metal2" => MaterialDesc::Metal {
                fresnel: self.metal2_fresnel(params)?,
                uroughness: self.float_param(params, "uroughness", 0.1)?,
                vroughness: self.float_param(params, "vroughness", 0.1)?,
            },
            "mattetranslucent" => {
                params.ignore("energyconserving");
                MaterialDesc::MatteTranslucent {
                    kr: self.color_param(params, "Kr", 1.0, true)?,
                    kt: self.color_param(params, "Kt", 1.0, true)?,
                    sigma: self.float_param(params, "sigma", 0.0)?,
                }
            }
            "null" => MaterialDesc::Null,
            "mix" => {
                let a = params.string("namedmaterial1")?;
                let b = params.string("namedmaterial2")?;
                let a = match a {
                    Some(n) => self.named_material(&n, pos),
                    None => self.default_material(),
                };
                let b = match b {
                    Some(n) => self.named_material(&n, pos),
                    None => self.default_material(),
                };
                MaterialDesc::Mix {
                    a,
                    b,
                    amount: self.float_param(params, "amount", 0.5)?,
                }
            }
            other => {
                self.warn(pos, format!("material \"{other}\" is not supported; using matte (with its Kd when given)"));
                let kd = self.color_param(params, "Kd", 0.9, true)?;
                for p in &params.params {
                    params.ignore(&p.name);
                }
                MaterialDesc::Matte {
                    kd,
                    sigma: Tex::float(0.0),
                }
            }
        })
    }

    /// metal2's Fresnel term: `texture fresnel` (a fresnel texture, or a float texture giving
    /// an index), `float fresnel` (an index), the course's `color fresnel` and `color Kr`
    /// (normal-incidence reflectance); LuxRender's default is index 5.
    fn metal2_fresnel(&mut self, params: &ParamList) -> Result<Fresnel, ParseError> {
        if let Some(p) = params.find("fresnel") {
            if p.ty == ParamType::Color {
                return Ok(Fresnel::Reflectance(
                    self.color_param(params, "fresnel", 1.0, true)?,
                ));
            }
            return Ok(match params.tex_float("fresnel", 5.0)? {
                TexValue::Const(c) => Fresnel::Index(Tex::Const(c)),
                TexValue::Named { name, pos } => match self.find_texture(&name, true) {
                    Some(TexBinding::Fresnel(f)) => f,
                    Some(TexBinding::Texture(id)) if !self.texture_is_color(id) => {
                        Fresnel::Index(Tex::Texture(id))
                    }
                    Some(TexBinding::Texture(id)) => Fresnel::Reflectance(Tex::Texture(id)),
                    None => {
                        self.warn(
                            &pos,
                            format!("no fresnel texture named \"{name}\"; using index 5"),
                        );
                        Fresnel::Index(Tex::float(5.0))
                    }
                },
            });
        }
        if params.count("Kr").is_some() {
            return Ok(Fresnel::Reflectance(
                self.color_param(params, "Kr", 1.0, true)?,
            ));
        }
        Ok(Fresnel::Index(Tex::float(5.0)))
    }
}
