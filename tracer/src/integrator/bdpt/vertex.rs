//! A vertex of a camera or light subpath, what a scattering one (a surface's BSDF, a volume's
//! phase function) does to the light it passes on, and the densities multiple importance
//! sampling asks of it: the area density with which one vertex samples the next (pbrt-v4's
//! and Veach's formulation; no cosine at a vertex in a volume), the density of a light's own
//! sampling of an emitter point, and of its emission toward a point.
//!
//! The densities are those of the directions alone: like pbrt-v4's, they leave out the
//! probabilities of the free flights between vertices (of scattering where a vertex in a volume
//! is, of passing through a volume to a surface). Every strategy that makes a path computes its
//! weight from the same densities, so the weights still sum to one over the strategies and the
//! estimate stays unbiased; they are only less well balanced in dense volumes.

use glam::Vec3;

use super::scene::BidirectionalScene;
use crate::geometry::SurfaceHit;
use crate::integrator::groups::LitBy;
use crate::integrator::media::sample_phase;
use crate::lights::Emitter;
use crate::material::Bsdf;
use crate::math::offset_origin;
use crate::medium::{MediumId, Phase, ShapeMedia};
use crate::sampler::VertexSamples;

/// Which way a subpath carries light, which decides the BSDF's adjoint.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Carries {
    /// A camera subpath: radiance flows toward its start.
    Radiance,
    /// A light subpath: light flows from its start.
    Importance,
}

/// A subpath vertex: where it is, what it carries and the densities of reaching it from either
/// side (area measure; solid angle for a vertex at infinity).
#[derive(Clone, Copy, Debug)]
pub(super) struct PathVertex {
    pub(super) kind: Kind,
    pub(super) p: Vec3,
    /// Geometric normal (zero off surfaces: the camera, point and spot lights, infinity, a
    /// volume's scattering event).
    pub(super) ng: Vec3,
    /// The subpath's throughput up to here (unused on a light vertex).
    pub(super) beta: Vec3,
    /// The density of this vertex as its own subpath sampled it.
    pub(super) pdf_fwd: f32,
    /// The density of this vertex as the other subpath would sample it.
    pub(super) pdf_rev: f32,
    /// Whether the subpath scattered specularly here: no strategy connects at such a vertex.
    pub(super) delta: bool,
    /// Whether the subpath met a dispersive interface here or before: a path joined at this
    /// vertex carries the sample's wavelength weight ([`super::walk::SampleWavelength`]).
    pub(super) dispersed: bool,
}

// Most vertices are surfaces, kept in a subpath's vector allocated once per unit: boxing the
// large variant would allocate per vertex.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub(super) enum Kind {
    /// The camera's lens point (the pinhole without a lens).
    Camera,
    /// A point on a light, or the lights at infinity seen along `toward`.
    Light(LightVertex),
    Surface(SurfaceVertex),
    /// A scattering event inside a volume.
    Medium(MediumVertex),
}

#[derive(Clone, Copy, Debug)]
pub(super) struct LightVertex {
    pub(super) emitter: Emitter,
    /// For a light at infinity (the environment, a distant light): the unit direction from the
    /// scene toward it.
    pub(super) toward: Option<Vec3>,
    pub(super) delta_position: bool,
    pub(super) delta_direction: bool,
}

#[derive(Clone, Copy, Debug)]
pub(super) struct SurfaceVertex {
    pub(super) hit: SurfaceHit,
    pub(super) bsdf: Bsdf,
    /// Unit direction toward the subpath's previous vertex.
    pub(super) wo: Vec3,
    pub(super) sides: ShapeMedia,
    /// The vertex's random numbers: its light sample's (a camera vertex's connection to a
    /// light) and lens sample's (a light vertex's connection to the camera) among them.
    pub(super) u: VertexSamples,
}

