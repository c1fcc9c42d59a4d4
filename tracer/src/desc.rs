//! The scene description: plain data produced by the parser and consumed by the renderer's
//! build step. Every LuxRender default is already applied here, so nothing downstream needs to
//! know the file format. Transforms are object-to-world; colours are linear RGB.
//!
//! Each concept keeps its own description, defaults and reading in its file: the camera in
//! [`crate::camera`], the film in [`crate::film`], the pixel filter in [`crate::filter`], the
//! surface integrator in [`crate::integrator::options`], the sampler in [`crate::sampler`],
//! shapes in [`crate::shape`], materials in [`crate::material`], textures in [`crate::texture`],
//! lights in [`crate::lights`], volumes in [`crate::medium`]; the families' enums and the shared leaf types are re-exported
//! here.

pub use crate::assets::{AssetKind, AssetRef};
pub use crate::budget::BudgetMeter;
pub use crate::camera::{CameraDesc, CameraKind};
pub use crate::diag::{SourcePos, Warning};
pub use crate::film::{FilmDesc, ToneMap};
pub use crate::filter::{FilterDesc, FilterKind};
pub use crate::integrator::options::{IntegratorDesc, RussianRoulette, Transport};
pub use crate::lights::{EnvMapDesc, LatLongConvention, LightDesc, PortalDesc};
pub use crate::material::MaterialDesc;
pub use crate::medium::{MediumDesc, MediumId, ShapeMedia, Volumes};
pub use crate::mesh::TriangleMesh;
pub use crate::refs::{ConstOrTexture, Fresnel, MaterialId, TextureId};
pub use crate::sampler::SamplerDesc;
pub use crate::shape::{AreaLightDesc, Cylinder, Disk, Geometry, Plane, ShapeDesc, Sphere};
pub use crate::texture::{Mapping2D, TextureDesc, TextureKind, Wrap};

#[derive(Clone, Debug)]
pub struct SceneDesc {
    pub camera: CameraDesc,
    pub film: FilmDesc,
    pub filter: FilterDesc,
    pub integrator: IntegratorDesc,
    pub sampler: SamplerDesc,
    pub textures: Vec<TextureDesc>,
    pub materials: Vec<MaterialDesc>,
    pub shapes: Vec<ShapeDesc>,
    /// `PortalShape`s: not shapes of the scene, but where light from a direction enters.
    pub portals: Vec<PortalDesc>,
    pub lights: Vec<LightDesc>,
    /// Named volumes (`MakeNamedVolume`) and the camera's.
    pub volumes: Volumes,
    pub warnings: Vec<Warning>,
    /// Every file read or referenced besides the main file, in first-use order, no repeats.
    pub assets: Vec<AssetRef>,
    /// What the parse counted against the build budget, figure by figure (the build's memory
    /// estimate among them); nothing for a description made otherwise.
    pub spent: BudgetMeter,
}

impl SceneDesc {
    /// The transport the scene renders with when the command line does not choose
    /// ([`IntegratorDesc::transport`]).
    pub fn transport(&self) -> Transport {
        self.integrator.transport(self.delta_caustics().is_some())
    }

    /// A delta light (point, spot, distant) and a material that scatters into one direction
    /// (mirror, smooth glass or metal), by their LuxRender names, when the scene has both: light
    /// that leaves the one and meets the other before a diffuse surface only a light subpath can
    /// carry, since no light sample finds the lamp through a delta lobe and no BSDF sample finds
    /// a point. Whether the geometry lets such light reach the camera is left to the render.
    pub fn delta_caustics(&self) -> Option<(&'static str, &'static str)> {
        let light = self.lights.iter().find(|l| l.is_delta())?;
        let material = self.materials.iter().find(|m| m.has_delta_lobe())?;
        Some((light.name(), material.name()))
    }
}
