//! Participating media: LuxRender 1.x's named volumes (`MakeNamedVolume`), the `Interior` and
//! `Exterior` of each shape, and the camera's volume. One file per kind ([`clear`],
//! [`homogeneous`]), the phase function in [`phase`], what shapes and the path tracer share
//! (ids, the sides of a surface, Beer-Lambert) in the leaf [`common`], and the
//! `VolumeIntegrator` statement (whether volumes scatter, as LuxRender's decides) in
//! [`integrator`].
//!
//! As in LuxRender, a shape takes the `Interior` and `Exterior` current when it is defined,
//! the camera sits in the `Exterior` current at `WorldEnd`, a `LightSource` in the `Exterior`
//! current at it, and a side with no volume takes
//! the volume of the ray that reaches it. Only glass2 reads a volume's `fresnel` index (as
//! the interior's over the exterior's; with its `dispersion`, at a path's wavelength where the
//! index varies with it).

pub mod clear;
pub mod common;
pub mod homogeneous;
pub mod integrator;
pub mod phase;

use glam::Vec3;

pub use clear::Clear;
pub use common::{MediumId, ShapeMedia};
pub use homogeneous::{Flight, Homogeneous};
pub use phase::Phase;

use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::wavelength::IndexCurve;

#[derive(Clone, Debug, PartialEq)]
pub enum MediumDesc {
    Clear(Clear),
    Homogeneous(Homogeneous),
}

/// The scene's volumes, the one the camera sits in and the ones the lights sit in.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Volumes {
    pub media: Vec<MediumDesc>,
    pub camera: Option<MediumId>,
    /// For each `LightSource` (`SceneDesc::lights`, in order), the Exterior current at it: as
    /// in LuxRender, the volume its light leaves into. Read by bidirectional light subpaths
    /// from point and spot lights; the path tracer's shadow rays find a light in whatever
    /// volume they reach it in. Missing entries (a description made otherwise) are no volume.
    pub lights: Vec<Option<MediumId>>,
}

impl Volumes {
    pub fn get(&self, id: MediumId) -> Option<&MediumDesc> {
        self.media.get(id.0 as usize)
    }

    /// The volume `LightSource` number `source` sits in.
    pub fn light(&self, source: usize) -> Option<MediumId> {
        self.lights.get(source).copied().flatten()
    }

    /// The index of refraction of a side of a surface: its volume's `fresnel`, 1 with none.
    pub fn index(&self, id: Option<MediumId>) -> f32 {
        id.and_then(|id| self.get(id))
            .map_or(1.0, MediumDesc::index)
    }

    /// A side's index as glass2 with `dispersion` takes it: [`Self::index`] and the volume's
    /// index over wavelength where it varies.
    pub fn index_curve(&self, id: Option<MediumId>) -> (f32, Option<&IndexCurve>) {
        let medium = id.and_then(|id| self.get(id));
        (
            medium.map_or(1.0, MediumDesc::index),
            medium.and_then(MediumDesc::dispersion),
        )
    }
}

impl MediumDesc {
    /// `MakeNamedVolume "name" ty params`; None (with a warning) for the kinds not rendered.
    pub fn read(
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Option<Self>, ParseError> {
        Ok(Some(match ty {
            "clear" => Self::Clear(Clear::read(params, pos, ctx)?),
            "homogeneous" => Self::Homogeneous(Homogeneous::read(params, pos, ctx)?),
            other => {
                for p in &params.params {
                    params.ignore(&p.name);
                }
                ctx.warn(
                    pos,
                    format!("MakeNamedVolume \"{other}\": only clear and homogeneous volumes are rendered; shapes naming it get no volume"),
                );
                return Ok(None);
            }
        }))
    }

    /// The LuxRender volume type.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Clear(_) => "clear",
            Self::Homogeneous(_) => "homogeneous",
        }
    }

    /// The `fresnel` index.
    pub fn index(&self) -> f32 {
        match self {
            Self::Clear(c) => c.index,
            Self::Homogeneous(h) => h.index,
        }
    }

    /// The `fresnel` index over wavelength, where it varies.
    pub fn dispersion(&self) -> Option<&IndexCurve> {
        match self {
            Self::Clear(c) => c.dispersion.as_ref(),
            Self::Homogeneous(h) => h.dispersion.as_ref(),
        }
    }

    /// Whether [`Self::flight`] needs a random number.
    pub fn scatters(&self) -> bool {
        match self {
            Self::Clear(_) => false,
            Self::Homogeneous(h) => h.scatters(),
        }
    }

    /// The fate of a ray crossing `length` of the volume (`u` is read only when
    /// [`Self::scatters`]).
    pub fn flight(&self, length: f32, u: f32) -> Flight {
        match self {
            Self::Clear(c) => Flight::Pass {
                weight: c.transmittance(length),
            },
            Self::Homogeneous(h) => h.flight(length, u),
        }
    }

    /// Beer-Lambert transmittance over `distance` (shadow rays).
    pub fn transmittance(&self, distance: f32) -> Vec3 {
        match self {
            Self::Clear(c) => c.transmittance(distance),
            Self::Homogeneous(h) => h.transmittance(distance),
        }
    }

    /// The phase function at a scattering event (only homogeneous volumes scatter).
    pub fn phase(&self) -> Phase {
        match self {
            Self::Clear(_) => Phase::new(Vec3::ZERO),
            Self::Homogeneous(h) => h.phase(),
        }
    }
}
