//! The scene description: plain data produced by the parser and consumed by the renderer's
//! build step. Every LuxRender default is already applied here, so nothing downstream needs to
//! know the file format. Transforms are object-to-world; colours are linear RGB.

use std::sync::Arc;

use glam::{Mat4, Vec3};

pub use crate::assets::{AssetKind, AssetRef};
pub use crate::diag::{SourcePos, Warning};
pub use crate::mesh::TriangleMesh;
pub use crate::param::{Fresnel, MaterialId, Tex, TextureId};

#[derive(Clone, Debug)]
pub struct SceneDesc {
    pub camera: CameraDesc,
    pub film: FilmDesc,
    pub filter: FilterDesc,
    pub integrator: IntegratorDesc,
    pub sampler: SamplerDesc,
    pub textures: Vec<TextureDesc>,
    pub materials: Vec<MaterialDesc>,
    pub shapes: Vec<ShapeDesc>,
    pub lights: Vec<LightDesc>,
    pub warnings: Vec<Warning>,
    /// Every file read or referenced besides the main file, in first-use order, no repeats.
    pub assets: Vec<AssetRef>,
}

// ---------------------------------------------------------------------------------------------
// Camera

#[derive(Clone, Debug, PartialEq)]
pub enum CameraKind {
    /// `fov` in degrees; spans the shorter screen-window axis (LuxRender rule).
    Perspective {
        fov: f32,
    },
    Orthographic,
    /// The course's fisheye (docs/architecture.md): `fov` in degrees is the angle off the axis at the
    /// circle's edge.
    Fisheye {
        fov: f32,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct CameraDesc {
    pub kind: CameraKind,
    /// Camera space: +x is image right, +y image up, +z the viewing direction.
    pub camera_to_world: Mat4,
    /// [xmin, xmax, ymin, ymax] in screen space (default follows the film aspect).
    pub screen_window: [f32; 4],
    pub lens_radius: f32,
    pub focal_distance: f32,
    pub hither: f32,
    pub yon: f32,
}

// ---------------------------------------------------------------------------------------------
// Film, filter, sampler, integrator

#[derive(Clone, Debug, PartialEq)]
pub enum ToneMap {
    /// scale = 1.25 / Yavg x (118/255)^gamma over pixels with Y > 0.
    AutoLinear,
    Linear {
        sensitivity: f32,
        exposure: f32,
        fstop: f32,
    },
    Reinhard {
        prescale: f32,
        postscale: f32,
        burn: f32,
    },
    Contrast {
        ywa: f32,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct FilmDesc {
    pub xresolution: u32,
    pub yresolution: u32,
    pub gamma: f32,
    pub tonemap: ToneMap,
    /// Output name without extension, as the file gives it (default "luxout").
    pub filename: String,
    pub haltspp: Option<u32>,
    pub halttime: Option<f32>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterKind {
    Box,
    Triangle,
    Gaussian { alpha: f32 },
    Mitchell { b: f32, c: f32 },
    BlackmanHarris,
    Sinc { tau: f32 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterDesc {
    pub kind: FilterKind,
    /// Half-widths in pixels.
    pub xwidth: f32,
    pub ywidth: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RussianRoulette {
    Efficiency,
    Probability,
    None,
}

#[derive(Clone, Debug, PartialEq)]
pub struct IntegratorDesc {
    pub max_depth: u32,
    pub rr_strategy: RussianRoulette,
    pub rr_continue_prob: f32,
    pub include_environment: bool,
    /// The SurfaceIntegrator the file named (e.g. "bidirectional" rendered as path).
    pub requested: String,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SamplerDesc {
    /// `pixelsamples` when the file gives it; the film's haltspp or the command line win.
    pub pixel_samples: Option<u32>,
    pub requested: String,
}

// ---------------------------------------------------------------------------------------------
// Textures: described in crate::texture, one file per type.

pub use crate::texture::{Mapping2D, TextureDesc, TextureKind, Wrap};

// ---------------------------------------------------------------------------------------------
// Materials

#[derive(Clone, Debug, PartialEq)]
pub enum MaterialDesc {
    Matte {
        kd: Tex,
        /// Oren-Nayar sigma in degrees.
        sigma: Tex,
    },
    /// LuxRender's Glossy2: Kd, Ks (already multiplied by ((i-1)/(i+1))^2 when index > 0),
    /// absorption Ka with depth d, anisotropic roughness.
    Glossy {
        kd: Tex,
        ks: Tex,
        ka: Tex,
        depth: Tex,
        uroughness: Tex,
        vroughness: Tex,
        multibounce: bool,
    },
    Mirror {
        kr: Tex,
    },
    /// glass and roughglass: zero roughness is the smooth specular glass.
    Glass {
        kr: Tex,
        kt: Tex,
        index: Tex,
        architectural: bool,
        uroughness: Tex,
        vroughness: Tex,
    },
    /// metal and metal2 both become a microfacet conductor.
    Metal {
        fresnel: Fresnel,
        uroughness: Tex,
        vroughness: Tex,
    },
    MatteTranslucent {
        kr: Tex,
        kt: Tex,
        sigma: Tex,
    },
    /// Invisible: rays pass through (used on emitters).
    Null,
    Mix {
        a: MaterialId,
        b: MaterialId,
        /// Weight of `b`.
        amount: Tex,
    },
}

// ---------------------------------------------------------------------------------------------
// Shapes

#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// Shared between instances of the same object.
    Mesh(Arc<TriangleMesh>),
    Sphere {
        radius: f32,
        zmin: f32,
        zmax: f32,
        /// Degrees.
        phimax: f32,
    },
    Disk {
        height: f32,
        radius: f32,
        inner_radius: f32,
        phimax: f32,
    },
    Cylinder {
        radius: f32,
        zmin: f32,
        zmax: f32,
        phimax: f32,
    },
    /// The course's infinite plane through the object-space origin with this normal.
    Plane { normal: Vec3 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct AreaLightDesc {
    /// Emitted radiance: L x gain, already normalised by power x efficacy when given.
    pub radiance: Vec3,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDesc {
    pub name: String,
    pub geometry: Geometry,
    pub object_to_world: Mat4,
    pub reverse_orientation: bool,
    pub material: MaterialId,
    pub area_light: Option<AreaLightDesc>,
}

// ---------------------------------------------------------------------------------------------
// Lights

/// How a LatLong map is indexed (docs/architecture.md): the seed tracer's u = (pi + phi) / 2pi, or
/// LuxRender's s = phi / 2pi with phi in [0, 2pi). Both use t = theta / pi.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LatLongConvention {
    #[default]
    Seed,
    LuxRender,
}

#[derive(Clone, Debug, PartialEq)]
pub struct EnvMapDesc {
    /// Path as written; listed in `assets`.
    pub filename: String,
    pub gamma: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LightDesc {
    Point {
        position: Vec3,
        /// Radiant intensity (L x gain, normalised by power x efficacy when given).
        intensity: Vec3,
    },
    Spot {
        position: Vec3,
        /// Unit direction in world space.
        direction: Vec3,
        intensity: Vec3,
        /// Degrees, LuxRender semantics (full cone half-angle, and falloff width).
        cone_angle: f32,
        cone_delta_angle: f32,
    },
    Distant {
        /// Unit direction the light travels *towards* the scene is `-to_light`.
        to_light: Vec3,
        radiance: Vec3,
    },
    Infinite {
        /// L x gain; multiplies the map when there is one.
        radiance: Vec3,
        map: Option<EnvMapDesc>,
        /// Light space has z up; this maps it to world space.
        light_to_world: Mat4,
    },
}
