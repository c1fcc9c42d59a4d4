//! The scene ready to render (world-space geometry and BVH, decoded textures, materials,
//! light sampling tables) and rendering one unit into a sample buffer.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use glam::{Vec2, Vec3, Vec4};

use crate::assets::AssetSource;
use crate::budget::{BuildGuard, Cancelled, Limit, OverBudget};
use crate::camera::Camera;
use crate::desc::{Geometry, MaterialDesc, SceneDesc};
use crate::film::{unit_sum, SampleBuffer, SplatSums};
use crate::filter::{FilmMass, PixelFilter};
use crate::geometry::{placed_bytes, SceneGeometry, SurfaceHit};
use crate::integrator::bdpt::{trace_bidirectional, BidirectionalScene, LightSplat, Subpaths};
use crate::integrator::options::{IntegratorDesc, Transport};
use crate::integrator::packet;
use crate::integrator::{
    trace_path, trace_path_by_group, Crossing, GroupRadiance, PathResult, PathScene, MAX_BRANCHES,
    MAX_PASS_THROUGH,
};
#[cfg(target_arch = "x86_64")]
use crate::lanes::Avx2Cpu;
use crate::lanes::{Lanes, OnLanes};
use crate::lights::Lights;
use crate::material::{Bsdf, Materials};
use crate::math::Ray;
use crate::medium::{ShapeMedia, Volumes};
use crate::refs::MaterialId;
use crate::sampler::{PacketSampler, PixelSampler};
use crate::texture::Textures;

use super::branching::{self, PilotScene};
use super::layers::LayerSample;
use super::outliers::OutlierFilter;
use super::settings::RenderSettings;
use super::unit::{FilmFrame, UnitStats, WorkUnit};

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

/// Checks `desc` against `guard`'s budget. A description the parser made was counted there,
/// statement by statement (`desc.spent`), and is checked again against this budget; what the
/// count misses of its shapes (all of them, for a description made otherwise) is counted here.
fn check_budget(desc: &SceneDesc, guard: BuildGuard) -> Result<(), OverBudget> {
    let mut meter = desc.spent.clone();
    let shapes = || desc.shapes.iter().map(|s| &s.geometry);
    let primitives: u64 = shapes().map(Geometry::primitive_count).sum();
    let placed: u64 = shapes().map(placed_bytes).sum();
    for (limit, amount) in [
        (Limit::Primitives, primitives),
        (Limit::MemoryBytes, placed),
    ] {
        let counted = meter.spent(limit);
        meter.spend(guard.budget, limit, amount.saturating_sub(counted))?;
    }
    Ok(())
}

/// Samples rendered between two looks at a unit's cancel flag.
pub const CANCEL_CHECK_SAMPLES: usize = 4096;

/// The scene ready to render: world-space geometry and BVH, textures, materials, lights.
pub struct RenderScene {
    desc: SceneDesc,
    settings: RenderSettings,
    camera: Camera,
    filter: PixelFilter,
    /// Each pixel's filter mass in the film, for light splats: a bidirectional render's only.
    film_mass: Option<FilmMass>,
    /// The one bidirectional strategy rendered ([`Self::with_only_strategy`]); None: all.
    only_strategy: Option<(usize, usize)>,
    frame: FilmFrame,
    geometry: SceneGeometry,
    /// Shared with the area lights whose colour is a texture.
    textures: Arc<Textures>,
    materials: Materials,
    lights: Lights,
    /// Per shape, for the object-space positions 3D texture mappings use.
    world_to_object: Vec<glam::Affine3A>,
    /// Per shape, see [`PathScene::crossing`].
    crossings: Vec<Crossing>,
    /// See [`PathScene::has_panes`].
    has_panes: bool,
    /// See [`PathScene::glossy_split`].
    glossy_split: bool,
    /// See [`PathScene::first_vertex_branches`]: chosen by [`branching::choose`].
    first_vertex_branches: usize,
    /// Whether camera paths are traced in packets where the CPU has the lanes
    /// ([`packet::covers`]).
    packets: bool,
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

