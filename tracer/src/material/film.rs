//! `film` and `filmindex`: the thin interference layer LuxRender 1.x puts on the specular
//! reflections of mirror, glass and shinymetal ([`ThinFilm`]).
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `film` | float texture, thickness in nm; 0 or less is no film | 0 ([`DEFAULT_FILM`]) |
//! | `filmindex` | float texture, the layer's index of refraction | 1.5 ([`DEFAULT_FILM_INDEX`]) |

use super::eval::HitTextures;
use crate::bxdf::thin_film::ThinFilm;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::ConstOrTexture;

pub const DEFAULT_FILM: f32 = 0.0;
pub const DEFAULT_FILM_INDEX: f32 = 1.5;

#[derive(Clone, Debug, PartialEq)]
pub struct FilmParams {
    pub thickness: ConstOrTexture,
    pub index: ConstOrTexture,
}

impl Default for FilmParams {
    /// No film.
    fn default() -> Self {
        Self {
            thickness: ConstOrTexture::float(DEFAULT_FILM),
            index: ConstOrTexture::float(DEFAULT_FILM_INDEX),
        }
    }
}

impl FilmParams {
    pub fn read(params: &ParamList, ctx: &mut dyn ParseContext) -> Result<Self, ParseError> {
        Ok(Self {
            thickness: ctx.float_param(params, "film", DEFAULT_FILM)?,
            index: ctx.float_param(params, "filmindex", DEFAULT_FILM_INDEX)?,
        })
    }

    /// The film at a hit; None where it has no thickness.
    pub fn at(&self, eval: &HitTextures) -> Option<ThinFilm> {
        ThinFilm::new(eval.float(self.thickness), eval.float(self.index))
    }

    pub fn textures(&self) -> [&ConstOrTexture; 2] {
        [&self.thickness, &self.index]
    }
}
