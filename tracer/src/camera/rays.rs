//! The cameras' rays: perspective with an optional thin lens, orthographic, and the course's
//! fisheye, through raster positions (the conventions in [`super`]).

use glam::{Mat3, Mat4, Vec2, Vec3};

use super::aperture::Aperture;
use super::desc::{CameraDesc, CameraKind, MIN_HITHER};
use crate::lanes::{Lanes, MAX_LANES};
use crate::math::Ray;

/// The focal distance from which on a thin lens is focused at infinity. A lens offset is below
/// f32's precision against it, so the rays are the pinhole's directions from the lens point;
/// it keeps the focal plane's arithmetic in range (LuxRender's default of 1e30, squared,
/// overflows f32).
pub const MAX_FOCAL_DISTANCE: f32 = 1e12;

#[derive(Clone, Debug)]
pub(super) enum Projection {
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
    pub(super) projection: Projection,
    pub(super) camera_to_world: Mat4,
    pub(super) world_to_camera: Mat4,
    /// How the camera transform scales areas (1 for a rigid camera): camera-space areas times
    /// this are world areas.
    pub(super) area_scale: f32,
    /// Screen window [xmin, xmax, ymin, ymax].
    pub(super) window: [f32; 4],
    pub(super) width: f32,
    pub(super) height: f32,
    pub(super) lens_radius: f32,
    pub(super) focal_distance: f32,
    pub(super) aperture: Aperture,
    /// The hither plane's distance: where LuxRender's autofocus ray starts.
    pub(super) hither: f32,
}

impl Camera {
    pub fn new(desc: &CameraDesc, width: u32, height: u32) -> Self {
        let projection = match desc.kind {
            CameraKind::Perspective { fov } => Projection::Perspective {
                tan_half_fov: libm::tanf(fov.to_radians() * 0.5),
            },
            CameraKind::Orthographic => Projection::Orthographic,
            CameraKind::Fisheye { fov } => Projection::Fisheye {
                fov_radians: fov.to_radians(),
            },
        };
        Self {
            projection,
            camera_to_world: desc.camera_to_world,
            world_to_camera: crate::math::inverse(&desc.camera_to_world),
            area_scale: crate::shape::kind::area_scale(
                Mat3::from_mat4(desc.camera_to_world).determinant().abs(),
            ),
            window: desc.screen_window,
            width: width as f32,
            height: height as f32,
            lens_radius: desc.lens_radius,
            focal_distance: desc.focal_distance.min(MAX_FOCAL_DISTANCE),
            aperture: desc.aperture,
            hither: desc.hither,
        }
    }

    /// The focal distance in use (the scene's, up to [`MAX_FOCAL_DISTANCE`], or autofocus's).
    pub fn focal_distance(&self) -> f32 {
        self.focal_distance
    }

    /// LuxRender 1.x's autofocus: focuses where the pinhole ray through the film's centre,
    /// starting at the hither plane, first hits something (`first_hit` gives a world ray's
    /// closest hit distance), and returns that distance; None, the focal distance kept, where
    /// it hits nothing, and for a fisheye (which has no lens). Computed once from the scene
    /// alone, so every worker focuses alike.
    ///
    /// LuxRender's centre is half its sample extent, which reaches past the film by the pixel
    /// filter's radius `filter_radius` on the top and left sides: its autofocus point sits
    /// that many pixels right of and below the film's middle, and so does this one.
    pub fn autofocus(
        &mut self,
        filter_radius: Vec2,
        first_hit: impl FnOnce(&Ray) -> Option<f32>,
    ) -> Option<f32> {
        if matches!(self.projection, Projection::Fisheye { .. }) {
            return None;
        }
        let extent = |size: f32, radius: f32| {
            let (start, end) = (
                (0.5 - radius).floor() as i64,
                (0.5 + size + radius).floor() as i64,
            );
            ((end - start) / 2) as f32
        };
        let film = Vec2::new(
            extent(self.width, filter_radius.x),
            extent(self.height, filter_radius.y),
        );
        let pinhole = Camera {
            lens_radius: 0.0,
            ..self.clone()
        };
        let ray = pinhole.generate_ray(film, Vec2::ZERO)?;
        let t = first_hit(&ray)?;
        let origin = self.world_to_camera.transform_point3(ray.origin);
        let hit = self.world_to_camera.transform_point3(ray.at(t));
        let towards = hit - origin;
        let cos = towards.z / towards.length();
        let distance = towards.length() - self.hither / cos;
        if !distance.is_finite() {
            return None;
        }
        self.focal_distance = distance.clamp(MIN_HITHER, MAX_FOCAL_DISTANCE);
        Some(self.focal_distance)
    }

