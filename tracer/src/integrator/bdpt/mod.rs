//! Bidirectional path tracing (`SurfaceIntegrator "bidirectional"`): a camera subpath and a
//! light subpath per sample, joined by every strategy their lengths allow and weighed by
//! multiple importance sampling (power heuristic; Veach 1997, chapter 10; pbrt-v4's
//! formulation). The light subpath's vertices seen by the camera (light tracing) land anywhere
//! on the film: they come back as [`LightSplat`]s for the renderer to add to the unit's light
//! splats, which the film divides by the light subpaths per pixel (`film.rs`).
//!
//! Files: `scene` (what the integrator needs of the scene, its bounds, the splats it returns:
//! the leaf), `vertex` (a subpath vertex and its densities), `walk` (a subpath's random walk),
//! `connect` (the strategies), `weight` (their MIS weight). The BSDFs, lights, camera, shadow
//! rays and sampler are the path tracer's.
//!
//! LuxRender's parameters: `eyedepth` and `lightdepth` bound the scattering vertices of each
//! subpath (8 each by default, at most [`MAX_DEPTH`]), `eyerrthreshold` and
//! `lightrrthreshold` are the least survival probabilities of LuxRender's roulette (0).
//!
//! Volumes: both subpaths walk through them as the path tracer's paths do (free flights,
//! scattering events as vertices with the phase function in place of a BSDF, `walk`), and every
//! strategy joins at an event as at a surface, its connection carrying the volumes'
//! transmittance (the path tracer's shadow rays). The camera subpath starts in the camera's
//! volume. A light subpath starts in the volume its light leaves into: an area light's, the one
//! its shape names on the emitting side; a point or spot light's, the Exterior current at its
//! `LightSource` (LuxRender's rule). Off a side that names none, it starts in no volume and so
//! takes (LuxRender's rule for a ray in no volume) the volume on the near side of the first
//! surface it meets: the volume a shadow ray from that surface toward the light travels in.
//! Light from a light at infinity takes that rule too, having crossed its first segment's
//! volume from infinity (its transmittance over an infinite distance, which is what a shadow
//! ray toward the light finds: none through a volume that absorbs or scatters).
//! Where a scene puts a point light in another volume than its Exterior, or names no volume
//! on the side of a surface a path reaches in one, light subpaths and the path tracer's light
//! samples may see different volumes; LuxRender's own integrators differ there too.

mod connect;
mod scene;
mod vertex;
mod walk;
mod weight;

pub use self::scene::{BidirectionalScene, LightSplat, MAX_DEPTH};

use glam::Vec3;

use self::scene::MAX_VERTICES;
use self::vertex::{Carries, Kind, LightVertex, PathVertex};
use self::walk::{walk, CrossedEmitter, SampleWavelength};
use self::weight::Limits;
use super::groups::{credit, GroupSink, LitBy};
use super::state::PathResult;
use crate::film::light_groups::MAX_LIGHT_GROUPS;
use crate::integrator::shadow::shadow_transmittance;
use crate::math::{offset_origin, Ray};
use crate::sampler::PixelSampler;

/// The subpaths of one sample, kept from sample to sample so that a unit allocates them once.
#[derive(Default)]
pub struct Subpaths {
    camera: Vec<PathVertex>,
    light: Vec<PathVertex>,
    /// The emitters the camera subpath crossed (lamps of null material).
    crossed: Vec<CrossedEmitter>,
}

impl Subpaths {
    pub fn new() -> Self {
        Self {
            camera: Vec::with_capacity(MAX_VERTICES),
            light: Vec::with_capacity(MAX_VERTICES),
            crossed: Vec::with_capacity(MAX_VERTICES),
        }
    }
}

