//! `Camera "perspective" "float fov" [90] ...`: the camera's description, LuxRender's defaults
//! and their reading; cameras: perspective with an optional thin lens, orthographic, and the
//! course's fisheye.
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `fov` (perspective, fisheye) | float, degrees | 90 |
//! | `frameaspectratio` | float | the film's xresolution / yresolution |
//! | `screenwindow` | 4 floats | the longer axis spans [-aspect, aspect], the shorter [-1, 1] |
//! | `lensradius` | float | 0 |
//! | `focaldistance` | float | 1e30 |
//! | `hither` | float | 1e-3 (at least 1e-4) |
//! | `yon` | float | 1e30 (at least hither) |
//! | `autofocus` | bool | false (true is a warning) |
//!
//! Other types (environment, realistic) are a warning and render as perspective. The camera
//! is placed by the transform current at the statement (world to camera).
//!
//! Film positions are raster coordinates: (0, 0) is the top-left corner of the image, x grows
//! right and y down, one unit per pixel.

use glam::{Mat4, Vec2, Vec3};

use crate::bxdf::local::sample_disk_concentric;
use crate::diag::SourcePos;
use crate::film::FilmDesc;
use crate::math::Ray;
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
    pub focal_distance: f32,
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
        if p.bool("autofocus", false)? {
            ctx.warn(
                pos,
                "Camera: autofocus is not supported; focaldistance is used as given".into(),
            );
        }
        let camera_to_world = world_to_camera.inverse();
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
            hither,
            yon: p.float("yon", DEFAULT_YON)?.clamp(hither, DEFAULT_YON),
        })
    }
}

#[derive(Clone, Debug)]
enum Projection {
    /// `tan_half_fov` maps screen coordinate 1 to the view axis tangent.
    Perspective {
        tan_half_fov: f32,
    },
    Orthographic,
    Fisheye {
        fov_radians: f32,
    },
}

#[derive(Clone, Debug)]
pub struct Camera {
    projection: Projection,
    camera_to_world: Mat4,
    /// Screen window [xmin, xmax, ymin, ymax].
    window: [f32; 4],
    width: f32,
    height: f32,
    lens_radius: f32,
    focal_distance: f32,
}

impl Camera {
    pub fn new(desc: &CameraDesc, width: u32, height: u32) -> Self {
        let projection = match desc.kind {
            CameraKind::Perspective { fov } => Projection::Perspective {
                tan_half_fov: (fov.to_radians() * 0.5).tan(),
            },
            CameraKind::Orthographic => Projection::Orthographic,
            CameraKind::Fisheye { fov } => Projection::Fisheye {
                fov_radians: fov.to_radians(),
            },
        };
        Self {
            projection,
            camera_to_world: desc.camera_to_world,
            window: desc.screen_window,
            width: width as f32,
            height: height as f32,
            lens_radius: desc.lens_radius,
            focal_distance: desc.focal_distance,
        }
    }

    /// The screen-space point of a raster position.
    fn screen(&self, film: Vec2) -> Vec2 {
        let [x0, x1, y0, y1] = self.window;
        Vec2::new(
            x0 + film.x / self.width * (x1 - x0),
            y1 - film.y / self.height * (y1 - y0),
        )
    }

    /// The world-space ray through raster position `film`, with `lens` in [0,1)^2 choosing the
    /// point on the lens. None where the camera sees nothing (outside the fisheye circle).
    pub fn generate_ray(&self, film: Vec2, lens: Vec2) -> Option<Ray> {
        let (origin, dir) = match self.projection {
            Projection::Perspective { tan_half_fov } => {
                let s = self.screen(film);
                let dir = Vec3::new(s.x * tan_half_fov, s.y * tan_half_fov, 1.0);
                self.thin_lens(Vec3::ZERO, dir, lens)
            }
            Projection::Orthographic => {
                let s = self.screen(film);
                self.thin_lens(Vec3::new(s.x, s.y, 0.0), Vec3::Z, lens)
            }
            Projection::Fisheye { fov_radians } => {
                let rx = 2.0 * film.x / self.width - 1.0;
                let ry = 1.0 - 2.0 * film.y / self.height;
                let r = (rx * rx + ry * ry).sqrt();
                if r > 1.0 {
                    return None;
                }
                let psi = r * fov_radians;
                let alpha = ry.atan2(rx);
                let (sin_psi, cos_psi) = psi.sin_cos();
                let (sin_a, cos_a) = alpha.sin_cos();
                (
                    Vec3::ZERO,
                    Vec3::new(sin_psi * cos_a, sin_psi * sin_a, cos_psi),
                )
            }
        };
        let origin = self.camera_to_world.transform_point3(origin);
        let dir = self.camera_to_world.transform_vector3(dir).normalize();
        Some(Ray::new(origin, dir))
    }