    /// Builds the scene under `guard`: the primitives and their memory are counted against the
    /// budget before anything is allocated for them, and the cancel flag is checked between
    /// the stages. Images are decoded under the `image` crate's allocation limit.
    pub fn build_guarded(
        desc: &SceneDesc,
        source: &dyn AssetSource,
        settings: &RenderSettings,
        guard: BuildGuard,
    ) -> Result<Self, BuildError> {
        check_budget(desc, guard)?;
        guard.check_cancel()?;
        let mut geometry = SceneGeometry::build(&desc.shapes);
        let crossings: Vec<Crossing> = desc
            .shapes
            .iter()
            .map(|s| crossing(desc, s.material))
            .collect();
        geometry.cross_in_occlusion(crossings.iter().map(|&c| c == Crossing::Null).collect());
        guard.check_cancel()?;
        let textures = Arc::new(Textures::new(&desc.textures, source)?);
        guard.check_cancel()?;
        let lights = Lights::build(
            &desc.shapes,
            &desc.lights,
            &geometry,
            &textures,
            source,
            settings.latlong,
        )?
        .with_portals(&desc.portals)
        .with_mirror_images(&flat_mirrors(desc, settings), &geometry)
        .with_groups(&desc.film.light_groups.of_sources);
        guard.check_cancel()?;
        let mut camera = Camera::new(&desc.camera, settings.width, settings.height);
        if desc.camera.autofocus {
            let filter_radius = Vec2::new(desc.filter.xwidth, desc.filter.ywidth);
            let first_hit = |ray: &Ray| geometry.closest(ray, f32::INFINITY).map(|hit| hit.t);
            match camera.autofocus(filter_radius, first_hit) {
                Some(distance) => tracing::info!("autofocus: focal distance {distance}"),
                None => tracing::warn!(
                    "autofocus: the ray through the screen centre hits nothing; focal \
                     distance {} kept",
                    camera.focal_distance()
                ),
            }
        }
        let mut scene = Self {
            camera,
            filter: PixelFilter::new(&desc.filter),
            film_mass: settings
                .renders_bidirectional(desc)
                .then(|| PixelFilter::new(&desc.filter).film_mass(settings.width, settings.height)),
            frame: settings.film_frame(desc),
            textures,
            materials: Materials::new(desc.materials.clone()),
            geometry,
            lights,
            world_to_object: desc
                .shapes
                .iter()
                .map(|s| crate::math::affine_inverse(&glam::Affine3A::from_mat4(s.object_to_world)))
                .collect(),
            has_panes: crossings.contains(&Crossing::Pane),
            crossings,
            glossy_split: glossy_split(desc),
            first_vertex_branches: 1,
            only_strategy: None,
            packets: false,
            desc: desc.clone(),
            settings: settings.clone(),
        };
        // A render that keeps its light groups apart traces each camera path as one path
        // (`trace_path_by_group`): no branches, and no packets, whose lanes add no groups.
        if scene.frame.layers.light_groups == 0 {
            let branches = branching::choose(&scene);
            scene.first_vertex_branches = branches;
            scene.packets = packet::covers(&scene);
        }
        Ok(scene)
    }

    /// The continuations camera paths take at their first broad vertex.
    pub fn first_vertex_branches(&self) -> usize {
        self.first_vertex_branches
    }

    /// The scene rendering bidirectional strategy (`s` light vertices, `t` camera vertices)
    /// alone, at full weight: what the tests compare each strategy's image with.
    pub fn with_only_strategy(mut self, s: usize, t: usize) -> Self {
        self.only_strategy = Some((s, t));
        self
    }

    /// The scene with `branches` continuations (clamped to 1 ..= [`MAX_BRANCHES`]) in place of
    /// the pilot's choice: what the tests compare counts with.
    pub fn with_first_vertex_branches(mut self, branches: usize) -> Self {
        self.first_vertex_branches = branches.clamp(1, MAX_BRANCHES);
        self
    }

