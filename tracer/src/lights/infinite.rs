//! The infinite light: constant radiance, or radiance times a LatLong environment map that is
//! importance-sampled by luminance (`infinitesample` is read as the same light).
//!
//! ```text
//! LightSource "infinite" "color L" [1 1 1] "float gain" [1] "string mapname" ["sky.exr"]
//!     "string mapping" ["latlong"] "float gamma" [1]
//! ```
//!
//! | parameter | default   | meaning                                                         |
//! |-----------|-----------|-----------------------------------------------------------------|
//! | `L`       | 1 1 1     | colour; multiplies the map when there is one                    |
//! | `gain`    | 1         | multiplies `L`                                                  |
//! | `mapname` | (none)    | LatLong image in light space (z up); empty means none           |
//! | `mapping` | "latlong" | anything else is a warning and read as latlong                  |
//! | `gamma`   | 1         | the map's encoding gamma                                        |
//!
//! Light space is mapped to the world by the current transform.

use std::f32::consts::{PI, TAU};

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::assets::AssetSource;
use crate::diag::SourcePos;
use crate::image_io::{self, Edge, ImageCost, RgbImage};
use crate::math::{atan2, luminance};
use crate::parse::context::{ImageUse, ParseContext};
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

use super::distribution::Distribution2D;
use super::emission::{emits, Emission};
use super::error::LightError;
use super::kind::{LatLongConvention, LightKind, MapSource};
use super::sample::uniform_sphere;
use super::facing::{FacingTables, FACING_BINS, MAX_FACING_CELLS};

/// `mapping`: the only one modelled.
pub const DEFAULT_MAPPING: &str = "latlong";
/// `gamma` of the map.
pub const DEFAULT_GAMMA: f32 = 1.0;

#[derive(Clone, Debug, PartialEq)]
pub struct EnvMapDesc {
    /// Path as written; listed in `assets`.
    pub filename: String,
    pub gamma: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct InfiniteLight {
    /// L x gain; multiplies the map when there is one.
    pub radiance: Vec3,
    pub map: Option<EnvMapDesc>,
    /// Light space has z up; this maps it to world space.
    pub light_to_world: Mat4,
}

impl InfiniteLight {
    pub(crate) fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let e = Emission::read(params, ctx)?;
        let mapping = params.string_or("mapping", DEFAULT_MAPPING)?;
        if mapping != DEFAULT_MAPPING {
            ctx.warn(
                pos,
                format!("LightSource \"infinite\": mapping \"{mapping}\" is not supported; using latlong"),
            );
        }
        let gamma = params.float("gamma", DEFAULT_GAMMA)?;
        let map = match params.string("mapname")? {
            Some(filename) if !filename.is_empty() => {
                ctx.check_image(&filename, ImageUse::Environment, pos)?;
                Some(EnvMapDesc { filename, gamma })
            }
            _ => None,
        };
        Ok(Self {
            radiance: e.l * e.gain,
            map,
            light_to_world: ctx.ctm(),
        })
    }
}

impl LightKind for InfiniteLight {
    type Sampler = Environment;

    fn files(&self) -> Vec<&str> {
        self.map.iter().map(|m| m.filename.as_str()).collect()
    }

    fn name(&self) -> &'static str {
        "infinite"
    }

    /// The light to sample, if it emits: its map read from `source` and decoded.
    fn light(&self, maps: &MapSource) -> Result<Option<Environment>, LightError> {
        if !emits(self.radiance) {
            return Ok(None);
        }
        let image = match &self.map {
            Some(map) => Some(load_map(maps.files, &map.filename, map.gamma)?),
            None => None,
        };
        if Environment::is_singular(&self.light_to_world) {
            tracing::warn!("infinite light: singular transform, using the identity");
        }
        Ok(Some(Environment::new(
            self.radiance,
            image,
            &self.light_to_world,
            maps.latlong,
        )))
    }
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

/// An infinite light ready to sample: the map decoded and its distribution built.
pub struct Environment {
    radiance: Vec3,
    map: Option<LatLongMap>,
    world_to_light: Mat3,
    light_to_world: Mat3,
    /// |det world_to_light|: with the renormalisation of directions, part of the solid-angle
    /// Jacobian between light and world space (1 for rotations).
    abs_det: f32,
}