/// One bidirectional sample: the radiance along `camera_ray` (None: the camera has no ray
/// there, as outside a fisheye's circle; the light subpath is traced all the same, since the
/// film counts one per camera sample), with the light subpath's splats pushed to `splats`.
/// Where `groups` keeps light groups, every strategy's light is credited to the group of the
/// light its path starts at, and each splat is followed by its groups' shares as splats of
/// their own ([`LightSplat::group`]: at most [`MAX_SPLATS_PER_SAMPLE`] in all).
pub fn trace_bidirectional<S: BidirectionalScene, G: GroupSink>(
    scene: &S,
    camera_ray: Option<Ray>,
    sampler: &mut PixelSampler,
    subpaths: &mut Subpaths,
    (splats, groups): (&mut Vec<LightSplat>, &mut G),
) -> PathResult {
    let integrator = scene.integrator();
    let limits = Limits {
        max_camera: scene.max_depth().min(MAX_DEPTH) as usize + 1,
        max_light: scene.light_depth().min(MAX_DEPTH) as usize + 1,
        only: scene.only_strategy(),
    };
    let Subpaths {
        camera,
        light,
        crossed,
    } = subpaths;
    camera.clear();
    light.clear();
    crossed.clear();
    let mut rays = 0;
    let mut light_sampler = sampler.light_subpath();
    let mut wavelength = SampleWavelength {
        number: sampler.wavelength_number(),
        drawn: None,
    };
    if let Some(ray) = camera_ray {
        camera.push(PathVertex {
            kind: Kind::Camera,
            p: ray.origin,
            ng: Vec3::ZERO,
            beta: Vec3::ONE,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            delta: false,
            dispersed: false,
        });
        rays += walk(
            scene,
            camera,
            crossed,
            ray,
            scene.volumes().camera,
            false,
            Vec3::ONE,
            limits.max_camera,
            Carries::Radiance,
            integrator.eye_rr_threshold,
            &mut wavelength,
            sampler,
        );
    }
    rays += light_subpath(
        scene,
        light,
        limits.max_light,
        &mut wavelength,
        &mut light_sampler,
    );

    let w = &wavelength;
    let lights = scene.lights();
    let light_start = light.first().and_then(PathVertex::lit_by);
    let mut radiance = Vec3::ZERO;
    let mut add = |light: Vec3, from: Option<LitBy>| {
        radiance += light;
        credit(groups, lights, from, light);
    };
    for t in 2..=camera.len() {
        let pt = &camera[t - 1];
        add(
            w.weigh(
                camera[t - 2].dispersed,
                connect::camera_hits_light(scene, &camera[..t - 1], pt, limits),
            ),
            pt.lit_by(),
        );
        if t < camera.len() || !pt.at_infinity() {
            let term = connect::camera_samples_light(scene, camera, t, limits, &mut rays);
            add(w.weigh(pt.dispersed, term.light), term.from);
        }
        for s in 2..=light.len() {
            add(
                w.weigh(
                    pt.dispersed || light[s - 1].dispersed,
                    connect::join(scene, light, s, camera, t, limits, &mut rays),
                ),
                light_start,
            );
        }
    }
    for c in crossed.iter() {
        add(
            w.weigh(
                camera[c.at - 1].dispersed,
                connect::camera_hits_light(scene, &camera[..c.at], &c.vertex, limits),
            ),
            c.vertex.lit_by(),
        );
    }
    for s in 2..=light.len() {
        if let Some(mut splat) =
            connect::camera_sees_light_vertex(scene, light, s, limits, &mut rays)
        {
            splat.radiance = w.weigh(light[s - 1].dispersed, splat.radiance);
            splats.push(splat);
            if G::ON {
                let mut shares = GroupSplats { splat, splats };
                credit(&mut shares, lights, light_start, splat.radiance);
            }
        }
    }
    // The camera ray escaped where its subpath ends at infinity straight after the camera
    // (crossed surfaces make no vertex), or has no vertex but the camera's (it escaped in a
    // scene without lights; or there is no camera ray, or a depth of 0 traces none): LuxRender's
    // alpha 0.
    let escaped = camera.get(1).is_none_or(PathVertex::at_infinity);
    PathResult {
        radiance,
        rays,
        escaped,
    }
}

