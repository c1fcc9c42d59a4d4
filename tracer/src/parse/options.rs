//! Render options given before WorldBegin: camera, film, pixel filter, surface integrator and
//! sampler, with LuxRender's defaults. The camera is described last, because its default
//! screen window follows the film's aspect ratio.

use glam::Mat4;

use super::builder::Builder;
use super::context::ParseContext;
use super::params::ParamList;
use super::{ParseError, Pos};
use crate::desc::{
    CameraDesc, CameraKind, FilmDesc, FilterDesc, FilterKind, IntegratorDesc, RussianRoulette,
    SamplerDesc, ToneMap,
};

struct CameraStatement {
    ty: String,
    params: ParamList,
    world_to_camera: Mat4,
    pos: Pos,
}

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
    /// `end` names the main file, for warnings about statements it lacks.
    pub fn finish(self, b: &mut Builder, end: &Pos) -> Result<Options, ParseError> {
        let film = match self.film {
            Some(f) => f,
            None => film(
                b,
                "fleximage",
                &ParamList::new(String::new(), Vec::new()),
                None,
            )?,
        };
        let camera = match self.camera {
            Some(c) => {
                let desc = camera(b, &c, &film)?;
                b.warn_unused(&c.params);
                desc
            }
            None => {
                b.warn(end, "no Camera statement: using a perspective camera at the origin looking along +z".into());
                let pos = end.clone();
                let c = CameraStatement {
                    ty: "perspective".into(),
                    params: ParamList::new("Camera \"perspective\"".into(), Vec::new()),
                    world_to_camera: Mat4::IDENTITY,
                    pos,
                };
                camera(b, &c, &film)?
            }
        };
        Ok((
            camera,
            film,
            self.filter.unwrap_or(FilterDesc {
                kind: FilterKind::Mitchell {
                    b: 1.0 / 3.0,
                    c: 1.0 / 3.0,
                },
                xwidth: 2.0,
                ywidth: 2.0,
            }),
            self.integrator.unwrap_or_else(|| path_defaults("path")),
            self.sampler.unwrap_or(SamplerDesc {
                pixel_samples: None,
                requested: "random".into(),
            }),
        ))
    }
}

fn path_defaults(requested: &str) -> IntegratorDesc {
    IntegratorDesc {
        max_depth: 16,
        rr_strategy: RussianRoulette::Efficiency,
        rr_continue_prob: 0.65,
        include_environment: true,
        requested: requested.to_string(),
    }
}

impl Builder<'_> {
    /// Camera, Film, PixelFilter, Sampler or SurfaceIntegrator.
    pub(super) fn option(
        &mut self,
        keyword: &str,
        ty: String,
        params: ParamList,
        pos: &Pos,
    ) -> Result<(), ParseError> {
        match keyword {
            "Camera" => {
                self.options.camera = Some(CameraStatement {
                    ty,
                    params,
                    world_to_camera: self.ctm,
                    pos: pos.clone(),
                });
                return Ok(());
            }
            "Film" => self.options.film = Some(film(self, &ty, &params, Some(pos))?),
            "PixelFilter" => self.options.filter = Some(filter(self, &ty, &params, pos)?),
            "SurfaceIntegrator" => {
                self.options.integrator = Some(integrator(self, &ty, &params, pos)?)
            }
            "Sampler" => {
                let n = params.int("pixelsamples", 0)?;
                // The sampler's algorithm is ours; only its sample count carries over.
                for p in &params.params {
                    params.ignore(&p.name);
                }
                self.options.sampler = Some(SamplerDesc {
                    pixel_samples: (n > 0).then_some(n as u32),
                    requested: ty,
                });
            }
            _ => unreachable!("dispatched option statements only"),
        }
        self.warn_unused(&params);
        Ok(())
    }
}

