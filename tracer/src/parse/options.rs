//! Render options given before WorldBegin: the statements `Camera`, `Film`, `PixelFilter`,
//! `SurfaceIntegrator` and `Sampler`, each read by its concept ([`crate::camera`],
//! [`crate::film`], [`crate::filter`], [`crate::integrator::options`], [`crate::sampler`]),
//! which also holds its defaults. The camera is read last, because its default screen window
//! follows the film's aspect ratio.

use glam::Mat4;

use super::context::ParseContext;
use super::error::ParseError;
use super::params::ParamList;
use crate::camera::{CameraDesc, DEFAULT_CAMERA};
use crate::diag::SourcePos;
use crate::film::FilmDesc;
use crate::filter::FilterDesc;
use crate::integrator::options::IntegratorDesc;
use crate::sampler::SamplerDesc;

/// The `Camera` statement, kept until the film is known.
struct CameraStatement {
    ty: String,
    params: ParamList,
    world_to_camera: Mat4,
    pos: SourcePos,
}

/// The option statements read so far.
#[derive(Default)]
pub struct OptionsState {
    camera: Option<CameraStatement>,
    film: Option<FilmDesc>,
    filter: Option<FilterDesc>,
    integrator: Option<IntegratorDesc>,
    sampler: Option<SamplerDesc>,
}

pub type Options = (
    CameraDesc,
    FilmDesc,
    FilterDesc,
    IntegratorDesc,
    SamplerDesc,
);

impl OptionsState {
    /// Camera, Film, PixelFilter, Sampler or SurfaceIntegrator.
    pub fn read(
        &mut self,
        ctx: &mut dyn ParseContext,
        keyword: &str,
        ty: String,
        params: ParamList,
        pos: &SourcePos,
    ) -> Result<(), ParseError> {
        match keyword {
            "Camera" => {
                self.camera = Some(CameraStatement {
                    ty,
                    params,
                    world_to_camera: ctx.ctm(),
                    pos: pos.clone(),
                });
                return Ok(());
            }
            "Film" => self.film = Some(FilmDesc::read(ctx, &ty, &params, Some(pos))?),
            "PixelFilter" => self.filter = Some(FilterDesc::read(ctx, &ty, &params, pos)?),
            "SurfaceIntegrator" => {
                self.integrator = Some(IntegratorDesc::read(ctx, &ty, &params, pos)?)
            }
            "Sampler" => self.sampler = Some(SamplerDesc::read(ty, &params)?),
            _ => unreachable!("dispatched option statements only"),
        }
        ctx.warn_unused(&params);
        Ok(())
    }

    /// The options with defaults for the statements the file lacks; `end` names the main
    /// file, for warnings about statements it lacks.
    pub fn finish(
        self,
        ctx: &mut dyn ParseContext,
        end: &SourcePos,
    ) -> Result<Options, ParseError> {
        let film = match self.film {
            Some(f) => f,
            None => FilmDesc::defaults(ctx)?,
        };
        let camera = match self.camera {
            Some(c) => {
                let desc =
                    CameraDesc::read(ctx, &c.ty, &c.params, c.world_to_camera, &c.pos, &film)?;
                ctx.warn_unused(&c.params);
                desc
            }
            None => {
                ctx.note(end, "no Camera statement: using a perspective camera at the origin looking along +z".into());
                let params = ParamList::new("Camera \"perspective\"".into(), Vec::new());
                CameraDesc::read(ctx, DEFAULT_CAMERA, &params, Mat4::IDENTITY, end, &film)?
            }
        };
        Ok((
            camera,
            film,
            self.filter.unwrap_or_default(),
            self.integrator
                .unwrap_or_else(|| IntegratorDesc::path_defaults("path")),
            self.sampler.unwrap_or_default(),
        ))
    }
}
