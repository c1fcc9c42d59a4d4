//! Materials and their BSDFs: matte (Oren-Nayar), glossy (Glossy2), mirror, glass and rough
//! glass, metal/metal2 (microfacet conductor), mattetranslucent, null, mix.
//!
//! OWNER: materials helper. Interface used by the integrator; keep the signatures.

use glam::{Vec2, Vec3};

use crate::desc::{MaterialId, SceneDesc};
use crate::geometry::SurfaceHit;
use crate::texture::Textures;

/// A sampled scattering direction.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Unit world-space direction away from the surface.
    pub wi: Vec3,
    /// BSDF value for (wo, wi), not multiplied by the cosine.
    pub f: Vec3,
    /// Solid-angle density; for specular lobes the discrete probability of the lobe.
    pub pdf: f32,
    pub specular: bool,
}

/// The BSDF at one surface point, in world space. Plain data: building one allocates nothing.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {}

impl Bsdf {
    /// True when the material is `null`: the ray continues straight through.
    pub fn is_pass_through(&self) -> bool {
        todo!("materials helper")
    }

    /// True when every lobe is specular (light sampling is useless here).
    pub fn is_specular(&self) -> bool {
        todo!("materials helper")
    }

    /// f(wo, wi) for the non-specular lobes; wo and wi are unit world directions away from
    /// the surface.
    pub fn eval(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        todo!("materials helper")
    }

    /// Density with which `sample` picks wi (non-specular lobes only).
    pub fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        todo!("materials helper")
    }

    /// Samples wi given wo; `u_lobe` picks a lobe, `u` the direction.
    pub fn sample(&self, _wo: Vec3, _u_lobe: f32, _u: Vec2) -> Option<BsdfSample> {
        todo!("materials helper")
    }
}

pub struct Materials {}

impl Materials {
    pub fn build(_desc: &SceneDesc) -> Self {
        todo!("materials helper")
    }

    /// The BSDF of material `id` at `hit`. `u_mix` resolves `mix` materials stochastically.
    pub fn bsdf(
        &self,
        _id: MaterialId,
        _hit: &SurfaceHit,
        _textures: &Textures,
        _u_mix: f32,
    ) -> Bsdf {
        todo!("materials helper")
    }
}
