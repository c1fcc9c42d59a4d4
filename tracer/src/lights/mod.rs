//! Lights: area lights on shapes, point, spot, distant and infinite (constant or LatLong map,
//! importance-sampled by luminance), and the choice of which light to sample.
//!
//! OWNER: lights helper. Interface used by the integrator; keep the signatures.

use glam::{Vec2, Vec3};

use crate::assets::AssetSource;
use crate::desc::{LatLongConvention, SceneDesc};
use crate::geometry::{SceneGeometry, SurfaceHit};

/// A light sample as seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the shading point towards the light.
    pub wi: Vec3,
    /// Radiance arriving along `-wi` (intensity / dist^2 for point lights).
    pub li: Vec3,
    /// Solid-angle density including the probability of choosing this light; for delta lights
    /// the choice probability alone.
    pub pdf: f32,
    /// Distance to the sampled point (f32::INFINITY for infinite and distant lights).
    pub dist: f32,
    pub delta: bool,
}

pub struct Lights {}

#[derive(Debug, thiserror::Error)]
pub enum LightError {
    #[error(transparent)]
    Asset(#[from] crate::assets::AssetError),
    #[error(transparent)]
    Decode(#[from] crate::image_io::DecodeError),
}

impl Lights {
    pub fn build(
        _desc: &SceneDesc,
        _geometry: &SceneGeometry,
        _source: &dyn AssetSource,
        _latlong: LatLongConvention,
    ) -> Result<Self, LightError> {
        todo!("lights helper")
    }

    pub fn is_empty(&self) -> bool {
        todo!("lights helper")
    }

    /// Samples a light as seen from `p` (with `u_select` choosing the light and `u` the point on
    /// it). None when the chosen light contributes nothing from here.
    pub fn sample(&self, _p: Vec3, _u_select: f32, _u: Vec2) -> Option<LightSample> {
        todo!("lights helper")
    }

    /// Radiance an area light emits from `hit` towards `wo` (front face only).
    pub fn emitted(&self, _hit: &SurfaceHit, _wo: Vec3) -> Vec3 {
        todo!("lights helper")
    }

    /// Solid-angle density with which `sample` from `from` would have chosen the emitter point
    /// `hit` (for MIS when a BSDF-sampled ray hits an area light).
    pub fn pdf_hit(&self, _from: Vec3, _hit: &SurfaceHit) -> f32 {
        todo!("lights helper")
    }

    /// Radiance from the infinite lights along a ray escaping in direction `dir`.
    pub fn environment(&self, _dir: Vec3) -> Vec3 {
        todo!("lights helper")
    }

    /// Solid-angle density with which `sample` would have chosen direction `dir` on the
    /// infinite lights.
    pub fn pdf_environment(&self, _dir: Vec3) -> f32 {
        todo!("lights helper")
    }
}
