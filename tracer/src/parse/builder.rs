//! The graphics state machine: walks statements in file order (following Includes), keeps
//! the current transform, attribute stack, named textures, materials and objects, and collects
//! the scene description.

use std::collections::hash_map::Entry;
use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use glam::{Mat4, Vec3};

use super::context::{BoundTexture, ImageUse, ParseContext};
use super::error::ParseError;
use super::luxrender_params::{plugin, verdict, Verdict};
use super::options::OptionsState;
use super::params::ParamList;
use super::reader::Reader;
use crate::assets::AssetSource;
use crate::assets::{AssetKind, AssetRef};
use crate::budget::{BudgetMeter, BuildGuard, Limit};
use crate::desc::{LightDesc, MaterialDesc, SceneDesc, ShapeDesc, TextureDesc, TextureKind};
use crate::diag::SourcePos as Pos;
use crate::diag::{Severity, Warning};
use crate::film::light_groups::{LightGroupDesc, LightGroups, DEFAULT_GROUP, MAX_LIGHT_GROUPS};
use crate::geometry::placed_bytes;
use crate::image_io::ImageCost;
use crate::lights::{map_cost, AreaLightParams, PortalDesc, SkyLight, MAX_PORTAL_TRIANGLES};
use crate::material::{Glass, Matte};
use crate::medium::integrator::VolumeIntegrator;
use crate::medium::{MediumDesc, MediumId, ShapeMedia, Volumes};
use crate::mesh::{ply, TriangleMesh};
use crate::refs::{ConstOrTexture, MaterialId, TextureId};
use crate::shape::{AreaLightDesc, Geometry};
use crate::texture::{self, Defined, Scale};
use crate::wavelength::Dispersion;
use image::ImageDecoder;

/// Include files may nest this deep (the main file is depth 0).
pub const MAX_INCLUDE_DEPTH: usize = 32;

#[derive(Clone, Debug, Default)]
struct GraphicsState {
    material: Option<MaterialId>,
    area_light: Option<AreaLightParams>,
    reverse_orientation: bool,
    /// `Interior` and `Exterior`.
    media: ShapeMedia,
    /// The lights (indices into `lights`) of the last `LightSource` of this attribute block:
    /// what a `PortalShape` lets in (LuxRender's `currentLight`).
    current_lights: Option<std::ops::Range<u32>>,
    /// The group of the `LightGroup` statement in force (an index into the builder's light
    /// groups); None: "default".
    light_group: Option<u8>,
}

#[derive(Clone, Debug)]
struct NamedTexture {
    name: String,
    is_color: bool,
    binding: BoundTexture,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FrameKind {
    Attribute,
    Transform,
    Object,
}

impl FrameKind {
    fn begin(self) -> &'static str {
        match self {
            FrameKind::Attribute => "AttributeBegin",
            FrameKind::Transform => "TransformBegin",
            FrameKind::Object => "ObjectBegin",
        }
    }
}

struct Frame {
    kind: FrameKind,
    pos: Pos,
    ctm: Mat4,
    /// Saved graphics state and texture scope (attribute and object blocks only).
    saved: Option<(GraphicsState, usize)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Block {
    Options,
    World,
    Ended,
}

/// A shape as defined, before instancing and area-light normalisation.
#[derive(Clone, Debug)]
pub struct PendingShape {
    pub desc: ShapeDesc,
    /// The area light and its light group.
    pub emitter: Option<(AreaLightParams, u8)>,
}

pub struct Builder<'s> {
    pub(super) source: &'s dyn AssetSource,
    guard: BuildGuard<'s>,
    spent: BudgetMeter,
    /// The main file's name, for diagnostics about the scene as a whole.
    main: String,
    include_stack: Vec<String>,
    pub(super) ctm: Mat4,
    named_coords: HashMap<String, Mat4>,
    gs: GraphicsState,
    stack: Vec<Frame>,
    block: Block,
    /// Inside MotionBegin/End: whether the block's first transform was applied already.
    motion: Option<bool>,
    options: OptionsState,
    textures_in_scope: Vec<NamedTexture>,
    named_materials: HashMap<String, MaterialId>,
    default_material: Option<MaterialId>,
    objects: HashMap<String, Vec<PendingShape>>,
    /// PLY meshes by file name, shared by every shape that loads the same file.
    ply_meshes: HashMap<String, Arc<TriangleMesh>>,
    current_object: Option<(String, Vec<PendingShape>)>,
    pub(super) textures: Vec<TextureDesc>,
    pub(super) materials: Vec<MaterialDesc>,
    shapes: Vec<ShapeDesc>,
    portals: Vec<PortalDesc>,
    pub(super) lights: Vec<LightDesc>,
    light_groups: LightGroups,
    /// `MakeNamedVolume` names; None for a kind that is not rendered (a warning).
    named_volumes: HashMap<String, Option<MediumId>>,
    volumes: Volumes,
    /// The `VolumeIntegrator` statement, if the file has one.
    volume_integrator: Option<(VolumeIntegrator, Pos)>,
    /// glass2 materials with the index of a shape's volumes, by (glass2, volumes).
    glass2_with_index: HashMap<(MaterialId, ShapeMedia), MaterialId>,
    warnings: Vec<Warning>,
    /// The index in `warnings` of each kind's first occurrence.
    warned: HashMap<String, usize>,
    assets: Vec<AssetRef>,
    asset_set: HashSet<AssetRef>,
    /// Image headers read so far: (width, height, colour type) by path.
    image_headers: HashMap<String, (u32, u32, image::ColorType)>,
    /// Image textures counted against the memory budget, by (path, gamma's bits): each is
    /// decoded once.
    texture_images: HashSet<(String, u32)>,
}

