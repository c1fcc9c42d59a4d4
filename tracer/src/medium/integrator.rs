//! The `VolumeIntegrator` statement: how LuxRender 1.x renders light in the named volumes.
//!
//! "multi" (what LuxBlend writes) and "single" scatter light in them; YAT's path tracer scatters
//! as "multi" does, so "single" is a difference where a volume scatters. LuxRender's default,
//! "emission", and "none" only attenuate a ray crossing a volume, by Beer-Lambert over its
//! extinction (absorption plus scattering: integrators/emission.cpp and none.cpp multiply by
//! exp(-tau)): no light scatters into the ray. YAT renders those as LuxRender does by making
//! every homogeneous volume a clear one of that extinction, which keeps its index for glass2.

use super::{Clear, MediumDesc, Volumes};
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;

/// LuxRender 1.x's volume integrator when the scene names none.
pub const DEFAULT_VOLUME_INTEGRATOR: &str = "emission";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeIntegrator {
    /// Attenuation only (LuxRender's default; also "none").
    Attenuating,
    Single,
    Multi,
}

impl VolumeIntegrator {
    /// `VolumeIntegrator "ty"`; an unknown type is a difference (LuxRender would not render
    /// the scene), read as the default.
    pub fn read(ctx: &mut dyn ParseContext, ty: &str, pos: &SourcePos) -> Self {
        match ty {
            "emission" | "none" => Self::Attenuating,
            "single" => Self::Single,
            "multi" => Self::Multi,
            other => {
                ctx.warn(
                    pos,
                    format!(
                        "VolumeIntegrator \"{other}\" is not a LuxRender 1.x volume integrator; \
                         read as \"{DEFAULT_VOLUME_INTEGRATOR}\""
                    ),
                );
                Self::Attenuating
            }
        }
    }

    /// The scene's `volumes` as this integrator renders them (`pos`: its statement, or the end
    /// of the main file for the default), saying what that does to volumes that scatter.
    pub fn apply(self, volumes: &mut Volumes, ctx: &mut dyn ParseContext, pos: &SourcePos) {
        let scattering = volumes.media.iter().filter(|m| m.scatters()).count();
        if scattering == 0 {
            return;
        }
        match self {
            Self::Multi => {}
            Self::Single => ctx.warn(
                pos,
                format!(
                    "VolumeIntegrator \"single\": LuxRender scatters light once in volumes; YAT \
                     scatters it as \"multi\" does ({scattering} volumes scatter)"
                ),
            ),
            Self::Attenuating => {
                for medium in &mut volumes.media {
                    if let MediumDesc::Homogeneous(h) = medium {
                        *medium = MediumDesc::Clear(Clear {
                            index: h.index,
                            dispersion: h.dispersion.clone(),
                            absorption: h.sigma_a + h.sigma_s,
                        });
                    }
                }
                ctx.note(
                    pos,
                    format!(
                        "the volume integrator (LuxRender's default \"{DEFAULT_VOLUME_INTEGRATOR}\" \
                         unless the scene names \"emission\" or \"none\") only attenuates light in \
                         volumes: {scattering} homogeneous volumes render without scattering, as \
                         LuxRender renders them (VolumeIntegrator \"multi\" scatters)"
                    ),
                );
            }
        }
    }
}
