//! Area lights: a shape whose front side emits. The statement sets the emission of every
//! shape that follows in its attribute block:
//!
//! ```text
//! AreaLightSource "area" "color L" [1 1 1] "float gain" [1] "float power" [100] "float efficacy" [17]
//! AreaLightSource "area" "texture L" "photo" "float power" [0]
//! ```
//!
//! | parameter  | default | meaning                                                          |
//! |------------|---------|------------------------------------------------------------------|
//! | `L`        | 1 1 1   | colour, or a colour texture                                      |
//! | `gain`     | 1       | multiplies `L`                                                   |
//! | `power`    | 100     | watts; with `efficacy` > 0 the gain is scaled so the shape emits that many lumens |
//! | `efficacy` | 17      | lumens per watt                                                  |
//!
//! Other types are read as `"area"` with a warning. The radiance is known once the shape's
//! world-space area is (LuxRender's normalisation divides by it) and, for a texture, once its
//! images are decoded (the normalisation divides by the texture's mean luminance, its mean
//! over the unit uv square here, which for an image map is the image's mean).
//!
//! A texture is evaluated where the surface is seen and where a light sample lands, at the
//! same uv and position either way (MIS weighs the two estimates of one value); a constant
//! colour costs no evaluation. The primitive a texture sees is always 0 (a harlequin emitter
//! is one colour): a sampled point does not know its primitive index.
//!
//! Points are sampled uniformly by area over the whole shape (triangles chosen by an area
//! table), except whole spheres, which are sampled inside the cone they subtend (only their
//! visible cap). Rays leaving the light (for light subpaths) start at a point uniform by area,
//! on whole spheres too (no shading point to see a cap from), and go cosine-weighted about the
//! front normal.

use std::f32::consts::{PI, TAU};
use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec2, Vec3, Vec3A};

use crate::bxdf::local::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::diag::SourcePos;
use crate::geometry::{AnalyticShape, ShapeSurface, SurfaceSample, TriangleSurface};
use crate::math::{luminance, Frame};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, TextureId};
use crate::shape::AreaLightDesc;
use crate::texture::{LookupPoint, Textures};

use super::distribution::Distribution1D;
use super::emission::{emits, normalised_gain, surface_color, DEFAULT_GAIN, DEFAULT_L};
use super::sample::{EmittedRay, LightSample};

/// `power`, watts.
pub const DEFAULT_POWER: f32 = 100.0;
/// `efficacy`, lumens per watt.
pub const DEFAULT_EFFICACY: f32 = 17.0;

/// Area light parameters kept in the graphics state; the radiance is known only once the
/// world-space area of each shape is.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLightParams {
    pub l: ConstOrTexture,
    pub gain: f32,
    pub power: f32,
    pub efficacy: f32,
}

impl AreaLightParams {
    /// Reads `AreaLightSource "ty"`.
    pub(crate) fn read(
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        if ty != "area" {
            ctx.warn(
                pos,
                format!("AreaLightSource \"{ty}\" is treated as \"area\""),
            );
        }
        Ok(Self {
            l: surface_color(params, "L", DEFAULT_L, ctx)?,
            gain: params.float("gain", DEFAULT_GAIN)?,
            power: params.float("power", DEFAULT_POWER)?,
            efficacy: params.float("efficacy", DEFAULT_EFFICACY)?,
        })
    }

    /// The emission of a shape of world-space area `area`.
    pub fn desc(&self, area: f32) -> AreaLightDesc {
        AreaLightDesc {
            l: self.l,
            gain: self.gain,
            power: self.power,
            efficacy: self.efficacy,
            area,
            group: 0,
        }
    }
}

impl AreaLightDesc {
    /// Constant radiance `radiance`, without power normalisation.
    pub fn constant(radiance: Vec3) -> Self {
        Self {
            l: ConstOrTexture::Const(radiance),
            gain: 1.0,
            power: 0.0,
            efficacy: 0.0,
            area: 0.0,
            group: 0,
        }
    }

