//! `Material "carpaint"`: metallic car paint after Günther et al. 2005 ("Efficient
//! acquisition and realistic rendering of car paint"), as LuxRender models it: a Lambert base
//! under three glossy flake lobes, each with its own weight, Fresnel reflectance and
//! roughness, and an absorbing clear layer.
//!
//! ```text
//! Material "carpaint" "string name" ["bmw339"]
//! Material "carpaint" "color Kd" [0.01 0.02 0.1] "color Ks1" [0.05 0.05 0.05] "float R1" [0.9]
//!     "float M1" [0.3] "color Ka" [0.1 0.1 0.1] "float d" [0.5]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `name` | string, a preset: ford f8, polaris silber, opel titan, bmw339, 2k acrylack, white, blue, blue matte | none; an unknown name warns and uses ford f8 ([`PRESETS`]) |
//! | `Kd` | color texture, base reflectance, clamped to [0, 1] | ford f8's |
//! | `Ks1`, `Ks2`, `Ks3` | color textures, lobe weights, clamped to [0, 1] | ford f8's |
//! | `R1`, `R2`, `R3` | float textures, lobe normal-incidence Fresnel reflectance, clamped to [0, 1] | ford f8's |
//! | `M1`, `M2`, `M3` | float textures, lobe roughness (GGX alpha; a lobe with M <= 0 is off) | ford f8's |
//! | `Ka` | color texture, clear-layer absorption, clamped to [0, 1] | 0 ([`DEFAULT_KA`]) |
//! | `d` | float texture, clear-layer thickness | 0 ([`DEFAULT_DEPTH`]) |
//!
//! With a `name`, the preset's values replace Kd, Ks1-3, R1-3 and M1-3 (as in LuxRender, which
//! then ignores those parameters). LuxRender's lobes use Schlick's distribution with
//! r = M^2, which is GGX with alpha = M. Where the three weights sum to more than 1 they are
//! scaled down (the [`crate::bxdf::coat::Coat`] rule), so custom layers cannot create
//! energy; the presets' weights are far below that.

use glam::Vec3;

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use crate::bxdf::coat::{Coat, CoatLobe};
use crate::bxdf::coat_over_base::Coating;
use crate::bxdf::diffuse::{DiffuseReflection, OrenNayar};
use crate::bxdf::microfacet::TrowbridgeReitz;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KA: f32 = 0.0;
pub const DEFAULT_DEPTH: f32 = 0.0;

/// One measured paint: base colour, three lobe weights, reflectances and roughnesses.
pub struct Preset {
    pub name: &'static str,
    pub kd: [f32; 3],
    pub ks: [[f32; 3]; 3],
    pub r: [f32; 3],
    pub m: [f32; 3],
}

/// Günther et al.'s measured paints, under the names LuxRender gives them; the first is the
/// default of every missing parameter.
pub const PRESETS: [Preset; 8] = [
    Preset {
        name: "ford f8",
        kd: [0.0012, 0.0015, 0.0018],
        ks: [
            [0.0049, 0.0076, 0.012],
            [0.01, 0.013, 0.018],
            [0.007, 0.0065, 0.0077],
        ],
        r: [0.15, 0.087, 0.9],
        m: [0.32, 0.11, 0.013],
    },
    Preset {
        name: "polaris silber",
        kd: [0.055, 0.063, 0.071],
        ks: [
            [0.065, 0.082, 0.088],
            [0.11, 0.11, 0.13],
            [0.008, 0.013, 0.015],
        ],
        r: [1.0, 0.92, 0.9],
        m: [0.38, 0.17, 0.013],
    },
    Preset {
        name: "opel titan",
        kd: [0.011, 0.013, 0.015],
        ks: [
            [0.057, 0.066, 0.078],
            [0.11, 0.12, 0.13],
            [0.0095, 0.014, 0.016],
        ],
        r: [0.85, 0.86, 0.9],
        m: [0.38, 0.17, 0.014],
    },
    Preset {
        name: "bmw339",
        kd: [0.012, 0.015, 0.016],
        ks: [
            [0.062, 0.076, 0.08],
            [0.11, 0.12, 0.12],
            [0.0083, 0.015, 0.016],
        ],
        r: [0.92, 0.87, 0.9],
        m: [0.39, 0.17, 0.013],
    },
    Preset {
        name: "2k acrylack",
        kd: [0.42, 0.32, 0.1],
        ks: [
            [0.0, 0.0, 0.0],
            [0.028, 0.026, 0.006],
            [0.017, 0.0075, 0.0041],
        ],
        r: [1.0, 0.9, 0.17],
        m: [0.88, 0.8, 0.015],
    },
    Preset {
        name: "white",
        kd: [0.61, 0.63, 0.55],
        ks: [
            [2.6e-6, 0.00031, 3.1e-8],
            [0.013, 0.011, 0.0083],
            [0.049, 0.042, 0.037],
        ],
        r: [0.049, 0.45, 0.17],
        m: [1.0, 0.15, 0.015],
    },
    Preset {
        name: "blue",
        kd: [0.0079, 0.023, 0.1],
        ks: [
            [0.0011, 0.0015, 0.0019],
            [0.025, 0.03, 0.043],
            [0.059, 0.074, 0.082],
        ],
        r: [1.0, 0.094, 0.17],
        m: [0.15, 0.043, 0.02],
    },
    Preset {
        name: "blue matte",
        kd: [0.0099, 0.036, 0.12],
        ks: [
            [0.0032, 0.0045, 0.0059],
            [0.18, 0.23, 0.28],
            [0.04, 0.049, 0.051],
        ],
        r: [1.0, 0.046, 0.17],
        m: [0.16, 0.075, 0.034],
    },
];