    /// The world-space ray through raster position `film`, with `lens` in [0,1)^2 choosing the
    /// point on the lens. None where the camera sees nothing (outside the fisheye circle).
    pub fn generate_ray(&self, film: Vec2, lens: Vec2) -> Option<Ray> {
        let Projection::Fisheye { fov_radians } = self.projection else {
            let (origin, dir) = self.flat_rays::<f32>(film.to_array(), lens.to_array())?;
            return Some(Ray::new(Vec3::from(origin), Vec3::from(dir)));
        };
        let rx = 2.0 * film.x / self.width - 1.0;
        let ry = 1.0 - 2.0 * film.y / self.height;
        let r = (rx * rx + ry * ry).sqrt();
        if r > 1.0 {
            return None;
        }
        let psi = r * fov_radians;
        let alpha = libm::atan2f(ry, rx);
        let (sin_psi, cos_psi) = libm::sincosf(psi);
        let (sin_a, cos_a) = libm::sincosf(alpha);
        let dir = Vec3::new(sin_psi * cos_a, sin_psi * sin_a, cos_psi);
        let origin = self.camera_to_world.transform_point3(Vec3::ZERO);
        let dir = self.camera_to_world.transform_vector3(dir).normalize();
        Some(Ray::new(origin, dir))
    }

    /// The rays of a packet's samples at raster positions `film`, lens points chosen by `lens`
    /// ([`Self::generate_ray`] lane by lane): in lanes ([`Self::flat_rays`]) but for a fisheye.
    #[inline(always)]
    pub fn packet_rays<L: Lanes>(&self, film: [L; 2], lens: [L; 2]) -> [Option<Ray>; MAX_LANES] {
        let mut rays = [None; MAX_LANES];
        // Not `Option::map` or closures: a closure would not inherit an AVX2 caller's features.
        if let Some(([ox, oy, oz], [dx, dy, dz])) = self.flat_rays(film, lens) {
            let (o, d) = (
                [ox.values(), oy.values(), oz.values()],
                [dx.values(), dy.values(), dz.values()],
            );
            for (i, ray) in rays.iter_mut().enumerate().take(L::N) {
                let origin = Vec3::new(o[0][i], o[1][i], o[2][i]);
                *ray = Some(Ray::new(origin, Vec3::new(d[0][i], d[1][i], d[2][i])));
            }
        } else {
            let (film, lens) = (
                [film[0].values(), film[1].values()],
                [lens[0].values(), lens[1].values()],
            );
            for (i, ray) in rays.iter_mut().enumerate().take(L::N) {
                let at = Vec2::new(film[0][i], film[1][i]);
                *ray = self.generate_ray(at, Vec2::new(lens[0][i], lens[1][i]));
            }
        }
        rays
    }

