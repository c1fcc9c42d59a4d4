//! Writes a parsed scene as a LuxCoreRender scene: SDL properties (`scene.scn`, `render.cfg`)
//! and world-space binary PLY meshes. LuxCore then renders the geometry, camera, materials and
//! lights exactly as YAT parsed them, which its own `.lxs` importer does not (it drops spheres
//! and planar mappings, refuses metal2's `color fresnel`, and loses named materials and the
//! camera). The benchmark's side-by-side comparison renders these exports.
//!
//! What LuxCore cannot express is either converted with a note (spheres, disks and cylinders
//! are tessellated; planar, spherical and cylindrical mappings are baked into vertex uvs;
//! infinite planes become large quads) or refused with [`ExportError::Unsupported`] (the
//! course's fisheye camera).

use std::collections::BTreeSet;
use std::f32::consts::PI;
use std::fmt::{Display, Write as _};
use std::path::Path;
use std::sync::Arc;

use glam::{Mat3, Mat4, Vec2, Vec3};
use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
    ScalarType,
};
use ply_rs_bw::writer::Writer;

use crate::desc::{
    CameraKind, FilterKind, Geometry, LatLongConvention, LightDesc, Mapping2D, MaterialDesc,
    SceneDesc, ShapeDesc, TextureKind, Wrap,
};
use crate::lights::{DistantLight, InfiniteLight, PointLight, SpotLight};
use crate::material::{
    Glass, Glossy, Matte, MatteTranslucent, Metal, Mirror, Mix as MixMaterial, Null,
};

use crate::mesh::tessellate::{plane_quad, tessellate};
use crate::mesh::TriangleMesh;

use crate::param::{Fresnel, MaterialId, Tex, TextureId};
use crate::texture::{
    Checkerboard2D, Checkerboard3D, Constant, ImageMap, Mix, Scale, TexturePoint,
};

/// Half the side of the quad an infinite plane becomes (scene units).
const PLANE_HALF_SIZE: f32 = 1.0e4;

#[derive(Clone, Debug)]
pub struct ExportOptions {
    /// How YAT indexes LatLong maps for this render; the export turns LuxCore's map to match.
    pub latlong: LatLongConvention,
    /// Segments around a tessellated sphere, disk or cylinder (half as many from pole to pole).
    pub segments: u32,
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            latlong: LatLongConvention::default(),
            segments: 256,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("LuxCore cannot render this scene faithfully: {0}")]
    Unsupported(String),
    #[error("cannot write the PLY of shape \"{shape}\": {error}")]
    Ply {
        shape: String,
        error: std::io::Error,
    },
}

/// A LuxCore scene in memory: paths in `scene` and `config` are relative to the folder the
/// files are written to (LuxCore resolves them from its working directory), image paths are
/// absolute.
#[derive(Debug)]
pub struct LuxCoreScene {
    /// `scene.scn`: camera, textures, materials, shapes, objects, lights.
    pub scene: String,
    /// `render.cfg`: film size, pixel filter and `scene.file`; the caller adds the engine,
    /// sampler, depth and halt conditions.
    pub config: String,
    /// (relative path, binary PLY bytes).
    pub meshes: Vec<(String, Vec<u8>)>,
    /// Approximations made, one line each.
    pub notes: Vec<String>,
}

impl LuxCoreScene {
    pub fn write_to(&self, dir: &Path) -> std::io::Result<()> {
        std::fs::create_dir_all(dir.join("meshes"))?;
        std::fs::write(dir.join("scene.scn"), &self.scene)?;
        std::fs::write(dir.join("render.cfg"), &self.config)?;
        for (path, bytes) in &self.meshes {
            std::fs::write(dir.join(path), bytes)?;
        }
        Ok(())
    }
}

/// SDL text: one `key = value` line per property.
#[derive(Default)]
struct Props(String);

impl Props {
    fn set(&mut self, key: impl Display, value: impl Display) {
        // Writing to a String cannot fail.
        let _ = writeln!(self.0, "{key} = {value}");
    }
}

fn v3(v: Vec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

fn quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "/").replace('"', ""))
}

fn tex_name(id: TextureId) -> String {
    format!("tex{}", id.0)
}

fn mat_name(id: MaterialId) -> String {
    format!("mat{}", id.0)
}

/// A material or texture parameter: a constant inline, a texture by name.
fn tex_value(t: &Tex, color: bool) -> String {
    match t {
        Tex::Const(c) if color => v3(*c),
        Tex::Const(c) => c.x.to_string(),
        Tex::Texture(id) => quoted(&tex_name(*id)),
    }
}