#[derive(Clone, Copy, Debug)]
pub(super) struct MediumVertex {
    pub(super) phase: Phase,
    /// Unit direction toward the subpath's previous vertex.
    pub(super) wo: Vec3,
    /// The volume the event is in: what rays leaving it travel in.
    pub(super) medium: Option<MediumId>,
    /// The vertex's random numbers, as a surface vertex's (the phase function's sample in
    /// `bsdf`, the light sample and lens sample in `light_select` and `light`).
    pub(super) u: VertexSamples,
}

/// A direction a scattering vertex sends its subpath on in, with what it carries.
pub(super) struct Scattered {
    pub(super) wi: Vec3,
    /// What the subpath's throughput is multiplied by: `f |cos| / pdf` at a surface (with the
    /// shading normals' correction for light carried from the lights), the phase function
    /// over its density in a volume.
    pub(super) weight: Vec3,
    /// The solid-angle density of `wi`, and of going back along `-wi` from `wi` (0 both for a
    /// specular sample).
    pub(super) pdf: f32,
    pub(super) pdf_rev: f32,
    pub(super) specular: bool,
}

impl PathVertex {
    /// A scattering vertex's random numbers (None for the camera and the lights).
    pub(super) fn samples(&self) -> Option<&VertexSamples> {
        match &self.kind {
            Kind::Surface(s) => Some(&s.u),
            Kind::Medium(m) => Some(&m.u),
            _ => None,
        }
    }

    /// What a scattering vertex sends toward unit `wi` of the light from its previous vertex
    /// (`carries` radiance) or of the light reaching it from there (importance, with the
    /// shading normals' correction): a surface's BSDF, a volume's phase function; 0 for the
    /// camera and the lights.
    pub(super) fn scatters_toward(&self, wi: Vec3, carries: Carries) -> Vec3 {
        match &self.kind {
            Kind::Surface(s) => match carries {
                Carries::Radiance => s.bsdf.eval(s.wo, wi),
                // Importance scatters by the adjoint BSDF, f(wi, wo): the same for reciprocal
                // BSDFs, not for `scatter` (f = R phase / |cos_i|).
                Carries::Importance => s.bsdf.eval(wi, s.wo) * shading_correction(s, s.wo, wi),
            },
            Kind::Medium(m) => m.phase.eval(m.wo, wi),
            _ => Vec3::ZERO,
        }
    }

    /// The cosine a connection along unit `w` takes at this vertex: with the shading normal at
    /// a surface, none (1) in a volume.
    pub(super) fn cos_toward(&self, w: Vec3) -> f32 {
        match &self.kind {
            Kind::Surface(s) => w.dot(s.hit.ns).abs(),
            _ => 1.0,
        }
    }

    /// Where a ray leaving this vertex along unit `dir` starts (off a surface, on the side it
    /// leaves into) and the volume it travels in: that side's at a surface, the event's in a
    /// volume, the camera's (`camera_medium`) at the lens.
    pub(super) fn leaving(
        &self,
        dir: Vec3,
        camera_medium: Option<MediumId>,
    ) -> (Vec3, Option<MediumId>) {
        match &self.kind {
            Kind::Surface(s) => (
                offset_origin(self.p, s.hit.ng, dir),
                s.sides.toward(dir, s.hit.ng),
            ),
            Kind::Medium(m) => (self.p, m.medium),
            _ => (self.p, camera_medium),
        }
    }