impl Environment {
    /// A singular `light_to_world` is replaced by the identity (reported by the caller).
    pub fn new(
        radiance: Vec3,
        map: Option<RgbImage>,
        light_to_world: &Mat4,
        convention: LatLongConvention,
    ) -> Self {
        let linear = Mat3::from_mat4(*light_to_world);
        let det = linear.determinant();
        let linear = if det != 0.0 && det.is_finite() {
            linear
        } else {
            Mat3::IDENTITY
        };
        let world_to_light = linear.inverse();
        Self {
            radiance,
            map: map.map(|image| LatLongMap::new(image, convention)),
            world_to_light,
            light_to_world: linear,
            abs_det: world_to_light.determinant().abs(),
        }
    }

    /// Whether the transform had to be replaced.
    pub fn is_singular(light_to_world: &Mat4) -> bool {
        let det = Mat3::from_mat4(*light_to_world).determinant();
        det == 0.0 || !det.is_finite()
    }

    /// Radiance arriving from world direction `dir` (unit).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        match &self.map {
            None => self.radiance,
            Some(map) => self.radiance * map.lookup(map.uv(self.to_light(dir))),
        }
    }

    /// Radiance from `dir` and the solid-angle density of [`Self::sample`] there (for a
    /// surface facing `facing`), with one conversion to map coordinates for both.
    pub fn radiance_and_pdf(&self, dir: Vec3, facing: Option<Vec3>) -> (Vec3, f32) {
        match &self.map {
            None => (self.radiance, 1.0 / (4.0 * PI)),
            Some(map) => {
                let d = self.to_light(dir);
                let uv = map.uv(d);
                (
                    self.radiance * map.lookup(uv),
                    self.map_pdf(map, d, uv, dir, facing),
                )
            }
        }
    }

    /// A world direction, its solid-angle density and the radiance from it. `facing` is the
    /// world-space normal of a reflecting surface on the side it takes light from: a map is
    /// then sampled by its facing tables ([`super::facing`]), which give no density behind it.
    pub fn sample(&self, u: Vec2, facing: Option<Vec3>) -> Option<(Vec3, f32, Vec3)> {
        match &self.map {
            None => Some((uniform_sphere(u), 1.0 / (4.0 * PI), self.radiance)),
            Some(map) => {
                // The texels looked up below sit in the sampled cell nearly always: their load
                // starts alongside the tables' own last cache miss.
                let (uv, pdf_uv) = match facing {
                    Some(n) => map
                        .facing
                        .sample(self.world_to_light * n, u, |row, column| {
                            map.prefetch_cell(row, column);
                        })?,
                    None => map
                        .distribution
                        .sample(u, |row, column| map.prefetch_cell(row, column))?,
                };
                let (d_light, sin_theta) = map.direction(uv);
                if pdf_uv <= 0.0 || sin_theta <= 0.0 {
                    return None;
                }
                let dir = (self.light_to_world * d_light).normalize_or_zero();
                let pdf = pdf_uv / (2.0 * PI * PI * sin_theta) * self.jacobian(dir);
                let radiance = self.radiance * map.lookup(uv);
                (dir != Vec3::ZERO && pdf.is_finite()).then_some((dir, pdf, radiance))
            }
        }
    }

    /// The solid-angle density of [`Self::sample`] for world direction `dir`.
    pub fn pdf(&self, dir: Vec3, facing: Option<Vec3>) -> f32 {
        match &self.map {
            None => 1.0 / (4.0 * PI),
            Some(map) => {
                let d = self.to_light(dir);
                self.map_pdf(map, d, map.uv(d), dir, facing)
            }
        }
    }

    fn to_light(&self, dir: Vec3) -> Vec3 {
        (self.world_to_light * dir).normalize_or_zero()
    }

    /// Density at light-space direction `d` (map coordinates `uv`, world direction `dir`).
    fn map_pdf(&self, map: &LatLongMap, d: Vec3, uv: Vec2, dir: Vec3, facing: Option<Vec3>) -> f32 {
        // Not sqrt(1 - z^2), which rounds to 0 near the poles.
        let sin_theta = d.truncate().length();
        if sin_theta <= 0.0 {
            return 0.0;
        }
        let density = match facing {
            Some(n) => map.facing.pdf(self.world_to_light * n, uv),
            None => map.distribution.pdf(uv),
        };
        density / (2.0 * PI * PI * sin_theta) * self.jacobian(dir)
    }

    /// d omega_light / d omega_world at world direction `dir` for the map d -> A d / |A d|.
    fn jacobian(&self, dir: Vec3) -> f32 {
        self.abs_det / (self.world_to_light * dir).length().powi(3)
    }

    /// pi R^2 times the luminance of the mean radiance: what a disk of the scene's size
    /// facing the light would receive.
    pub fn power(&self, scene_radius: f32) -> f32 {
        let mean = self.map.as_ref().map_or(Vec3::ONE, LatLongMap::mean);
        PI * scene_radius * scene_radius * luminance(self.radiance * mean)
    }
}