/// Whether a 2D mapping is one LuxCore lacks and the export bakes into vertex uvs.
fn is_baked(mapping: &Mapping2D) -> bool {
    !matches!(mapping, Mapping2D::Uv { .. })
}

fn push_tex(t: &Tex, out: &mut Vec<TextureId>) {
    if let Tex::Texture(id) = t {
        out.push(*id);
    }
}

/// Textures a texture reads directly.
fn texture_inputs(kind: &TextureKind) -> Vec<TextureId> {
    let mut out = Vec::new();
    for t in kind.references() {
        push_tex(&t, &mut out);
    }
    out
}

/// The one non-uv mapping the material's textures use, if any: shapes with this material get
/// it baked into their uvs. A material that also reads uv-mapped textures, or two different
/// baked mappings, cannot be expressed.
fn material_bake(desc: &SceneDesc, material: MaterialId) -> Result<Option<Mapping2D>, ExportError> {
    let mut seen_mats = BTreeSet::new();
    let mut seen_tex = BTreeSet::new();
    let mut mat_stack = vec![material];
    let mut tex_stack = Vec::new();
    while let Some(m) = mat_stack.pop() {
        if !seen_mats.insert(m.0) {
            continue;
        }
        if let Some(md) = desc.materials.get(m.0 as usize) {
            tex_stack.extend(md.textures());
            mat_stack.extend(md.materials());
        }
    }
    let mut baked: Vec<&Mapping2D> = Vec::new();
    let mut uv_mapped = false;
    while let Some(t) = tex_stack.pop() {
        if !seen_tex.insert(t.0) {
            continue;
        }
        let Some(td) = desc.textures.get(t.0 as usize) else {
            continue;
        };
        tex_stack.extend(texture_inputs(&td.kind));
        match td.kind.mapping() {
            Some(m) if is_baked(m) && !baked.contains(&m) => baked.push(m),
            Some(m) if is_baked(m) => {}
            Some(_) => uv_mapped = true,
            None => {}
        }
    }
    match baked.as_slice() {
        [] => Ok(None),
        [m] if !uv_mapped => Ok(Some((*m).clone())),
        _ => Err(ExportError::Unsupported(format!(
            "material #{} combines texture mappings that cannot share one set of vertex uvs",
            material.0
        ))),
    }
}

fn write_camera(desc: &SceneDesc, p: &mut Props) -> Result<(), ExportError> {
    let c = &desc.camera;
    let kind = match c.kind {
        CameraKind::Perspective { fov } => {
            p.set("scene.camera.fieldofview", fov);
            "perspective"
        }
        CameraKind::Orthographic => "orthographic",
        CameraKind::Fisheye { .. } => {
            return Err(ExportError::Unsupported(
                "LuxCore has no fisheye camera".into(),
            ))
        }
    };
    let m = c.camera_to_world;
    let orig = m.transform_point3(Vec3::ZERO);
    let dir = m.transform_vector3(Vec3::Z).normalize();
    let up = m.transform_vector3(Vec3::Y).normalize();
    // LuxRender's LookAt puts image right along dir x up; a camera transform that mirrors
    // this would render mirrored in LuxCore, which builds its camera from orig, target, up.
    let right = m.transform_vector3(Vec3::X);
    if right.dot(dir.cross(up)) <= 0.0 {
        return Err(ExportError::Unsupported(
            "the camera transform mirrors the image".into(),
        ));
    }
    p.set("scene.camera.type", quoted(kind));
    p.set("scene.camera.lookat.orig", v3(orig));
    p.set("scene.camera.lookat.target", v3(orig + dir));
    p.set("scene.camera.up", v3(up));
    let [x0, x1, y0, y1] = c.screen_window;
    p.set("scene.camera.screenwindow", format!("{x0} {x1} {y0} {y1}"));
    p.set("scene.camera.lensradius", c.lens_radius);
    p.set("scene.camera.focaldistance", c.focal_distance);
    p.set("scene.camera.autofocus.enable", 0);
    p.set("scene.camera.cliphither", c.hither);
    p.set("scene.camera.clipyon", c.yon);
    Ok(())
}