    /// The subpath's next direction from a scattering vertex, drawn from its own numbers.
    pub(super) fn sample_on(&self, carries: Carries) -> Option<Scattered> {
        match &self.kind {
            Kind::Surface(s) => {
                let bs = s.bsdf.sample(s.wo, s.u.lobe, s.u.bsdf)?;
                if bs.pdf <= 0.0 || bs.f == Vec3::ZERO {
                    return None;
                }
                // Importance scatters by the adjoint BSDF (`scatters_toward`); a specular
                // sample's value is its own.
                let f = match carries {
                    Carries::Importance if !bs.specular => self.scatters_toward(bs.wi, carries),
                    Carries::Importance => bs.f * shading_correction(s, s.wo, bs.wi),
                    Carries::Radiance => bs.f,
                };
                let weight = f * (bs.wi.dot(s.hit.ns).abs() / bs.pdf);
                let (pdf, pdf_rev) = if bs.specular {
                    (0.0, 0.0)
                } else {
                    (bs.pdf, s.bsdf.pdf(bs.wi, s.wo))
                };
                Some(Scattered {
                    wi: bs.wi,
                    weight,
                    pdf,
                    pdf_rev,
                    specular: bs.specular,
                })
            }
            Kind::Medium(m) => {
                let ps = sample_phase(&m.phase, m.wo, m.u.bsdf)?;
                Some(Scattered {
                    wi: ps.wi,
                    weight: ps.weight,
                    pdf: ps.pdf,
                    pdf_rev: m.phase.pdf(ps.wi, m.wo),
                    specular: false,
                })
            }
            _ => None,
        }
    }

    /// Whether the vertex is a light at infinity (its densities are per solid angle).
    pub(super) fn at_infinity(&self) -> bool {
        matches!(
            self.kind,
            Kind::Light(LightVertex {
                toward: Some(_),
                ..
            })
        )
    }

    /// Whether a light vertex is a delta light (a point, a spot, a distant light), which no
    /// path can hit.
    pub(super) fn is_delta_light(&self) -> bool {
        matches!(self.kind, Kind::Light(l) if l.delta_position || l.delta_direction)
    }

    /// The emitter the vertex is on: a light vertex's, or the area light of a surface a camera
    /// path hit.
    pub(super) fn emitter<S: BidirectionalScene>(&self, scene: &S) -> Option<Emitter> {
        match &self.kind {
            Kind::Light(l) => Some(l.emitter),
            Kind::Surface(s) => scene.lights().emitter_of_shape(s.hit.shape),
            Kind::Camera | Kind::Medium(_) => None,
        }
    }

    /// The solid-angle density `pdf` of a direction leaving this vertex toward `next`, as an
    /// area density at `next` (unchanged for a vertex at infinity).
    pub(super) fn area_density(&self, pdf: f32, next: &PathVertex) -> f32 {
        if next.at_infinity() {
            return pdf;
        }
        let d = next.p - self.p;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 {
            return 0.0;
        }
        let cos = if next.ng == Vec3::ZERO {
            1.0
        } else {
            (next.ng.dot(d) / dist2.sqrt()).abs()
        };
        pdf * cos / dist2
    }

    /// The unit direction from this vertex to `next` (toward infinity for a light there).
    pub(super) fn direction_to(&self, next: &PathVertex) -> Vec3 {
        match next.kind {
            Kind::Light(LightVertex {
                toward: Some(w), ..
            }) => w,
            _ => (next.p - self.p).normalize_or_zero(),
        }
    }

    /// The area density with which this vertex, reached from `prev`, samples `next`: the
    /// camera's ray density, a light's emission, the BSDF's or the phase function's sample.
    pub(super) fn pdf_toward<S: BidirectionalScene>(
        &self,
        scene: &S,
        prev: Option<&PathVertex>,
        next: &PathVertex,
    ) -> f32 {
        match &self.kind {
            Kind::Camera => {
                if next.at_infinity() {
                    return 0.0;
                }
                let cos = if next.ng == Vec3::ZERO {
                    1.0
                } else {
                    next.ng.dot(self.direction_to(next)).abs()
                };
                scene.camera().density_at(self.p, next.p) * cos
            }
            Kind::Light(_) => self.pdf_light(scene, next),
            Kind::Surface(s) => {
                let Some(prev) = prev else {
                    return 0.0;
                };
                let pdf = s.bsdf.pdf(self.direction_to(prev), self.direction_to(next));
                self.area_density(pdf, next)
            }
            Kind::Medium(m) => {
                let Some(prev) = prev else {
                    return 0.0;
                };
                let pdf = m
                    .phase
                    .pdf(self.direction_to(prev), self.direction_to(next));
                self.area_density(pdf, next)
            }
        }
    }