fn film(
    b: &mut Builder,
    ty: &str,
    params: &ParamList,
    pos: Option<&Pos>,
) -> Result<FilmDesc, ParseError> {
    if let Some(pos) = pos {
        if ty != "fleximage" {
            b.warn(pos, format!("Film \"{ty}\" is read as \"fleximage\""));
        }
    }
    let resolution = |name: &str, default: i32| -> Result<u32, ParseError> {
        let v = params.int(name, default)?;
        match params.find(name) {
            Some(p) if !(1..=65536).contains(&v) => {
                Err(params.error(p, format!("{v} is not a resolution in 1..65536")))
            }
            _ => Ok(v as u32),
        }
    };
    let xresolution = resolution("xresolution", 800)?;
    let yresolution = resolution("yresolution", 600)?;
    let kernel = params.string_or("tonemapkernel", "autolinear")?;
    let tonemap = match kernel.as_str() {
        "autolinear" => ToneMap::AutoLinear,
        "linear" => ToneMap::Linear {
            sensitivity: params.float("linear_sensitivity", 50.0)?,
            exposure: params.float("linear_exposure", 1.0)?,
            fstop: params.float("linear_fstop", 2.8)?,
        },
        "reinhard" => ToneMap::Reinhard {
            prescale: params.float("reinhard_prescale", 1.0)?,
            postscale: params.float("reinhard_postscale", 1.0)?,
            burn: params.float("reinhard_burn", 6.0)?,
        },
        "contrast" => ToneMap::Contrast {
            ywa: params.float("contrast_ywa", 1.0)?,
        },
        other => {
            if let Some(pos) = pos {
                b.warn(
                    pos,
                    format!("Film: unknown tonemapkernel \"{other}\"; using autolinear"),
                );
            }
            ToneMap::AutoLinear
        }
    };
    // The parameters of the kernels not chosen are legitimately present in exported files.
    for name in [
        "linear_sensitivity",
        "linear_exposure",
        "linear_fstop",
        "linear_gamma",
        "reinhard_prescale",
        "reinhard_postscale",
        "reinhard_burn",
        "contrast_ywa",
    ] {
        params.ignore(name);
    }
    let haltspp = params.int("haltspp", -1)?;
    let halttime = params.float("halttime", -1.0)?;
    Ok(FilmDesc {
        xresolution,
        yresolution,
        gamma: params.float("gamma", 2.2)?,
        tonemap,
        filename: params.string_or("filename", "luxout")?,
        haltspp: (haltspp > 0).then_some(haltspp as u32),
        halttime: (halttime > 0.0).then_some(halttime),
    })
}

fn filter(
    b: &mut Builder,
    ty: &str,
    params: &ParamList,
    pos: &Pos,
) -> Result<FilterDesc, ParseError> {
    let (kind, width) = match ty {
        "box" => (FilterKind::Box, 0.5),
        "triangle" => (FilterKind::Triangle, 2.0),
        "gaussian" => (
            FilterKind::Gaussian {
                alpha: params.float("alpha", 2.0)?,
            },
            2.0,
        ),
        "mitchell" => {
            params.ignore("supersample");
            (
                FilterKind::Mitchell {
                    b: params.float("B", 1.0 / 3.0)?,
                    c: params.float("C", 1.0 / 3.0)?,
                },
                2.0,
            )
        }
        // Catmull-Rom is the Mitchell-Netravali filter with B = 0, C = 1/2.
        "catmullrom" => (FilterKind::Mitchell { b: 0.0, c: 0.5 }, 2.0),
        "blackmanharris" => (FilterKind::BlackmanHarris, 4.0),
        "sinc" => (
            FilterKind::Sinc {
                tau: params.float("tau", 3.0)?,
            },
            4.0,
        ),
        other => {
            b.warn(
                pos,
                format!("PixelFilter \"{other}\" is unknown; using mitchell"),
            );
            (
                FilterKind::Mitchell {
                    b: 1.0 / 3.0,
                    c: 1.0 / 3.0,
                },
                2.0,
            )
        }
    };
    let width = |name: &str| -> Result<f32, ParseError> {
        let w = params.float(name, width)?;
        match params.find(name) {
            Some(p) if w <= 0.0 => Err(params.error(p, "the filter width must be positive")),
            _ => Ok(w),
        }
    };
    Ok(FilterDesc {
        kind,
        xwidth: width("xwidth")?,
        ywidth: width("ywidth")?,
    })
}