    /// Moves a pinhole ray onto a lens point aimed at the same point of the focal plane. With
    /// radius 0 the pinhole ray is returned untouched, so the image is exactly the pinhole one.
    fn thin_lens(&self, origin: Vec3, dir: Vec3, lens: Vec2) -> (Vec3, Vec3) {
        if self.lens_radius <= 0.0 {
            return (origin, dir);
        }
        let on_lens = sample_disk_concentric(lens) * self.lens_radius;
        let focus = origin + dir * (self.focal_distance / dir.z);
        let lens_point = origin + Vec3::new(on_lens.x, on_lens.y, 0.0);
        (lens_point, focus - lens_point)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn desc(kind: CameraKind, lens_radius: f32) -> CameraDesc {
        // Looking down +y from the origin with z up: camera x = world +x, camera y = world +z.
        let camera_to_world = Mat4::from_cols(
            Vec3::X.extend(0.0),
            Vec3::Z.extend(0.0),
            Vec3::Y.extend(0.0),
            glam::Vec4::W,
        );
        CameraDesc {
            kind,
            camera_to_world,
            screen_window: [-2.0, 2.0, -1.0, 1.0],
            lens_radius,
            focal_distance: 5.0,
            hither: 1e-3,
            yon: 1e30,
        }
    }

    #[test]
    fn perspective_centre_and_edges() {
        let cam = Camera::new(&desc(CameraKind::Perspective { fov: 90.0 }, 0.0), 200, 100);
        let centre = cam
            .generate_ray(Vec2::new(100.0, 50.0), Vec2::ZERO)
            .unwrap();
        assert!((centre.dir - Vec3::Y).length() < 1e-6);
        // fov spans the shorter axis: the top edge is 45 degrees up, the right edge atan(2).
        let top = cam.generate_ray(Vec2::new(100.0, 0.0), Vec2::ZERO).unwrap();
        assert!((top.dir - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);
        let right = cam
            .generate_ray(Vec2::new(200.0, 50.0), Vec2::ZERO)
            .unwrap();
        assert!((right.dir - Vec3::new(2.0, 1.0, 0.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn thin_lens_rays_meet_at_the_focal_plane() {
        let cam = Camera::new(&desc(CameraKind::Perspective { fov: 60.0 }, 0.2), 64, 32);
        let film = Vec2::new(40.0, 10.0);
        let pinhole = Camera::new(&desc(CameraKind::Perspective { fov: 60.0 }, 0.0), 64, 32)
            .generate_ray(film, Vec2::ZERO)
            .unwrap();
        let target = pinhole.at(5.0 / pinhole.dir.y);
        for lens in [
            Vec2::new(0.1, 0.9),
            Vec2::new(0.7, 0.3),
            Vec2::new(0.5, 0.5),
        ] {
            let ray = cam.generate_ray(film, lens).unwrap();
            let hit = ray.at((5.0 - ray.origin.y) / ray.dir.y);
            assert!((hit - target).length() < 1e-4, "{hit} vs {target}");
            assert!(ray.origin.length() <= 0.2 + 1e-6);
        }
    }

    #[test]
    fn zero_lens_radius_is_exactly_the_pinhole() {
        let thin = Camera::new(&desc(CameraKind::Perspective { fov: 50.0 }, 0.0), 64, 32);
        let a = thin
            .generate_ray(Vec2::new(3.3, 7.1), Vec2::new(0.9, 0.2))
            .unwrap();
        let b = thin
            .generate_ray(Vec2::new(3.3, 7.1), Vec2::new(0.1, 0.6))
            .unwrap();
        assert_eq!(a.origin, b.origin);
        assert_eq!(a.dir, b.dir);
    }

    #[test]
    fn fisheye_circle() {
        let cam = Camera::new(&desc(CameraKind::Fisheye { fov: 90.0 }, 0.0), 100, 100);
        assert!(cam.generate_ray(Vec2::new(1.0, 1.0), Vec2::ZERO).is_none());
        let centre = cam.generate_ray(Vec2::new(50.0, 50.0), Vec2::ZERO).unwrap();
        assert!((centre.dir - Vec3::Y).length() < 1e-6);
        // Halfway to the right edge: psi = 45 degrees towards camera +x.
        let half = cam.generate_ray(Vec2::new(75.0, 50.0), Vec2::ZERO).unwrap();
        assert!((half.dir - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-5);
        // The top edge is straight up (psi = fov = 90 degrees).
        let top = cam.generate_ray(Vec2::new(50.0, 0.0), Vec2::ZERO).unwrap();
        assert!((top.dir - Vec3::Z).length() < 1e-5);
    }
}
