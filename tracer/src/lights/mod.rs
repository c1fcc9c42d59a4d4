//! Lights: area lights on shapes, point, spot, distant and infinite (constant or LatLong map,
//! importance-sampled by luminance), and the choice of which light to sample.
//!
//! A light is chosen with probability proportional to an estimate of its power. The infinite
//! lights act as one mixture: a direction sampled from any of them carries the sum of their
//! radiance and the mixture's density, which is what `environment` and `pdf_environment`
//! return for an escaping ray, so MIS sees the same numbers from both sides.

mod area;
mod distribution;
mod infinite;
mod punctual;

#[cfg(test)]
mod tests;

use glam::{Vec2, Vec3};

use crate::assets::AssetSource;
use crate::desc::{LatLongConvention, LightDesc, SceneDesc};
use crate::geometry::{SceneGeometry, SurfaceHit};
use crate::image_io::{self, RgbImage};

use area::AreaLight;
use distribution::Distribution1D;
use infinite::InfiniteLight;
use punctual::{DeltaSample, DistantLight, PointLight, SpotLight};

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

enum Light {
    Area(AreaLight),
    Point(PointLight),
    Spot(SpotLight),
    Distant(DistantLight),
    Infinite(InfiniteLight),
}

/// An infinite light never starves: it gets at least this fraction of the other lights' power
/// (scene-size estimates of sky power are rough, and the sky often matters more than they say).
const INFINITE_POWER_FLOOR: f32 = 0.1;

pub struct Lights {
    lights: Vec<Light>,
    /// Over `lights`, by estimated power.
    selection: Distribution1D,
    /// For each shape, the index of its area light in `lights`.
    shape_light: Vec<Option<u32>>,
    /// Indices into `lights` of the infinite lights.
    infinite: Vec<u32>,
}

