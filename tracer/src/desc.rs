//! The scene description: plain data produced by the parser and consumed by the renderer's
//! build step. Every LuxRender default is already applied here, so nothing downstream needs to
//! know the file format. Transforms are object-to-world; colours are linear RGB.
//!
//! Each concept keeps its own description, defaults and reading in its file: the camera in
//! [`crate::camera`], the film in [`crate::film`], the pixel filter in [`crate::filter`], the
//! surface integrator in [`crate::integrator::options`], the sampler in [`crate::sampler`],
//! shapes in [`crate::shape`]; they are re-exported here.

use glam::{Mat4, Vec3};

pub use crate::assets::{AssetKind, AssetRef};
pub use crate::camera::{CameraDesc, CameraKind};
pub use crate::diag::{SourcePos, Warning};
pub use crate::film::{FilmDesc, ToneMap};
pub use crate::filter::{FilterDesc, FilterKind};
pub use crate::integrator::options::{IntegratorDesc, RussianRoulette};
pub use crate::mesh::TriangleMesh;
pub use crate::param::{Fresnel, MaterialId, Tex, TextureId};
pub use crate::sampler::SamplerDesc;
pub use crate::shape::{AreaLightDesc, Geometry, ShapeDesc};

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
    pub lights: Vec<LightDesc>,
    pub warnings: Vec<Warning>,
    /// Every file read or referenced besides the main file, in first-use order, no repeats.
    pub assets: Vec<AssetRef>,
}

// ---------------------------------------------------------------------------------------------
// Textures: described in crate::texture, one file per type.

pub use crate::texture::{Mapping2D, TextureDesc, TextureKind, Wrap};

// ---------------------------------------------------------------------------------------------
// Materials

pub use crate::material::MaterialDesc;

// ---------------------------------------------------------------------------------------------
// Lights

/// How a LatLong map is indexed (docs/architecture.md): the seed tracer's u = (pi + phi) / 2pi, or
/// LuxRender's s = phi / 2pi with phi in [0, 2pi). Both use t = theta / pi.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LatLongConvention {
    #[default]
    Seed,
    LuxRender,
}

#[derive(Clone, Debug, PartialEq)]
pub struct EnvMapDesc {
    /// Path as written; listed in `assets`.
    pub filename: String,
    pub gamma: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LightDesc {
    Point {
        position: Vec3,
        /// Radiant intensity (L x gain, normalised by power x efficacy when given).
        intensity: Vec3,
    },
    Spot {
        position: Vec3,
        /// Unit direction in world space.
        direction: Vec3,
        intensity: Vec3,
        /// Degrees, LuxRender semantics (full cone half-angle, and falloff width).
        cone_angle: f32,
        cone_delta_angle: f32,
    },
    Distant {
        /// Unit direction the light travels *towards* the scene is `-to_light`.
        to_light: Vec3,
        radiance: Vec3,
    },
    Infinite {
        /// L x gain; multiplies the map when there is one.
        radiance: Vec3,
        map: Option<EnvMapDesc>,
        /// Light space has z up; this maps it to world space.
        light_to_world: Mat4,
    },
}
