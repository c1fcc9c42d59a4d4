//! The camera seen from the scene: where on the film a world point is seen through a lens
//! point, and the density of the camera's rays there. Light tracing (a light subpath's vertex
//! connected to the camera) needs both, and bidirectional path tracing's multiple importance
//! sampling needs the density of a camera path's first vertex.
//!
//! One quantity serves both: the camera's ray density at a point `x` per unit area
//! perpendicular to the ray, given the lens point, over the whole film (every camera sample of
//! the film counted, those outside a fisheye's circle too). The film divides light splats by
//! the light subpaths per pixel (`film.rs`), so a light-tracing splat is the light subpath's
//! throughput times the BSDF toward the lens times `|cos|` at `x` times this density: its
//! expectation over the film's light subpaths is then each pixel's mean radiance, the camera
//! estimate's. For a camera path, the density times `|cos|` at its first hit is that vertex's
//! area density given its lens point (the lens point's own density cancels: both strategies
//! sample it alike).
//!
//! - Pinhole and thin-lens perspective: the density of directions from the lens point is
//!   `1 / (A cos^3 theta)` per solid angle, A the screen window's area on the plane one unit
//!   ahead (theta from the view axis; for a lens point the focal plane maps to the screen as
//!   the pinhole's does, so the same form holds), divided by the squared distance.
//! - Orthographic: parallel rays from a lens offset `o` all run along `(-o, focaldistance)`;
//!   the density per perpendicular area is `1 / (A cos theta)`, A the screen window's area.
//! - Fisheye (the course's equidistant mapping, no lens): raster radius r = psi / fov, so the
//!   direction density is `psi / (4 fov^2 sin psi)` (the screen's normalised square is 4 units
//!   of area), divided by the squared distance.

use glam::{Vec2, Vec3};

use super::rays::{Camera, Projection};

/// A world point as the camera sees it through a lens point: the light-tracing connection.
#[derive(Clone, Copy, Debug)]
pub struct CameraView {
    /// Raster position on the film.
    pub raster: Vec2,
    /// The lens point (world space; the pinhole without a lens).
    pub lens_point: Vec3,
    /// The camera's ray density at the point per unit area perpendicular to the ray (see the
    /// module's notes), given the lens point.
    pub density: f32,
}

impl Camera {
    /// Where world point `x` lands on the film through the lens point `u_lens` chooses (the
    /// same lens point a camera ray of that `u_lens` leaves from), and the camera's ray density
    /// there; None where the camera does not see `x` (behind it, off the film, outside a
    /// fisheye's circle).
    pub fn view(&self, x: Vec3, u_lens: Vec2) -> Option<CameraView> {
        let c = self.world_to_camera.transform_point3(x);
        let offset =
            if self.lens_radius > 0.0 && !matches!(self.projection, Projection::Fisheye { .. }) {
                self.aperture.sample(u_lens) * self.lens_radius
            } else {
                Vec2::ZERO
            };
        let (screen, lens, density) = match self.projection {
            Projection::Perspective { tan_half_fov } => {
                let lens = offset.extend(0.0);
                let d = c - lens;
                if d.z <= 0.0 {
                    return None;
                }
                // The focal plane point the ray from the lens point crosses, seen from the
                // pinhole (without a lens: the direction itself).
                let focus = if self.lens_radius > 0.0 {
                    lens + d * (self.focal_distance / d.z)
                } else {
                    d
                };
                let screen = focus.truncate() / (focus.z * tan_half_fov);
                let cos = d.z / d.length();
                let area = self.screen_area() * tan_half_fov * tan_half_fov;
                (screen, lens, 1.0 / (area * cos * cos * cos))
            }
            Projection::Orthographic => {
                if c.z <= 0.0 {
                    return None;
                }
                // The screen point whose ray through the lens offset meets `c` (the ray runs
                // from (s + o, 0) to (s, focaldistance)).
                let screen = if self.lens_radius > 0.0 {
                    c.truncate() + offset * (c.z / self.focal_distance - 1.0)
                } else {
                    c.truncate()
                };
                let lens = (screen + offset).extend(0.0);
                let along = Vec3::new(-offset.x, -offset.y, self.focal_distance);
                let cos = if self.lens_radius > 0.0 {
                    along.z / along.length()
                } else {
                    1.0
                };
                (screen, lens, 1.0 / (self.screen_area() * cos))
            }
            Projection::Fisheye { fov_radians } => {
                let length = c.length();
                if length <= 0.0 {
                    return None;
                }
                let dir = c / length;
                let psi = libm::acosf(dir.z.clamp(-1.0, 1.0));
                let r = psi / fov_radians;
                if r > 1.0 {
                    return None;
                }
                let planar = dir.truncate();
                let around = planar.length();
                let screen = if around > 0.0 {
                    planar * (r / around)
                } else {
                    Vec2::ZERO
                };
                let sin = libm::sinf(psi);
                // psi / sin psi tends to 1 on the axis.
                let ratio = if sin > 1e-6 { psi / sin } else { 1.0 };
                let density = ratio / (4.0 * fov_radians * fov_radians);
                // The fisheye's screen is the normalised square [-1, 1]^2.
                let raster = Vec2::new(
                    (screen.x + 1.0) * 0.5 * self.width,
                    (1.0 - screen.y) * 0.5 * self.height,
                );
                return self.seen(raster, Vec3::ZERO, x, density);
            }
        };
        let [x0, x1, y0, y1] = self.window;
        let raster = Vec2::new(
            (screen.x - x0) / (x1 - x0) * self.width,
            (y1 - screen.y) / (y1 - y0) * self.height,
        );
        self.seen(raster, lens, x, density)
    }