    /// What multiplies `L`: the gain, normalised by power and efficacy for an `L` of mean
    /// luminance `mean_luminance`.
    pub fn scale(&self, mean_luminance: f32) -> f32 {
        normalised_gain(
            self.gain,
            self.power,
            self.efficacy,
            self.area * PI * mean_luminance,
        )
    }

    /// The radiance of a constant `L`; None for a texture.
    pub fn radiance(&self) -> Option<Vec3> {
        match self.l {
            ConstOrTexture::Const(l) => Some(l * self.scale(luminance(l))),
            ConstOrTexture::Texture(_) => None,
        }
    }
}

/// Points per side of the uv grid over which a texture's mean is taken.
const MEAN_GRID: u32 = 32;

/// A varying `L`, evaluated where the surface is seen or sampled.
struct EmissionTexture {
    textures: Arc<Textures>,
    l: TextureId,
    scale: f32,
    /// The shape's, for the object-space position local 3D mappings see.
    world_to_object: Affine3A,
}

impl EmissionTexture {
    /// The radiance at world point `p` with surface coordinates `uv`.
    fn at(&self, p: Vec3, uv: Vec2) -> Vec3 {
        let at = LookupPoint {
            p: self.world_to_object.transform_point3(p),
            p_world: p,
            uv,
            prim: 0,
        };
        self.textures
            .eval(ConstOrTexture::Texture(self.l), &at)
            .max(Vec3::ZERO)
            * self.scale
    }

    /// The texture's mean over the unit uv square (cell centres; the point is the uv in the
    /// z = 0 plane, so a 3D texture gives some mean of its pattern).
    fn mean(textures: &Textures, l: TextureId) -> Vec3 {
        let n = MEAN_GRID;
        let mut sum = Vec3::ZERO;
        for j in 0..n {
            for i in 0..n {
                let uv = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
                let at = LookupPoint::new(uv.extend(0.0), uv);
                sum += textures
                    .eval(ConstOrTexture::Texture(l), &at)
                    .max(Vec3::ZERO);
            }
        }
        sum / (n * n) as f32
    }
}

/// Points this close to a sphere light (squared distance to its centre over radius^2) sample
/// it by area, not by cone: a point on the sphere itself (an emitting sphere seen from
/// inside) lies inside or outside by rounding only, and the cone from a point on the surface
/// is degenerate. Area sampling is valid everywhere, so the margin costs nothing in bias.
const ON_SPHERE: f32 = 1.0 + 1e-3;

/// Below this sin^2 of the cone's half-angle (about 1.5 degrees) the cone is sampled through
/// Taylor expansions: 1 - cos(theta_max) would cancel catastrophically (pbrt-v4).
const SMALL_CONE_SIN2: f32 = 0.000_685_23;

/// An area light ready to sample.
pub struct AreaLight {
    /// The constant radiance, or a texture's mean radiance (what the light's power is
    /// estimated from).
    radiance: Vec3,
    texture: Option<EmissionTexture>,
    emitter: Emitter,
}

enum Emitter {
    Triangles {
        triangles: Vec<TriangleSurface>,
        by_area: Distribution1D,
        area: f32,
    },
    /// A whole sphere under a similarity transform.
    Sphere {
        centre: Vec3,
        radius: f32,
        shape: Box<AnalyticShape>,
    },
    Quadric(Box<AnalyticShape>),
}

