//! Lights: what a `LightSource` statement describes ([`LightDesc`], one file per kind, read
//! through the name table `read`), area lights on shapes (`area`), and the sampler the
//! integrator asks ([`Lights`]): point, spot, distant, infinite (constant or LatLong map,
//! importance-sampled by luminance), sun (a small cone), sky (Preetham or Hosek-Wilkie,
//! tabulated and sampled like a map) and area lights, and the choice of which light to sample.
//!
//! A light is chosen with probability proportional to an estimate of its power. The lights at
//! infinity (infinite, sky, sun) act as one mixture: a direction sampled from any of them
//! carries the sum of their radiance and the mixture's density, which is what `environment`
//! and `pdf_environment` return for an escaping ray, so MIS sees the same numbers from both
//! sides.
//!
//! For a bidirectional integrator the sampler also starts rays at the lights
//! ([`Lights::sample_emission`], [`EmissionSample`]) and says how likely a given ray leaving a
//! light was ([`Lights::emission_pdf`]), pbrt-v4's `SampleLe` and `PDF_Le`: each kind samples
//! its own rays (area lights a point by area and a cosine-weighted direction, point lights the
//! sphere, spots their cone), and light from a direction (distant lights, the lights at
//! infinity) enters through a disc of the scene's bounding sphere ([`sample::SceneSphere`]).
//! The lights at infinity emit as the one mixture they are for escaping rays: a direction
//! sampled from any member carries the mixture's radiance and density. The mixture's choice
//! probability (the sum of its members') goes with the position density, as a light's choice
//! does, and its direction density is the mixture's divided by it, a density over the sphere
//! (integrating to 1), so `le / (pdf_pos pdf_dir)` estimates the mixture's flux into the
//! scene.
//!
//! Area lights are also sampled through flat mirrors, as their images (`mirrored`): scenes
//! whose lamps light a room by way of a mirror get that light by next-event estimation
//! instead of by BSDF samples that happen to find the lamp.
//!
//! Files: one per kind (`point`, `spot`, `distant`, `infinite`, `sun`, `sky/`, `area`), each
//! with its statement, parameters and defaults, reading and sampling; the leaves they share:
//! `emission` (`L`, `gain`, LuxRender's power/efficacy normalisation), `sample` (the sample
//! types), `error`, `distribution` (sampling tables), `facing` (a map's tables for the side a
//! surface faces); `mirrored` (lamp images in flat mirrors), `lamp_spheres` (which lamps a cone
//! of directions may reach), `triangle_lamps` (a few plain triangle lamps sampled in lanes).
//! A new kind is one new file (its description, its reader, its [`LightKind`] impl) plus one
//! line in the kind list below, which generates the rest; a light of a new sort (not a point,
//! a spot, a direction, a map or a cone at infinity) also needs its [`Light`] member.

mod area;
mod distribution;
mod emission;
mod error;
mod facing;
mod kind;
mod lamp_spheres;
mod mirrored;
mod portals;
mod sample;
mod triangle_lamps;

#[cfg(test)]
mod tests;

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::assets::AssetSource;
use crate::diag::SourcePos;
use crate::geometry::{SceneGeometry, SurfaceHit, TriangleSurface};
use crate::math::Cone;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::shape::ShapeDesc;
use crate::texture::Textures;

pub use area::AreaLightParams;
pub use error::LightError;
pub use infinite::{map_cost, EnvMapDesc};
pub use kind::{LatLongConvention, LightKind, MapSource};
pub use mirrored::{follows_plane, ImageSample, ImageWeights, IMAGE_SHARE};
pub use portals::{PortalDesc, MAX_PORTAL_TRIANGLES};
pub use sample::{EmissionSample, Emitter, LightPoint, LightSample};
pub use sky::SkyModel;
pub use sun::sun_rgb;
pub use triangle_lamps::{LightSamples, TriangleLamps};

use area::AreaLight;
use distribution::Distribution1D;
use infinite::Environment;
use lamp_spheres::LampSpheres;
use mirrored::MirrorImages;
use portals::{Entry, Portals};
use sample::{EmittedRay, SceneSphere};
use spot::SpotCone;
use sun::SunDisc;

