//! A surface vertex: its light sample (the lights', or a lamp image's) and its BSDF sample,
//! shared by the path loop and by a packet's lanes shaded one at a time.

use glam::Vec3;

use super::direct::direct_light;
use super::groups::LightTerm;
use super::light_draw::{BsdfCounts, LightDraw};
use super::mirror_images::{direct_light_via_mirror, split_light_sample};
use super::scene::PathScene;
use crate::geometry::SurfaceHit;
use crate::material::{Bsdf, BsdfSample};
use crate::medium::ShapeMedia;
use crate::sampler::VertexSamples;

/// A surface vertex a path scatters at: what [`walk`] does there, and what a packet's lane
/// that meets a material the packet does not shade in lanes has done for it
/// ([`super::packet`]), the same operations either way.
///
/// [`walk`]: super::path::walk
pub(super) struct Vertex<'a> {
    pub(super) hit: &'a SurfaceHit,
    /// The direction the path arrived from.
    pub(super) wo: Vec3,
    pub(super) bsdf: &'a Bsdf,
    pub(super) sides: ShapeMedia,
    /// The path's vertices up to this one, this one counted.
    pub(super) depth: u32,
    /// The BSDF samples the vertex's light sample is weighed against.
    pub(super) bsdf_counts: BsdfCounts,
}

/// Where a vertex's light sample goes ([`Vertex::choose_light`]).
pub(super) enum LightChoice {
    /// To a lamp image: the light it brings, weighed.
    Image(LightTerm),
    /// To the lights, with this draw.
    Lights(LightDraw),
}

impl Vertex<'_> {
    /// The vertex's light sample (None at a specular vertex), drawn from `u`, and the share of
    /// its light samples that went to lamp images; its rays counted in `rays`.
    #[inline(always)]
    pub(super) fn light<S: PathScene>(
        &self,
        scene: &S,
        u: &VertexSamples,
        rays: &mut u32,
    ) -> (Option<Vec3>, f32) {
        let (term, image_share) = self.light_term(scene, u, rays);
        (term.map(|t| t.light), image_share)
    }

    /// [`Self::light`] with the light its sample came from, for light groups.
    #[inline(always)]
    pub(super) fn light_term<S: PathScene>(
        &self,
        scene: &S,
        u: &VertexSamples,
        rays: &mut u32,
    ) -> (Option<LightTerm>, f32) {
        if self.bsdf.is_specular() {
            return (None, 0.0);
        }
        let (choice, image_share) = self.choose_light(scene, u, rays);
        let term = match choice {
            LightChoice::Image(term) => term,
            LightChoice::Lights(draw) => {
                direct_light(scene, self.hit, self.wo, self.bsdf, self.sides, draw, rays)
            }
        };
        (Some(term), image_share)
    }

    /// Where the light sample of this vertex (not a specular one) goes, and the share of its
    /// light samples that went to lamp images: see [`Self::light`].
    #[inline(always)]
    pub(super) fn choose_light<S: PathScene>(
        &self,
        scene: &S,
        u: &VertexSamples,
        rays: &mut u32,
    ) -> (LightChoice, f32) {
        let lights = scene.lights();
        let (hit, wo, bsdf) = (self.hit, self.wo, self.bsdf);
        // A path through a mirror needs one more vertex: none past the last.
        let (draw, image) = if lights.has_mirror_images() && self.depth < scene.max_depth() {
            split_light_sample(lights, hit.p, u)
        } else {
            (LightDraw::lights_only(u), None)
        };
        let draw = LightDraw {
            bsdf_counts: self.bsdf_counts,
            ..draw
        };
        match image {
            Some(images) => {
                let light = direct_light_via_mirror(scene, hit, wo, bsdf, &images, draw, rays);
                (LightChoice::Image(light), draw.share)
            }
            // What the lights leave (nothing where no image is seen).
            None => (LightChoice::Lights(draw), 1.0 - draw.share),
        }
    }

    /// The path's BSDF sample here and what its throughput is multiplied by; None where the
    /// path ends (no sample, or one that carries nothing).
    #[inline(always)]
    pub(super) fn sample(&self, u: &VertexSamples) -> Option<(BsdfSample, Vec3)> {
        let bs = self.bsdf.sample(self.wo, u.lobe, u.bsdf)?;
        if bs.pdf <= 0.0 || bs.f == Vec3::ZERO {
            return None;
        }
        let cos = bs.wi.dot(self.hit.ns).abs();
        let weight = bs.f * (cos / bs.pdf);
        Some((bs, weight))
    }
}