/// An equirectangular map in light space (z up): t = theta / pi with row 0 straight up, and s
/// by `convention`.
struct LatLongMap {
    image: RgbImage,
    convention: LatLongConvention,
    /// Over cells of the map (one per texel, or per block of texels on a large map), by
    /// luminance x sin(theta).
    distribution: Distribution2D,
    /// The same cells for surfaces facing one way or another.
    facing: FacingTables,
}

/// The most cells a map's distribution holds (16 bytes each: 2 MiB). One record is read per
/// sample at a random place, and a table of one per texel outgrows the caches: Captain Falcon's
/// 1600x800 map made 20 MiB, and its reads were the largest item of that scene's profile. A
/// larger map gets one cell per block of 2x2, 4x4, ... texels, sampled uniformly inside: the
/// density follows the blocks' sums, which for a map of more than 131,072 texels changes the
/// noise hardly at all, and it stays unbiased (any density that is positive wherever light
/// is, is; and where it is not, the path's BSDF samples are weighted in fully).
const MAX_DISTRIBUTION_CELLS: usize = 1 << 17;

/// Bytes a distribution cell's records take, kept and while they are built (the cell's sum,
/// its alias records in the map's distribution and in the facing tables' per-block tables, the
/// facing tables' weights and directions, the alias construction's f64 temporaries), rounded up.
const BYTES_PER_CELL: u64 = 128;
/// Bytes of one facing table's record per block, with its temporaries, rounded up.
const BYTES_PER_FACING_BLOCK: u64 = 32;

/// What a `width` x `height` map takes as an environment: `image` (its texels), its sampling
/// tables, and while they are built, the luminance and the blurred density per texel.
pub fn map_cost(image: ImageCost, width: u32, height: u32) -> ImageCost {
    let texels = u64::from(width) * u64::from(height);
    let (across, down) = distribution_cells(width as usize, height as usize);
    let cells = (across * down) as u64;
    let tables =
        cells * BYTES_PER_CELL + (FACING_BINS * MAX_FACING_CELLS) as u64 * BYTES_PER_FACING_BLOCK;
    let per_texel = 2 * std::mem::size_of::<f32>() as u64;
    ImageCost {
        kept: image.kept + tables,
        transient: image.transient.max(texels * per_texel),
    }
}

/// Cells across and down for a `w` x `h` map: texels in blocks of the least power-of-two side
/// that keeps them within [`MAX_DISTRIBUTION_CELLS`] (a 4x4 block is one tile of the image's
/// texel storage, which the sampler's prefetch then loads whole).
fn distribution_cells(w: usize, h: usize) -> (usize, usize) {
    let mut side = 1;
    while w.div_ceil(side) * h.div_ceil(side) > MAX_DISTRIBUTION_CELLS {
        side *= 2;
    }
    (w.div_ceil(side), h.div_ceil(side))
}

/// `func` (`w` x `h` texels) summed into `across` x `down` cells that split [0, 1)^2 evenly,
/// each texel into the cell holding its centre.
fn cell_sums(func: &[f32], w: usize, h: usize, across: usize, down: usize) -> Vec<f32> {
    if (across, down) == (w, h) {
        return func.to_vec();
    }
    let cell = |i: usize, n: usize, cells: usize| (2 * i + 1) * cells / (2 * n);
    let mut sums = vec![0.0f32; across * down];
    for (y, row) in func.chunks_exact(w.max(1)).enumerate() {
        let cy = cell(y, h, down);
        for (x, &f) in row.iter().enumerate() {
            sums[cy * across + cell(x, w, across)] += f;
        }
    }
    sums
}