#[derive(Debug, thiserror::Error)]
pub enum LightError {
    #[error(transparent)]
    Asset(#[from] crate::assets::AssetError),
    #[error(transparent)]
    Decode(#[from] crate::image_io::DecodeError),
}

impl Lights {
    pub fn build(
        desc: &SceneDesc,
        geometry: &SceneGeometry,
        source: &dyn AssetSource,
        latlong: LatLongConvention,
    ) -> Result<Self, LightError> {
        let mut lights = Vec::new();
        let mut shape_light = vec![None; desc.shapes.len()];
        for (index, shape) in desc.shapes.iter().enumerate() {
            let Some(area_light) = &shape.area_light else {
                continue;
            };
            if !emits(area_light.radiance) {
                continue;
            }
            let Some(surface) = geometry.shape_surface(index as u32) else {
                tracing::warn!(
                    "shape \"{}\": area light ignored (an infinite plane or a degenerate shape \
                     has no surface to sample)",
                    shape.name
                );
                continue;
            };
            let light = AreaLight::new(area_light.radiance, surface);
            if light.area() > 0.0 {
                shape_light[index] = Some(lights.len() as u32);
                lights.push(Light::Area(light));
            }
        }

        for light in &desc.lights {
            match light {
                LightDesc::Point {
                    position,
                    intensity,
                } => {
                    if emits(*intensity) {
                        lights.push(Light::Point(PointLight {
                            position: *position,
                            intensity: *intensity,
                        }));
                    }
                }
                LightDesc::Spot {
                    position,
                    direction,
                    intensity,
                    cone_angle,
                    cone_delta_angle,
                } => {
                    if emits(*intensity) {
                        lights.push(Light::Spot(SpotLight::new(
                            *position,
                            *direction,
                            *intensity,
                            *cone_angle,
                            *cone_delta_angle,
                        )));
                    }
                }
                LightDesc::Distant { to_light, radiance } => {
                    let to_light = to_light.normalize_or_zero();
                    if emits(*radiance) && to_light != Vec3::ZERO {
                        lights.push(Light::Distant(DistantLight {
                            to_light,
                            radiance: *radiance,
                        }));
                    }
                }
                LightDesc::Infinite {
                    radiance,
                    map,
                    light_to_world,
                } => {
                    if !emits(*radiance) {
                        continue;
                    }
                    let image = match map {
                        Some(map) => Some(load_map(source, &map.filename, map.gamma)?),
                        None => None,
                    };
                    if InfiniteLight::is_singular(light_to_world) {
                        tracing::warn!("infinite light: singular transform, using the identity");
                    }
                    lights.push(Light::Infinite(InfiniteLight::new(
                        *radiance,
                        image,
                        light_to_world,
                        latlong,
                    )));
                }
            }
        }

        let scene_radius = geometry
            .bounds()
            .map_or(1.0, |(lo, hi)| (0.5 * (hi - lo).length()).max(1e-3));
        let mut powers: Vec<f32> = lights
            .iter()
            .map(|light| match light {
                Light::Area(l) => l.power(),
                Light::Point(l) => l.power(),
                Light::Spot(l) => l.power(),
                Light::Distant(l) => l.power(scene_radius),
                Light::Infinite(l) => l.power(scene_radius),
            })
            .collect();
        let finite_power: f32 = lights
            .iter()
            .zip(&powers)
            .filter(|(l, _)| !matches!(l, Light::Infinite(_)))
            .map(|(_, p)| p)
            .sum();
        for (light, power) in lights.iter().zip(&mut powers) {
            if matches!(light, Light::Infinite(_)) {
                *power = power.max(INFINITE_POWER_FLOOR * finite_power);
            }
        }
        let infinite = (0..lights.len() as u32)
            .filter(|&i| matches!(lights[i as usize], Light::Infinite(_)))
            .collect();
        Ok(Self {
            lights,
            selection: Distribution1D::new(powers),
            shape_light,
            infinite,
        })
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Samples a light as seen from `p` (with `u_select` choosing the light and `u` the point on
    /// it). None when the chosen light contributes nothing from here.
    pub fn sample(&self, p: Vec3, u_select: f32, u: Vec2) -> Option<LightSample> {
        let (index, pmf, _) = self.selection.sample_discrete(u_select)?;
        let delta = |s: DeltaSample| LightSample {
            wi: s.wi,
            li: s.li,
            pdf: pmf,
            dist: s.dist,
            delta: true,
        };
        match &self.lights[index] {
            Light::Area(light) => {
                let s = light.sample(p, u)?;
                Some(LightSample {
                    wi: s.wi,
                    li: light.radiance(),
                    pdf: pmf * s.pdf,
                    dist: s.dist,
                    delta: false,
                })
            }
            Light::Point(light) => light.sample(p).map(delta),
            Light::Spot(light) => light.sample(p).map(delta),
            Light::Distant(light) => Some(delta(light.sample())),
            Light::Infinite(light) => {
                let (wi, pdf, li) = light.sample(u)?;
                // A lone infinite light is the whole mixture: its own density and radiance
                // serve, without looking the direction up again.
                let (li, pdf) = if self.infinite.len() == 1 {
                    (li, pmf * pdf)
                } else {
                    self.environment_and_pdf(wi)
                };
                (pdf > 0.0).then_some(LightSample {
                    wi,
                    li,
                    pdf,
                    dist: f32::INFINITY,
                    delta: false,
                })
            }
        }
    }

    fn area_light(&self, shape: u32) -> Option<(u32, &AreaLight)> {
        let index = (*self.shape_light.get(shape as usize)?)?;
        match &self.lights[index as usize] {
            Light::Area(light) => Some((index, light)),
            _ => None,
        }
    }

    /// Radiance an area light emits from `hit` towards `wo` (front face only).
    pub fn emitted(&self, hit: &SurfaceHit, wo: Vec3) -> Vec3 {
        match self.area_light(hit.shape) {
            Some((_, light)) if hit.ng.dot(wo) > 0.0 => light.radiance(),
            _ => Vec3::ZERO,
        }
    }

    /// Solid-angle density with which `sample` from `from` would have chosen the emitter point
    /// `hit` (for MIS when a BSDF-sampled ray hits an area light).
    pub fn pdf_hit(&self, from: Vec3, hit: &SurfaceHit) -> f32 {
        self.area_light(hit.shape).map_or(0.0, |(index, light)| {
            self.selection.pmf(index as usize) * light.pdf(from, hit.p, hit.ng)
        })
    }

    /// Radiance from the infinite lights along a ray escaping in direction `dir`.
    pub fn environment(&self, dir: Vec3) -> Vec3 {
        self.infinite_lights()
            .map(|(_, light)| light.radiance(dir))
            .sum()
    }

    /// Solid-angle density with which `sample` would have chosen direction `dir` on the
    /// infinite lights.
    pub fn pdf_environment(&self, dir: Vec3) -> f32 {
        self.infinite_lights()
            .map(|(index, light)| self.selection.pmf(index) * light.pdf(dir))
            .sum()
    }

    /// [`Self::environment`] and [`Self::pdf_environment`] together, for an escaping ray that
    /// needs its MIS weight.
    pub fn environment_and_pdf(&self, dir: Vec3) -> (Vec3, f32) {
        self.infinite_lights()
            .map(|(index, light)| {
                let (radiance, pdf) = light.radiance_and_pdf(dir);
                (radiance, self.selection.pmf(index) * pdf)
            })
            .fold((Vec3::ZERO, 0.0), |(r, p), (ri, pi)| (r + ri, p + pi))
    }

    fn infinite_lights(&self) -> impl Iterator<Item = (usize, &InfiniteLight)> {
        self.infinite
            .iter()
            .filter_map(|&i| match &self.lights[i as usize] {
                Light::Infinite(light) => Some((i as usize, light)),
                _ => None,
            })
    }
}

/// Whether a colour can light anything.
fn emits(c: Vec3) -> bool {
    c.is_finite() && c.max_element() > 0.0
}

fn load_map(source: &dyn AssetSource, filename: &str, gamma: f32) -> Result<RgbImage, LightError> {
    let bytes = source.read(filename)?;
    let image = image_io::decode(&bytes, filename, gamma)?;
    Ok(if image.is_empty() {
        RgbImage::from_linear(1, 1, vec![Vec3::ZERO])
    } else {
        image
    })
}
