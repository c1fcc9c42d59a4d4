//! The blender_* textures: Blender's procedural textures as LuxRender 1.x reads them, one file
//! each ([`clouds`], [`wood`], [`marble`], [`musgrave`], [`stucci`], [`noise`], [`voronoi`],
//! [`distortednoise`], [`magic`], [`blend`]), their shared parameters and blending in
//! [`common`], and their noise bases and fractal sums in [`noise_basis`].
//!
//! Each pattern maps the texture-space point to an intensity (or a colour, reduced to one),
//! which blends `tex1` into `tex2`.

pub mod blend;
pub mod clouds;
pub mod common;
pub mod distortednoise;
pub mod magic;
pub mod marble;
pub mod musgrave;
pub mod noise;
pub mod noise_basis;
pub mod stucci;
pub mod voronoi;
pub mod wood;

#[cfg(test)]
mod tests;

use glam::Vec3;

use crate::diag::SourcePos;
use crate::refs::ConstOrTexture;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::texture::common::{Declared, ReferencedTextures, LookupPoint};
use crate::texture::kind::TextureType;
pub use common::{Base, Pattern};

#[derive(Clone, Debug, PartialEq)]
pub enum BlenderKind {
    Clouds(clouds::Clouds),
    Wood(wood::Wood),
    Marble(marble::Marble),
    Musgrave(musgrave::Musgrave),
    Stucci(stucci::Stucci),
    Noise(noise::Noise),
    Voronoi(voronoi::Voronoi),
    DistortedNoise(distortednoise::DistortedNoise),
    Magic(magic::Magic),
    Blend(blend::Blend),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Blender {
    pub base: Base,
    pub kind: BlenderKind,
}

impl Blender {
    /// The blender_* texture of LuxRender type `class`, `None` for any other type.
    pub fn read(
        class: &str,
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Option<Self>, ParseError> {
        let kind = match class {
            "blender_clouds" => BlenderKind::Clouds(clouds::Clouds::read(params, pos, ctx)?),
            "blender_wood" => BlenderKind::Wood(wood::Wood::read(params, pos, ctx)?),
            "blender_marble" => BlenderKind::Marble(marble::Marble::read(params, pos, ctx)?),
            "blender_musgrave" => {
                BlenderKind::Musgrave(musgrave::Musgrave::read(params, pos, ctx)?)
            }
            "blender_stucci" => BlenderKind::Stucci(stucci::Stucci::read(params, pos, ctx)?),
            "blender_noise" => BlenderKind::Noise(noise::Noise::read(params)?),
            "blender_voronoi" => BlenderKind::Voronoi(voronoi::Voronoi::read(params, pos, ctx)?),
            "blender_distortednoise" => {
                BlenderKind::DistortedNoise(distortednoise::DistortedNoise::read(params, pos, ctx)?)
            }
            "blender_magic" => BlenderKind::Magic(magic::Magic::read(params)?),
            "blender_blend" => BlenderKind::Blend(blend::Blend::read(params, pos, ctx)?),
            _ => return Ok(None),
        };
        let blender = Self {
            base: Base::read(decl, params, pos, ctx)?,
            kind,
        };
        // Accepted, on purpose (see noise_basis): YAT does not copy Blender's tabulated random
        // numbers, so a pattern has Blender's character but its features sit elsewhere.
        if blender.uses_noise_tables() {
            ctx.accepted_once(
                format!("{class} noise"),
                pos,
                format!("{class}: YAT's noise bases have Blender's character but not its random tables, so the pattern's features are not where LuxRender puts them"),
            );
        }
        Ok(Some(blender))
    }


    /// Whether the pattern depends on Blender's tabulated noise (all but magic, blend, the
    /// noise-free wood types and cell noise).
    fn uses_noise_tables(&self) -> bool {
        use noise_basis::NoiseBasis::CellNoise;
        match &self.kind {
            BlenderKind::Magic(_) | BlenderKind::Blend(_) | BlenderKind::Noise(_) => false,
            BlenderKind::Wood(w) => {
                matches!(
                    w.kind,
                    wood::WoodType::BandNoise | wood::WoodType::RingNoise
                ) && w.basis != CellNoise
            }
            BlenderKind::Clouds(c) => c.basis != CellNoise,
            BlenderKind::Marble(m) => m.basis != CellNoise,
            BlenderKind::Stucci(s) => s.basis != CellNoise,
            BlenderKind::Musgrave(m) => m.fractal.basis != CellNoise,
            BlenderKind::DistortedNoise(d) => d.distorted != CellNoise || d.distortion != CellNoise,
            BlenderKind::Voronoi(_) => true,
        }
    }


    /// The pattern's raw result at texture-space point `p`.
    pub fn pattern(&self, p: Vec3) -> Pattern {
        match &self.kind {
            BlenderKind::Clouds(t) => t.pattern(p),
            BlenderKind::Wood(t) => t.pattern(p),
            BlenderKind::Marble(t) => t.pattern(p),
            BlenderKind::Musgrave(t) => t.pattern(p),
            BlenderKind::Stucci(t) => t.pattern(p),
            BlenderKind::Noise(t) => t.pattern(p),
            BlenderKind::Voronoi(t) => t.pattern(p),
            BlenderKind::DistortedNoise(t) => t.pattern(p),
            BlenderKind::Magic(t) => t.pattern(p),
            BlenderKind::Blend(t) => t.pattern(p),
        }
    }
}

impl TextureType for Blender {
    /// LuxRender's type name.
    fn name(&self) -> &'static str {
        match self.kind {
            BlenderKind::Clouds(_) => "blender_clouds",
            BlenderKind::Wood(_) => "blender_wood",
            BlenderKind::Marble(_) => "blender_marble",
            BlenderKind::Musgrave(_) => "blender_musgrave",
            BlenderKind::Stucci(_) => "blender_stucci",
            BlenderKind::Noise(_) => "blender_noise",
            BlenderKind::Voronoi(_) => "blender_voronoi",
            BlenderKind::DistortedNoise(_) => "blender_distortednoise",
            BlenderKind::Magic(_) => "blender_magic",
            BlenderKind::Blend(_) => "blender_blend",
        }
    }

    /// The textures it blends.
    fn references(&self) -> Vec<ConstOrTexture> {
        vec![self.base.tex1, self.base.tex2]
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        let f = self.base.weight(self.pattern(self.base.mapping.map(at)));
        let (a, b) = (
            textures.eval(self.base.tex1, at),
            textures.eval(self.base.tex2, at),
        );
        a + f * (b - a)
    }
}