impl<'s> Builder<'s> {
    pub fn new(source: &'s dyn AssetSource, guard: BuildGuard<'s>) -> Self {
        Self {
            source,
            guard,
            spent: BudgetMeter::default(),
            main: String::new(),
            include_stack: Vec::new(),
            ctm: Mat4::IDENTITY,
            named_coords: HashMap::new(),
            gs: GraphicsState::default(),
            stack: Vec::new(),
            block: Block::Options,
            motion: None,
            options: OptionsState::default(),
            textures_in_scope: Vec::new(),
            named_materials: HashMap::new(),
            default_material: None,
            objects: HashMap::new(),
            ply_meshes: HashMap::new(),
            current_object: None,
            textures: Vec::new(),
            materials: Vec::new(),
            shapes: Vec::new(),
            portals: Vec::new(),
            lights: Vec::new(),
            light_groups: LightGroups::default(),
            named_volumes: HashMap::new(),
            volumes: Volumes::default(),
            volume_integrator: None,
            glass2_with_index: HashMap::new(),
            warnings: Vec::new(),
            warned: HashMap::new(),
            assets: Vec::new(),
            asset_set: HashSet::new(),
            image_headers: HashMap::new(),
            texture_images: HashSet::new(),
        }
    }

    // -----------------------------------------------------------------------------------------
    // Budget

    /// Adds to a figure of the build budget what the statement at `pos` costs.
    pub(super) fn spend(&mut self, limit: Limit, amount: u64, pos: &Pos) -> Result<(), ParseError> {
        self.spent
            .spend(self.guard.budget, limit, amount)
            .map_err(|exceeded| ParseError::OverBudget {
                pos: pos.clone(),
                exceeded,
            })
    }

    /// Adds what an image costs in memory (kept, and transient while it is made) to the build
    /// budget for the statement at `pos`.
    fn spend_image(&mut self, cost: ImageCost, pos: &Pos) -> Result<(), ParseError> {
        self.spent
            .spend_with_transient(
                self.guard.budget,
                Limit::MemoryBytes,
                cost.kept,
                cost.transient,
            )
            .map_err(|exceeded| ParseError::OverBudget {
                pos: pos.clone(),
                exceeded,
            })
    }

    // -----------------------------------------------------------------------------------------
    // Files and statements

    pub fn run_file(&mut self, name: &str, text: &[u8]) -> Result<(), ParseError> {
        if self.include_stack.is_empty() {
            self.main = name.to_string();
        }
        self.include_stack.push(name.to_string());
        let mut r = Reader::new(name, text);
        while let Some((keyword, pos)) = r.keyword()? {
            self.guard
                .check_cancel()
                .map_err(|_| ParseError::Cancelled { pos: pos.clone() })?;
            self.statement(keyword, &pos, &mut r)?;
        }
        self.include_stack.pop();
        Ok(())
    }

