//! The `Camera` statement: its description, LuxRender's defaults and their reading (the table
//! in [`super`]).

use glam::Mat4;

use super::aperture::Aperture;
use crate::diag::SourcePos;
use crate::film::FilmDesc;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// The camera type of a scene without a `Camera` statement.
pub const DEFAULT_CAMERA: &str = "perspective";
/// Field of view in degrees when the file does not say.
pub const DEFAULT_FOV: f32 = 90.0;
pub const DEFAULT_LENS_RADIUS: f32 = 0.0;
pub const DEFAULT_FOCAL_DISTANCE: f32 = 1e30;
pub const DEFAULT_HITHER: f32 = 1e-3;
/// The nearest a hither plane may be.
pub const MIN_HITHER: f32 = 1e-4;
pub const DEFAULT_YON: f32 = 1e30;

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
    /// The focal plane's distance along the view axis, as the scene gives it (the camera
    /// reads anything from [`super::rays::MAX_FOCAL_DISTANCE`] on as infinity).
    pub focal_distance: f32,
    /// Focus on the first hit of the ray through the screen's centre, found once the scene's
    /// geometry is built ([`super::Camera::autofocus`]), in place of `focal_distance`.
    pub autofocus: bool,
    /// The lens's shape and weighting (perspective only: LuxRender's other cameras have the
    /// round one).
    pub aperture: Aperture,
    pub hither: f32,
    pub yon: f32,
}

impl CameraDesc {
    /// Reads `Camera "ty"` given where it was (`world_to_camera`, the transform current at the
    /// statement) and the film (whose aspect ratio the default screen window follows).
    pub fn read(
        ctx: &mut dyn ParseContext,
        ty: &str,
        p: &ParamList,
        world_to_camera: Mat4,
        pos: &SourcePos,
        film: &FilmDesc,
    ) -> Result<Self, ParseError> {
        let fov = || p.float("fov", DEFAULT_FOV);
        let kind = match ty {
            "perspective" => CameraKind::Perspective { fov: fov()? },
            "orthographic" => CameraKind::Orthographic,
            "fisheye" => CameraKind::Fisheye { fov: fov()? },
            other => {
                ctx.warn(
                    pos,
                    format!(
                        "Camera \"{other}\" is not supported; rendering with a perspective camera"
                    ),
                );
                for q in &p.params {
                    p.ignore(&q.name);
                }
                CameraKind::Perspective { fov: fov()? }
            }
        };
        let frame = p.float(
            "frameaspectratio",
            film.xresolution as f32 / film.yresolution as f32,
        )?;
        let screen_window = match p.floats("screenwindow")? {
            Some((v, param)) => <[f32; 4]>::try_from(v.as_slice())
                .map_err(|_| p.error(param, format!("expected 4 floats, got {}", v.len())))?,
            None if frame > 1.0 => [-frame, frame, -1.0, 1.0],
            None => [-1.0, 1.0, -1.0 / frame, 1.0 / frame],
        };
        let aperture = if ty == "perspective" {
            Aperture::read(p)?
        } else {
            Aperture::default()
        };
        let camera_to_world = crate::math::inverse(&world_to_camera);
        if !camera_to_world
            .to_cols_array()
            .iter()
            .all(|v| v.is_finite())
            || world_to_camera.determinant() == 0.0
        {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: "Camera: the current transform (world to camera) is not invertible".into(),
            });
        }
        let hither = p.float("hither", DEFAULT_HITHER)?.max(MIN_HITHER);
        Ok(CameraDesc {
            kind,
            camera_to_world,
            screen_window,
            lens_radius: p.float("lensradius", DEFAULT_LENS_RADIUS)?,
            focal_distance: p.float("focaldistance", DEFAULT_FOCAL_DISTANCE)?,
            autofocus: p.bool("autofocus", false)?,
            aperture,
            hither,
            yon: p.float("yon", DEFAULT_YON)?.clamp(hither, DEFAULT_YON),
        })
    }
}