    /// [`PilotScene::camera_ray`] and the sample's position within its pixel.
    #[inline(always)]
    fn camera_sample(&self, x: u32, y: u32, sampler: &mut PixelSampler) -> (Vec2, Option<Ray>) {
        let (u, lens) = sampler.get_camera();
        let film = Vec2::new(x as f32 + u.x, y as f32 + u.y);
        (u, self.camera.generate_ray(film, lens))
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

    /// The film's size and the border of every unit's buffer: what a film merging this
    /// scene's units is made with.
    pub fn frame(&self) -> FilmFrame {
        self.frame
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
    /// buffer bytes on any machine and thread (one thread sums a unit, pixel by pixel and
    /// sample by sample in a fixed order). Its samples lie uniformly in its tile's pixels and
    /// are splatted through the pixel filter into the tile and the border around it
    /// ([`FilmFrame::region`]). An adaptive unit takes samples only in the pixels of its active
    /// blocks (they still splat into their neighbours, active or not) and sums its odd-index
    /// samples apart as well.
    ///
    /// Where an adaptive render's sample density changes (at the edge of a block that goes on
    /// beside one that stopped), a pixel's samples are no longer spread evenly under its filter:
    /// the denser side weighs more in its mean. The pixel is still a weighted mean of radiance
    /// near it, only with a slightly lopsided filter, a bias of the order of the radiance's
    /// change across the filter's width in those edge pixels, and none in flat regions (which
    /// are what stops early).
    pub fn render_unit(&self, unit: &WorkUnit) -> (SampleBuffer, UnitStats) {
        self.render_unit_cancellable(unit, &AtomicBool::new(false))
            .expect("never cancelled")
    }

    /// [`Self::render_unit`], giving up (`None`) soon after `cancel` is set: it is checked
    /// before every pixel and every [`CANCEL_CHECK_SAMPLES`] samples of a pixel, so a unit
    /// stops within a few thousand paths' time (checked before every sample, it costs
    /// measurable speed: bench/RESULTS.md, "The integrator's inlining"). A render server sets
    /// it when the unit's caller is gone.
    pub fn render_unit_cancellable(
        &self,
        unit: &WorkUnit,
        cancel: &AtomicBool,
    ) -> Option<(SampleBuffer, UnitStats)> {
        if self.bidirectional() {
            return self.render_unit_bidirectional(unit, cancel);
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(cpu) = Avx2Cpu::detect().filter(|_| self.packets) {
            return cpu.run(&UnitOnLanes {
                scene: self,
                unit,
                cancel,
            });
        }
        self.render_unit_in::<f32>(unit, cancel)
    }

    /// [`Self::render_unit_cancellable`] with the camera paths of `L::N` consecutive samples
    /// of a pixel traced as a packet ([`packet::trace_packet`]) where they fit (one at a time
    /// for `f32`, and for the samples left over): the same bits either way.
    #[inline(always)]
    pub(crate) fn render_unit_in<L: Lanes>(
        &self,
        unit: &WorkUnit,
        cancel: &AtomicBool,
    ) -> Option<(SampleBuffer, UnitStats)> {
        let mut sums = UnitSums::new(SampleBuffer::new(*unit, &self.frame), self.outliers(unit));
        let mut stats = UnitStats::default();
        let adaptive = unit.mask.is_some();
        let grouped = self.frame.layers.light_groups > 0;
        let seed = self.settings.seed;
        for y in unit.y0..unit.y1 {
            for x in unit.x0..unit.x1 {
                if !unit.renders(x, y) {
                    continue;
                }
                for chunk in (unit.sample_start..unit.sample_end).step_by(CANCEL_CHECK_SAMPLES) {
                    if cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    let chunk_end = chunk
                        .saturating_add(CANCEL_CHECK_SAMPLES as u32)
                        .min(unit.sample_end);
                    let mut index = chunk;
                    while index < chunk_end {
                        // A packet's lanes share their sampler's permutation range: an adaptive
                        // pixel's nested blocks hold whole packets.
                        let fits = L::N > 1
                            && self.packets
                            && index as usize + L::N <= chunk_end as usize
                            && (!adaptive || (index as usize).is_multiple_of(L::N));
                        if !fits {
                            let mut sampler = self.sample_stream(unit, (x, y, index));
                            let (u, ray) = self.camera_sample(x, y, &mut sampler);
                            // A sample without a camera ray (outside a fisheye's circle) is black
                            // and sees nothing.
                            let escaped = PathResult {
                                escaped: true,
                                ..PathResult::default()
                            };
                            let (path, groups) = match ray {
                                None => (escaped, None),
                                Some(ray) if grouped => {
                                    let (path, groups) =
                                        trace_path_by_group(self, ray, &mut sampler);
                                    (path, Some(groups))
                                }
                                Some(ray) => (trace_path(self, ray, &mut sampler), None),
                            };
                            self.add_sample(
                                &mut sums,
                                &mut stats,
                                (x, y, index),
                                u,
                                (path, groups),
                            );
                            index += 1;
                            continue;
                        }
                        let mut sampler = if adaptive {
                            PacketSampler::<L>::nested(x, y, index, seed)
                        } else {
                            PacketSampler::<L>::new(x, y, index, self.settings.spp, seed)
                        };
                        let (film, lens) = sampler.get_camera();
                        let at = [L::splat(x as f32) + film[0], L::splat(y as f32) + film[1]];
                        let rays = self.camera.packet_rays(at, lens);
                        let paths = packet::trace_packet(self, &rays, &mut sampler);
                        let film = [film[0].values(), film[1].values()];
                        for i in 0..L::N {
                            let (sample, u) =
                                ((x, y, index + i as u32), Vec2::new(film[0][i], film[1][i]));
                            self.add_sample(&mut sums, &mut stats, sample, u, (paths[i], None));
                        }
                        index += L::N as u32;
                    }
                }
            }
        }
        Some((sums.into_buffer(), stats))
    }

    /// Whether units render with bidirectional path tracing
    /// ([`RenderSettings::renders_bidirectional`]): their buffers then carry light splats.
    pub fn bidirectional(&self) -> bool {
        self.frame.light_splats
    }

    /// [`Self::render_unit_cancellable`] with bidirectional path tracing, one sample at a
    /// time: each sample's camera path into the unit's sums, its light subpath's splats into
    /// the unit's light splats, wherever on the film they land.
    fn render_unit_bidirectional(
        &self,
        unit: &WorkUnit,
        cancel: &AtomicBool,
    ) -> Option<(SampleBuffer, UnitStats)> {
        let mut sums = UnitSums::new(SampleBuffer::new(*unit, &self.frame), self.outliers(unit));
        let mut stats = UnitStats::default();
        let mut splat_sums = SplatSums::new();
        let mass = self
            .film_mass
            .as_ref()
            .expect("a bidirectional scene has its film mass");
        let mut subpaths = Subpaths::new();
        let mut splats = Vec::with_capacity(crate::integrator::bdpt::MAX_SPLATS_PER_SAMPLE);
        let grouped = self.frame.layers.light_groups > 0;
        for y in unit.y0..unit.y1 {
            for x in unit.x0..unit.x1 {
                if !unit.renders(x, y) {
                    continue;
                }
                for index in unit.sample_start..unit.sample_end {
                    if ((index - unit.sample_start) as usize).is_multiple_of(CANCEL_CHECK_SAMPLES)
                        && cancel.load(Ordering::Relaxed)
                    {
                        return None;
                    }
                    let mut sampler = self.sample_stream(unit, (x, y, index));
                    let (u, ray) = self.camera_sample(x, y, &mut sampler);
                    splats.clear();
                    let (path, groups) = if grouped {
                        let mut groups = GroupRadiance::default();
                        let path = trace_bidirectional(
                            self,
                            ray,
                            &mut sampler,
                            &mut subpaths,
                            (&mut splats, &mut groups),
                        );
                        (path, Some(groups))
                    } else {
                        let sinks = (&mut splats, &mut ());
                        let path =
                            trace_bidirectional(self, ray, &mut sampler, &mut subpaths, sinks);
                        (path, None)
                    };
                    self.add_sample(&mut sums, &mut stats, (x, y, index), u, (path, groups));
                    for splat in &splats {
                        self.add_light_splat(mass, &mut splat_sums, splat);
                    }
                }
            }
        }
        // Splats that are not finite, or beyond what a unit may report, are dropped as such
        // samples are.
        stats.dropped += splat_sums.dropped() + splat_sums.refused();
        let mut buffer = sums.into_buffer();
        buffer.splats = splat_sums.into_splats();
        Some((buffer, stats))
    }

    /// Adds a light subpath's splat to every film pixel its filter reaches, weighed by the
    /// filter over each pixel's filter mass (no weight sum divides a splat: see
    /// [`PixelFilter::film_mass`]), in the plane of the image's light or of its light group
    /// ([`FilmFrame::splat_entries`]).
    fn add_light_splat(&self, mass: &FilmMass, splat_sums: &mut SplatSums, splat: &LightSplat) {
        let (width, height) = (self.frame.width, self.frame.height);
        let plane = splat.group.map_or(0, |g| 1 + u64::from(g)) * u64::from(width * height);
        let (px, py) = (splat.raster.x.floor(), splat.raster.y.floor());
        if !(0.0..width as f32).contains(&px) || !(0.0..height as f32).contains(&py) {
            return;
        }
        let u = Vec2::new(splat.raster.x - px, splat.raster.y - py);
        let f = self
            .filter
            .footprint((px as u32, py as u32), u, (0, 0), (width, height));
        for row in 0..f.row_count() {
            let y = f.rows.first + row as u32;
            let weights = f.row(row);
            for (column, &w) in weights[..f.column_count()].iter().enumerate() {
                let x = f.columns.first + column as u32;
                let weight = w / mass.at(x, y);
                // Within u32 for every film the memory budget admits; one beyond is dropped.
                let Ok(at) = u32::try_from(plane + u64::from(y * width + x)) else {
                    continue;
                };
                splat_sums.add(at, splat.radiance * weight);
            }
        }
    }

    /// The sample stream of sample `index` of pixel (x, y) in `unit`: an adaptive pixel may
    /// stop after any round, so its samples are nested; a uniform one takes all of the
    /// render's.
    #[inline(always)]
    fn sample_stream(&self, unit: &WorkUnit, (x, y, index): (u32, u32, u32)) -> PixelSampler {
        let seed = self.settings.seed;
        if unit.mask.is_some() {
            PixelSampler::nested(x, y, index, seed)
        } else {
            PixelSampler::new(x, y, index, self.settings.spp, seed)
        }
    }

    /// Counts sample `index` of pixel (x, y), at `u` in the pixel, and splats its light and its
    /// layers' values, its light groups' light among them when the render keeps them (a sample
    /// whose light is not finite is dropped, layers and all).
    #[inline(always)]
    fn add_sample(
        &self,
        sums: &mut UnitSums,
        stats: &mut UnitStats,
        (x, y, index): (u32, u32, u32),
        u: Vec2,
        (path, groups): (PathResult, Option<GroupRadiance>),
    ) {
        stats.samples += 1;
        stats.rays += u64::from(path.rays);
        let offsets = self.frame.layers.offsets();
        if let Some(at) = offsets.samples {
            // Every sample taken counts, dropped or not: the count is the plan's.
            let region = sums.buffer.region;
            let pixel = ((y - region.y0) * region.width() + x - region.x0) as usize;
            let plane = self.plane_offset(&sums.buffer, (x, y));
            sums.layers[(plane + pixel) * self.frame.layers.len() + at] += 1.0;
        }
        if !path.radiance.is_finite() {
            stats.dropped += 1;
            return;
        }
        if let Some(outliers) = &mut sums.outliers {
            let at = Vec2::new(x as f32, y as f32) + u;
            if outliers.rejects(at, crate::math::luminance(path.radiance)) {
                return;
            }
        }
        let half = sums.buffer.unit.mask.is_some() && index % 2 == 1;
        let alpha = if path.escaped { 0.0 } else { 1.0 };
        let mut layers = if self.frame.layers.aovs.need_first_surface() {
            let mut layers = self.first_surface(&sums.buffer.unit, (x, y, index));
            layers.alpha = alpha;
            stats.rays += 1;
            layers
        } else {
            LayerSample::alpha(alpha)
        };
        if let Some(groups) = groups {
            layers.light_groups = groups.0;
        }
        self.splat(sums, (x, y), u, (path.radiance, layers), half);
    }

    /// The outlier filter of `unit`'s samples, when the Film rejects outliers.
    fn outliers(&self, unit: &WorkUnit) -> Option<OutlierFilter> {
        let width = [self.desc.filter.xwidth, self.desc.filter.ywidth];
        OutlierFilter::new(self.desc.film.outlier_k, width, unit.tile())
    }

    /// Where the source plane of the block of pixel (x, y) starts in `buffer`'s sums (0 for a
    /// uniform unit), in pixels.
    fn plane_offset(&self, buffer: &SampleBuffer, (x, y): (u32, u32)) -> usize {
        if buffer.unit.mask.is_some() {
            self.frame.source_plane(x, y) * buffer.region.pixel_count()
        } else {
            0
        }
    }

    /// The AOVs' values of sample `index` of pixel (x, y) (its alpha left 0): the sample's
    /// camera ray, drawn again as the sample drew it, to the first surface that is not
    /// `null`; its BSDF (a mix resolved at its middle) gives the albedo and the shading normal
    /// on the camera's side, the distance from the ray's origin the depth. Nothing where the
    /// ray escapes (or has none).
    fn first_surface(&self, unit: &WorkUnit, sample: (u32, u32, u32)) -> LayerSample {
        let nothing = LayerSample::alpha(0.0);
        let mut sampler = self.sample_stream(unit, sample);
        let Some(camera_ray) = self.camera_sample(sample.0, sample.1, &mut sampler).1 else {
            return nothing;
        };
        let mut ray = camera_ray;
        for _ in 0..=MAX_PASS_THROUGH {
            let Some(hit) = self.geometry.intersect(&ray, f32::INFINITY) else {
                return nothing;
            };
            if PathScene::crossing(self, hit.shape) == Crossing::Null {
                ray = Ray::new(crate::math::offset_origin(hit.p, hit.ng, ray.dir), ray.dir);
                continue;
            }
            let bsdf = self.bsdf_at(&hit, 0.5);
            let wo = -ray.dir;
            return LayerSample {
                albedo: bsdf.albedo(wo).clamp(Vec3::ZERO, Vec3::ONE),
                normal: bsdf.shading_normal_toward(wo),
                depth: Some(hit.p.distance(camera_ray.origin)),
                ..nothing
            };
        }
        nothing
    }

    /// Adds a sample at `pixel + u` with `radiance` (and its layers' values, where the frame
    /// keeps layers) to every pixel of the buffer's region its filter reaches (in the source
    /// plane of its block when the unit is adaptive), and to the half sums too when `half`
    /// (which keep no layers).
    fn splat(
        &self,
        sums: &mut UnitSums,
        (x, y): (u32, u32),
        u: Vec2,
        (radiance, layers): (Vec3, LayerSample),
        half: bool,
    ) {
        let region = sums.buffer.region;
        let f = self
            .filter
            .footprint((x, y), u, (region.x0, region.y0), (region.x1, region.y1));
        let width = region.width() as usize;
        let plane_len = region.pixel_count();
        let plane = self.plane_offset(&sums.buffer, (x, y));
        let first_column = (f.columns.first - region.x0) as usize;
        let taps = f.column_count();
        let sample = radiance.extend(1.0);
        for row in 0..f.row_count() {
            let start = (f.rows.first - region.y0) as usize * width + row * width + first_column;
            let weights = f.row(row);
            // Each row's run of pixels is sliced once, so the loops below check no bounds (a
            // check per tap was a third of the splat's instructions).
            let add = |pixels: &mut [Vec4]| {
                for (sum, &w) in pixels[start..start + taps].iter_mut().zip(&weights) {
                    *sum += sample * w;
                }
            };
            add(&mut sums.all[plane..plane + plane_len]);
            if half {
                add(&mut sums.half);
            }
        }
        let k = self.frame.layers.len();
        if k > 0 {
            let values = layers.values(self.frame.layers);
            // The sample count's value is 0 here: it is counted in its own pixel alone.
            let values = &values[..k];
            for row in 0..f.row_count() {
                let start =
                    (f.rows.first - region.y0) as usize * width + row * width + first_column;
                let weights = f.row(row);
                let run = &mut sums.layers[(plane + start) * k..(plane + start + taps) * k];
                for (pixel, &w) in run.chunks_exact_mut(k).zip(&weights) {
                    for (sum, &v) in pixel.iter_mut().zip(values) {
                        *sum += v * w;
                    }
                }
            }
        }
    }
}

/// A unit's sums while it renders: each pixel's radiance sums and weight side by side, so that
/// a sample adds to a pixel with one 4-lane multiply and one add. Each lane does what adding
/// the sums one at a time did (`sum += c * w`, the weight's lane `w = 1 * w` exactly), so the
/// buffer has the same bits.
/// A unit's render on the lane type [`OnLanes`] picks.
struct UnitOnLanes<'a> {
    scene: &'a RenderScene,
    unit: &'a WorkUnit,
    cancel: &'a AtomicBool,
}

impl OnLanes for UnitOnLanes<'_> {
    type Output = Option<(SampleBuffer, UnitStats)>;

    // Inlined into the lane type's target-feature function: the render loop is compiled for it.
    #[inline(always)]
    fn run<L: Lanes>(&self) -> Self::Output {
        self.scene.render_unit_in::<L>(self.unit, self.cancel)
    }
}

struct UnitSums {
    buffer: SampleBuffer,
    /// The unit's outliers, where the Film rejects them (`render::outliers`).
    outliers: Option<OutlierFilter>,
    all: Vec<Vec4>,
    half: Vec<Vec4>,
    /// The layers' sums, laid out as the buffer's.
    layers: Vec<f32>,
}

impl UnitSums {
    fn new(mut buffer: SampleBuffer, outliers: Option<OutlierFilter>) -> Self {
        Self {
            outliers,
            all: vec![Vec4::ZERO; buffer.weight.len()],
            half: vec![Vec4::ZERO; buffer.half_weight.len()],
            layers: std::mem::take(&mut buffer.layers),
            buffer,
        }
    }

