//! The light sample handed to the integrator, and the sample of a delta light (point, spot,
//! distant) before the choice probability is known. A leaf shared by the light files and the
//! sampler in `mod.rs`.

use glam::Vec3;

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

/// Direction and radiance of a delta light as seen from a point.
pub struct DeltaSample {
    pub wi: Vec3,
    pub li: Vec3,
    pub dist: f32,
}

impl DeltaSample {
    /// The light sample, for a light chosen with probability `pmf`.
    pub fn chosen(self, pmf: f32) -> LightSample {
        LightSample {
            wi: self.wi,
            li: self.li,
            pdf: pmf,
            dist: self.dist,
            delta: true,
        }
    }
}