/// Generates the light family from its kind list (see [`lights!`]'s invocation below): each
/// kind's module and re-export, the [`LightDesc`] variant, the name table from LuxRender's
/// light types to the kind's readers, and the dispatch `match`es, each arm a call of the
/// kind's [`LightKind`] method; a kind's line ends with the [`Light`] member its sampler
/// becomes.
macro_rules! lights {
    ($($module:ident::$kind:ident as $variant:ident { $($name:literal => $read:ident),+ } => $sampler:expr,)+) => {
        $(mod $module;)+
        $(pub use $module::$kind;)+

        /// A `LightSource` statement as described: plain data with LuxRender's defaults applied.
        #[derive(Clone, Debug, PartialEq)]
        pub enum LightDesc {
            $($variant($kind),)+
        }

        impl LightDesc {
            /// The reader of LuxRender light type `ty`; None for a type this renderer does not
            /// know.
            fn reader(ty: &str) -> Option<Reader<Self>> {
                Some(match ty {
                    $($($name => |params, pos, ctx| Ok(Self::$variant($kind::$read(params, pos, ctx)?)),)+)+
                    _ => return None,
                })
            }

            /// The LuxRender type name.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$variant(l) => l.name(),)+
                }
            }

            /// Whether the light is at a point or from one direction (point, goniometric, spot,
            /// distant): no surface a path meets can hit it.
            pub fn is_delta(&self) -> bool {
                matches!(self, Self::Point(_) | Self::Spot(_) | Self::Distant(_))
            }

            /// The files the light references (as written; the scene lists them in its assets).
            pub fn files(&self) -> Vec<&str> {
                match self {
                    $(Self::$variant(l) => l.files(),)+
                }
            }

            /// The light ready to sample (see [`LightKind::light`]).
            fn light(&self, maps: &MapSource) -> Result<Option<Light>, LightError> {
                Ok(match self {
                    $(Self::$variant(l) => l.light(maps)?.map($sampler),)+
                })
            }
        }
    };
}

// The kinds: `module::Kind as Variant { "luxrender type" => reader, ... } => sampler member,`.
lights! {
    point::PointLight as Point { "point" => read, "goniometric" => read } => Light::Point,
    spot::SpotLight as Spot { "spot" => read } => Light::Spot,
    distant::DistantLight as Distant { "distant" => read } => Light::Distant,
    infinite::InfiniteLight as Infinite { "infinite" => read, "infinitesample" => read }
        => |l| Light::Infinite(AtInfinity::Map(l)),
    sun::SunLight as Sun { "sun" => read } => |l| Light::Infinite(AtInfinity::Sun(l)),
    sky::SkyLight as Sky { "sky" => read_preetham, "sky2" => read_hosek }
        => |l| Light::Infinite(AtInfinity::Sky(l)),
}

impl LightDesc {
    /// Whether the light comes from a direction (distant, or at infinity: infinite, sun, sky),
    /// the lights that have portals.
    pub fn enters_from_a_direction(&self) -> bool {
        !matches!(self, Self::Point(_) | Self::Spot(_))
    }
}

/// Reads a light of type `T` from a statement's parameters.
type Reader<T> = fn(&ParamList, &SourcePos, &mut dyn ParseContext) -> Result<T, ParseError>;