/// The most light splats one sample makes: one per light subpath vertex seen by the camera,
/// each followed, where the render keeps light groups, by a share per group.
pub const MAX_SPLATS_PER_SAMPLE: usize = (MAX_DEPTH as usize + 1) * (1 + MAX_LIGHT_GROUPS);

/// Sends each light group's share of `splat` on as a splat of its own.
struct GroupSplats<'a> {
    splat: LightSplat,
    splats: &'a mut Vec<LightSplat>,
}

impl GroupSink for GroupSplats<'_> {
    const ON: bool = true;

    fn add(&mut self, group: u8, light: Vec3) {
        self.splats.push(LightSplat {
            radiance: light,
            group: Some(group),
            ..self.splat
        });
    }
}

/// Samples a light subpath into `light`: a ray leaving a light, then its walk.
fn light_subpath<S: BidirectionalScene>(
    scene: &S,
    light: &mut Vec<PathVertex>,
    max_vertices: usize,
    wavelength: &mut SampleWavelength,
    sampler: &mut PixelSampler,
) -> u32 {
    let lights = scene.lights();
    let u_select = sampler.get_1d();
    let (u_pos, u_dir) = (sampler.get_2d(), sampler.get_2d());
    let Some(sample) = lights.sample_emission(u_select, u_pos, u_dir) else {
        return 0;
    };
    let e = sample.ray;
    if e.pdf_pos <= 0.0 || e.pdf_dir <= 0.0 || e.le == Vec3::ZERO {
        return 0;
    }
    let at_infinity =
        e.delta_direction || matches!(sample.emitter, crate::lights::Emitter::Environment);
    let normal = e.normal.unwrap_or(Vec3::ZERO);
    let mut start = PathVertex {
        kind: Kind::Light(LightVertex {
            emitter: sample.emitter,
            toward: at_infinity.then_some(-e.dir),
            delta_position: e.delta_position,
            delta_direction: e.delta_direction,
        }),
        p: e.origin,
        ng: normal,
        // Never read: a light's own point is joined to camera vertices by their light
        // samples, not by this vertex (the strategies of `connect.rs`).
        beta: Vec3::ZERO,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
        delta: false,
        dispersed: false,
    };
    start.pdf_fwd = start.pdf_light_origin(scene, &start);
    light.push(start);
    let cos = e.normal.map_or(1.0, |n| n.dot(e.dir).abs());
    let mut beta = e.le * (cos / (e.pdf_pos * e.pdf_dir));
    let mut rays = 0;
    // Light from infinity starts on a disc at the edge of the finite shapes' bounds. An
    // infinite plane reaches past it, between the disc and the light: the light's way from
    // infinity to the disc is a shadow ray then (else the sky below the horizon would shine
    // up through the ground onto everything above it).
    if at_infinity && scene.geometry().has_planes() {
        beta *= shadow_transmittance(scene, e.origin, -e.dir, f32::INFINITY, None, &mut rays);
        if beta == Vec3::ZERO {
            return rays;
        }
    }
    // Off the lamp's surface, as any ray leaving a surface (else it may hit the lamp itself).
    let origin = e
        .normal
        .map_or(e.origin, |n| offset_origin(e.origin, n, e.dir));
    // The volume the light leaves into (see the module's doc).
    let medium = match (lights.shape_of(sample.emitter), e.normal) {
        (Some(shape), Some(n)) => scene.shape_media(shape).toward(e.dir, n),
        _ if at_infinity => None,
        _ => lights
            .source_of(sample.emitter)
            .and_then(|source| scene.volumes().light(source)),
    };
    // A light subpath gathers no emission: it keeps no emitter it crosses (and the empty
    // vector allocates nothing).
    rays + walk(
        scene,
        light,
        &mut Vec::new(),
        Ray::new(origin, e.dir),
        medium,
        at_infinity,
        beta,
        max_vertices,
        Carries::Importance,
        scene.integrator().light_rr_threshold,
        wavelength,
        sampler,
    )
}