    /// [`Self::generate_ray`] in lanes for a perspective or orthographic camera (every lane
    /// gets the bits one lane gets): world-space origins and unit directions through raster
    /// positions `film`, lens points chosen by `lens`. None for a fisheye camera.
    #[inline(always)]
    pub fn flat_rays<L: Lanes>(&self, film: [L; 2], lens: [L; 2]) -> Option<([L; 3], [L; 3])> {
        // Loops and splats, not `map`: a closure would not inherit an AVX2 caller's features.
        let [x0, x1, y0, y1] = self.window;
        let (x0, x1, y0, y1) = (L::splat(x0), L::splat(x1), L::splat(y0), L::splat(y1));
        // The screen-space point.
        let sx = x0 + film[0] / L::splat(self.width) * (x1 - x0);
        let sy = y1 - film[1] / L::splat(self.height) * (y1 - y0);
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let (origin, dir) = match self.projection {
            Projection::Perspective { tan_half_fov } => {
                let tan = L::splat(tan_half_fov);
                ([zero; 3], [sx * tan, sy * tan, one])
            }
            Projection::Orthographic => ([sx, sy, zero], [zero, zero, one]),
            Projection::Fisheye { .. } => return None,
        };
        // The thin lens moves a pinhole ray onto a lens point aimed at the same point of the
        // focal plane. With radius 0 the pinhole ray is kept untouched, so the image is exactly
        // the pinhole one.
        let (origin, dir) = if self.lens_radius <= 0.0 {
            (origin, dir)
        } else {
            let radius = L::splat(self.lens_radius);
            let [lx, ly] = self.aperture.sample_lanes(lens);
            let to_focus = L::splat(self.focal_distance) / dir[2];
            let lens_point = [
                origin[0] + lx * radius,
                origin[1] + ly * radius,
                // glam's `origin + Vec3::new(x, y, 0.0)` adds the 0 (a -0 becomes +0).
                origin[2] + zero,
            ];
            let mut towards = [zero; 3];
            for c in 0..3 {
                towards[c] = origin[c] + dir[c] * to_focus - lens_point[c];
            }
            (lens_point, towards)
        };
        // `Mat4::transform_point3`, `transform_vector3`, `Vec3::normalize`: their operations in
        // their order.
        let m = self.camera_to_world.to_cols_array_2d();
        let mut axes = [[zero; 3]; 4];
        for (axis, column) in axes.iter_mut().zip(m) {
            for c in 0..3 {
                axis[c] = L::splat(column[c]);
            }
        }
        let mut world_origin = [zero; 3];
        let mut world_dir = [zero; 3];
        for c in 0..3 {
            let along = axes[1][c] * dir[1] + axes[0][c] * dir[0];
            world_dir[c] = axes[2][c] * dir[2] + along;
            let at = axes[1][c] * origin[1] + axes[0][c] * origin[0];
            world_origin[c] = axes[3][c] + (axes[2][c] * origin[2] + at);
        }
        let [dx, dy, dz] = world_dir;
        let length = (dx * dx + dy * dy + dz * dz).sqrt();
        let recip = one / length;
        Some((world_origin, [dx * recip, dy * recip, dz * recip]))
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
            autofocus: false,
            aperture: Default::default(),
            hither: 1e-3,
            yon: 1e30,
        }
    }

    /// The ray of a perspective or orthographic camera as glam's transforms give it (what the
    /// camera computed before its rays were written over lanes).
    fn glam_ray(cam: &Camera, film: Vec2, lens: Vec2) -> Ray {
        let [x0, x1, y0, y1] = cam.window;
        let s = Vec2::new(
            x0 + film.x / cam.width * (x1 - x0),
            y1 - film.y / cam.height * (y1 - y0),
        );
        let (origin, dir) = match cam.projection {
            Projection::Perspective { tan_half_fov } => (
                Vec3::ZERO,
                Vec3::new(s.x * tan_half_fov, s.y * tan_half_fov, 1.0),
            ),
            _ => (Vec3::new(s.x, s.y, 0.0), Vec3::Z),
        };
        let (origin, dir) = if cam.lens_radius <= 0.0 {
            (origin, dir)
        } else {
            let on_lens = crate::bxdf::local::sample_disk_concentric(lens) * cam.lens_radius;
            let focus = origin + dir * (cam.focal_distance / dir.z);
            let lens_point = origin + Vec3::new(on_lens.x, on_lens.y, 0.0);
            (lens_point, focus - lens_point)
        };
        Ray::new(
            cam.camera_to_world.transform_point3(origin),
            cam.camera_to_world.transform_vector3(dir).normalize(),
        )
    }

    /// Perspective and orthographic rays in lanes, with and without a lens, under a turned and
    /// moved camera with an uneven screen window: every lane type gives, lane by lane, the bits
    /// of glam's transforms of the camera-space ray; a fisheye camera has none in lanes.
    #[test]
    fn rays_in_lanes_are_glams_rays_bit_for_bit() {
        use crate::lanes::tests::on_every_lane_type;
        use crate::lanes::OnLanes;
        use crate::lanes::MAX_LANES;

        struct Agrees(Vec<Camera>);
        impl OnLanes for Agrees {
            type Output = ();
            fn run<L: Lanes>(&self) {
                let mut rng = fastrand::Rng::with_seed(4);
                for cam in &self.0 {
                    for _ in 0..500 {
                        let mut v = [[0.0; MAX_LANES]; 4];
                        let scales = [cam.width, cam.height, 1.0, 1.0];
                        for (row, scale) in v.iter_mut().zip(scales) {
                            for value in &mut row[..L::N] {
                                *value = rng.f32() * scale;
                            }
                        }
                        let film = [L::load(&v[0]), L::load(&v[1])];
                        let lens = [L::load(&v[2]), L::load(&v[3])];
                        let (origin, dir) = cam.flat_rays(film, lens).expect("a flat camera");
                        let (origin, dir) = (origin.map(L::values), dir.map(L::values));
                        for i in 0..L::N {
                            let want = glam_ray(
                                cam,
                                Vec2::new(v[0][i], v[1][i]),
                                Vec2::new(v[2][i], v[3][i]),
                            );
                            let got = [origin, dir].map(|r| [r[0][i], r[1][i], r[2][i]]);
                            let bits = |v: [f32; 3]| v.map(f32::to_bits);
                            assert_eq!(bits(got[0]), bits(want.origin.to_array()), "{cam:?}");
                            assert_eq!(bits(got[1]), bits(want.dir.to_array()), "{cam:?}");
                        }
                    }
                }
            }
        }
        let turned = Mat4::from_translation(Vec3::new(0.3, -4.0, 1.7))
            * Mat4::from_rotation_z(0.7)
            * Mat4::from_rotation_x(-1.2);
        let camera = |kind, lens_radius| {
            let desc = CameraDesc {
                camera_to_world: turned,
                screen_window: [-1.7, 1.7, -0.95, 0.95],
                ..desc(kind, lens_radius)
            };
            Camera::new(&desc, 96, 54)
        };
        let perspective = CameraKind::Perspective { fov: 40.0 };
        let cameras = vec![
            camera(perspective.clone(), 0.0),
            camera(perspective, 0.15),
            camera(CameraKind::Orthographic, 0.0),
            camera(CameraKind::Orthographic, 0.1),
        ];
        on_every_lane_type(&Agrees(cameras));
        let fisheye = camera(CameraKind::Fisheye { fov: 180.0 }, 0.0);
        assert!(fisheye.flat_rays([0.5f32; 2], [0.5; 2]).is_none());
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

    /// LuxRender's default focal distance (1e30) with a lens: rays leave the lens points
    /// parallel to the pinhole's, so the image is sharp at infinity, not black.
    #[test]
    fn a_lens_at_the_default_focal_distance_is_focused_at_infinity() {
        let kind = CameraKind::Perspective { fov: 60.0 };
        let far = CameraDesc {
            focal_distance: crate::camera::DEFAULT_FOCAL_DISTANCE,
            ..desc(kind.clone(), 0.1)
        };
        let (cam, pinhole) = (
            Camera::new(&far, 64, 32),
            Camera::new(&desc(kind, 0.0), 64, 32),
        );
        let mut rng = fastrand::Rng::with_seed(3);
        for _ in 0..200 {
            let film = Vec2::new(rng.f32() * 64.0, rng.f32() * 32.0);
            let lens = Vec2::new(rng.f32(), rng.f32());
            let ray = cam.generate_ray(film, lens).unwrap();
            let straight = pinhole.generate_ray(film, lens).unwrap();
            assert!(ray.origin.is_finite() && ray.dir.is_finite(), "{ray:?}");
            assert!(
                (ray.dir - straight.dir).length() < 1e-6,
                "{ray:?} vs {straight:?}"
            );
            assert!(ray.origin.length() <= 0.1 + 1e-6);
        }
    }

    /// Autofocus aims the pinhole ray where LuxRender does (half its sample extent: the
    /// film's middle moved by the filter radius, floored as it floors it) and focuses at the
    /// hit's distance from the hither plane along that ray.
    #[test]
    fn autofocus_focuses_on_the_centre_rays_first_hit() {
        let mut cam = Camera::new(&desc(CameraKind::Perspective { fov: 60.0 }, 0.2), 64, 32);
        let pinhole = Camera::new(&desc(CameraKind::Perspective { fov: 60.0 }, 0.0), 64, 32);
        let mut aimed = None;
        // Radius 2: the extent runs from floor(-1.5) = -2 to floor(66.5) = 66 across, so
        // its half is 34; down, -2 to 34, half 18.
        let focal = cam.autofocus(Vec2::splat(2.0), |ray| {
            aimed = Some(*ray);
            Some(7.0)
        });
        let want = pinhole
            .generate_ray(Vec2::new(34.0, 18.0), Vec2::ZERO)
            .unwrap();
        let aimed = aimed.expect("autofocus traced a ray");
        assert!(
            (aimed.dir - want.dir).length() < 1e-6,
            "{aimed:?} vs {want:?}"
        );
        let cos = (cam.world_to_camera.transform_vector3(want.dir)).z;
        let focal = focal.expect("a hit focuses");
        assert!((focal - (7.0 - 1e-3 / cos)).abs() < 1e-5, "{focal}");
        assert_eq!(cam.focal_distance(), focal);
        // Nothing hit: the focal distance stays.
        let before = cam.focal_distance();
        assert_eq!(cam.autofocus(Vec2::splat(2.0), |_| None), None);
        assert_eq!(cam.focal_distance(), before);
        let mut fisheye = Camera::new(&desc(CameraKind::Fisheye { fov: 90.0 }, 0.0), 64, 32);
        assert_eq!(fisheye.autofocus(Vec2::ZERO, |_| Some(1.0)), None);
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