    /// The camera's ray density at world point `x` per unit area perpendicular to the ray
    /// from `lens_point` (see [`CameraView::density`]); 0 where the camera does not see `x`.
    /// For a camera path's first vertex, whose ray left from `lens_point`.
    pub fn density_at(&self, lens_point: Vec3, x: Vec3) -> f32 {
        let lens = self.world_to_camera.transform_point3(lens_point);
        // The lens offset that point is at: for an orthographic lens, its offset from the
        // screen point its ray left from, which `view` finds again from the offset.
        let c = self.world_to_camera.transform_point3(x);
        let density = match self.projection {
            Projection::Perspective { tan_half_fov } => {
                let d = c - lens;
                if d.z <= 0.0 {
                    return 0.0;
                }
                let cos = d.z / d.length();
                let area = self.screen_area() * tan_half_fov * tan_half_fov;
                1.0 / (area * cos * cos * cos) / self.distance_squared(lens_point, x)
            }
            Projection::Orthographic => {
                let d = c - lens;
                if d.z <= 0.0 {
                    return 0.0;
                }
                1.0 / (self.screen_area() * d.z / d.length()) / self.area_scale
            }
            Projection::Fisheye { fov_radians } => {
                let length = c.length();
                if length <= 0.0 {
                    return 0.0;
                }
                let psi = libm::acosf((c.z / length).clamp(-1.0, 1.0));
                if psi > fov_radians {
                    return 0.0;
                }
                let sin = libm::sinf(psi);
                let ratio = if sin > 1e-6 { psi / sin } else { 1.0 };
                ratio / (4.0 * fov_radians * fov_radians) / self.distance_squared(lens_point, x)
            }
        };
        if density.is_finite() {
            density
        } else {
            0.0
        }
    }

    /// The view of `x` at `raster` through camera-space lens point `lens`, with the density
    /// per solid angle (perspective, fisheye) or per camera-space area (orthographic) turned
    /// into world units; None off the film.
    fn seen(&self, raster: Vec2, lens: Vec3, x: Vec3, density: f32) -> Option<CameraView> {
        let on_film =
            (0.0..self.width).contains(&raster.x) && (0.0..self.height).contains(&raster.y);
        if !on_film || !density.is_finite() {
            return None;
        }
        let lens_point = self.camera_to_world.transform_point3(lens);
        let density = match self.projection {
            Projection::Orthographic => density / self.area_scale,
            _ => density / self.distance_squared(lens_point, x),
        };
        (density.is_finite() && density > 0.0).then_some(CameraView {
            raster,
            lens_point,
            density,
        })
    }

    fn distance_squared(&self, lens_point: Vec3, x: Vec3) -> f32 {
        lens_point.distance_squared(x)
    }

    /// The screen window's area in screen units.
    fn screen_area(&self) -> f32 {
        let [x0, x1, y0, y1] = self.window;
        ((x1 - x0) * (y1 - y0)).abs()
    }
}

#[cfg(test)]
mod tests {
    use glam::Mat4;

    use super::*;
    use crate::camera::desc::{CameraDesc, CameraKind};

    fn camera(kind: CameraKind, lens_radius: f32) -> Camera {
        let camera_to_world = Mat4::from_translation(Vec3::new(0.3, -4.0, 1.7))
            * Mat4::from_rotation_z(0.7)
            * Mat4::from_rotation_x(-1.2);
        let desc = CameraDesc {
            kind,
            camera_to_world,
            screen_window: [-1.7, 1.7, -0.95, 0.95],
            lens_radius,
            focal_distance: 5.0,
            autofocus: false,
            aperture: Default::default(),
            hither: 1e-3,
            yon: 1e30,
        };
        Camera::new(&desc, 96, 54)
    }

