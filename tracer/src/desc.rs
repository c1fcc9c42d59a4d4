//! The scene description: plain data produced by the parser and consumed by the renderer's
//! build step. Every LuxRender default is already applied here, so nothing downstream needs to
//! know the file format. Transforms are object-to-world; colours are linear RGB.

use std::sync::Arc;

use glam::{Mat4, Vec3};

pub use crate::assets::{AssetKind, AssetRef};
pub use crate::diag::{SourcePos, Warning};
pub use crate::lights::{
    AreaLightDesc, DistantLight, EnvMapDesc, InfiniteLight, LatLongConvention, LightDesc,
    PointLight, SpotLight,
};
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
// Textures

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    Black,
    White,
    Clamp,
}

/// 2D texture-coordinate generation. `world_to_texture` is the inverse of the transform current
/// at the `Texture` statement.
#[derive(Clone, Debug, PartialEq)]
pub enum Mapping2D {
    /// s = uscale x u + udelta, t = vscale x v + vdelta.
    Uv {
        uscale: f32,
        vscale: f32,
        udelta: f32,
        vdelta: f32,
    },
    /// s = uscale x phi / 2pi + udelta, t = vscale x theta / pi + vdelta.
    Spherical {
        world_to_texture: Mat4,
        uscale: f32,
        vscale: f32,
        udelta: f32,
        vdelta: f32,
    },
    /// s = uscale x phi / 2pi + udelta, t = vscale x (1 - z) / 2 + vdelta.
    Cylindrical {
        world_to_texture: Mat4,
        uscale: f32,
        vscale: f32,
        udelta: f32,
        vdelta: f32,
    },
    /// s = dot(p, v1) + udelta, t = dot(p, v2) + vdelta with p in texture space.
    Planar {
        world_to_texture: Mat4,
        v1: Vec3,
        v2: Vec3,
        udelta: f32,
        vdelta: f32,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub enum TextureKind {
    ImageMap {
        /// Path as written, relative to the main file's folder; listed in `assets`.
        filename: String,
        gamma: f32,
        gain: f32,
        wrap: Wrap,
        mapping: Mapping2D,
    },
    Checkerboard2D {
        tex1: Tex,
        tex2: Tex,
        mapping: Mapping2D,
    },
    Checkerboard3D {
        tex1: Tex,
        tex2: Tex,
        world_to_texture: Mat4,
    },
    Constant(Vec3),
    Scale {
        tex1: Tex,
        tex2: Tex,
    },
    Mix {
        tex1: Tex,
        tex2: Tex,
        amount: Tex,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct TextureDesc {
    pub name: String,
    /// "float" or "color" textures: a float texture's value is splatted over RGB.
    pub is_color: bool,
    pub kind: TextureKind,
}

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
pub struct ShapeDesc {
    pub name: String,
    pub geometry: Geometry,
    pub object_to_world: Mat4,
    pub reverse_orientation: bool,
    pub material: MaterialId,
    pub area_light: Option<AreaLightDesc>,
}
