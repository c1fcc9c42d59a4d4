//! The render API every node uses: settings, the unit plan, the built scene and rendering one
//! unit into a sample buffer.

use glam::{Vec2, Vec3};

use crate::assets::AssetSource;
use crate::camera::Camera;
use crate::desc::{LatLongConvention, SceneDesc};
use crate::film::SampleBuffer;
use crate::filter::FilterSampler;
use crate::geometry::{SceneGeometry, SurfaceHit};
use crate::integrator::trace_path;
use crate::lights::Lights;
use crate::material::{Bsdf, Materials};
use crate::sampler::PixelSampler;
use crate::texture::Textures;

/// Everything besides the scene that decides the image. Identical settings and scene give
/// bit-identical images whatever renders them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u64,
    pub latlong: LatLongConvention,
}

/// Command-line overrides of what the scene file says.
#[derive(Clone, Debug, Default)]
pub struct RenderOverrides {
    pub spp: Option<u32>,
    pub max_depth: Option<u32>,
    pub seed: Option<u64>,
    pub resolution: Option<(u32, u32)>,
    pub latlong: LatLongConvention,
}

/// Samples per pixel when neither the file nor the command line says.
pub const DEFAULT_SPP: u32 = 64;

impl RenderSettings {
    pub fn resolve(desc: &SceneDesc, overrides: &RenderOverrides) -> Self {
        let (width, height) = overrides
            .resolution
            .unwrap_or((desc.film.xresolution, desc.film.yresolution));
        let spp = overrides
            .spp
            .or(desc.film.haltspp)
            .or(desc.sampler.pixel_samples)
            .unwrap_or(DEFAULT_SPP)
            .max(1);
        Self {
            width: width.max(1),
            height: height.max(1),
            spp,
            max_depth: overrides.max_depth.unwrap_or(desc.integrator.max_depth),
            seed: overrides.seed.unwrap_or(0),
            latlong: overrides.latlong,
        }
    }
}

/// A tile of pixels x a range of sample indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WorkUnit {
    /// Position in the plan; results are keyed by it.
    pub index: u32,
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    pub sample_start: u32,
    pub sample_end: u32,
}

impl WorkUnit {
    pub fn pixel_count(&self) -> usize {
        ((self.x1 - self.x0) * (self.y1 - self.y0)) as usize
    }

    pub fn sample_count(&self) -> u64 {
        self.pixel_count() as u64 * u64::from(self.sample_end - self.sample_start)
    }
}

/// Counters a unit's render reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UnitStats {
    pub samples: u64,
    pub rays: u64,
    /// NaN or infinite samples dropped instead of entering the film.
    pub dropped: u64,
}