    /// The buffer with the sums, each radiance sum clamped as reported ([`unit_sum`]).
    fn into_buffer(self) -> SampleBuffer {
        let mut buffer = self.buffer;
        let planes = [
            (&mut buffer.rgb, &mut buffer.weight, self.all),
            (&mut buffer.half_rgb, &mut buffer.half_weight, self.half),
        ];
        for (rgb, weight, sums) in planes {
            for ((rgb, weight), sum) in rgb.iter_mut().zip(weight.iter_mut()).zip(sums) {
                *rgb = unit_sum(sum.truncate());
                *weight = sum.w;
            }
        }
        buffer.layers = self.layers;
        buffer
    }
}

/// The shapes whose lamp images the path tracer samples: triangle meshes under a plain
/// `mirror` (a bump map or a mix would bend the reflection), unless the scene turns that off or
/// has volumes (the integrator samples images only between surfaces).
fn flat_mirrors(desc: &SceneDesc, settings: &RenderSettings) -> Vec<u32> {
    // A lamp seen in a mirror from a non-specular vertex is indirect light, which direct
    // lighting leaves out.
    if !desc.integrator.mirror_images
        || !desc.volumes.media.is_empty()
        || settings.transport == Transport::DirectLighting
    {
        return Vec::new();
    }
    (0..desc.shapes.len() as u32)
        .filter(|&i| {
            let shape = &desc.shapes[i as usize];
            matches!(shape.geometry, Geometry::Mesh(_))
                && matches!(
                    desc.materials.get(shape.material.0 as usize),
                    Some(MaterialDesc::Mirror(_))
                )
        })
        .collect()
}

/// How shadow rays cross the shapes material `id` is on: a `null` always, a pane of
/// architectural glass (bumped or not; inside a mix it is a choice a shadow ray cannot make,
/// and it blocks) with its transmittance.
fn crossing(desc: &SceneDesc, id: MaterialId) -> Crossing {
    let pane = |m: &MaterialDesc| matches!(m, MaterialDesc::Glass(g) if g.architectural);
    match desc.materials.get(id.0 as usize) {
        Some(MaterialDesc::Null(_)) => Crossing::Null,
        Some(m) if pane(m) => Crossing::Pane,
        Some(MaterialDesc::Bumped(m, _)) if pane(m) => Crossing::Pane,
        _ => Crossing::Blocks,
    }
}

/// Whether material `id` is `null`: paths and shadow rays cross the shapes it is on.
fn is_null(desc: &SceneDesc, id: MaterialId) -> bool {
    matches!(
        desc.materials.get(id.0 as usize),
        Some(MaterialDesc::Null(_))
    )
}

/// Whether the path tracer may split glossy vertices ([`PathScene::glossy_split`]): the scene
/// file allows it, a lamp (an area light) may shine in a metal's narrow lobe, and no volume, or
/// material that may let a ray through at one hit and not at the next, makes a split sample's
/// way differ from the path's (a split sample crosses only `null` itself): a mix with a `null`
/// side, or a `layered` (whose uncaught rays pass through).
fn glossy_split(desc: &SceneDesc) -> bool {
    fn may_be_glossy(m: &MaterialDesc) -> bool {
        match m {
            MaterialDesc::Metal(_) | MaterialDesc::ShinyMetal(_) => true,
            MaterialDesc::Bumped(inner, _) => may_be_glossy(inner),
            _ => false,
        }
    }
    let sometimes_passes = |m: &MaterialDesc| match m {
        MaterialDesc::Mix(_) => m.materials().iter().any(|&id| is_null(desc, id)),
        MaterialDesc::Layered(_) => true,
        _ => false,
    };
    desc.integrator.glossy_split
        && desc.shapes.iter().any(|s| s.area_light.is_some())
        && desc.materials.iter().any(may_be_glossy)
        && desc.volumes.media.is_empty()
        && !desc.materials.iter().any(sometimes_passes)
}

impl PilotScene for RenderScene {
    fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// None outside a fisheye's circle.
    fn camera_ray(&self, x: u32, y: u32, sampler: &mut PixelSampler) -> Option<Ray> {
        self.camera_sample(x, y, sampler).1
    }
}

impl BidirectionalScene for RenderScene {
    fn camera(&self) -> &Camera {
        &self.camera
    }

    fn light_depth(&self) -> u32 {
        self.desc.integrator.light_depth
    }

    fn only_strategy(&self) -> Option<(usize, usize)> {
        self.only_strategy
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

    fn glossy_split(&self) -> bool {
        self.glossy_split
    }

    fn direct_lighting(&self) -> bool {
        self.settings.transport == Transport::DirectLighting
    }

    fn first_vertex_branches(&self) -> usize {
        self.first_vertex_branches
    }

    fn crossing(&self, shape: u32) -> Crossing {
        self.crossings
            .get(shape as usize)
            .copied()
            .unwrap_or(Crossing::Blocks)
    }

    fn has_panes(&self) -> bool {
        self.has_panes
    }
}