    fn include(&mut self, path: String, pos: &Pos) -> Result<(), ParseError> {
        if self.include_stack.contains(&path) {
            let mut chain = self.include_stack.join(" -> ");
            chain.push_str(" -> ");
            chain.push_str(&path);
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!("Include cycle: {chain}"),
            });
        }
        if self.include_stack.len() > MAX_INCLUDE_DEPTH {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!(
                    "Include \"{path}\": includes nest deeper than {MAX_INCLUDE_DEPTH} levels"
                ),
            });
        }
        self.spend(Limit::IncludeVisits, 1, pos)?;
        let bytes = self.read_asset(&path, AssetKind::Include, pos)?;
        self.spend(Limit::ParsedBytes, bytes.len() as u64, pos)?;
        self.run_file(&path, &bytes)
    }

    fn statement(&mut self, keyword: &str, pos: &Pos, r: &mut Reader) -> Result<(), ParseError> {
        if self.block == Block::Ended {
            r.skip_statement()?;
            self.note_once(
                "after WorldEnd".into(),
                pos,
                format!("{keyword} after WorldEnd: statements after WorldEnd are ignored"),
            );
            return Ok(());
        }
        match keyword {
            "Identity" => self.transform(Mat4::IDENTITY, false, pos)?,
            "Translate" => {
                let v = r.numbers::<3>("Translate")?;
                self.transform(Mat4::from_translation(Vec3::from_array(v)), true, pos)?;
            }
            "Scale" => {
                let v = r.numbers::<3>("Scale")?;
                self.transform(Mat4::from_scale(Vec3::from_array(v)), true, pos)?;
            }
            "Rotate" => {
                let [angle, x, y, z] = r.numbers::<4>("Rotate")?;
                let axis = Vec3::new(x, y, z);
                if axis.length_squared() == 0.0 || !axis.length_squared().is_finite() {
                    return Err(ParseError::Invalid {
                        pos: pos.clone(),
                        message: "Rotate: the axis must be a non-zero vector".into(),
                    });
                }
                let m = Mat4::from_axis_angle(axis.normalize(), angle.to_radians());
                self.transform(m, true, pos)?;
            }
            "LookAt" => {
                let v = r.numbers::<9>("LookAt")?;
                let m = look_at(
                    Vec3::new(v[0], v[1], v[2]),
                    Vec3::new(v[3], v[4], v[5]),
                    Vec3::new(v[6], v[7], v[8]),
                )
                .ok_or_else(|| ParseError::Invalid {
                    pos: pos.clone(),
                    message: "LookAt: the eye and target coincide, or the up vector is parallel to the viewing direction".into(),
                })?;
                self.transform(m, true, pos)?;
            }
            "Transform" | "ConcatTransform" => {
                let v = r.numbers::<16>(keyword)?;
                self.transform(Mat4::from_cols_array(&v), keyword == "ConcatTransform", pos)?;
            }
            "CoordinateSystem" => {
                let name = r.string("a coordinate system name")?;
                self.named_coords.insert(name, self.ctm);
            }
            "CoordSysTransform" => {
                let name = r.string("a coordinate system name")?;
                match self.named_coords.get(&name) {
                    Some(m) => self.ctm = *m,
                    None => self.note(
                        pos,
                        format!("CoordSysTransform: no coordinate system named \"{name}\""),
                    ),
                }
            }
            "MotionBegin" => {
                r.number_array("MotionBegin")?;
                self.motion = Some(false);
                self.warn_once(
                    "motion".into(),
                    pos,
                    "MotionBegin: motion blur is not rendered; each motion block uses its first transform".into()
                );
            }
            "MotionEnd" => self.motion = None,
            "AttributeBegin" => self.push(FrameKind::Attribute, pos),
            "TransformBegin" => self.push(FrameKind::Transform, pos),
            "AttributeEnd" => self.pop(FrameKind::Attribute, pos),
            "TransformEnd" => self.pop(FrameKind::Transform, pos),
            "WorldBegin" => {
                if self.block == Block::World {
                    self.note(pos, "WorldBegin inside the world block ignored".into());
                } else {
                    self.block = Block::World;
                    self.ctm = Mat4::IDENTITY;
                    self.named_coords.insert("world".into(), Mat4::IDENTITY);
                }
            }
            "WorldEnd" => {
                for f in std::mem::take(&mut self.stack) {
                    self.note(&f.pos, format!("{} is never closed", f.kind.begin()));
                }
                // LuxRender gives the camera the Exterior current at WorldEnd.
                self.volumes.camera = self.gs.media.exterior;
                self.block = Block::Ended;
            }
            "Include" => {
                let path = r.string("the file to include")?;
                self.include(path, pos)?;
            }
            "Camera" | "Film" | "PixelFilter" | "Sampler" | "SurfaceIntegrator" => {
                let ty = r.string(&format!("the {keyword} type"))?;
                let params = r.params(format!("{keyword} \"{ty}\""))?;
                if self.block == Block::World {
                    self.note(pos, format!("{keyword} inside the world block is ignored (it belongs before WorldBegin)"));
                    return Ok(());
                }
                if keyword == "Camera" {
                    self.named_coords
                        .insert("camera".into(), crate::math::inverse(&self.ctm));
                }
                let mut options = std::mem::take(&mut self.options);
                let read = options.read(self, keyword, ty, params, pos);
                self.options = options;
                read?;
            }
            "Accelerator" | "Renderer" | "VolumeIntegrator" => {
                let ty = r.string(&format!("the {keyword} type"))?;
                let params = r.params(format!("{keyword} \"{ty}\""))?;
                if self.block == Block::World {
                    self.note(pos, format!("{keyword} inside the world block is ignored (it belongs before WorldBegin)"));
                    return Ok(());
                }
                if keyword == "VolumeIntegrator" {
                    let integrator = VolumeIntegrator::read(self, &ty, pos);
                    self.volume_integrator = Some((integrator, pos.clone()));
                } else if plugin(&params.statement).is_none() {
                    self.note(
                        pos,
                        format!("{keyword} \"{ty}\" is not a LuxRender 1.x {}; YAT renders the same image with its own", keyword.to_lowercase()),
                    );
                }
                self.warn_unused(&params);
            }
            "LightGroup" => {
                let name = r.string("the light group's name")?;
                let params = r.params(format!("LightGroup \"{name}\""))?;
                if self.block != Block::World {
                    self.note(pos, "LightGroup outside the world block is ignored, as LuxRender 1.x ignores it".into());
                    params.ignore_all();
                    return Ok(());
                }
                let group = self.light_group_named(&name, pos)?;
                self.light_groups.groups[usize::from(group)].read_settings(&params)?;
                if !params.params.is_empty() {
                    self.diagnose(
                        Severity::Note,
                        "LightGroup settings".into(),
                        pos,
                        "LightGroup settings (enabled, scale, rgbscale, temperature) weigh the \
                         group in YAT's image, as LuxRender 1.x's window and .flm weigh it; \
                         LuxRender's parser leaves them"
                            .into(),
                    );
                }
                self.gs.light_group = Some(group);
                self.warn_unused(&params);
            }
            "SearchPath" => {
                r.string("the search path")?;
                self.note_once(
                    "SearchPath".into(),
                    pos,
                    "SearchPath is ignored, as LuxRender 1.x's parser ignores it: files are \
                     found relative to the scene file"
                        .into(),
                );
            }
            "Volume" => {
                r.skip_statement()?;
                self.warn_once(
                    "volume regions".into(),
                    pos,
                    "Volume: volume regions are not rendered (named volumes given as Interior and Exterior are); ignored".into(),
                );
            }
            "Texture" | "Material" | "MakeNamedMaterial" | "NamedMaterial" | "LightSource"
            | "AreaLightSource" | "Shape" | "ReverseOrientation" | "ObjectBegin" | "ObjectEnd"
            | "ObjectInstance" | "MakeNamedVolume" | "Interior" | "Exterior" | "PortalShape" => {
                if self.block == Block::Options {
                    r.skip_statement()?;
                    self.note(pos, format!("{keyword} before WorldBegin is ignored"));
                    return Ok(());
                }
                self.world_statement(keyword, pos, r)?;
            }
            _ => {
                r.skip_statement()?;
                self.warn_once(
                    format!("statement|{keyword}"),
                    pos,
                    format!("unknown statement `{keyword}` ignored"),
                );
            }
        }
        Ok(())
    }

    fn world_statement(
        &mut self,
        keyword: &str,
        pos: &Pos,
        r: &mut Reader,
    ) -> Result<(), ParseError> {
        match keyword {
            "Texture" => {
                let name = r.string("the texture name")?;
                let kind = r.string("the texture kind (\"float\" or \"color\")")?;
                let class = r.string("the texture type")?;
                let params = r.params(format!("Texture \"{class}\""))?;
                let defined = texture::read(&name, &kind, &class, &params, pos, self)?;
                self.define_texture(name, defined);
                self.warn_unused(&params);
            }
            "Material" => {
                let ty = r.string("the material type")?;
                let params = r.params(format!("Material \"{ty}\""))?;
                let ty = if ty.is_empty() {
                    params.string_or("type", "matte")?
                } else {
                    ty
                };
                let id = self.material(&ty, &params, pos)?;
                self.gs.material = Some(id);
            }
            "MakeNamedMaterial" => {
                let name = r.string("the material name")?;
                let params = r.params("MakeNamedMaterial".into())?;
                let ty = params.string_or("type", "matte")?;
                let params = ParamList::new(format!("Material \"{ty}\""), params.params);
                let id = self.material(&ty, &params, pos)?;
                self.named_materials.insert(name, id);
            }
            "NamedMaterial" => {
                let name = r.string("the material name")?;
                match self.named_materials.get(&name) {
                    Some(&id) => self.gs.material = Some(id),
                    None => self.note(pos, format!("NamedMaterial: no material named \"{name}\"; the current material stays")),
                }
            }
            "LightSource" => {
                let ty = r.string("the light type")?;
                let params = r.params(format!("LightSource \"{ty}\""))?;
                if self.current_object.is_some() {
                    self.warn_once("light in object".into(), pos, "LightSource inside ObjectBegin is not instanced; it is added once where defined".into());
                }
                let lights = crate::lights::read(&ty, &params, pos, self)?;
                let skies = lights
                    .iter()
                    .filter(|l| matches!(l, LightDesc::Sky(_)))
                    .count();
                self.spend(Limit::Texels, skies as u64 * SkyLight::TABLE_TEXELS, pos)?;
                for _ in 0..skies {
                    self.spend_image(SkyLight::table_cost(), pos)?;
                }
                let exterior = self.gs.media.exterior;
                self.volumes.lights.extend(lights.iter().map(|_| exterior));
                let group = self.light_group(pos)?;
                self.light_groups
                    .of_sources
                    .extend(lights.iter().map(|_| group));
                let first = self.lights.len() as u32;
                self.lights.extend(lights);
                self.gs.current_lights = Some(first..self.lights.len() as u32);
                self.warn_unused(&params);
            }
            "AreaLightSource" => {
                let ty = r.string("the area light type")?;
                let params = r.params(format!("AreaLightSource \"{ty}\""))?;
                self.gs.area_light = Some(AreaLightParams::read(&ty, &params, pos, self)?);
                self.warn_unused(&params);
            }
            "Shape" => {
                let ty = r.string("the shape type")?;
                let params = r.params(format!("Shape \"{ty}\""))?;
                self.shape_statement(&ty, &params, pos)?;
                self.warn_unused(&params);
            }
            "PortalShape" => {
                let ty = r.string("the shape type")?;
                let params = r.params(format!("PortalShape \"{ty}\""))?;
                self.portal_statement(&ty, &params, pos)?;
                self.warn_unused(&params);
            }
            "ReverseOrientation" => self.gs.reverse_orientation = !self.gs.reverse_orientation,
            "MakeNamedVolume" => {
                let name = r.string("the volume name")?;
                let ty = r.string("the volume type")?;
                let params = r.params(format!("MakeNamedVolume \"{ty}\""))?;
                let medium = MediumDesc::read(&ty, &params, pos, self)?.map(|m| {
                    self.volumes.media.push(m);
                    MediumId(self.volumes.media.len() as u32 - 1)
                });
                if self.named_volumes.insert(name.clone(), medium).is_some() {
                    self.warn(pos, format!("MakeNamedVolume: volume \"{name}\" redefined; later shapes use the new one"));
                }
                self.warn_unused(&params);
            }
            "Interior" | "Exterior" => {
                let name = r.string("the volume name")?;
                // The empty name is LuxRender's "no volume".
                let medium = if name.is_empty() {
                    None
                } else {
                    match self.named_volumes.get(&name) {
                        Some(&m) => m,
                        None => {
                            self.warn(
                                pos,
                                format!("{keyword}: no volume named \"{name}\"; using none"),
                            );
                            None
                        }
                    }
                };
                if keyword == "Interior" {
                    self.gs.media.interior = medium;
                } else {
                    self.gs.media.exterior = medium;
                }
            }
            "ObjectBegin" => {
                let name = r.string("the object name")?;
                if let Some((open, _)) = &self.current_object {
                    return Err(ParseError::Invalid {
                        pos: pos.clone(),
                        message: format!(
                            "ObjectBegin \"{name}\" inside object \"{open}\": objects cannot nest"
                        ),
                    });
                }
                self.push(FrameKind::Object, pos);
                self.current_object = Some((name, Vec::new()));
            }
            "ObjectEnd" => {
                if self.current_object.is_none() {
                    self.note(pos, "ObjectEnd without ObjectBegin ignored".into());
                } else {
                    self.pop(FrameKind::Object, pos);
                }
            }
            "ObjectInstance" => {
                let name = r.string("the object name")?;
                match self.objects.get(&name) {
                    Some(shapes) => {
                        let shapes = shapes.clone();
                        for mut s in shapes {
                            // LuxRender: an instance's volumes, where set, override its shapes'.
                            let own = s.desc.media;
                            s.desc.media = ShapeMedia {
                                interior: self.gs.media.interior.or(own.interior),
                                exterior: self.gs.media.exterior.or(own.exterior),
                            };
                            self.emit_shape(s, self.ctm, pos)?;
                        }
                    }
                    None => self.note(pos, format!("ObjectInstance: no object named \"{name}\"")),
                }
            }
            _ => unreachable!("dispatched world statements only"),
        }
        Ok(())
    }

    // -----------------------------------------------------------------------------------------
    // Transforms and blocks

    /// Applies a transform statement: post-multiplies (`concat`) or replaces the current
    /// matrix. Inside a motion block only the first transform counts. A product that overflows
    /// (`Scale 1e30` twice) is refused: nothing placed under it could be rendered.
    fn transform(&mut self, m: Mat4, concat: bool, pos: &Pos) -> Result<(), ParseError> {
        if let Some(applied) = self.motion {
            if applied {
                return Ok(());
            }
            self.motion = Some(true);
        }
        let ctm = if concat { self.ctm * m } else { m };
        if !ctm.is_finite() {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: "the transform overflows: the current matrix would hold a value beyond \
                          the range of 32-bit floats"
                    .into(),
            });
        }
        self.ctm = ctm;
        Ok(())
    }

    fn push(&mut self, kind: FrameKind, pos: &Pos) {
        let saved =
            (kind != FrameKind::Transform).then(|| (self.gs.clone(), self.textures_in_scope.len()));
        self.stack.push(Frame {
            kind,
            pos: pos.clone(),
            ctm: self.ctm,
            saved,
        });
    }

    fn pop(&mut self, kind: FrameKind, pos: &Pos) {
        let end = match kind {
            FrameKind::Attribute => "AttributeEnd",
            FrameKind::Transform => "TransformEnd",
            FrameKind::Object => "ObjectEnd",
        };
        let Some(frame) = self.stack.pop() else {
            self.note(pos, format!("{end} without a matching begin ignored"));
            return;
        };
        if frame.kind != kind {
            self.note(
                pos,
                format!("{end} closes the {} at {}", frame.kind.begin(), frame.pos),
            );
        }
        self.ctm = frame.ctm;
        if let Some((gs, textures_len)) = frame.saved {
            self.gs = gs;
            self.textures_in_scope.truncate(textures_len);
        }
        if frame.kind == FrameKind::Object {
            if let Some((name, shapes)) = self.current_object.take() {
                self.objects.insert(name, shapes);
            }
        }
    }

    // -----------------------------------------------------------------------------------------
    // Names

    pub(super) fn bind_texture(&mut self, name: String, is_color: bool, binding: BoundTexture) {
        self.textures_in_scope.push(NamedTexture {
            name,
            is_color,
            binding,
        });
    }

    /// Binds what a `Texture` statement defined (if anything) to its name.
    fn define_texture(&mut self, name: String, defined: Option<Defined>) {
        match defined {
            Some(Defined::Texture(desc)) => {
                let is_color = desc.is_color;
                let id = self.add_texture(desc);
                self.bind_texture(name, is_color, BoundTexture::Texture(id));
            }
            Some(Defined::Fresnel(f)) => self.bind_texture(name, true, BoundTexture::Fresnel(f)),
            None => {}
        }
    }

    pub(super) fn add_texture(&mut self, t: TextureDesc) -> TextureId {
        self.textures.push(t);
        TextureId(self.textures.len() as u32 - 1)
    }

    /// Describes a material, stores it and returns its id. Warns about parameters it did not
    /// read.
    fn material(
        &mut self,
        ty: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<MaterialId, ParseError> {
        params.ignore("type");
        let desc = MaterialDesc::read(ty, params, pos, self)?;
        self.warn_unused(params);
        Ok(self.add_material(desc))
    }

    pub(super) fn add_material(&mut self, m: MaterialDesc) -> MaterialId {
        self.materials.push(m);
        MaterialId(self.materials.len() as u32 - 1)
    }

    // -----------------------------------------------------------------------------------------
    // Shapes

    fn shape_statement(
        &mut self,
        ty: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<(), ParseError> {
        let Some(geometry) = Geometry::read(self, ty, params, pos)? else {
            return Ok(());
        };
        // The object-space mesh is kept with the description. One the PLY cache also holds
        // was counted when its file was read.
        if let Geometry::Mesh(mesh) = &geometry {
            if Arc::strong_count(mesh) == 1 {
                self.spend(Limit::MemoryBytes, mesh.heap_bytes(), pos)?;
            }
        }
        let material = match self.gs.material {
            Some(id) => id,
            None => self.default_material(),
        };
        let shape = PendingShape {
            desc: ShapeDesc {
                name: params.string("name")?.unwrap_or_default(),
                geometry,
                object_to_world: self.ctm,
                reverse_orientation: self.gs.reverse_orientation,
                material,
                area_light: None,
                media: self.gs.media,
            },
            emitter: match self.gs.area_light.clone() {
                Some(light) => Some((light, self.light_group(pos)?)),
                None => None,
            },
        };
        match &mut self.current_object {
            Some((_, shapes)) => shapes.push(shape),
            None => self.emit_shape(shape, Mat4::IDENTITY, pos)?,
        }
        Ok(())
    }

    /// A `PortalShape`: read as a shape is, kept for the lights of the block's last
    /// `LightSource` when some of them are distant or at infinity ([`crate::lights`]'s
    /// portals), within the scene's [`MAX_PORTAL_TRIANGLES`].
    fn portal_statement(
        &mut self,
        ty: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<(), ParseError> {
        let Some(geometry) = Geometry::read(self, ty, params, pos)? else {
            return Ok(());
        };
        params.ignore("name");
        let Some(lights) = self.gs.current_lights.clone() else {
            self.note(
                pos,
                "PortalShape with no LightSource before it in its attribute block lets no \
                 light in, as in LuxRender; ignored"
                    .into(),
            );
            return Ok(());
        };
        let from_a_direction = self.lights[lights.start as usize..lights.end as usize]
            .iter()
            .any(LightDesc::enters_from_a_direction);
        if !from_a_direction {
            self.note(
                pos,
                "PortalShape of a point or spot light: only distant lights and the lights at \
                 infinity have portals, as in LuxRender; ignored"
                    .into(),
            );
            return Ok(());
        }
        if self.current_object.is_some() {
            self.note(
                pos,
                "PortalShape inside ObjectBegin is placed where it is defined, not instanced"
                    .into(),
            );
        }
        let portal = PortalDesc {
            geometry,
            object_to_world: self.ctm,
            reverse_orientation: self.gs.reverse_orientation,
            lights,
        };
        let triangles = portal.triangle_count();
        if triangles == 0 {
            self.warn(
                pos,
                format!("PortalShape \"{ty}\": an unbounded or empty shape has no surface light can enter through; ignored"),
            );
            return Ok(());
        }
        let held: u64 = self.portals.iter().map(PortalDesc::triangle_count).sum();
        if held + triangles > MAX_PORTAL_TRIANGLES {
            self.warn(
                pos,
                format!(
                    "PortalShape: the scene's portals would hold {} triangles, more than the \
                     {MAX_PORTAL_TRIANGLES} they may; this portal is ignored (its light still \
                     enters, found by camera paths)",
                    held + triangles
                ),
            );
            return Ok(());
        }
        self.diagnose(
            Severity::NoEffect,
            "PortalShape".into(),
            pos,
            "PortalShape: light subpaths of its light start on it (bidirectional transport); \
             the image is the same, its noise lower where light enters an interior through it"
                .into(),
        );
        self.portals.push(portal);
        Ok(())
    }

    /// Places a shape in the world (`instance` is the ObjectInstance transform; `pos` the
    /// statement that places it) and sets its area light's radiance from its world-space area.
    fn emit_shape(
        &mut self,
        shape: PendingShape,
        instance: Mat4,
        pos: &Pos,
    ) -> Result<(), ParseError> {
        let primitives = shape.desc.geometry.primitive_count();
        self.spend(Limit::Primitives, primitives, pos)?;
        self.spend(Limit::MemoryBytes, placed_bytes(&shape.desc.geometry), pos)?;
        let mut desc = shape.desc;
        desc.object_to_world = instance * desc.object_to_world;
        if !desc.object_to_world.is_finite() {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: "the object's transform times the instance's overflows the range of \
                          32-bit floats"
                    .into(),
            });
        }
        desc.area_light = shape.emitter.map(|(light, group)| AreaLightDesc {
            group,
            ..light.desc(desc.world_area())
        });
        desc.material = self.glass2_index(desc.material, desc.media, pos);
        self.shapes.push(desc);
        Ok(())
    }

    /// glass2 refracts with its volumes' indices (LuxRender's Glass2::GetBSDF): the shape's
    /// interior index over its exterior's, 1 for a side with no volume; with `dispersion`, at a
    /// path's wavelength where either varies with it. Returns the material a shape with `media`
    /// uses in place of `material`.
    fn glass2_index(&mut self, material: MaterialId, media: ShapeMedia, pos: &Pos) -> MaterialId {
        let glass2 = |g: &Glass| g.index_from_volumes;
        let takes_index = match self.materials.get(material.0 as usize) {
            Some(MaterialDesc::Glass(g)) => glass2(g),
            Some(MaterialDesc::Bumped(inner, _)) => {
                matches!(inner.as_ref(), MaterialDesc::Glass(g) if glass2(g))
            }
            _ => false,
        };
        if !takes_index {
            return material;
        }
        if media.interior.is_none() {
            self.warn_once(
                "glass2 without interior".into(),
                pos,
                "glass2 on a shape with no Interior volume has index 1, as in LuxRender: it does not refract".into(),
            );
        }
        if media.is_empty() {
            return material;
        }
        if let Some(&id) = self.glass2_with_index.get(&(material, media)) {
            return id;
        }
        let index = self.volumes.index(media.interior) / self.volumes.index(media.exterior);
        let dispersion = Dispersion::between(
            self.volumes.index_curve(media.interior),
            self.volumes.index_curve(media.exterior),
        );
        let mut desc = self.materials[material.0 as usize].clone();
        let glass = match &mut desc {
            MaterialDesc::Glass(g) => Some(g),
            MaterialDesc::Bumped(inner, _) => match inner.as_mut() {
                MaterialDesc::Glass(g) => Some(g),
                _ => None,
            },
            _ => None,
        };
        if let Some(g) = glass {
            g.index = ConstOrTexture::float(index);
            if g.dispersion {
                g.volume_dispersion = dispersion;
            }
        }
        let id = self.add_material(desc);
        self.glass2_with_index.insert((material, media), id);
        id
    }

    /// The light group of a light declared here: the `LightGroup` in force, or "default"
    /// (created at its first light, as LuxRender's context creates it).
    fn light_group(&mut self, pos: &Pos) -> Result<u8, ParseError> {
        match self.gs.light_group {
            Some(group) => Ok(group),
            None => self.light_group_named(DEFAULT_GROUP, pos),
        }
    }

    /// The index of the light group `name`, a new group when it is new; Err past
    /// [`MAX_LIGHT_GROUPS`].
    fn light_group_named(&mut self, name: &str, pos: &Pos) -> Result<u8, ParseError> {
        let groups = &mut self.light_groups.groups;
        if let Some(at) = groups.iter().position(|g| g.name == name) {
            return Ok(at as u8);
        }
        if groups.len() >= MAX_LIGHT_GROUPS {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!(
                    "light group \"{name}\" would be the scene's {}th: YAT keeps at most \
                     {MAX_LIGHT_GROUPS}",
                    groups.len() + 1
                ),
            });
        }
        groups.push(LightGroupDesc::named(name));
        Ok((groups.len() - 1) as u8)
    }

    // -----------------------------------------------------------------------------------------

    pub fn finish(mut self) -> Result<SceneDesc, ParseError> {
        let end = Pos::new(&self.main, 0, 0);
        for f in std::mem::take(&mut self.stack) {
            self.note(&f.pos, format!("{} is never closed", f.kind.begin()));
        }
        if self.block == Block::Options {
            self.note(&end, "no WorldBegin: the scene is empty".into());
        }
        if self.block == Block::World {
            // No WorldEnd: the camera's volume is the Exterior current at the end.
            self.volumes.camera = self.gs.media.exterior;
        }
        let (volume_integrator, at) = self
            .volume_integrator
            .take()
            .unwrap_or_else(|| (VolumeIntegrator::Attenuating, end.clone()));
        let mut volumes = std::mem::take(&mut self.volumes);
        volume_integrator.apply(&mut volumes, &mut self, &at);
        self.volumes = volumes;
        let options = std::mem::take(&mut self.options);
        let (camera, mut film, filter, integrator, sampler) = options.finish(&mut self, &end)?;
        film.light_groups = std::mem::take(&mut self.light_groups);
        Ok(SceneDesc {
            camera,
            film,
            filter,
            integrator,
            sampler,
            textures: self.textures,
            materials: self.materials,
            shapes: self.shapes,
            portals: self.portals,
            lights: self.lights,
            volumes: self.volumes,
            warnings: self.warnings,
            assets: self.assets,
            spent: self.spent,
        })
    }
}

