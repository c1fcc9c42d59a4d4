//! The scene ready to render (world-space geometry and BVH, decoded textures, materials,
//! light sampling tables) and rendering one unit into a sample buffer.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::{Vec2, Vec3};

use crate::assets::AssetSource;
use crate::budget::{BudgetMeter, BuildGuard, Cancelled, Limit, OverBudget};
use crate::camera::Camera;
use crate::desc::{MaterialDesc, SceneDesc};
use crate::film::{unit_sum, SampleBuffer};
use crate::filter::FilterSampler;
use crate::geometry::{SceneGeometry, SurfaceHit};
use crate::integrator::options::IntegratorDesc;
use crate::integrator::path::{trace_path, PathScene};
use crate::lights::Lights;
use crate::material::{Bsdf, Materials};
use crate::medium::{ShapeMedia, Volumes};
use crate::sampler::PixelSampler;
use crate::texture::Textures;

use super::settings::RenderSettings;
use super::unit::{UnitStats, WorkUnit};

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error(transparent)]
    Texture(#[from] crate::texture::TextureError),
    #[error(transparent)]
    Light(#[from] crate::lights::LightError),
    #[error(transparent)]
    OverBudget(#[from] OverBudget),
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// Samples rendered between two looks at a unit's cancel flag.
pub const CANCEL_CHECK_SAMPLES: usize = 4096;

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
    /// Builds the scene under the default budget.
    pub fn build(
        desc: &SceneDesc,
        source: &dyn AssetSource,
        settings: &RenderSettings,
    ) -> Result<Self, BuildError> {
        Self::build_guarded(desc, source, settings, BuildGuard::default())
    }

    /// Builds the scene under `guard`: the primitives are counted against the budget before
    /// anything is allocated for them (a description that came from the parser was counted
    /// there already, statement by statement), and the cancel flag is checked between the
    /// stages. Images are decoded under the `image` crate's allocation limit.
    pub fn build_guarded(
        desc: &SceneDesc,
        source: &dyn AssetSource,
        settings: &RenderSettings,
        guard: BuildGuard,
    ) -> Result<Self, BuildError> {
        let primitives = desc.shapes.iter().map(|s| s.geometry.primitive_count());
        BudgetMeter::default().spend(guard.budget, Limit::Primitives, primitives.sum())?;
        guard.check_cancel()?;
        let geometry = SceneGeometry::build(&desc.shapes);
        guard.check_cancel()?;
        let shapes = desc.shapes.iter();
        let area_lights = shapes.map(|s| (s.name.as_str(), s.area_light.as_ref()));
        let lights = Lights::build(
            area_lights,
            &desc.lights,
            &geometry,
            source,
            settings.latlong,
        )?;
        guard.check_cancel()?;
        let textures = Textures::new(&desc.textures, source)?;
        guard.check_cancel()?;
        Ok(Self {
            camera: Camera::new(&desc.camera, settings.width, settings.height),
            filter: FilterSampler::new(&desc.filter),
            textures,
            materials: Materials::new(desc.materials.clone()),
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
        self.materials.bsdf(
            self.desc.shapes[shape].material,
            hit,
            &self.world_to_object[shape],
            &self.textures,
            u_mix,
        )
    }

    /// Renders one unit on the calling thread. Deterministic: the same unit gives the same
    /// buffer bytes on any machine and thread. An adaptive unit renders only the pixels of its
    /// active blocks (the others stay zero) and sums its odd-index samples apart as well.
    pub fn render_unit(&self, unit: &WorkUnit) -> (SampleBuffer, UnitStats) {
        self.render_unit_cancellable(unit, &AtomicBool::new(false))
            .expect("never cancelled")
    }

    /// [`Self::render_unit`], giving up (`None`) soon after `cancel` is set: it is checked
    /// before every pixel and every [`CANCEL_CHECK_SAMPLES`] samples of a pixel, so a unit
    /// stops within a few thousand paths' time. (Checked before every sample it cost 5% of the
    /// render speed.)
    /// A render server sets it when the unit's caller is gone.
    pub fn render_unit_cancellable(
        &self,
        unit: &WorkUnit,
        cancel: &AtomicBool,
    ) -> Option<(SampleBuffer, UnitStats)> {
        let mut buffer = SampleBuffer::new(*unit);
        let mut stats = UnitStats::default();
        let tile_width = unit.x1 - unit.x0;
        let keep_half = unit.mask.is_some();
        for y in unit.y0..unit.y1 {
            for x in unit.x0..unit.x1 {
                if !unit.renders(x, y) {
                    continue;
                }
                let i = ((y - unit.y0) * tile_width + (x - unit.x0)) as usize;
                // [all samples, odd-index samples]: the second only for adaptive units.
                let mut rgb = [Vec3::ZERO; 2];
                let mut weight = [0.0f32; 2];
                for chunk in (unit.sample_start..unit.sample_end).step_by(CANCEL_CHECK_SAMPLES) {
                    if cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    let chunk_end = chunk.saturating_add(CANCEL_CHECK_SAMPLES as u32);
                    for index in chunk..chunk_end.min(unit.sample_end) {
                        let mut sampler =
                            PixelSampler::new(x, y, index, self.settings.spp, self.settings.seed);
                        let (offset, w) = self.filter.sample(sampler.get_2d());
                        let lens = sampler.get_2d();
                        let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + offset;
                        stats.samples += 1;
                        let parts = if keep_half && index % 2 == 1 { 2 } else { 1 };
                        let Some(ray) = self.camera.generate_ray(film, lens) else {
                            weight[..parts].iter_mut().for_each(|s| *s += w);
                            continue;
                        };
                        let path = trace_path(self, ray, &mut sampler);
                        stats.rays += u64::from(path.rays);
                        if path.radiance.is_finite() {
                            rgb[..parts]
                                .iter_mut()
                                .for_each(|s| *s += path.radiance * w);
                            weight[..parts].iter_mut().for_each(|s| *s += w);
                        } else {
                            stats.dropped += 1;
                        }
                    }
                }
                buffer.rgb[i] = unit_sum(rgb[0]);
                buffer.weight[i] = weight[0];
                if keep_half {
                    buffer.half_rgb[i] = unit_sum(rgb[1]);
                    buffer.half_weight[i] = weight[1];
                }
            }
        }
        Some((buffer, stats))
    }
}

impl PathScene for RenderScene {
    fn integrator(&self) -> &IntegratorDesc {
        &self.desc.integrator
    }

    fn max_depth(&self) -> u32 {
        self.settings.max_depth
    }

    fn geometry(&self) -> &SceneGeometry {
        &self.geometry
    }

    fn lights(&self) -> &Lights {
        &self.lights
    }

    fn bsdf_at(&self, hit: &SurfaceHit, u_mix: f32) -> Bsdf {
        RenderScene::bsdf_at(self, hit, u_mix)
    }

    fn volumes(&self) -> &Volumes {
        &self.desc.volumes
    }

    fn shape_media(&self, shape: u32) -> ShapeMedia {
        self.desc
            .shapes
            .get(shape as usize)
            .map_or_else(ShapeMedia::default, |s| s.media)
    }

    fn is_pass_through(&self, shape: u32) -> bool {
        let material = self.desc.shapes.get(shape as usize).map(|s| s.material);
        matches!(
            material.and_then(|m| self.desc.materials.get(m.0 as usize)),
            Some(MaterialDesc::Null(_))
        )
    }
}