    /// The area density at `next` of this emitter vertex's emission toward it (a light's
    /// sampling of a light subpath's first direction; the disc of a light at infinity).
    pub(super) fn pdf_light<S: BidirectionalScene>(&self, scene: &S, next: &PathVertex) -> f32 {
        let Some(emitter) = self.emitter(scene) else {
            return 0.0;
        };
        let lights = scene.lights();
        let cos_next = |w: Vec3| {
            if next.ng == Vec3::ZERO {
                1.0
            } else {
                next.ng.dot(w).abs()
            }
        };
        if let Kind::Light(LightVertex {
            toward: Some(toward),
            ..
        }) = self.kind
        {
            // Light from infinity leaves a disc as wide as the scene: its density is the
            // disc's, per area across the light's direction (none beyond it).
            return cos_next(toward) * lights.pdf_from_infinity(emitter, -toward, next.p);
        }
        let dir = self.direction_to(next);
        let normal = (self.ng != Vec3::ZERO).then_some(self.ng);
        let (_, pdf_dir) = lights.emission_pdf(emitter, self.p, normal, dir);
        self.area_density(pdf_dir, next)
    }

    /// The density with which the lights choose this emitter point (per area; per solid angle
    /// for the lights at infinity) as a light subpath's start: 0 for delta lights, which only
    /// light subpaths and light samples reach.
    pub(super) fn pdf_light_origin<S: BidirectionalScene>(
        &self,
        scene: &S,
        next: &PathVertex,
    ) -> f32 {
        if self.is_delta_light() {
            return 0.0;
        }
        let Some(emitter) = self.emitter(scene) else {
            return 0.0;
        };
        let lights = scene.lights();
        if let Kind::Light(LightVertex {
            toward: Some(toward),
            ..
        }) = self.kind
        {
            return lights.pdf_environment(toward, None);
        }
        let dir = self.direction_to(next);
        let normal = (self.ng != Vec3::ZERO).then_some(self.ng);
        lights.emission_pdf(emitter, self.p, normal, dir).0
    }

    /// The radiance a camera path's last vertex (on an area light, or at infinity) sends back
    /// along the path.
    /// Where the light this vertex emits comes from, for light groups: the light of a light
    /// vertex (the lights at infinity along `toward`), the area light of a surface vertex.
    pub(super) fn lit_by(&self) -> Option<LitBy> {
        match &self.kind {
            Kind::Light(LightVertex {
                emitter: Emitter::Light(index),
                ..
            }) => Some(LitBy::Light(*index)),
            Kind::Light(LightVertex {
                emitter: Emitter::Environment,
                toward,
                ..
            }) => toward.map(LitBy::Environment),
            Kind::Surface(s) => Some(LitBy::Shape(s.hit.shape)),
            _ => None,
        }
    }

    pub(super) fn emitted<S: BidirectionalScene>(&self, scene: &S) -> Vec3 {
        match &self.kind {
            Kind::Light(LightVertex {
                toward: Some(toward),
                ..
            }) => scene.lights().environment(*toward),
            Kind::Surface(s) => scene.lights().emitted(&s.hit, s.wo),
            _ => Vec3::ZERO,
        }
    }
}

/// The factor that keeps light carried from the lights (importance's adjoint) consistent with
/// shading normals: `|wo.ns| |wi.ng| / (|wo.ng| |wi.ns|)`, `wo` toward where the light came
/// from and `wi` where it goes (Veach 1997, 5.3).
pub(super) fn shading_correction(s: &SurfaceVertex, wo: Vec3, wi: Vec3) -> f32 {
    let (ng, ns) = (s.hit.ng, s.hit.ns);
    let denom = wo.dot(ng).abs() * wi.dot(ns).abs();
    if denom <= 0.0 {
        return 0.0;
    }
    wo.dot(ns).abs() * wi.dot(ng).abs() / denom
}
