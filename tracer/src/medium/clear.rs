//! `MakeNamedVolume "name" "clear"`: a volume that absorbs but never scatters, such as the
//! inside of coloured glass or clear water.
//!
//! ```text
//! MakeNamedVolume "glass" "clear" "float fresnel" [1.5] "color absorption" [0.5 0.05 0.9]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `fresnel` | float or fresnel texture: the index glass2 refracts with | 1.5 ([`DEFAULT_FRESNEL`](super::common::DEFAULT_FRESNEL)) |
//! | `absorption` | colour: sigma_a per scene unit (LuxRender takes scene units as metres) | 0 ([`DEFAULT_ABSORPTION`]) |
//!
//! LuxRender multiplies the absorption by the world-space length travelled, so a ray crossing
//! d units keeps exp(-absorption d) of its radiance (LuxBlend's "absorption depth" and scale
//! are folded into the number it writes).

use glam::Vec3;

use super::common::{read_color, read_index, transmittance};
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::wavelength::IndexCurve;

pub const DEFAULT_ABSORPTION: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Clear {
    /// The `fresnel` index (a dispersive texture's mean).
    pub index: f32,
    /// The `fresnel` texture's index over wavelength, where it varies.
    pub dispersion: Option<IndexCurve>,
    /// sigma_a per scene unit.
    pub absorption: Vec3,
}

impl Clear {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let statement = "MakeNamedVolume \"clear\"";
        let (index, dispersion) = read_index(params, statement, pos, ctx)?;
        Ok(Self {
            index,
            dispersion,
            absorption: read_color(
                params,
                "absorption",
                DEFAULT_ABSORPTION,
                statement,
                pos,
                ctx,
            )?,
        })
    }

    /// The fraction of radiance kept over `distance`.
    pub fn transmittance(&self, distance: f32) -> Vec3 {
        transmittance(self.absorption, distance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Beer-Lambert: a slab of thickness d keeps exp(-sigma_a d) per channel, a channel with
    /// no absorption keeps everything even over an infinite distance, and an absorbing channel
    /// keeps nothing of an infinite one.
    #[test]
    fn beer_lambert_through_a_slab() {
        let clear = Clear {
            index: 1.5,
            dispersion: None,
            absorption: Vec3::new(0.0, 0.7, 2.5),
        };
        for d in [0.0f32, 0.1, 0.37, 1.0, 2.2] {
            let t = clear.transmittance(d);
            let expected = Vec3::new(1.0, libm::expf(-0.7f32 * d), libm::expf(-2.5f32 * d));
            assert!(
                (t - expected).abs().max_element() < 1e-4,
                "d {d}: {t} vs {expected}"
            );
        }
        // exp(-0.7 * 2) = 0.2466
        assert!((clear.transmittance(2.0).y - 0.246_597).abs() < 1e-4);
        assert_eq!(clear.transmittance(f32::INFINITY), Vec3::new(1.0, 0.0, 0.0));
    }
}
