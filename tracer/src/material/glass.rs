//! `Material "glass"`, `"roughglass"` and `"glass2"`: a dielectric interface, smooth, rough
//! (microfacet) or architectural (thin, no refraction).
//!
//! ```text
//! Material "glass" "color Kr" [1 1 1] "color Kt" [1 1 1] "float index" [1.5]
//! Material "roughglass" "float uroughness" [0.05] "float vroughness" [0.05]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kr` | color texture (constants not clamped when read; clamped per hit), glass and roughglass | 1 ([`DEFAULT_KR`]); LuxRender's glass2 has none: it reflects white |
//! | `Kt` | color texture (likewise) | 1 ([`DEFAULT_KT`]); white on glass2 |
//! | `index` | float texture | 1.5 ([`DEFAULT_INDEX`]); glass2 has none: its index is its shape's `Interior` volume's `fresnel` over its `Exterior`'s, 1 for a side with no volume ([`GLASS2_INDEX_WITHOUT_VOLUMES`] when it has neither), set per shape by the parser |
//! | `architectural` | bool | false: a thin pane (a window) that does not bend light; shadow rays cross it with its straight transmittance, as LuxRender's do ([`crate::integrator::Crossing::Pane`]) |
//! | `uroughness`, `vroughness` | float textures, roughglass only | 0.001 ([`DEFAULT_ROUGHGLASS_ROUGHNESS`]); 0 (smooth) for glass and glass2 |
//! | `film`, `filmindex` | float textures, glass only | thin-film interference on the reflection, as LuxRender's ([`super::film`]); LuxRender's roughglass and glass2 have none |
//! | `cauchyb` | float texture, glass and roughglass | 0: Cauchy's B in um^2, the index at wavelength l being `index + cauchyb / l^2` (LuxRender's formula): a path crossing the interface takes one wavelength there ([`crate::wavelength`]); on architectural glass, which does not bend light, it is left out |
//! | `dispersion` | bool, glass2 only | false: with it, a path crossing the interface takes one wavelength there, as with `cauchyb`, where its volumes' `fresnel` textures vary with wavelength (`cauchy`, `abbe`, `sellmeier`, `sopra`, `luxpop`: [`crate::texture::fresnel`]), and refracts at the interior's index over the exterior's at that wavelength (set per shape by the parser, [`Glass::volume_dispersion`]); without it glass2 refracts every wavelength at the ratio of the textures' mean indices, as LuxRender's does |
//!
//! A non-positive index is treated as no interface (index 1).

use super::eval::{texture_ids, HitTextures};
use super::film::FilmParams;
use super::kind::MaterialKind;
use crate::bxdf::dielectric::{Dielectric, Surface};
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::wavelength::{Dispersion, CAUCHY_B_PER_UM2};

pub const DEFAULT_KR: f32 = 1.0;
pub const DEFAULT_KT: f32 = 1.0;
pub const DEFAULT_INDEX: f32 = 1.5;
/// glass2 on a shape with no volumes: LuxRender's Glass2 falls back to a vacuum-to-vacuum
/// interface, index 1 (no refraction, no reflection).
pub const GLASS2_INDEX_WITHOUT_VOLUMES: f32 = 1.0;
/// roughglass's default roughness (glass and glass2 are smooth: roughness 0).
pub const DEFAULT_ROUGHGLASS_ROUGHNESS: f32 = 0.001;

/// glass and roughglass: zero roughness is the smooth specular glass.
#[derive(Clone, Debug, PartialEq)]
pub struct Glass {
    pub kr: ConstOrTexture,
    pub kt: ConstOrTexture,
    pub index: ConstOrTexture,
    /// Cauchy's B, um^2 (0: no dispersion).
    pub cauchyb: ConstOrTexture,
    pub architectural: bool,
    pub uroughness: ConstOrTexture,
    pub vroughness: ConstOrTexture,
    /// glass2: `index` is replaced, per shape, by its volumes' (see the table above).
    pub index_from_volumes: bool,
    /// glass2's `dispersion`.
    pub dispersion: bool,
    /// glass2 with `dispersion`: how its volumes' relative index varies with wavelength, set
    /// per shape by the parser with `index` (none where neither volume's index varies).
    pub volume_dispersion: Dispersion,
    pub film: FilmParams,
}

impl Glass {
    /// `Material "glass"`.
    pub fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Self::read_as("glass", params, ctx)
    }

    /// `Material "roughglass"`.
    pub fn read_rough(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Self::read_as("roughglass", params, ctx)
    }

    /// `Material "glass2"`.
    pub fn read_glass2(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Self::read_as("glass2", params, ctx)
    }

    fn read_as(
        ty: &str,
        params: &ParamList,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let rough = if ty == "roughglass" {
            DEFAULT_ROUGHGLASS_ROUGHNESS
        } else {
            0.0
        };
        let glass2 = ty == "glass2";
        let white = ConstOrTexture::float(1.0);
        Ok(Self {
            kr: if glass2 {
                white
            } else {
                ctx.color_param(params, "Kr", DEFAULT_KR, false)?
            },
            kt: if glass2 {
                white
            } else {
                ctx.color_param(params, "Kt", DEFAULT_KT, false)?
            },
            index: if glass2 {
                ConstOrTexture::float(GLASS2_INDEX_WITHOUT_VOLUMES)
            } else {
                ctx.float_param(params, "index", DEFAULT_INDEX)?
            },
            architectural: params.bool("architectural", false)?,
            uroughness: if rough > 0.0 {
                ctx.float_param(params, "uroughness", rough)?
            } else {
                ConstOrTexture::float(0.0)
            },
            vroughness: if rough > 0.0 {
                ctx.float_param(params, "vroughness", rough)?
            } else {
                ConstOrTexture::float(0.0)
            },
            cauchyb: if glass2 {
                ConstOrTexture::float(0.0)
            } else {
                ctx.float_param(params, "cauchyb", 0.0)?
            },
            index_from_volumes: glass2,
            dispersion: glass2 && params.bool("dispersion", false)?,
            volume_dispersion: Dispersion::None,
            film: if ty == "glass" {
                FilmParams::read(params, ctx)?
            } else {
                FilmParams::default()
            },
        })
    }
}

impl MaterialKind for Glass {
    fn textures(&self) -> Vec<TextureId> {
        let [film, film_index] = self.film.textures();
        texture_ids(&[
            &self.kr,
            &self.kt,
            &self.index,
            &self.cauchyb,
            &self.uroughness,
            &self.vroughness,
            film,
            film_index,
        ])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        let eta = eval.float(self.index);
        let surface = if self.architectural {
            Surface::Thin
        } else {
            match eval.roughness(self.uroughness, self.vroughness) {
                Some(distrib) => Surface::Rough(distrib),
                None => Surface::Smooth,
            }
        };
        Bxdf::Dielectric(Dielectric {
            kr: eval.color(self.kr),
            kt: eval.color(self.kt),
            // A non-positive index is meaningless; treat it as no interface.
            eta: if eta > 0.0 { eta } else { 1.0 },
            surface,
            film: self.film.at(eval),
            dispersion: if self.index_from_volumes {
                self.volume_dispersion
            } else {
                Dispersion::CauchyB(dispersion(eval.float(self.cauchyb)))
            },
        })
    }
}

/// `cauchyb` (um^2) as the BxDF's B (nm^2); a value that is not a number is none.
fn dispersion(cauchyb: f32) -> f32 {
    let b = cauchyb * CAUCHY_B_PER_UM2;
    if b.is_finite() {
        b
    } else {
        0.0
    }
}