    fn cameras() -> Vec<Camera> {
        let hexagonal = Camera {
            aperture: crate::camera::aperture::Aperture {
                blades: 6,
                distribution: crate::camera::aperture::LensDistribution::Gaussian,
            },
            ..camera(CameraKind::Perspective { fov: 40.0 }, 0.3)
        };
        let at_infinity = Camera {
            focal_distance: super::super::rays::MAX_FOCAL_DISTANCE,
            ..camera(CameraKind::Perspective { fov: 40.0 }, 0.3)
        };
        vec![
            camera(CameraKind::Perspective { fov: 40.0 }, 0.0),
            camera(CameraKind::Perspective { fov: 40.0 }, 0.3),
            hexagonal,
            at_infinity,
            camera(CameraKind::Orthographic, 0.0),
            camera(CameraKind::Orthographic, 0.3),
            camera(CameraKind::Fisheye { fov: 60.0 }, 0.0),
        ]
    }

    /// A point on a camera ray, viewed through the ray's own lens sample, lands where the ray
    /// left the film, through the lens point it left from, and its density is the one the
    /// camera path's first vertex there gets.
    #[test]
    fn a_point_on_a_camera_ray_is_seen_where_the_ray_started() {
        let mut rng = fastrand::Rng::with_seed(11);
        for cam in cameras() {
            let mut checked = 0;
            for _ in 0..2000 {
                let film = Vec2::new(rng.f32() * 96.0, rng.f32() * 54.0);
                let lens = Vec2::new(rng.f32(), rng.f32());
                let Some(ray) = cam.generate_ray(film, lens) else {
                    continue;
                };
                let x = ray.at(0.5 + 9.0 * rng.f32());
                let view = cam.view(x, lens).expect("a point on a camera ray is seen");
                assert!(
                    (view.raster - film).length() < 2e-3,
                    "{:?}: {} vs {film}",
                    cam.projection,
                    view.raster
                );
                assert!(
                    (view.lens_point - ray.origin).length() < 1e-4,
                    "{:?}",
                    cam.projection
                );
                let density = cam.density_at(view.lens_point, x);
                assert!(
                    (density / view.density - 1.0).abs() < 1e-4,
                    "{:?}: {density} vs {}",
                    cam.projection,
                    view.density
                );
                checked += 1;
            }
            assert!(checked > 1000);
        }
    }

    /// Over a plane every camera ray of one lens point crosses, the density times the cosine
    /// integrates to the share of the film's samples that have a ray: 1, and pi / 4 for the
    /// fisheye's circle in its square. This is the normalisation light tracing relies on.
    #[test]
    fn density_integrates_to_the_films_share_of_rays() {
        for cam in cameras() {
            for u_lens in [Vec2::new(0.5, 0.5), Vec2::new(0.9, 0.2)] {
                // A plane across the view, tilted, 7 units ahead in camera space.
                let to_world = cam.camera_to_world;
                let normal = to_world
                    .transform_vector3(Vec3::new(0.2, -0.1, 1.0))
                    .normalize();
                let centre = to_world.transform_point3(Vec3::new(0.0, 0.0, 7.0));
                let u_axis = normal.any_orthonormal_vector();
                let v_axis = normal.cross(u_axis);
                let half = match cam.projection {
                    Projection::Perspective { .. } => 6.0,
                    Projection::Orthographic => 3.0,
                    Projection::Fisheye { .. } => 20.0,
                };
                let n = 800;
                let step = 2.0 * half / n as f32;
                let mut total = 0.0f64;
                for i in 0..n {
                    for j in 0..n {
                        let a = -half + (i as f32 + 0.5) * step;
                        let b = -half + (j as f32 + 0.5) * step;
                        let x = centre + u_axis * a + v_axis * b;
                        // Only what this lens point sees: the same point's view through
                        // the lens sample.
                        let Some(view) = cam.view(x, u_lens) else {
                            continue;
                        };
                        let cos = (x - view.lens_point).normalize().dot(normal).abs();
                        total += f64::from(view.density * cos * step * step);
                    }
                }
                let want = match cam.projection {
                    Projection::Fisheye { .. } => std::f64::consts::FRAC_PI_4,
                    _ => 1.0,
                };
                assert!(
                    (total / want - 1.0).abs() < 0.01,
                    "{:?} lens {u_lens}: {total} vs {want}",
                    cam.projection
                );
            }
        }
    }

    #[test]
    fn points_behind_or_off_the_film_are_not_seen() {
        for cam in cameras() {
            let behind = cam
                .camera_to_world
                .transform_point3(Vec3::new(0.0, 0.0, -3.0));
            assert!(
                cam.view(behind, Vec2::splat(0.5)).is_none(),
                "{:?}",
                cam.projection
            );
            let aside = cam
                .camera_to_world
                .transform_point3(Vec3::new(500.0, 0.0, 1.0));
            assert!(
                cam.view(aside, Vec2::splat(0.5)).is_none(),
                "{:?}",
                cam.projection
            );
        }
    }
}