/// Reads `LightSource "ty"` through the name table: the lights it makes (`sunsky` and
/// `sunsky2` make a sun and a sky from the same parameters, as LuxRender does), none for an
/// unknown type (a warning).
pub(crate) fn read(
    ty: &str,
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Vec<LightDesc>, ParseError> {
    let sky: Reader<SkyLight> = match ty {
        "sunsky" => SkyLight::read_preetham,
        "sunsky2" => SkyLight::read_hosek,
        _ => {
            let Some(read) = LightDesc::reader(ty) else {
                params.ignore_all();
                ctx.warn(pos, format!("unknown LightSource \"{ty}\" skipped"));
                return Ok(Vec::new());
            };
            return Ok(vec![read(params, pos, ctx)?]);
        }
    };
    Ok(vec![
        LightDesc::Sun(SunLight::read(params, pos, ctx)?),
        LightDesc::Sky(sky(params, pos, ctx)?),
    ])
}

enum Light {
    Area(AreaLight),
    Point(PointLight),
    Spot(SpotCone),
    Distant(DistantLight),
    Infinite(AtInfinity),
}

/// A light at infinity: one member of the environment mixture.
enum AtInfinity {
    Map(Environment),
    /// A tabulated sky: a map whose power is weighed against the sun's.
    Sky(Environment),
    Sun(SunDisc),
}

impl AtInfinity {
    fn radiance(&self, dir: Vec3) -> Vec3 {
        match self {
            AtInfinity::Map(l) | AtInfinity::Sky(l) => l.radiance(dir),
            AtInfinity::Sun(l) => l.radiance(dir),
        }
    }

    fn pdf(&self, dir: Vec3, facing: Option<Vec3>) -> f32 {
        match self {
            AtInfinity::Map(l) | AtInfinity::Sky(l) => l.pdf(dir, facing),
            AtInfinity::Sun(l) => l.pdf(dir),
        }
    }

    fn radiance_and_pdf(&self, dir: Vec3, facing: Option<Vec3>) -> (Vec3, f32) {
        match self {
            AtInfinity::Map(l) | AtInfinity::Sky(l) => l.radiance_and_pdf(dir, facing),
            AtInfinity::Sun(l) => l.radiance_and_pdf(dir),
        }
    }

    fn sample(&self, u: Vec2, facing: Option<Vec3>) -> Option<(Vec3, f32, Vec3)> {
        match self {
            AtInfinity::Map(l) | AtInfinity::Sky(l) => l.sample(u, facing),
            AtInfinity::Sun(l) => l.sample(u),
        }
    }

    fn power(&self, scene_radius: f32) -> f32 {
        match self {
            AtInfinity::Map(l) => l.power(scene_radius),
            // The sun's power is the irradiance of a disk facing it; a disk facing a sky of
            // mean radiance L receives about pi L, pi times what a map's estimate says.
            // Weighed alike, sun and sky share light samples as they share the daylight.
            AtInfinity::Sky(l) => PI * l.power(scene_radius),
            AtInfinity::Sun(l) => l.power(scene_radius),
        }
    }
}

/// The area lights among `lights`, with their indices.
fn area_lights(lights: &[Light]) -> impl Iterator<Item = (usize, &AreaLight)> {
    lights.iter().enumerate().filter_map(|(i, l)| match l {
        Light::Area(area) => Some((i, area)),
        _ => None,
    })
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
    /// For each area light (the first of `lights`), the shape it lies on: `shape_light`'s
    /// inverse.
    light_shape: Vec<u32>,
    /// For each light after the area lights, the index of the `LightSource` it came from.
    light_source: Vec<u32>,
    /// Indices into `lights` of the infinite lights.
    infinite: Vec<u32>,
    /// The area lights' images in flat mirrors ([`mirrored`]; empty unless the scene adds them).
    images: MirrorImages,
    /// The area lights' bounding spheres, for [`Self::lamp_may_be_in`].
    lamp_spheres: LampSpheres,
    /// The lights as tables for packets, when they are a few plain triangle lamps.
    triangle_lamps: Option<TriangleLamps>,
    /// Around the geometry: what rays from distant lights and the lights at infinity enter by.
    sphere: SceneSphere,
    /// The portals light subpaths of the lights at infinity enter by, when they have any
    /// ([`portals`]; [`Self::with_portals`]).
    environment_portals: Option<Portals>,
    /// The portals of distant lights that have them, by index into `lights`.
    distant_portals: Vec<(u32, Portals)>,
    /// The probability of choosing one of the lights at infinity, the mixture they form.
    environment_pmf: f32,
    /// Each light's light group (`film::light_groups`; all 0 until [`Self::with_groups`]).
    groups: Vec<u8>,
}

impl Lights {
    /// The lights of a scene: `shapes` are its shapes in order (an area light is sampled on
    /// `geometry`'s surface of its shape, a textured one evaluates `textures`), `lights` the
    /// `LightSource`s; maps are read from `source` and indexed by `latlong`.
    pub fn build<'a>(
        shapes: impl IntoIterator<Item = &'a ShapeDesc>,
        lights: &[LightDesc],
        geometry: &SceneGeometry,
        textures: &Arc<Textures>,
        source: &dyn AssetSource,
        latlong: LatLongConvention,
    ) -> Result<Self, LightError> {
        let descs = lights;
        let mut lights = Vec::new();
        let mut shape_light = Vec::new();
        let mut light_shape = Vec::new();
        let mut groups = Vec::new();
        for (index, shape) in shapes.into_iter().enumerate() {
            shape_light.push(None);
            let Some(area_light) = &shape.area_light else {
                continue;
            };
            let Some(surface) = geometry.shape_surface(index as u32) else {
                tracing::warn!(
                    "shape \"{}\": area light ignored (an infinite plane or a degenerate shape \
                     has no surface to sample)",
                    shape.name
                );
                continue;
            };
            let Some(light) = AreaLight::new(area_light, shape.object_to_world, surface, textures)
            else {
                continue;
            };
            if light.area() > 0.0 {
                shape_light[index] = Some(lights.len() as u32);
                light_shape.push(index as u32);
                groups.push(area_light.group);
                lights.push(Light::Area(light));
            }
        }

        let maps = MapSource {
            files: source,
            latlong,
        };
        let mut light_source = Vec::new();
        for (index, desc) in descs.iter().enumerate() {
            lights.extend(desc.light(&maps)?);
            light_source.resize(lights.len() - light_shape.len(), index as u32);
        }

        let bounds = geometry.bounds();
        let scene_radius = bounds.map_or(1.0, |(lo, hi)| (0.5 * (hi - lo).length()).max(1e-3));
        let sphere = SceneSphere {
            centre: bounds.map_or(Vec3::ZERO, |(lo, hi)| 0.5 * (lo + hi)),
            radius: scene_radius,
        };
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
        let infinite: Vec<u32> = (0..lights.len() as u32)
            .filter(|&i| matches!(lights[i as usize], Light::Infinite(_)))
            .collect();
        let lamp_boxes: Vec<(Vec3, Vec3)> = area_lights(&lights).map(|(_, l)| l.bounds()).collect();
        let selection = Distribution1D::new(powers);
        let environment_pmf = infinite.iter().map(|&i| selection.pmf(i as usize)).sum();
        let lamps = lights.iter().map(|light| match light {
            Light::Area(lamp) => Some(lamp),
            _ => None,
        });
        Ok(Self {
            lamp_spheres: LampSpheres::new(&lamp_boxes),
            triangle_lamps: TriangleLamps::new(lamps, &selection),
            groups: groups
                .into_iter()
                .chain(std::iter::repeat(0))
                .take(lights.len())
                .collect(),
            lights,
            selection,
            shape_light,
            light_shape,
            light_source,
            infinite,
            images: Default::default(),
            sphere,
            environment_portals: None,
            distant_portals: Vec::new(),
            environment_pmf,
        })
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// The lights as tables a packet's lanes sample together ([`TriangleLamps::sample`] gives
    /// [`Self::sample`]'s bits), when they are a few untextured triangle lamps.
    pub fn triangle_lamps(&self) -> Option<&TriangleLamps> {
        self.triangle_lamps.as_ref()
    }

    /// Samples a light as seen from `p` (with `u_select` choosing the light and `u` the point on
    /// it). `facing` is the normal of a surface that only reflects, on the side it takes light
    /// from (see [`Bsdf::gathers_from`](crate::material::Bsdf::gathers_from)): environment
    /// maps are then sampled for that side. None when the chosen light contributes nothing
    /// from here.
    pub fn sample(
        &self,
        p: Vec3,
        facing: Option<Vec3>,
        u_select: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let (index, pmf, _) = self.selection.sample_discrete(u_select)?;
        match &self.lights[index] {
            Light::Area(light) => light.sample_chosen(p, u, pmf),
            Light::Point(light) => light.sample(p).map(|s| s.chosen(pmf)),
            Light::Spot(light) => light.sample(p).map(|s| s.chosen(pmf)),
            Light::Distant(light) => Some(light.sample().chosen(pmf)),
            Light::Infinite(light) => self.sample_environment(light, facing, u, pmf),
        }
    }

    /// A direction sampled from one of the infinite lights (chosen with probability `pmf`),
    /// with the radiance and density of the whole mixture.
    fn sample_environment(
        &self,
        light: &AtInfinity,
        facing: Option<Vec3>,
        u: Vec2,
        pmf: f32,
    ) -> Option<LightSample> {
        let (wi, pdf, li) = light.sample(u, facing)?;
        // A lone infinite light is the whole mixture: its own density and radiance
        // serve, without looking the direction up again.
        let (li, pdf) = if self.infinite.len() == 1 {
            (li, pmf * pdf)
        } else {
            self.environment_and_pdf(wi, facing)
        };
        (pdf > 0.0).then_some(LightSample {
            wi,
            li,
            pdf,
            dist: f32::INFINITY,
            delta: false,
        })
    }

    /// A light point seen from `p`, for connecting a subpath vertex there to a light: the
    /// light sample [`Self::sample`] returns for `facing` None and the same numbers (the same
    /// bits), and the point it reached on the light.
    pub fn sample_light_point(
        &self,
        p: Vec3,
        u_select: f32,
        u: Vec2,
    ) -> Option<(LightSample, LightPoint)> {
        let (index, pmf, _) = self.selection.sample_discrete(u_select)?;
        let emitter = Emitter::Light(index as u32);
        Some(match &self.lights[index] {
            Light::Area(light) => {
                let s = light.sample(p, u)?;
                let on = LightPoint::finite(emitter, p + s.wi * s.dist, Some(s.n));
                (s.chosen(pmf), on)
            }
            Light::Point(light) => (
                light.sample(p)?.chosen(pmf),
                LightPoint::finite(emitter, light.position, None),
            ),
            Light::Spot(light) => (
                light.sample(p)?.chosen(pmf),
                LightPoint::finite(emitter, light.position(), None),
            ),
            Light::Distant(light) => {
                let s = light.sample().chosen(pmf);
                (s, LightPoint::at_infinity(emitter, p, s.wi, &self.sphere))
            }
            Light::Infinite(light) => {
                let s = self.sample_environment(light, None, u, pmf)?;
                let at = LightPoint::at_infinity(Emitter::Environment, p, s.wi, &self.sphere);
                (s, at)
            }
        })
    }

    /// Samples a ray leaving one of the lights: `u_select` chooses the light (as in
    /// [`Self::sample`]), `u_pos` the point, `u_dir` the direction. None when the chosen light
    /// emits nothing that way.
    pub fn sample_emission(
        &self,
        u_select: f32,
        u_pos: Vec2,
        u_dir: Vec2,
    ) -> Option<EmissionSample> {
        let (index, pmf, _) = self.selection.sample_discrete(u_select)?;
        let ray = match &self.lights[index] {
            Light::Area(light) => light.sample_emission(u_pos, u_dir)?,
            Light::Point(light) => light.sample_emission(u_dir),
            Light::Spot(light) => light.sample_emission(u_dir)?,
            Light::Distant(light) => {
                light.sample_emission(self.entry(Emitter::Light(index as u32)), u_pos)?
            }
            Light::Infinite(light) => {
                let ray = self.sample_environment_emission(light, u_pos, u_dir)?;
                return Some(ray.chosen(Emitter::Environment, self.environment_pmf));
            }
        };
        Some(ray.chosen(Emitter::Light(index as u32), pmf))
    }

    /// A ray of the mixture at infinity whose direction member `light` sampled: the
    /// mixture's radiance, the disc's position density (the mixture's choice probability still
    /// to multiply it) and the mixture's direction density given that choice.
    fn sample_environment_emission(
        &self,
        light: &AtInfinity,
        u_pos: Vec2,
        u_dir: Vec2,
    ) -> Option<EmittedRay> {
        let (wi, _, _) = light.sample(u_dir, None)?;
        let dir = -wi;
        let (le, pdf_dir) = self.environment_emission(dir);
        if pdf_dir.is_nan() || pdf_dir <= 0.0 {
            return None;
        }
        let (origin, pdf_pos) = self.entry(Emitter::Environment).sample(dir, u_pos)?;
        Some(EmittedRay {
            origin,
            dir,
            normal: None,
            le,
            pdf_pos,
            pdf_dir,
            delta_position: false,
            delta_direction: false,
        })
    }

    /// The mixture at infinity's radiance travelling along `dir` and its density of that
    /// direction given the mixture's choice (what [`Self::pdf_environment`] says of `-dir`,
    /// over the mixture's choice probability).
    fn environment_emission(&self, dir: Vec3) -> (Vec3, f32) {
        let (le, pdf) = self.environment_and_pdf(-dir, None);
        (le, pdf / self.environment_pmf)
    }

    /// The (pdf_pos, pdf_dir) [`Self::sample_emission`] has for a ray leaving `emitter` along
    /// unit `dir` (front normal `normal` for an area light): for an area light hit by a camera
    /// path, for a light point [`Self::sample_light_point`] reached, for an escaping ray
    /// (`Emitter::Environment`, `dir` minus the escaping ray's direction). `origin` is the
    /// ray's start, which only portals' densities need (an area light's depends on its normal
    /// only, the discs' are uniform). pdf_dir is zero where sampling could not have produced the ray
    /// (behind an area light, outside a spot's cone); both are zero for an emitter that is
    /// not one, and for an area light given no normal.
    pub fn emission_pdf(
        &self,
        emitter: Emitter,
        origin: Vec3,
        normal: Option<Vec3>,
        dir: Vec3,
    ) -> (f32, f32) {
        let index = match emitter {
            Emitter::Light(index) => index as usize,
            Emitter::Environment => return self.environment_emission_pdf(origin, dir),
        };
        let (pdf_pos, pdf_dir) = match (self.lights.get(index), normal) {
            (Some(Light::Area(light)), Some(n)) => light.emission_pdf(n, dir),
            (Some(Light::Point(light)), _) => light.emission_pdf(),
            (Some(Light::Spot(light)), _) => light.emission_pdf(dir),
            (Some(Light::Distant(light)), _) => light.emission_pdf(self.entry(emitter), origin),
            (Some(Light::Infinite(_)), _) => return self.environment_emission_pdf(origin, dir),
            (Some(Light::Area(_)), None) | (None, _) => return (0.0, 0.0),
        };
        (self.selection.pmf(index) * pdf_pos, pdf_dir)
    }

    fn environment_emission_pdf(&self, origin: Vec3, dir: Vec3) -> (f32, f32) {
        if self.environment_pmf <= 0.0 {
            return (0.0, 0.0);
        }
        let pdf_pos =
            self.environment_pmf * self.entry(Emitter::Environment).pdf_start(dir, origin);
        (pdf_pos, self.environment_emission(dir).1)
    }

    /// The emitter of shape `shape`'s area light, if it has one.
    pub fn emitter_of_shape(&self, shape: u32) -> Option<Emitter> {
        self.area_light(shape)
            .map(|(index, _)| Emitter::Light(index))
    }

    /// The shape emitter `emitter` lies on, when it is an area light.
    pub fn shape_of(&self, emitter: Emitter) -> Option<u32> {
        match emitter {
            Emitter::Light(index) => self.light_shape.get(index as usize).copied(),
            Emitter::Environment => None,
        }
    }

    /// The index of the `LightSource` (among the scene description's lights) emitter
    /// `emitter` came from, when it is not an area light (the lights at infinity together are
    /// none).
    pub fn source_of(&self, emitter: Emitter) -> Option<usize> {
        match emitter {
            Emitter::Light(index) => {
                let after_area = (index as usize).checked_sub(self.light_shape.len())?;
                self.light_source.get(after_area).map(|&i| i as usize)
            }
            Emitter::Environment => None,
        }
    }

    /// The scene's bounding sphere (centre, radius): the discs rays from distant lights and the
    /// lights at infinity start on are its size.
    pub fn scene_sphere(&self) -> (Vec3, f32) {
        (self.sphere.centre, self.sphere.radius)
    }

    /// The density, per area across `dir`, with which emission from `emitter` (a distant light
    /// or the lights at infinity) travelling along `dir` passes `x`: the disc's
    /// ([`SceneSphere::pdf_reaching`]) or its portals' ([`Portals::pdf_reaching`]).
    pub fn pdf_from_infinity(&self, emitter: Emitter, dir: Vec3, x: Vec3) -> f32 {
        self.entry(emitter).pdf_reaching(dir, x)
    }

    /// What emission from `emitter`, a distant light or the lights at infinity, enters the
    /// scene by: its portals, or the disc of the scene's sphere.
    fn entry(&self, emitter: Emitter) -> Entry<'_> {
        let portals = match emitter {
            Emitter::Environment => self.environment_portals.as_ref(),
            Emitter::Light(index) => self
                .distant_portals
                .iter()
                .find(|(light, _)| *light == index)
                .map(|(_, portals)| portals),
        };
        match portals {
            Some(portals) => Entry::Portals(portals, &self.sphere),
            None => Entry::Disc(&self.sphere),
        }
    }

    /// The lights with the scene's portals: each portal lets in the lights of the
    /// `LightSource` it follows (`portals`' light indices are into the scene description's
    /// lights) where they are distant or at infinity (the lights at infinity share their
    /// portals, being one mixture); point and spot lights have none, as in LuxRender.
    pub fn with_portals(mut self, portals: &[PortalDesc]) -> Self {
        let area_lights = self.light_shape.len();
        let mut environment = Vec::new();
        let mut distant: Vec<(u32, Vec<TriangleSurface>)> = Vec::new();
        for portal in portals {
            let triangles = portal.triangles();
            for (after_area, &source) in self.light_source.iter().enumerate() {
                if !portal.lights.contains(&source) {
                    continue;
                }
                let index = (area_lights + after_area) as u32;
                match &self.lights[index as usize] {
                    Light::Infinite(_) => environment.extend_from_slice(&triangles),
                    Light::Distant(_) => match distant.iter_mut().find(|(l, _)| *l == index) {
                        Some((_, tris)) => tris.extend_from_slice(&triangles),
                        None => distant.push((index, triangles.clone())),
                    },
                    _ => {}
                }
            }
        }
        self.environment_portals = Portals::new(environment);
        self.distant_portals = distant
            .into_iter()
            .filter_map(|(index, tris)| Some((index, Portals::new(tris)?)))
            .collect();
        self
    }

    /// The lights with their light groups: `of_sources[i]` is the group of the scene
    /// description's `LightSource` `i` (area lights have theirs from their shapes).
    pub fn with_groups(mut self, of_sources: &[u8]) -> Self {
        let area_lights = self.light_shape.len();
        for (after_area, &source) in self.light_source.iter().enumerate() {
            self.groups[area_lights + after_area] =
                of_sources.get(source as usize).copied().unwrap_or(0);
        }
        self
    }

    /// The light group of `emitter`: of its light, or, for the lights at infinity, of them all
    /// when they are in one group (None when they are in several: [`Self::environment_by_group`]
    /// splits their light).
    pub fn light_group(&self, emitter: Emitter) -> Option<u8> {
        match emitter {
            Emitter::Light(index) => self.groups.get(index as usize).copied(),
            Emitter::Environment => {
                let mut groups = self.infinite.iter().map(|&i| self.groups[i as usize]);
                let first = groups.next().unwrap_or(0);
                groups.all(|g| g == first).then_some(first)
            }
        }
    }

    /// Each light at infinity's group and radiance along an escaping ray's direction `dir`.
    pub fn environment_by_group(&self, dir: Vec3, mut add: impl FnMut(u8, Vec3)) {
        for (index, light) in self.infinite_lights() {
            add(self.groups[index], light.radiance(dir));
        }
    }

    /// The emitter [`Self::sample`] chooses with `u_select` (the lights at infinity as one).
    pub fn chosen_emitter(&self, u_select: f32) -> Option<Emitter> {
        let (index, _, _) = self.selection.sample_discrete(u_select)?;
        Some(match self.lights[index] {
            Light::Infinite(_) => Emitter::Environment,
            _ => Emitter::Light(index as u32),
        })
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
            Some((_, light)) if hit.ng.dot(wo) > 0.0 => light.radiance_at(hit.p, hit.uv),
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

    /// Solid-angle density with which `sample` (for a surface facing `facing`) would have
    /// chosen direction `dir` on the infinite lights.
    pub fn pdf_environment(&self, dir: Vec3, facing: Option<Vec3>) -> f32 {
        self.infinite_lights()
            .map(|(index, light)| self.selection.pmf(index) * light.pdf(dir, facing))
            .sum()
    }

    /// [`Self::environment`] and [`Self::pdf_environment`] together, for an escaping ray that
    /// needs its MIS weight.
    pub fn environment_and_pdf(&self, dir: Vec3, facing: Option<Vec3>) -> (Vec3, f32) {
        self.infinite_lights()
            .map(|(index, light)| {
                let (radiance, pdf) = light.radiance_and_pdf(dir, facing);
                (radiance, self.selection.pmf(index) * pdf)
            })
            .fold((Vec3::ZERO, 0.0), |(r, p), (ri, pi)| (r + ri, p + pi))
    }

    /// Adds the lamp images of the flat mirrors among `mirror_shapes` (shapes whose material is
    /// a plain `mirror`; the `mirrored` module says which take part).
    pub fn with_mirror_images(mut self, mirror_shapes: &[u32], geometry: &SceneGeometry) -> Self {
        let lamps: Vec<(u32, &AreaLight, f32)> = area_lights(&self.lights)
            .map(|(i, area)| (i as u32, area, self.selection.pmf(i)))
            .collect();
        self.images = MirrorImages::new(mirror_shapes, geometry, &lamps);
        self
    }

    /// Whether an area light may lie in `cone` seen from `p` (true may be wrong, false is not).
    pub fn lamp_may_be_in(&self, p: Vec3, cone: &Cone) -> bool {
        self.lamp_spheres.may_reach(p, cone)
    }

    /// Whether a ray from `p` along `dir` may reach an area light (false is never wrong).
    pub fn lamp_may_be_along(&self, p: Vec3, dir: Vec3) -> bool {
        self.lamp_spheres.may_reach_along(p, dir)
    }

    /// Whether the scene has lamp images (most have none).
    #[inline]
    pub fn has_mirror_images(&self) -> bool {
        !self.images.is_empty()
    }

    /// The lamp images a shading point `p` sees, weighted; None where it sees none (its light
    /// samples then all go to the lights, else [`IMAGE_SHARE`] of them to these).
    pub fn image_weights(&self, p: Vec3) -> Option<ImageWeights> {
        self.images.seen_from(p)
    }

    /// Samples a lamp image seen from the point `seen` was weighed at: `u_select` chooses the
    /// image, `u` the point on the lamp. None when the chosen image shows nothing from there.
    pub fn sample_image(&self, seen: &ImageWeights, u_select: f32, u: Vec2) -> Option<ImageSample> {
        self.images.sample(seen, u_select, u, |index| {
            match self.lights.get(index as usize) {
                Some(Light::Area(light)) => Some(light),
                _ => None,
            }
        })
    }

    /// Solid-angle density with which [`Self::sample_image`] from `p` would have chosen the
    /// emitter point `hit` through mirror plane `plane` (for MIS when a BSDF-sampled ray reaches
    /// a lamp after that mirror; not including [`IMAGE_SHARE`]).
    pub fn image_pdf(&self, p: Vec3, plane: u16, hit: &SurfaceHit) -> f32 {
        self.area_light(hit.shape)
            .map_or(0.0, |lamp| self.images.pdf(p, plane, lamp, hit))
    }

    /// The mirror plane a hit lies in, when it is on a flat mirror that takes part.
    pub fn mirror_plane(&self, hit: &SurfaceHit) -> Option<u16> {
        self.images.mirror_plane(hit)
    }

    /// The plane reflection of direction `v` in mirror plane `plane`.
    pub fn reflect_in_plane(&self, plane: u16, v: Vec3) -> Vec3 {
        self.images.reflect(plane, v)
    }

    fn infinite_lights(&self) -> impl Iterator<Item = (usize, &AtInfinity)> {
        self.infinite
            .iter()
            .filter_map(|&i| match &self.lights[i as usize] {
                Light::Infinite(light) => Some((i as usize, light)),
                _ => None,
            })
    }
}