/// The surface a light point was sampled on.
enum SampledSurface<'a> {
    Triangle(&'a TriangleSurface),
    Quadric(&'a AnalyticShape),
}

/// A point on the light as seen from a shading point.
pub struct EmitterSample {
    pub wi: Vec3,
    pub dist: f32,
    /// Solid-angle density.
    pub pdf: f32,
    /// The radiance the point emits towards the shading point.
    pub li: Vec3,
    /// The front normal at the point.
    pub n: Vec3,
}

impl EmitterSample {
    /// The light sample, for a light chosen with probability `pmf`.
    pub fn chosen(&self, pmf: f32) -> LightSample {
        LightSample {
            wi: self.wi,
            li: self.li,
            pdf: pmf * self.pdf,
            dist: self.dist,
            delta: false,
        }
    }
}

impl AreaLight {
    /// The light `desc` on `surface`, a shape placed by `object_to_world`; None when it emits
    /// nothing.
    pub fn new(
        desc: &AreaLightDesc,
        object_to_world: Mat4,
        surface: ShapeSurface,
        textures: &Arc<Textures>,
    ) -> Option<Self> {
        let (radiance, texture) = match desc.l {
            ConstOrTexture::Const(l) => (l * desc.scale(luminance(l)), None),
            ConstOrTexture::Texture(l) => {
                let mean = EmissionTexture::mean(textures, l);
                let scale = desc.scale(luminance(mean));
                let texture = EmissionTexture {
                    textures: Arc::clone(textures),
                    l,
                    scale,
                    world_to_object: crate::math::affine_inverse(&Affine3A::from_mat4(
                        object_to_world,
                    )),
                };
                (mean * scale, Some(texture))
            }
        };
        if !emits(radiance) {
            return None;
        }
        let emitter = match surface {
            ShapeSurface::Triangles(triangles) => {
                let areas: Vec<f32> = triangles.iter().map(TriangleSurface::area).collect();
                let area = areas.iter().map(|&a| f64::from(a)).sum::<f64>() as f32;
                Emitter::Triangles {
                    triangles,
                    by_area: Distribution1D::new(areas),
                    area,
                }
            }
            ShapeSurface::Analytic(shape) => match shape.whole_sphere() {
                Some((centre, radius)) => Emitter::Sphere {
                    centre,
                    radius,
                    shape,
                },
                None => Emitter::Quadric(shape),
            },
        };
        Some(Self {
            radiance,
            texture,
            emitter,
        })
    }

    /// The radiance the front side emits at `hit`.
    pub fn radiance_at(&self, p: Vec3, uv: Vec2) -> Vec3 {
        match &self.texture {
            None => self.radiance,
            Some(t) => t.at(p, uv),
        }
    }

    /// An untextured light on triangles: its triangles, their choice by area, its area and
    /// radiance (what [`super::TriangleLamps`] tabulates). None for other lights.
    pub fn plain_triangles(&self) -> Option<(&[TriangleSurface], &Distribution1D, f32, Vec3)> {
        match (&self.emitter, &self.texture) {
            (
                Emitter::Triangles {
                    triangles,
                    by_area,
                    area,
                },
                None,
            ) => Some((triangles, by_area, *area, self.radiance)),
            _ => None,
        }
    }

    pub fn area(&self) -> f32 {
        match &self.emitter {
            Emitter::Triangles { area, .. } => *area,
            Emitter::Sphere { shape, .. } | Emitter::Quadric(shape) => shape.area(),
        }
    }

    /// The box around the emitting surface.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match &self.emitter {
            Emitter::Triangles { triangles, .. } => triangles
                .iter()
                .flat_map(|t| t.vertices)
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                }),
            Emitter::Sphere { shape, .. } | Emitter::Quadric(shape) => {
                let b = shape.world_bounds();
                (b.min.into(), b.max.into())
            }
        }
    }

    /// Radiant flux of a one-sided Lambertian emitter.
    pub fn power(&self) -> f32 {
        luminance(self.radiance) * self.area() * PI
    }

    /// A point on the light seen from `from`; None when it shows its back (or nothing).
    // Inlined into `sample_chosen`, as when that was its only caller (the lamp images call it
    // too).
    #[inline(always)]
    pub fn sample(&self, from: Vec3, u: Vec2) -> Option<EmitterSample> {
        let (point, on) = match &self.emitter {
            Emitter::Sphere {
                centre,
                radius,
                shape,
            } => {
                if from.distance_squared(*centre) <= radius * radius * ON_SPHERE {
                    self.sample_area(u)?
                } else {
                    let (wi, dist, pdf) =
                        sample_sphere_cone(from, *centre, *radius, shape.orientation(), u)?;
                    let li = self.li(from, wi, dist, SampledSurface::Quadric(shape));
                    let n = (from + wi * dist - *centre).normalize() * shape.orientation();
                    return Some(EmitterSample {
                        wi,
                        dist,
                        pdf,
                        li,
                        n,
                    });
                }
            }
            _ => self.sample_area(u)?,
        };
        let to_light = point.p - from;
        let dist2 = to_light.length_squared();
        let dist = dist2.sqrt();
        let wi = to_light / dist;
        let cos_light = -point.n.dot(wi);
        let pdf = point.pdf_area * dist2 / cos_light;
        (cos_light > 0.0 && pdf.is_finite()).then(|| EmitterSample {
            wi,
            dist,
            pdf,
            li: self.li(from, wi, dist, on),
            n: point.n,
        })
    }

    /// A point uniform by area over the whole surface, and the surface it is on.
    #[inline(always)]
    fn sample_area(&self, u: Vec2) -> Option<(SurfaceSample, SampledSurface<'_>)> {
        Some(match &self.emitter {
            Emitter::Triangles {
                triangles,
                by_area,
                area,
            } => {
                let (i, _, u0) = by_area.sample_discrete(u.x)?;
                let s = triangles[i].sample(Vec2::new(u0, u.y));
                let s = SurfaceSample {
                    pdf_area: 1.0 / area,
                    ..s
                };
                (s, SampledSurface::Triangle(&triangles[i]))
            }
            Emitter::Sphere { shape, .. } | Emitter::Quadric(shape) => {
                (shape.sample(u), SampledSurface::Quadric(shape))
            }
        })
    }

    /// The area density of [`Self::sample_area`] at a point with front normal `n`.
    fn pdf_area(&self, n: Vec3) -> f32 {
        match &self.emitter {
            Emitter::Triangles { area, .. } => 1.0 / area,
            Emitter::Sphere { shape, .. } | Emitter::Quadric(shape) => shape.pdf_area(n),
        }
    }

    /// A ray leaving the light: `u_pos` chooses the point (uniform by area), `u_dir` the
    /// direction (cosine-weighted about the front normal). The radiance is the texture's at
    /// the point, as a ray hitting it there would see it.
    pub fn sample_emission(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmittedRay> {
        let (point, on) = self.sample_area(u_pos)?;
        let dir = Frame::from_normal(point.n).to_world(sample_cosine_hemisphere(u_dir));
        // The density from the direction itself, not from the hemisphere sample's cosine: it
        // is what `emission_pdf` computes for this ray.
        let (pdf_pos, pdf_dir) = self.emission_pdf(point.n, dir);
        (pdf_dir > 0.0 && pdf_pos.is_finite()).then(|| EmittedRay {
            origin: point.p,
            dir,
            normal: Some(point.n),
            le: self.li(point.p, point.n, 0.0, on),
            pdf_pos,
            pdf_dir,
            delta_position: false,
            delta_direction: false,
        })
    }

    /// The (area, solid-angle) densities of [`Self::sample_emission`] for a ray leaving the
    /// light point with front normal `n` along unit `dir`; no direction density behind it.
    pub fn emission_pdf(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        let cos = n.dot(dir);
        let pdf_dir = if cos > 0.0 {
            cosine_hemisphere_pdf(cos)
        } else {
            0.0
        };
        (self.pdf_area(n), pdf_dir)
    }

    /// The radiance of the light point `from + dist wi` of surface `on`, at the uv a ray from
    /// `from` would hit there (interpolated on the triangle, or the quadric's own
    /// parametrisation of the point; with `dist` 0, the point `from` itself).
    fn li(&self, from: Vec3, wi: Vec3, dist: f32, on: SampledSurface) -> Vec3 {
        let Some(texture) = &self.texture else {
            return self.radiance;
        };
        let p = from + wi * dist;
        let uv = match on {
            SampledSurface::Triangle(triangle) => triangle.uv_at(p),
            SampledSurface::Quadric(shape) => {
                shape.hit(Vec3A::from(from), Vec3A::from(wi), dist, 0).uv
            }
        };
        texture.at(p, uv)
    }

    /// [`Self::sample`] as a light sample, for a light chosen with probability `pmf`.
    pub fn sample_chosen(&self, from: Vec3, u: Vec2, pmf: f32) -> Option<LightSample> {
        Some(self.sample(from, u)?.chosen(pmf))
    }

    /// The solid-angle density of [`Self::sample`] from `from` at the light point `p` with
    /// front normal `n`.
    pub fn pdf(&self, from: Vec3, p: Vec3, n: Vec3) -> f32 {
        let to_from = from - p;
        let dist2 = to_from.length_squared();
        let cos_light = n.dot(to_from) / dist2.sqrt();
        if cos_light.is_nan() || cos_light <= 0.0 {
            return 0.0;
        }
        let pdf_area = match &self.emitter {
            Emitter::Sphere { centre, radius, .. } => {
                let dc2 = from.distance_squared(*centre);
                if dc2 <= radius * radius * ON_SPHERE {
                    self.pdf_area(n)
                } else {
                    return 1.0 / (TAU * one_minus_cos_max(radius * radius / dc2));
                }
            }
            _ => self.pdf_area(n),
        };
        let pdf = pdf_area * dist2 / cos_light;
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }
}