/// LuxCore's uvmapping2d is YAT's uv mapping (scale, then offset), and both read image row
/// t x height counted from the top, so the parameters carry over unchanged.
fn write_mapping(p: &mut Props, prefix: &str, mapping: &Mapping2D) {
    p.set(format!("{prefix}.mapping.type"), quoted("uvmapping2d"));
    let (scale, delta) = match *mapping {
        Mapping2D::Uv {
            uscale,
            vscale,
            udelta,
            vdelta,
        } => (Vec2::new(uscale, vscale), Vec2::new(udelta, vdelta)),
        // Baked: the vertex uvs already hold the texture coordinates.
        _ => (Vec2::ONE, Vec2::ZERO),
    };
    p.set(
        format!("{prefix}.mapping.uvscale"),
        format!("{} {}", scale.x, scale.y),
    );
    p.set(
        format!("{prefix}.mapping.uvdelta"),
        format!("{} {}", delta.x, delta.y),
    );
}

fn write_textures(
    desc: &SceneDesc,
    scene_dir: &Path,
    p: &mut Props,
    notes: &mut Vec<String>,
) -> Result<(), ExportError> {
    for (i, t) in desc.textures.iter().enumerate() {
        let prefix = format!("scene.textures.{}", tex_name(TextureId(i as u32)));
        let color = t.is_color;
        match &t.kind {
            TextureKind::ImageMap(ImageMap {
                filename,
                gamma,
                gain,
                wrap,
                mapping,
            }) => {
                p.set(format!("{prefix}.type"), quoted("imagemap"));
                let path = scene_dir.join(filename);
                p.set(format!("{prefix}.file"), quoted(&path.to_string_lossy()));
                p.set(format!("{prefix}.gamma"), gamma);
                p.set(format!("{prefix}.gain"), gain);
                let wrap = match wrap {
                    Wrap::Repeat => "repeat",
                    Wrap::Black => "black",
                    Wrap::White => "white",
                    Wrap::Clamp => "clamp",
                };
                p.set(format!("{prefix}.wrap"), quoted(wrap));
                if !color {
                    p.set(format!("{prefix}.channel"), quoted("mean"));
                }
                write_mapping(p, &prefix, mapping);
            }
            TextureKind::Checkerboard2D(Checkerboard2D {
                tex1,
                tex2,
                mapping,
            }) => {
                p.set(format!("{prefix}.type"), quoted("checkerboard2d"));
                p.set(format!("{prefix}.texture1"), tex_value(tex1, color));
                p.set(format!("{prefix}.texture2"), tex_value(tex2, color));
                write_mapping(p, &prefix, mapping);
            }
            TextureKind::Checkerboard3D(Checkerboard3D {
                tex1,
                tex2,
                world_to_texture,
            }) => {
                p.set(format!("{prefix}.type"), quoted("checkerboard3d"));
                p.set(format!("{prefix}.texture1"), tex_value(tex1, color));
                p.set(format!("{prefix}.texture2"), tex_value(tex2, color));
                p.set(format!("{prefix}.mapping.type"), quoted("globalmapping3d"));
                p.set(
                    format!("{prefix}.mapping.transformation"),
                    matrix(world_to_texture),
                );
                notes.push(format!(
                    "texture \"{}\": checkerboard3d in world space (YAT: the shape's object space)",
                    t.name
                ));
            }
            TextureKind::Constant(Constant { value }) => {
                p.set(format!("{prefix}.type"), quoted("constfloat3"));
                p.set(format!("{prefix}.value"), v3(*value));
            }
            TextureKind::Scale(Scale { tex1, tex2 }) => {
                p.set(format!("{prefix}.type"), quoted("scale"));
                p.set(format!("{prefix}.texture1"), tex_value(tex1, color));
                p.set(format!("{prefix}.texture2"), tex_value(tex2, color));
            }
            TextureKind::Mix(Mix { tex1, tex2, amount }) => {
                p.set(format!("{prefix}.type"), quoted("mix"));
                p.set(format!("{prefix}.texture1"), tex_value(tex1, color));
                p.set(format!("{prefix}.texture2"), tex_value(tex2, color));
                p.set(format!("{prefix}.amount"), tex_value(amount, false));
            }
            // A texture type the exporter does not map yet (none today).
            #[allow(unreachable_patterns)]
            other => {
                return Err(ExportError::Unsupported(format!(
                    "texture \"{}\": no LuxCore equivalent for type \"{}\"",
                    t.name,
                    other.name()
                )))
            }
        }
    }
    Ok(())
}

