//! The light sample handed to the integrator, and the sample of a delta light (point, spot,
//! distant) before the choice probability is known; the ray leaving a light (emission
//! sampling, for light subpaths) and the light point a light sample reached; the scene sphere
//! that light from a direction enters through, and the direction samplings several kinds
//! share. A leaf shared by the light files and the sampler in `mod.rs`.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};

use crate::bxdf::local::sample_disk_concentric;
use crate::math::Frame;

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

/// Which emitter a light vertex is on: a light of the list (an area light, point, spot,
/// distant), or the lights at infinity as one mixture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Emitter {
    Light(u32),
    Environment,
}

/// A ray leaving a light: what each kind's `sample_emission` returns (`pdf_pos` its own), and,
/// within an [`EmissionSample`], a light subpath's first vertex and direction.
#[derive(Clone, Copy, Debug)]
pub struct EmittedRay {
    /// The point the light leaves: on an area light's surface; a point or spot light's
    /// position; for distant lights and the lights at infinity a point of the disc
    /// [`SceneSphere::entry_point`] samples.
    pub origin: Vec3,
    /// Unit direction the light travels.
    pub dir: Vec3,
    /// An area light's front normal at `origin`; None for every other kind.
    pub normal: Option<Vec3>,
    /// Radiance along `dir` for area lights and the lights at infinity (the mixture's total
    /// radiance arriving from -dir); intensity for point and spot lights; irradiance for a
    /// distant light.
    pub le: Vec3,
    /// Area density of `origin` (in an [`EmissionSample`], times the probability of choosing
    /// the emitter: for the mixture at infinity the sum of its members'); for point and spot
    /// lights 1 (the choice probability alone in a sample).
    pub pdf_pos: f32,
    /// Solid-angle density of `dir` given `origin` (1 for a distant light's delta direction).
    pub pdf_dir: f32,
    pub delta_position: bool,
    pub delta_direction: bool,
}

/// A ray leaving one of the scene's lights, chosen among them: its `pdf_pos` includes the
/// choice's probability.
#[derive(Clone, Copy, Debug)]
pub struct EmissionSample {
    pub emitter: Emitter,
    pub ray: EmittedRay,
}

impl EmittedRay {
    /// The emission sample of `emitter`, chosen with probability `pmf`.
    pub fn chosen(self, emitter: Emitter, pmf: f32) -> EmissionSample {
        EmissionSample {
            emitter,
            ray: EmittedRay {
                pdf_pos: pmf * self.pdf_pos,
                ..self
            },
        }
    }
}

/// The point on the light a light sample reached, for connecting a camera subpath to it.
#[derive(Clone, Copy, Debug)]
pub struct LightPoint {
    pub emitter: Emitter,
    /// The point on the light (an area light's surface point, a point or spot light's
    /// position); for distant lights and the lights at infinity `p + wi 2 r` (r the scene
    /// sphere's radius) stands in: a point outside the scene along the sample's direction.
    pub p: Vec3,
    /// An area light's front normal at `p`; None for every other kind.
    pub normal: Option<Vec3>,
    /// Distant lights and the mixture at infinity.
    pub at_infinity: bool,
    pub delta_position: bool,
    pub delta_direction: bool,
}

impl LightPoint {
    /// A point at a finite distance: on an area light, with its front normal, or a point or
    /// spot light's position (no normal: a delta position).
    pub fn finite(emitter: Emitter, p: Vec3, normal: Option<Vec3>) -> Self {
        Self {
            emitter,
            p,
            normal,
            at_infinity: false,
            delta_position: normal.is_none(),
            delta_direction: false,
        }
    }

    /// The stand-in point `from + wi 2 r` of a light at infinity seen along `wi` from `from`, a
    /// point of the scene: outside the scene `sphere`. A distant light's direction is a delta;
    /// the mixture at infinity (`Emitter::Environment`) has a density.
    pub fn at_infinity(emitter: Emitter, from: Vec3, wi: Vec3, sphere: &SceneSphere) -> Self {
        Self {
            emitter,
            p: from + wi * (2.0 * sphere.radius),
            normal: None,
            at_infinity: true,
            delta_position: false,
            delta_direction: emitter != Emitter::Environment,
        }
    }
}

/// The sphere around the scene's geometry. Light from a direction (a distant light, the lights
/// at infinity) leaves a disc of its radius facing that direction: every ray that crosses the
/// scene crosses the disc once.
#[derive(Clone, Copy, Debug)]
pub struct SceneSphere {
    pub centre: Vec3,
    pub radius: f32,
}

impl SceneSphere {
    /// A point uniform on the disc perpendicular to `dir` (unit, the way the light travels),
    /// one radius back from the centre against `dir`: outside the scene, so the ray from it
    /// along `dir` crosses all of it.
    pub fn entry_point(&self, dir: Vec3, u: Vec2) -> Vec3 {
        let d = sample_disk_concentric(u) * self.radius;
        let frame = Frame::from_normal(dir);
        self.centre + frame.to_world(Vec3::new(d.x, d.y, -self.radius))
    }

    /// The area density of [`Self::entry_point`]: 1 / (pi r^2).
    pub fn pdf_area(&self) -> f32 {
        1.0 / (PI * self.radius * self.radius)
    }

    /// The density, per area across `dir`, with which rays from [`Self::entry_point`]'s disc
    /// along `dir` pass `x`: the disc's within the cylinder the disc sweeps, 0 outside it. The
    /// sphere bounds the finite shapes only: an infinite plane reaches beyond it, where no
    /// light from infinity starts.
    pub fn pdf_reaching(&self, dir: Vec3, x: Vec3) -> f32 {
        let v = x - self.centre;
        let along = v.dot(dir);
        let across = v - along * dir;
        if along < -self.radius || across.length_squared() > self.radius * self.radius {
            0.0
        } else {
            self.pdf_area()
        }
    }
}

/// A direction uniform over the unit sphere.
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin, cos) = libm::sincosf(TAU * u.y);
    Vec3::new(r * cos, r * sin, z)
}

/// A direction uniform inside the cone about +z whose half-angle has 1 - cos =
/// `one_minus_cos` (given so, since 1 - cos of a narrow cone cancels): 1 - cos theta is
/// uniform in [0, one_minus_cos], and sin theta comes from it directly.
pub fn uniform_cone(u: Vec2, one_minus_cos: f32) -> Vec3 {
    let h = u.x * one_minus_cos;
    let cos = 1.0 - h;
    let sin = (h * (2.0 - h)).max(0.0).sqrt();
    let (sp, cp) = libm::sincosf(TAU * u.y);
    Vec3::new(sin * cp, sin * sp, cos)
}