fn one_minus_cos_max(sin2_max: f32) -> f32 {
    if sin2_max < SMALL_CONE_SIN2 {
        sin2_max / 2.0
    } else {
        1.0 - (1.0 - sin2_max).max(0.0).sqrt()
    }
}

/// pbrt-v4's sphere sampling from outside: a direction uniform in the cone of the sphere's
/// silhouette, turned into the point where it meets the sphere: (direction, distance,
/// solid-angle density).
fn sample_sphere_cone(
    from: Vec3,
    centre: Vec3,
    radius: f32,
    orientation: f32,
    u: Vec2,
) -> Option<(Vec3, f32, f32)> {
    let dc2 = from.distance_squared(centre);
    let sin2_max = radius * radius / dc2;
    let sin_max = sin2_max.sqrt();
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    let (cos_theta, sin2_theta) = if sin2_max < SMALL_CONE_SIN2 {
        let sin2_theta = sin2_max * u.x;
        ((1.0 - sin2_theta).sqrt(), sin2_theta)
    } else {
        let cos_theta = (cos_max - 1.0) * u.x + 1.0;
        (cos_theta, 1.0 - cos_theta * cos_theta)
    };
    // The angle at the centre between the direction back to `from` and the sampled point.
    let cos_alpha =
        sin2_theta / sin_max + cos_theta * (1.0 - sin2_theta / sin2_max).max(0.0).sqrt();
    let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
    let (sin_phi, cos_phi) = libm::sincosf(TAU * u.y);
    let frame = Frame::from_normal((centre - from).normalize());
    let outward = frame.to_world(-Vec3::new(
        sin_alpha * cos_phi,
        sin_alpha * sin_phi,
        cos_alpha,
    ));
    let p = centre + radius * outward;
    let to_light = p - from;
    let dist = to_light.length();
    let wi = to_light / dist;
    let pdf = 1.0 / (TAU * one_minus_cos_max(sin2_max));
    // Under ReverseOrientation the visible cap shows its back.
    (orientation * outward.dot(wi) < 0.0 && pdf.is_finite()).then_some((wi, dist, pdf))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_gain_follows_power_and_efficacy() {
        let l = Vec3::new(1.0, 0.5, 0.25);
        let e = AreaLightParams {
            l: ConstOrTexture::Const(l),
            gain: 2.0,
            power: 100.0,
            efficacy: 17.0,
        };
        let area = 0.5;
        let r = e.desc(area).radiance().unwrap();
        let expected_gain = 2.0 * 100.0 * 17.0 / (area * PI * luminance(l));
        assert!((r - l * expected_gain).abs().max_element() < 1e-3 * expected_gain);
        // Emitted luminous power then equals gain x power x efficacy: Y(L x gain) x area x pi.
        assert!((luminance(r) * area * PI - 2.0 * 1700.0).abs() < 0.5);
        let off = AreaLightParams {
            power: 0.0,
            ..e.clone()
        };
        assert_eq!(off.desc(area).radiance(), Some(l * 2.0));
        // An infinite plane has no finite power: the gain stays as given.
        assert_eq!(e.desc(f32::INFINITY).radiance(), Some(l * 2.0));
    }
}
