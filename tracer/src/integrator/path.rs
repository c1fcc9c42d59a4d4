//! The path tracer: unidirectional path tracing with next-event estimation, multiple importance sampling of
//! light and BSDF samples (power heuristic), and Russian roulette.

use glam::Vec3;

use super::options::{IntegratorDesc, RussianRoulette};
use crate::geometry::{SceneGeometry, SurfaceHit};
use crate::lights::Lights;
use crate::material::Bsdf;
use crate::math::{offset_origin, Ray};
use crate::sampler::PixelSampler;

/// What the path tracer needs from the scene. The renderer's built scene implements it, so the
/// integrator does not depend on how the scene is built.
pub trait PathScene {
    /// The scene's SurfaceIntegrator settings.
    fn integrator(&self) -> &IntegratorDesc;
    /// Bounces per path (the settings' max depth, which the command line may override).
    fn max_depth(&self) -> u32;
    fn geometry(&self) -> &SceneGeometry;
    fn lights(&self) -> &Lights;
    /// The BSDF at a hit; `u_mix` resolves mix materials.
    fn bsdf_at(&self, hit: &SurfaceHit, u_mix: f32) -> Bsdf;
}

/// Null surfaces crossed in a row before a path gives up (guards against stacked coplanar
/// null faces).
const MAX_PASS_THROUGH: u32 = 64;

/// Bounces before Russian roulette may end a path.
const RR_MIN_DEPTH: u32 = 3;

/// Radiance along a camera ray, and the number of rays traced for it.
pub struct PathResult {
    pub radiance: Vec3,
    pub rays: u32,
}

fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    if a + b > 0.0 {
        a / (a + b)
    } else {
        0.0
    }
}

/// Where the ray that reached the current vertex was sampled, for MIS on emitters it hits.
struct PrevScatter {
    p: Vec3,
    pdf: f32,
    specular: bool,
}

pub fn trace_path<S: PathScene>(scene: &S, mut ray: Ray, sampler: &mut PixelSampler) -> PathResult {
    let integrator = scene.integrator();
    let max_depth = scene.max_depth();
    let lights = scene.lights();
    let mut radiance = Vec3::ZERO;
    let mut throughput = Vec3::ONE;
    let mut rays = 0u32;
    let mut depth = 0u32;
    let mut pass_through = 0u32;
    // The camera ray counts as specular: emitters it sees are taken at full weight.
    let mut prev = PrevScatter {
        p: ray.origin,
        pdf: 0.0,
        specular: true,
    };

    loop {
        rays += 1;
        let Some(hit) = scene.geometry().intersect(&ray, f32::INFINITY) else {
            if depth > 0 || integrator.include_environment {
                let (le, weight) = if prev.specular {
                    (lights.environment(ray.dir), 1.0)
                } else {
                    let (le, pdf) = lights.environment_and_pdf(ray.dir);
                    (le, power_heuristic(prev.pdf, pdf))
                };
                radiance += throughput * le * weight;
            }
            break;
        };
        let wo = -ray.dir;

        let le = lights.emitted(&hit, wo);
        if le != Vec3::ZERO {
            let weight = if prev.specular {
                1.0
            } else {
                power_heuristic(prev.pdf, lights.pdf_hit(prev.p, &hit))
            };
            radiance += throughput * le * weight;
        }

        let bsdf = scene.bsdf_at(&hit, sampler.get_1d());
        if bsdf.is_pass_through() {
            pass_through += 1;
            if pass_through > MAX_PASS_THROUGH {
                break;
            }
            ray = Ray::new(offset_origin(hit.p, hit.ng, ray.dir), ray.dir);
            continue;
        }
        pass_through = 0;
        if depth >= max_depth {
            break;
        }
        depth += 1;

        if !bsdf.is_specular() {
            radiance += throughput * direct_light(scene, &hit, wo, &bsdf, sampler, &mut rays);
        } else {
            // Keep the dimension layout of a vertex fixed whatever the material.
            sampler.get_1d();
            sampler.get_2d();
        }

        let Some(bs) = bsdf.sample(wo, sampler.get_1d(), sampler.get_2d()) else {
            break;
        };
        if bs.pdf <= 0.0 || bs.f == Vec3::ZERO {
            break;
        }
        let cos = bs.wi.dot(hit.ns).abs();
        throughput *= bs.f * (cos / bs.pdf);

        let u_rr = sampler.get_1d();
        if depth >= RR_MIN_DEPTH {
            let continue_prob = match integrator.rr_strategy {
                RussianRoulette::None => 1.0,
                RussianRoulette::Probability => integrator.rr_continue_prob,
                // The largest channel, not luminance: a path along a saturated red wall
                // has a small luminance but a large red throughput, and dividing that by a
                // small survival probability is what makes coloured fireflies.
                RussianRoulette::Efficiency => throughput.max_element().clamp(0.05, 1.0),
            };
            if u_rr >= continue_prob {
                break;
            }
            throughput /= continue_prob;
        }

        prev = PrevScatter {
            p: hit.p,
            pdf: bs.pdf,
            specular: bs.specular,
        };
        ray = Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi);
    }
    PathResult { radiance, rays }
}

/// One light sample, weighted against BSDF sampling by the power heuristic.
fn direct_light<S: PathScene>(
    scene: &S,
    hit: &SurfaceHit,
    wo: Vec3,
    bsdf: &Bsdf,
    sampler: &mut PixelSampler,
    rays: &mut u32,
) -> Vec3 {
    let u_select = sampler.get_1d();
    let u_light = sampler.get_2d();
    let Some(ls) = scene.lights().sample(hit.p, u_select, u_light) else {
        return Vec3::ZERO;
    };
    if ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let f = bsdf.eval(wo, ls.wi);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let origin = offset_origin(hit.p, hit.ng, ls.wi);
    // Stop short of the light's own surface.
    let tmax = if ls.dist.is_finite() {
        (origin - hit.p).length().mul_add(-1.0, ls.dist) * (1.0 - 1e-3)
    } else {
        f32::INFINITY
    };
    *rays += 1;
    if scene.geometry().occluded(&Ray::new(origin, ls.wi), tmax) {
        return Vec3::ZERO;
    }
    let weight = if ls.delta {
        1.0
    } else {
        power_heuristic(ls.pdf, bsdf.pdf(wo, ls.wi))
    };
    f * ls.li * (ls.wi.dot(hit.ns).abs() * weight / ls.pdf)
}