/// The preset called `name`.
pub fn preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

#[derive(Clone, Debug, PartialEq)]
pub struct CarPaint {
    pub kd: ConstOrTexture,
    pub ks: [ConstOrTexture; 3],
    pub r: [ConstOrTexture; 3],
    pub m: [ConstOrTexture; 3],
    pub ka: ConstOrTexture,
    pub depth: ConstOrTexture,
}

impl CarPaint {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let ka = ctx.color_param(params, "Ka", DEFAULT_KA, true)?;
        let depth = ctx.float_param(params, "d", DEFAULT_DEPTH)?;
        let layer_names = [
            "Kd", "Ks1", "Ks2", "Ks3", "R1", "R2", "R3", "M1", "M2", "M3",
        ];
        if let Some(name) = params.string("name")? {
            let p = preset(&name).unwrap_or_else(|| {
                ctx.warn(
                    pos,
                    format!("carpaint: no preset named \"{name}\"; using \"ford f8\""),
                );
                &PRESETS[0]
            });
            // LuxRender reads no layer parameter when a preset is named.
            for n in layer_names {
                if let Some(p) = params.find(n) {
                    let pos = p.pos.clone();
                    params.ignore(n);
                    ctx.note(
                        &pos,
                        format!("carpaint: \"{n}\" is ignored when a preset \"name\" is given"),
                    );
                }
            }
            return Ok(Self::from_preset(p, ka, depth));
        }
        let d = &PRESETS[0];
        let mut color = |n: &str, c: [f32; 3]| -> Result<ConstOrTexture, ParseError> {
            ctx.color_param(params, n, 0.0, true).map(|t| match t {
                // color_param's default is a splat; the preset's is a colour.
                ConstOrTexture::Const(_) if params.find(n).is_none() => ConstOrTexture::color(Vec3::from_array(c)),
                t => t,
            })
        };
        let kd = color("Kd", d.kd)?;
        let ks = [
            color("Ks1", d.ks[0])?,
            color("Ks2", d.ks[1])?,
            color("Ks3", d.ks[2])?,
        ];
        let mut float = |n: &str, v: f32| ctx.float_param(params, n, v);
        Ok(Self {
            kd,
            ks,
            r: [
                float("R1", d.r[0])?,
                float("R2", d.r[1])?,
                float("R3", d.r[2])?,
            ],
            m: [
                float("M1", d.m[0])?,
                float("M2", d.m[1])?,
                float("M3", d.m[2])?,
            ],
            ka,
            depth,
        })
    }

    /// Preset `p` with clear-layer absorption `ka` and thickness `depth`.
    pub fn from_preset(p: &Preset, ka: ConstOrTexture, depth: ConstOrTexture) -> Self {
        let color = |c: [f32; 3]| ConstOrTexture::color(Vec3::from_array(c));
        Self {
            kd: color(p.kd),
            ks: p.ks.map(color),
            r: p.r.map(ConstOrTexture::float),
            m: p.m.map(ConstOrTexture::float),
            ka,
            depth,
        }
    }
}

impl MaterialKind for CarPaint {
    fn textures(&self) -> Vec<TextureId> {
        let mut params = vec![&self.kd];
        params.extend(&self.ks);
        params.extend(&self.r);
        params.extend(&self.m);
        params.extend([&self.ka, &self.depth]);
        texture_ids(&params)
    }

    /// The base under the flakes.
    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        Bxdf::Diffuse(DiffuseReflection {
            r: eval.color(self.kd),
            roughness: OrenNayar::new(0.0),
        })
    }

    fn coating(&self, eval: &HitTextures) -> Option<Coating> {
        let off = CoatLobe {
            weight: Vec3::ZERO,
            r0: Vec3::ZERO,
            distrib: None,
        };
        let mut lobes = [off; 3];
        let mut count = 0;
        for i in 0..3 {
            let weight = eval.color(self.ks[i]);
            let m = eval.float(self.m[i]);
            // As in LuxRender, a lobe without weight or roughness is absent.
            if weight.max_element() > 0.0 && m > 0.0 {
                lobes[count] = CoatLobe {
                    weight,
                    r0: Vec3::splat(eval.float(self.r[i]).clamp(0.0, 1.0)),
                    distrib: TrowbridgeReitz::from_roughness(m, m),
                };
                count += 1;
            }
        }
        let coat = Coat::new(
            &lobes[..count],
            eval.color(self.ka),
            eval.float(self.depth),
            None,
        );
        Some(Coating::two_sided(coat, true))
    }
}