impl ParseContext for Builder<'_> {
    fn diagnose(&mut self, severity: Severity, key: String, pos: &Pos, message: String) {
        match self.warned.entry(key) {
            Entry::Occupied(first) => self.warnings[*first.get()].repeat(pos),
            Entry::Vacant(slot) => {
                slot.insert(self.warnings.len());
                self.warnings
                    .push(Warning::new(severity, pos.clone(), message));
            }
        }
    }

    fn ctm(&self) -> Mat4 {
        self.ctm
    }

    fn find_texture(&self, name: &str, want_color: bool) -> Option<BoundTexture> {
        let mut any = None;
        for t in self
            .textures_in_scope
            .iter()
            .rev()
            .filter(|t| t.name == name)
        {
            if t.is_color == want_color {
                return Some(t.binding.clone());
            }
            any.get_or_insert(&t.binding);
        }
        any.cloned()
    }

    fn texture_is_color(&self, id: TextureId) -> bool {
        self.textures[id.0 as usize].is_color
    }

    fn uniform_texture(&self, tex: ConstOrTexture) -> Option<Vec3> {
        texture::Textures::uniform_value(&self.textures, tex)
    }

    fn scaled_texture(&mut self, id: TextureId, factor: f32) -> TextureId {
        let is_color = self.textures[id.0 as usize].is_color;
        let name = format!("{} x {factor}", self.textures[id.0 as usize].name);
        self.add_texture(TextureDesc {
            name,
            is_color,
            kind: TextureKind::Scale(Scale {
                tex1: ConstOrTexture::Texture(id),
                tex2: ConstOrTexture::float(factor),
            }),
        })
    }

    fn named_material(&mut self, name: &str, pos: &Pos) -> MaterialId {
        match self.named_materials.get(name) {
            Some(&id) => id,
            None => {
                self.warn(
                    pos,
                    format!("no material named \"{name}\"; using the default matte"),
                );
                self.default_material()
            }
        }
    }

    fn default_material(&mut self) -> MaterialId {
        if let Some(id) = self.default_material {
            return id;
        }
        let id = self.add_material(MaterialDesc::Matte(Matte::default()));
        self.default_material = Some(id);
        id
    }

    fn read_asset(
        &mut self,
        path: &str,
        kind: AssetKind,
        pos: &Pos,
    ) -> Result<Arc<[u8]>, ParseError> {
        let bytes = self.source.read(path).map_err(|error| ParseError::Asset {
            pos: pos.clone(),
            error,
        })?;
        let r = AssetRef {
            path: path.to_string(),
            kind,
        };
        if self.asset_set.insert(r.clone()) {
            self.assets.push(r);
            // A worker holds the files it was sent until its build ends.
            self.spend(Limit::MemoryBytes, bytes.len() as u64, pos)?;
        }
        Ok(bytes)
    }

    fn ply_mesh(&mut self, path: &str, pos: &Pos) -> Result<Arc<TriangleMesh>, ParseError> {
        if let Some(m) = self.ply_meshes.get(path) {
            return Ok(m.clone());
        }
        let bytes = self.read_asset(path, AssetKind::Ply, pos)?;
        self.spend(Limit::ParsedBytes, bytes.len() as u64, pos)?;
        let mesh = ply::read_valid_mesh(&bytes).map_err(|message| ParseError::Ply {
            pos: pos.clone(),
            path: path.to_string(),
            message,
        })?;
        self.spend(Limit::MemoryBytes, mesh.heap_bytes(), pos)?;
        let mesh = Arc::new(mesh);
        self.ply_meshes.insert(path.to_string(), mesh.clone());
        Ok(mesh)
    }

    fn warn_unused(&mut self, params: &ParamList) {
        for p in &params.params {
            if let Some(Verdict { severity, message }) = verdict(params, p) {
                // One kind per statement, parameter and verdict: a parameter's later
                // occurrences are listed as positions of its first.
                let key = format!("param|{severity:?}|{}|{}", params.statement, p.decl());
                self.diagnose(severity, key, &p.pos, message);
            }
        }
    }

    fn check_primitives(&self, count: u64, pos: &Pos) -> Result<(), ParseError> {
        // A copy of the meter: checking spends nothing.
        self.spent
            .clone()
            .spend(self.guard.budget, Limit::Primitives, count)
            .map(|_| ())
            .map_err(|exceeded| ParseError::OverBudget {
                pos: pos.clone(),
                exceeded,
            })
    }

    fn eval_float_texture(
        &mut self,
        tex: ConstOrTexture,
        points: &[(Vec3, glam::Vec2)],
        pos: &Pos,
    ) -> Result<Vec<f32>, ParseError> {
        let textures = texture::Textures::new(&self.textures, self.source).map_err(|e| {
            ParseError::Invalid {
                pos: pos.clone(),
                message: e.to_string(),
            }
        })?;
        Ok(points
            .iter()
            .map(|&(p, uv)| {
                let mut at = texture::LookupPoint::new(p, uv);
                at.p_world = self.ctm.transform_point3(p);
                textures.eval(tex, &at).element_sum() / 3.0
            })
            .collect())
    }

    fn check_image(&mut self, path: &str, purpose: ImageUse, pos: &Pos) -> Result<(), ParseError> {
        let (width, height, color) = match self.image_headers.get(path) {
            Some(&header) => header,
            None => {
                let bytes = self.read_asset(path, AssetKind::Image, pos)?;
                // The format as the decoder will find it (TGA, which has no magic number, by
                // the extension); its decoder reads the header only, no texel.
                let header = crate::image_io::format(&bytes, path)
                    .map(|format| {
                        image::ImageReader::with_format(std::io::Cursor::new(&bytes[..]), format)
                    })
                    .and_then(|r| r.into_decoder())
                    .map_err(|e| e.to_string())
                    .map(|d| {
                        let (width, height) = d.dimensions();
                        (width, height, d.color_type())
                    })
                    .map_err(|message| ParseError::Image {
                        pos: pos.clone(),
                        path: path.to_string(),
                        message,
                    })?;
                self.image_headers.insert(path.to_string(), header);
                // Counted from the header, before anything is decoded.
                self.spend(
                    Limit::Texels,
                    u64::from(header.0) * u64::from(header.1),
                    pos,
                )?;
                header
            }
        };
        let decoded = ImageCost::decode(width, height, color);
        match purpose {
            ImageUse::Texture { gamma } => {
                if self
                    .texture_images
                    .insert((path.to_string(), gamma.to_bits()))
                {
                    self.spend_image(decoded, pos)?;
                }
            }
            ImageUse::Environment => self.spend_image(map_cost(decoded, width, height), pos)?,
        }
        Ok(())
    }
}

/// LuxRender's LookAt (world-to-camera): right = normalize(cross(dir, up)),
/// up' = cross(right, dir); camera space has +x right, +y up, +z along the view.
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Option<Mat4> {
    let dir = (target - eye).try_normalize()?;
    let right = dir.cross(up.try_normalize()?).try_normalize()?;
    let new_up = right.cross(dir);
    let camera_to_world = Mat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        eye.extend(1.0),
    );
    let world_to_camera = crate::math::inverse(&camera_to_world);
    world_to_camera
        .to_cols_array()
        .iter()
        .all(|v| v.is_finite())
        .then_some(world_to_camera)
}