impl std::ops::AddAssign for UnitStats {
    fn add_assign(&mut self, o: Self) {
        self.samples += o.samples;
        self.rays += o.rays;
        self.dropped += o.dropped;
    }
}

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error(transparent)]
    Texture(#[from] crate::texture::TextureError),
    #[error(transparent)]
    Light(#[from] crate::lights::LightError),
}

/// Tiles of this many pixels on a side.
pub const TILE_SIZE: u32 = 64;

/// Sample ranges per tile: enough passes for useful previews and balancing, few enough that a
/// unit's work dwarfs its network round trip.
pub const PASSES: u32 = 8;

/// The unit plan: tiles of `TILE_SIZE` in scanline order, and `PASSES` sample ranges, ordered
/// by sample range first so that any prefix of the plan covers the whole image. It depends on
/// the settings only: a pixel's sum is added up unit by unit, so the same plan everywhere is
/// what makes in-process and distributed images bit-identical.
pub fn plan_units(settings: &RenderSettings) -> Vec<WorkUnit> {
    let samples_per_unit = settings.spp.div_ceil(PASSES).max(1);
    let mut units = Vec::new();
    let mut start = 0;
    while start < settings.spp {
        let end = (start + samples_per_unit).min(settings.spp);
        for y0 in (0..settings.height).step_by(TILE_SIZE as usize) {
            for x0 in (0..settings.width).step_by(TILE_SIZE as usize) {
                units.push(WorkUnit {
                    index: units.len() as u32,
                    x0,
                    y0,
                    x1: (x0 + TILE_SIZE).min(settings.width),
                    y1: (y0 + TILE_SIZE).min(settings.height),
                    sample_start: start,
                    sample_end: end,
                });
            }
        }
        start = end;
    }
    units
}

/// The scene ready to render: world-space geometry and BVH, textures, materials, lights.
pub struct RenderScene {
    desc: SceneDesc,
    settings: RenderSettings,
    camera: Camera,
    filter: FilterSampler,
    geometry: SceneGeometry,
    textures: Textures,
    materials: Materials,
    lights: Lights,
    /// Per shape, for the object-space positions 3D texture mappings use.
    world_to_object: Vec<glam::Affine3A>,
}

impl RenderScene {
    pub fn build(
        desc: &SceneDesc,
        source: &dyn AssetSource,
        settings: &RenderSettings,
    ) -> Result<Self, BuildError> {
        let geometry = SceneGeometry::build(desc);
        let shapes = desc.shapes.iter();
        let area_lights = shapes.map(|s| (s.name.as_str(), s.area_light.as_ref()));
        let lights = Lights::build(
            area_lights,
            &desc.lights,
            &geometry,
            source,
            settings.latlong,
        )?;
        Ok(Self {
            camera: Camera::new(&desc.camera, settings.width, settings.height),
            filter: FilterSampler::new(&desc.filter),
            textures: Textures::build(desc, source)?,
            materials: Materials::build(desc),
            geometry,
            lights,
            world_to_object: desc
                .shapes
                .iter()
                .map(|s| glam::Affine3A::from_mat4(s.object_to_world).inverse())
                .collect(),
            desc: desc.clone(),
            settings: settings.clone(),
        })
    }

    pub fn desc(&self) -> &SceneDesc {
        &self.desc
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    pub fn geometry(&self) -> &SceneGeometry {
        &self.geometry
    }

    pub fn lights(&self) -> &Lights {
        &self.lights
    }

    pub fn triangle_count(&self) -> usize {
        self.geometry.triangle_count()
    }

    /// The BSDF at a hit; `u_mix` resolves mix materials.
    pub fn bsdf_at(&self, hit: &SurfaceHit, u_mix: f32) -> Bsdf {
        let shape = hit.shape as usize;
        let p_object = self.world_to_object[shape].transform_point3(hit.p);
        self.materials.bsdf(
            self.desc.shapes[shape].material,
            hit,
            p_object,
            &self.textures,
            u_mix,
        )
    }

    /// Renders one unit on the calling thread. Deterministic: the same unit gives the same
    /// buffer bytes on any machine and thread.
    pub fn render_unit(&self, unit: &WorkUnit) -> (SampleBuffer, UnitStats) {
        let mut buffer = SampleBuffer::new(*unit);
        let mut stats = UnitStats::default();
        let tile_width = unit.x1 - unit.x0;
        for y in unit.y0..unit.y1 {
            for x in unit.x0..unit.x1 {
                let i = ((y - unit.y0) * tile_width + (x - unit.x0)) as usize;
                let mut rgb = Vec3::ZERO;
                let mut weight = 0.0f32;
                for index in unit.sample_start..unit.sample_end {
                    let mut sampler =
                        PixelSampler::new(x, y, index, self.settings.spp, self.settings.seed);
                    let (offset, w) = self.filter.sample(sampler.get_2d());
                    let lens = sampler.get_2d();
                    let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + offset;
                    stats.samples += 1;
                    let Some(ray) = self.camera.generate_ray(film, lens) else {
                        weight += w;
                        continue;
                    };
                    let path = trace_path(self, ray, &mut sampler);
                    stats.rays += u64::from(path.rays);
                    if path.radiance.is_finite() {
                        rgb += path.radiance * w;
                        weight += w;
                    } else {
                        stats.dropped += 1;
                    }
                }
                buffer.rgb[i] = rgb.to_array();
                buffer.weight[i] = weight;
            }
        }
        (buffer, stats)
    }
}