fn integrator(
    b: &mut Builder,
    ty: &str,
    params: &ParamList,
    pos: &Pos,
) -> Result<IntegratorDesc, ParseError> {
    let depth = |name: &str| -> Result<u32, ParseError> {
        let d = params.int(name, 16)?;
        match params.find(name) {
            Some(p) if d < 0 => Err(params.error(p, "the depth cannot be negative")),
            _ => Ok(d as u32),
        }
    };
    match ty {
        "path" => {
            let strategy = params.string_or("rrstrategy", "efficiency")?;
            let rr_strategy = match strategy.as_str() {
                "efficiency" => RussianRoulette::Efficiency,
                "probability" => RussianRoulette::Probability,
                "none" => RussianRoulette::None,
                other => {
                    b.warn(pos, format!("SurfaceIntegrator \"path\": unknown rrstrategy \"{other}\"; using efficiency"));
                    RussianRoulette::Efficiency
                }
            };
            params.ignore("lightstrategy");
            params.ignore("shadowraycount");
            Ok(IntegratorDesc {
                max_depth: depth("maxdepth")?,
                rr_strategy,
                rr_continue_prob: params.float("rrcontinueprob", 0.65)?,
                include_environment: params.bool("includeenvironment", true)?,
                requested: ty.to_string(),
            })
        }
        "bidirectional" => {
            let max_depth = depth("eyedepth")?;
            for name in [
                "lightdepth",
                "lightraycount",
                "lightpathstrategy",
                "lightstrategy",
                "eyerrthreshold",
                "lightrrthreshold",
            ] {
                params.ignore(name);
            }
            b.warn_once(
                "bidirectional".into(),
                pos,
                format!("SurfaceIntegrator \"bidirectional\" is rendered as path tracing with max depth {max_depth} (its eyedepth)"),
            );
            Ok(IntegratorDesc {
                max_depth,
                ..path_defaults(ty)
            })
        }
        other => {
            for p in &params.params {
                params.ignore(&p.name);
            }
            b.warn(pos, format!("SurfaceIntegrator \"{other}\" is not available; rendering with \"path\" and its defaults"));
            Ok(path_defaults(other))
        }
    }
}

fn camera(b: &mut Builder, c: &CameraStatement, film: &FilmDesc) -> Result<CameraDesc, ParseError> {
    let p = &c.params;
    let fov = || p.float("fov", 90.0);
    let kind = match c.ty.as_str() {
        "perspective" => CameraKind::Perspective { fov: fov()? },
        "orthographic" => CameraKind::Orthographic,
        "fisheye" => CameraKind::Fisheye { fov: fov()? },
        other => {
            b.warn(
                &c.pos,
                format!("Camera \"{other}\" is not supported; rendering with a perspective camera"),
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
    if p.bool("autofocus", false)? {
        b.warn(
            &c.pos,
            "Camera: autofocus is not supported; focaldistance is used as given".into(),
        );
    }
    let camera_to_world = c.world_to_camera.inverse();
    if !camera_to_world
        .to_cols_array()
        .iter()
        .all(|v| v.is_finite())
        || c.world_to_camera.determinant() == 0.0
    {
        return Err(ParseError::Invalid {
            pos: c.pos.clone(),
            message: "Camera: the current transform (world to camera) is not invertible".into(),
        });
    }
    let hither = p.float("hither", 1e-3)?.max(1e-4);
    Ok(CameraDesc {
        kind,
        camera_to_world,
        screen_window,
        lens_radius: p.float("lensradius", 0.0)?,
        focal_distance: p.float("focaldistance", 1e30)?,
        hither,
        yon: p.float("yon", 1e30)?.clamp(hither, 1e30),
    })
}