impl LatLongMap {
    fn new(image: RgbImage, convention: LatLongConvention) -> Self {
        let (w, h) = (image.width as usize, image.height as usize);
        let lum: Vec<f32> = image.texels().map(luminance).collect();
        // The map is looked up bilinearly, so a texel's cell also shows 1/4 of each
        // neighbour on its half: over the cell that averages to 3/4 own + 1/8 per side, per
        // axis. Sampling that blur keeps the density positive wherever the lookup is.
        let mut func = vec![0.0f32; w * h];
        for y in 0..h {
            let sin_theta = libm::sinf((y as f32 + 0.5) / h as f32 * PI);
            for x in 0..w {
                let mut sum = 0.0;
                for (dy, wy) in [(-1i64, 0.125f32), (0, 0.75), (1, 0.125)] {
                    let yy = (y as i64 + dy).clamp(0, h as i64 - 1) as usize;
                    for (dx, wx) in [(-1i64, 0.125f32), (0, 0.75), (1, 0.125)] {
                        let xx = (x as i64 + dx).rem_euclid(w as i64) as usize;
                        sum += wy * wx * lum[yy * w + xx];
                    }
                }
                func[y * w + x] = sum * sin_theta;
            }
        }
        let (cells_across, cells_down) = distribution_cells(w, h);
        let cells = cell_sums(&func, w, h, cells_across, cells_down);
        let facing = FacingTables::new(&cells, cells_across, cells_down, |uv| {
            Self::direction_by(convention, uv).0
        });
        Self {
            distribution: Distribution2D::new(&cells, cells_across, cells_down),
            facing,
            image,
            convention,
        }
    }

    /// Starts loading the texels of distribution cell (`column`, `row`), where a sample is
    /// about to land.
    fn prefetch_cell(&self, row: usize, column: usize) {
        let (w, h) = (self.image.width as usize, self.image.height as usize);
        let (across, down) = self.distribution.cells();
        self.image.prefetch(column * w / across, row * h / down);
    }

    /// Map coordinates of a unit light-space direction.
    fn uv(&self, d: Vec3) -> Vec2 {
        let theta = atan2(d.truncate().length(), d.z);
        let phi = atan2(d.y, d.x);
        let s = match self.convention {
            LatLongConvention::Seed => (PI + phi) / TAU,
            LatLongConvention::LuxRender => {
                if phi < 0.0 {
                    (phi + TAU) / TAU
                } else {
                    phi / TAU
                }
            }
        };
        Vec2::new(s, theta / PI)
    }

    /// The light-space direction at map coordinates `uv`, and sin(theta) there.
    fn direction(&self, uv: Vec2) -> (Vec3, f32) {
        Self::direction_by(self.convention, uv)
    }

    fn direction_by(convention: LatLongConvention, uv: Vec2) -> (Vec3, f32) {
        let (sin_theta, cos_theta) = libm::sincosf(uv.y * PI);
        let phi = match convention {
            LatLongConvention::Seed => uv.x * TAU - PI,
            LatLongConvention::LuxRender => uv.x * TAU,
        };
        let (sin_phi, cos_phi) = libm::sincosf(phi);
        (
            Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta),
            sin_theta,
        )
    }

    /// Bilinear between texel centres, wrapping around in s and clamped in t.
    fn lookup(&self, uv: Vec2) -> Vec3 {
        self.image.bilinear(uv, Edge::Repeat, Edge::Clamp).0
    }

    /// Mean radiance over the sphere: texels weighted by their solid angle.
    fn mean(&self) -> Vec3 {
        let (w, h) = (self.image.width as usize, self.image.height as usize);
        let mut sum = Vec3::ZERO;
        for y in 0..h {
            let (t0, t1) = (y as f32 / h as f32 * PI, (y + 1) as f32 / h as f32 * PI);
            let solid_angle = TAU / w as f32 * (libm::cosf(t0) - libm::cosf(t1));
            let row: Vec3 = (y * w..(y + 1) * w).map(|i| self.image.texel(i)).sum();
            sum += row * solid_angle;
        }
        sum / (4.0 * PI)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_maps_are_sampled_by_blocks_that_keep_their_sums() {
        assert_eq!(distribution_cells(64, 32), (64, 32));
        assert_eq!(distribution_cells(512, 256), (512, 256));
        // Captain Falcon's map: 4x4 blocks, 80,000 cells.
        assert_eq!(distribution_cells(1600, 800), (400, 200));
        // Sides that blocks do not divide: the last block is partial.
        let (across, down) = distribution_cells(1001, 499);
        assert_eq!((across, down), (501, 250));

        let (w, h) = (1001, 499);
        let func: Vec<f32> = (0..w * h).map(|i| (i % 7 + 1) as f32).collect();
        let sums = cell_sums(&func, w, h, across, down);
        let total = |v: &[f32]| v.iter().map(|&f| f64::from(f)).sum::<f64>();
        assert!((total(&sums) / total(&func) - 1.0).abs() < 1e-6);
        // Every cell holds a texel centre: none is left without density.
        assert!(sums.iter().all(|&s| s > 0.0));
    }
}