/// Matrix properties are the 16 entries column by column (glam's own order).
fn matrix(m: &Mat4) -> String {
    m.to_cols_array()
        .iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Writes material `m` under `name`; `emission` is added for emitting shapes (a null material
/// that emits becomes black matte: it shows the light and reflects nothing).
fn write_material(p: &mut Props, name: &str, m: &MaterialDesc, emission: Option<Vec3>) {
    let prefix = format!("scene.materials.{name}");
    let mut set = |key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
    match m {
        MaterialDesc::Matte(Matte { kd, sigma }) => {
            let rough = *sigma != Tex::float(0.0);
            set("type", quoted(if rough { "roughmatte" } else { "matte" }));
            set("kd", tex_value(kd, true));
            if rough {
                set("sigma", tex_value(sigma, false));
            }
        }
        MaterialDesc::Glossy(Glossy {
            kd,
            ks,
            ka,
            depth,
            uroughness,
            vroughness,
            multibounce,
        }) => {
            set("type", quoted("glossy2"));
            set("kd", tex_value(kd, true));
            set("ks", tex_value(ks, true));
            set("ka", tex_value(ka, true));
            set("d", tex_value(depth, false));
            set("uroughness", tex_value(uroughness, false));
            set("vroughness", tex_value(vroughness, false));
            set("multibounce", u8::from(*multibounce).to_string());
        }
        MaterialDesc::Mirror(Mirror { kr }) => {
            set("type", quoted("mirror"));
            set("kr", tex_value(kr, true));
        }
        MaterialDesc::Glass(Glass {
            kr,
            kt,
            index,
            architectural,
            uroughness,
            vroughness,
        }) => {
            let rough = *uroughness != Tex::float(0.0) || *vroughness != Tex::float(0.0);
            let kind = match (architectural, rough) {
                (true, _) => "archglass",
                (false, true) => "roughglass",
                (false, false) => "glass",
            };
            set("type", quoted(kind));
            set("kr", tex_value(kr, true));
            set("kt", tex_value(kt, true));
            set("interiorior", tex_value(index, false));
            set("exteriorior", "1".into());
            if rough && !architectural {
                set("uroughness", tex_value(uroughness, false));
                set("vroughness", tex_value(vroughness, false));
            }
        }
        MaterialDesc::Metal(Metal {
            fresnel,
            uroughness,
            vroughness,
        }) => {
            set("type", quoted("metal2"));
            set("fresnel", quoted(&format!("{name}_fresnel")));
            set("uroughness", tex_value(uroughness, false));
            set("vroughness", tex_value(vroughness, false));
            let fprefix = format!("scene.textures.{name}_fresnel");
            match fresnel {
                Fresnel::Reflectance(kr) => {
                    p.set(format!("{fprefix}.type"), quoted("fresnelcolor"));
                    p.set(format!("{fprefix}.kr"), tex_value(kr, true));
                }
                Fresnel::Index(n) => {
                    p.set(format!("{fprefix}.type"), quoted("fresnelconst"));
                    p.set(format!("{fprefix}.n"), tex_value(n, true));
                    p.set(format!("{fprefix}.k"), "0 0 0");
                }
                Fresnel::Conductor { eta, k } => {
                    p.set(format!("{fprefix}.type"), quoted("fresnelconst"));
                    p.set(format!("{fprefix}.n"), v3(*eta));
                    p.set(format!("{fprefix}.k"), v3(*k));
                }
            }
        }
        MaterialDesc::MatteTranslucent(MatteTranslucent { kr, kt, .. }) => {
            set("type", quoted("mattetranslucent"));
            set("kr", tex_value(kr, true));
            set("kt", tex_value(kt, true));
        }
        MaterialDesc::Null(_) if emission.is_some() => {
            set("type", quoted("matte"));
            set("kd", "0 0 0".into());
        }
        MaterialDesc::Mix(MixMaterial { a, b, amount }) => {
            set("type", quoted("mix"));
            set("material1", quoted(&mat_name(*a)));
            set("material2", quoted(&mat_name(*b)));
            set("amount", tex_value(amount, false));
        }
        // Kinds with no parameters LuxCore needs (null) go by their name.
        other => set("type", quoted(other.name())),
    }
    if let Some(radiance) = emission {
        p.set(format!("{prefix}.emission"), v3(radiance));
        p.set(format!("{prefix}.emission.gain"), "1 1 1");
        p.set(format!("{prefix}.emission.power"), 0);
        p.set(format!("{prefix}.emission.efficency"), 0);
    }
}

/// Binary little-endian PLY of a world-space mesh.
fn ply_bytes(
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    uvs: Option<&[Vec2]>,
    indices: &[[u32; 3]],
) -> std::io::Result<Vec<u8>> {
    let mut ply = Ply::<DefaultElement>::new();
    ply.header.encoding = Encoding::BinaryLittleEndian;
    let float = || PropertyType::Scalar(ScalarType::Float);
    let mut vertex = ElementDef::new("vertex".into());
    let mut names = vec!["x", "y", "z"];
    if normals.is_some() {
        names.extend(["nx", "ny", "nz"]);
    }
    if uvs.is_some() {
        // LuxCore's PLY reader takes uvs as s and t.
        names.extend(["s", "t"]);
    }
    for n in &names {
        vertex
            .properties
            .add(PropertyDef::new((*n).into(), float()));
    }
    ply.header.elements.add(vertex);
    let mut face = ElementDef::new("face".into());
    face.properties.add(PropertyDef::new(
        "vertex_indices".into(),
        PropertyType::List(ScalarType::UChar, ScalarType::UInt),
    ));
    ply.header.elements.add(face);

    let vertices = (0..positions.len())
        .map(|i| {
            let mut values = positions[i].to_array().to_vec();
            if let Some(n) = normals {
                values.extend(n[i].to_array());
            }
            if let Some(uv) = uvs {
                values.extend(uv[i].to_array());
            }
            let mut e = DefaultElement::new();
            for (name, value) in names.iter().zip(values) {
                e.insert((*name).into(), Property::Float(value));
            }
            e
        })
        .collect();
    let faces = indices
        .iter()
        .map(|tri| {
            let mut e = DefaultElement::new();
            e.insert("vertex_indices".into(), Property::ListUInt(tri.to_vec()));
            e
        })
        .collect();
    ply.payload.insert("vertex".into(), vertices);
    ply.payload.insert("face".into(), faces);
    let mut out = Vec::new();
    Writer::new()
        .write_ply(&mut out, &mut ply)
        .map_err(std::io::Error::other)?;
    Ok(out)
}

/// The shape's mesh in world space, wound so LuxCore's front face (counter-clockwise, the
/// geometric normal cross(p1 - p0, p2 - p0)) is YAT's.
fn export_shape(
    desc: &SceneDesc,
    shape: &ShapeDesc,
    opts: &ExportOptions,
    notes: &mut Vec<String>,
) -> Result<Option<Vec<u8>>, ExportError> {
    let mesh: Arc<TriangleMesh> = match &shape.geometry {
        Geometry::Mesh(m) => m.clone(),
        Geometry::Plane { normal } => {
            notes.push(format!(
                "shape \"{}\": infinite plane as a {}-unit square",
                shape.name,
                2.0 * PLANE_HALF_SIZE
            ));
            Arc::new(plane_quad(*normal, PLANE_HALF_SIZE))
        }
        g => match tessellate(g, opts.segments) {
            Some(m) => {
                notes.push(format!(
                    "shape \"{}\": tessellated into {} triangles",
                    shape.name,
                    m.indices.len()
                ));
                Arc::new(m)
            }
            None => return Ok(None),
        },
    };
    if mesh.indices.is_empty() {
        return Ok(None);
    }
    let m = shape.object_to_world;
    let linear = Mat3::from_mat4(m);
    let det = linear.determinant();
    if det == 0.0 || !det.is_finite() {
        return Ok(None);
    }
    let positions: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|&p| m.transform_point3(p))
        .collect();
    let normal_matrix = linear.inverse().transpose();
    let normals: Option<Vec<Vec3>> = mesh
        .normals
        .as_ref()
        .filter(|n| n.len() == mesh.positions.len())
        .map(|n| {
            n.iter()
                .map(|&n| (normal_matrix * n).normalize_or_zero())
                .collect()
        });
    let object_uv = |i: usize| -> Vec2 {
        mesh.uvs
            .as_ref()
            .and_then(|uv| uv.get(i))
            .map_or(Vec2::ZERO, |&[u, v]| Vec2::new(u, v))
    };
    let uvs: Option<Vec<Vec2>> = match material_bake(desc, shape.material)? {
        Some(mapping) => Some(
            (0..mesh.positions.len())
                .map(|i| {
                    mapping.map(&TexturePoint {
                        p: mesh.positions[i],
                        uv: object_uv(i),
                    })
                })
                .collect(),
        ),
        None => mesh
            .uvs
            .as_ref()
            .filter(|uv| uv.len() == mesh.positions.len())
            .map(|_| (0..mesh.positions.len()).map(object_uv).collect()),
    };
    let flip = shape.reverse_orientation ^ (det < 0.0);
    let indices: Vec<[u32; 3]> = mesh
        .indices
        .iter()
        .filter(|tri| tri.iter().all(|&i| (i as usize) < positions.len()))
        .map(|&[a, b, c]| if flip { [a, c, b] } else { [a, b, c] })
        .collect();
    ply_bytes(&positions, normals.as_deref(), uvs.as_deref(), &indices)
        .map(Some)
        .map_err(|error| ExportError::Ply {
            shape: shape.name.clone(),
            error,
        })
}

fn write_light(
    p: &mut Props,
    index: usize,
    light: &LightDesc,
    scene_dir: &Path,
    opts: &ExportOptions,
    notes: &mut Vec<String>,
) {
    let prefix = format!("scene.lights.light{index}");
    let mut set = |key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
    match light {
        LightDesc::Point(PointLight {
            position,
            intensity,
        }) => {
            set("type", quoted("point"));
            set("position", v3(*position));
            set("color", v3(*intensity));
            set("gain", "1 1 1".into());
            set("power", "0".into());
            set("efficency", "0".into());
        }
        LightDesc::Spot(SpotLight {
            position,
            direction,
            intensity,
            cone_angle,
            cone_delta_angle,
        }) => {
            set("type", quoted("spot"));
            set("position", v3(*position));
            set("target", v3(*position + *direction));
            set("color", v3(*intensity));
            set("gain", "1 1 1".into());
            set("power", "0".into());
            set("efficency", "0".into());
            set("coneangle", cone_angle.to_string());
            set("conedeltaangle", cone_delta_angle.to_string());
        }
        LightDesc::Distant(DistantLight { to_light, radiance }) => {
            set("type", quoted("distant"));
            set("direction", v3(-*to_light));
            set("color", v3(*radiance));
            set("gain", "1 1 1".into());
        }
        LightDesc::Infinite(InfiniteLight {
            radiance,
            map: None,
            ..
        }) => {
            set("type", quoted("constantinfinite"));
            set("color", v3(*radiance));
            set("gain", "1 1 1".into());
        }
        LightDesc::Infinite(InfiniteLight {
            radiance,
            map: Some(map),
            light_to_world,
        }) => {
            set("type", quoted("infinite"));
            let path = scene_dir.join(&map.filename);
            set("file", quoted(&path.to_string_lossy()));
            set("gamma", map.gamma.to_string());
            set("gain", v3(*radiance));
            // The seed's u = (pi + phi) / 2pi is LuxRender's phi / 2pi half a turn on.
            let turn = match opts.latlong {
                LatLongConvention::LuxRender => Mat4::IDENTITY,
                LatLongConvention::Seed => Mat4::from_rotation_z(PI),
            };
            set("transformation", matrix(&(*light_to_world * turn)));
        }
        // A kind added later that LuxCore has no mapping for yet.
        #[allow(unreachable_patterns)]
        other => notes.push(format!(
            "light {index} (\"{}\"): not exported",
            other.name()
        )),
    }
}

fn write_config(desc: &SceneDesc) -> String {
    let mut c = Props::default();
    c.set("scene.file", quoted("scene.scn"));
    c.set("film.width", desc.film.xresolution);
    c.set("film.height", desc.film.yresolution);
    let f = &desc.filter;
    let kind = match f.kind {
        FilterKind::Box => "BOX",
        FilterKind::Triangle | FilterKind::Sinc { .. } => "BLACKMANHARRIS",
        FilterKind::Gaussian { alpha } => {
            c.set("film.filter.gaussian.alpha", alpha);
            "GAUSSIAN"
        }
        FilterKind::Mitchell { b, c: cc } => {
            c.set("film.filter.mitchell.b", b);
            c.set("film.filter.mitchell.c", cc);
            "MITCHELL"
        }
        FilterKind::BlackmanHarris => "BLACKMANHARRIS",
    };
    c.set("film.filter.type", quoted(kind));
    c.set("film.filter.xwidth", f.xwidth);
    c.set("film.filter.ywidth", f.ywidth);
    c.0
}

/// Converts a parsed scene. `scene_dir` is the main file's folder (image paths are relative
/// to it).
pub fn export(
    desc: &SceneDesc,
    scene_dir: &Path,
    opts: &ExportOptions,
) -> Result<LuxCoreScene, ExportError> {
    let mut notes = Vec::new();
    if matches!(
        desc.filter.kind,
        FilterKind::Triangle | FilterKind::Sinc { .. }
    ) {
        notes.push("pixel filter: LuxCore has no triangle or sinc filter; Blackman-Harris".into());
    }
    let mut p = Props::default();
    write_camera(desc, &mut p)?;
    write_textures(desc, scene_dir, &mut p, &mut notes)?;
    for (i, m) in desc.materials.iter().enumerate() {
        write_material(&mut p, &mat_name(MaterialId(i as u32)), m, None);
    }
    let mut meshes = Vec::new();
    for (i, shape) in desc.shapes.iter().enumerate() {
        let Some(bytes) = export_shape(desc, shape, opts, &mut notes)? else {
            notes.push(format!("shape \"{}\": degenerate, left out", shape.name));
            continue;
        };
        let path = format!("meshes/shape{i}.ply");
        p.set(format!("scene.shapes.shape{i}.type"), quoted("mesh"));
        p.set(format!("scene.shapes.shape{i}.ply"), quoted(&path));
        let material = match &shape.area_light {
            Some(area) => {
                let name = format!("emitter{i}");
                let m = desc.materials.get(shape.material.0 as usize);
                write_material(
                    &mut p,
                    &name,
                    m.unwrap_or(&MaterialDesc::Null(Null)),
                    Some(area.radiance),
                );
                name
            }
            None => mat_name(shape.material),
        };
        p.set(
            format!("scene.objects.object{i}.shape"),
            quoted(&format!("shape{i}")),
        );
        p.set(
            format!("scene.objects.object{i}.material"),
            quoted(&material),
        );
        meshes.push((path, bytes));
    }
    for (i, light) in desc.lights.iter().enumerate() {
        write_light(&mut p, i, light, scene_dir, opts, &mut notes);
    }
    Ok(LuxCoreScene {
        scene: p.0,
        config: write_config(desc),
        meshes,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::MemorySource;
    use crate::mesh::ply::read_mesh;
    use crate::parse::parse_scene;

    fn parse(world: &str, camera: &str) -> SceneDesc {
        let text = format!(
            "LookAt 0 -5 1  0 0 1  0 0 1\n{camera}\n\
             Film \"fleximage\" \"integer xresolution\" [64] \"integer yresolution\" [32]\n\
             WorldBegin\n{world}\nWorldEnd\n"
        );
        let mut png = Vec::new();
        image::RgbImage::new(2, 2)
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let mut source = MemorySource::new();
        source.insert("main.lxs", text.into_bytes().into());
        source.insert("c.png", png.into());
        parse_scene("main.lxs", &source).expect("test scene parses")
    }

    fn export_world(world: &str) -> LuxCoreScene {
        let desc = parse(world, "Camera \"perspective\" \"float fov\" [40]");
        export(&desc, Path::new("/scenes"), &ExportOptions::default()).expect("exports")
    }

    /// The value of `key` in SDL text.
    fn value<'a>(scn: &'a str, key: &str) -> &'a str {
        scn.lines()
            .find_map(|l| l.strip_prefix(key)?.strip_prefix(" = "))
            .unwrap_or_else(|| panic!("{key} missing from\n{scn}"))
    }

    fn floats(s: &str) -> Vec<f32> {
        s.split_whitespace().map(|x| x.parse().unwrap()).collect()
    }

    #[test]
    fn camera_keeps_lookat_fov_and_screen_window() {
        let lux = export_world("");
        let scn = &lux.scene;
        assert_eq!(value(scn, "scene.camera.type"), "\"perspective\"");
        assert_eq!(
            floats(value(scn, "scene.camera.lookat.orig")),
            [0.0, -5.0, 1.0]
        );
        let target = floats(value(scn, "scene.camera.lookat.target"));
        assert!((target[1] + 4.0).abs() < 1e-5 && (target[2] - 1.0).abs() < 1e-5);
        assert_eq!(floats(value(scn, "scene.camera.fieldofview")), [40.0]);
        assert_eq!(
            floats(value(scn, "scene.camera.screenwindow")),
            [-2.0, 2.0, -1.0, 1.0]
        );
        assert_eq!(value(&lux.config, "film.width"), "64");
    }

    #[test]
    fn fisheye_is_refused() {
        let desc = parse("", "Camera \"fisheye\" \"float fov\" [90]");
        let err = export(&desc, Path::new("."), &ExportOptions::default()).unwrap_err();
        assert!(err.to_string().contains("fisheye"), "{err}");
    }

    #[test]
    fn emitter_gets_its_own_black_material_with_the_parsed_radiance() {
        let lux = export_world(
            "AttributeBegin\nMaterial \"null\"\n\
             AreaLightSource \"area\" \"color L\" [1 0.5 0.25] \"float gain\" [4] \"float power\" [0]\n\
             Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 2 1 0 2 0 1 2]\n\
             AttributeEnd",
        );
        let scn = &lux.scene;
        assert_eq!(value(scn, "scene.objects.object0.material"), "\"emitter0\"");
        assert_eq!(value(scn, "scene.materials.emitter0.type"), "\"matte\"");
        assert_eq!(floats(value(scn, "scene.materials.emitter0.kd")), [0.0; 3]);
        assert_eq!(
            floats(value(scn, "scene.materials.emitter0.emission")),
            [4.0, 2.0, 1.0]
        );
    }

    #[test]
    fn meshes_are_world_space_and_reverse_orientation_swaps_winding() {
        let shape = "Shape \"trianglemesh\" \"integer indices\" [0 1 2] \
                     \"point P\" [0 0 0 1 0 0 0 1 0]";
        for (reverse, mirror) in [(false, false), (true, false), (false, true), (true, true)] {
            let lux = export_world(&format!(
                "AttributeBegin\nTranslate 1 2 3\n{}{}{shape}\nAttributeEnd",
                if reverse { "ReverseOrientation\n" } else { "" },
                if mirror { "Scale -1 1 1\n" } else { "" },
            ));
            let mesh = read_mesh(&lux.meshes[0].1).expect("our PLY reads back");
            let x = if mirror { -1.0 } else { 1.0 };
            assert_eq!(
                mesh.positions,
                [
                    Vec3::new(1.0, 2.0, 3.0),
                    Vec3::new(1.0 + x, 2.0, 3.0),
                    Vec3::new(1.0, 3.0, 3.0)
                ]
            );
            let swapped = reverse ^ mirror;
            let expected = if swapped { [0, 2, 1] } else { [0, 1, 2] };
            assert_eq!(
                mesh.indices,
                [expected],
                "reverse {reverse} mirror {mirror}"
            );
        }
    }

    #[test]
    fn planar_mapping_is_baked_into_vertex_uvs() {
        let lux = export_world(
            "Texture \"checks\" \"color\" \"imagemap\" \"string filename\" [\"c.png\"] \
             \"string mapping\" [\"planar\"] \"float udelta\" [0.5] \"float vdelta\" [0.25]\n\
             Material \"matte\" \"texture Kd\" [\"checks\"]\n\
             AttributeBegin\nTranslate 10 0 0\nScale 3 3 3\n\
             Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0]\n\
             AttributeEnd",
        );
        let scn = &lux.scene;
        assert_eq!(value(scn, "scene.textures.tex0.file"), "\"/scenes/c.png\"");
        assert_eq!(
            floats(value(scn, "scene.textures.tex0.mapping.uvscale")),
            [1.0, 1.0]
        );
        assert_eq!(
            floats(value(scn, "scene.textures.tex0.mapping.uvdelta")),
            [0.0, 0.0]
        );
        // Planar mapping projects the object-space point: (0,0), (1,0), (0,1) plus delta.
        let mesh = read_mesh(&lux.meshes[0].1).unwrap();
        assert_eq!(mesh.uvs.unwrap(), [[0.5, 0.25], [1.5, 0.25], [0.5, 1.25]]);
    }

    #[test]
    fn uv_mapping_parameters_carry_over_and_metal2_gets_a_fresnel_texture() {
        let lux = export_world(
            "Texture \"t\" \"color\" \"imagemap\" \"string filename\" [\"c.png\"] \
             \"float vscale\" [-1] \"float vdelta\" [1]\n\
             Material \"metal2\" \"color fresnel\" [0.4 0.4 0.4] \"float uroughness\" [0.1] \
             \"float vroughness\" [0.1]\n\
             Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0]",
        );
        let scn = &lux.scene;
        assert_eq!(
            floats(value(scn, "scene.textures.tex0.mapping.uvscale")),
            [1.0, -1.0]
        );
        assert_eq!(
            floats(value(scn, "scene.textures.tex0.mapping.uvdelta")),
            [0.0, 1.0]
        );
        let m = value(scn, "scene.objects.object0.material").trim_matches('"');
        assert_eq!(
            value(scn, &format!("scene.materials.{m}.type")),
            "\"metal2\""
        );
        let fresnel = value(scn, &format!("scene.materials.{m}.fresnel")).trim_matches('"');
        let fresnel = format!("scene.textures.{fresnel}");
        assert_eq!(value(scn, &format!("{fresnel}.type")), "\"fresnelcolor\"");
        assert_eq!(floats(value(scn, &format!("{fresnel}.kr"))), [0.4; 3]);
    }
}
